#!/usr/bin/env bash
# Output folders shared by processes (docs/CLUSTER.md "Shared file systems", docs/USAGE.md "The
# commands"): shards in two PID namespaces (two nodes), the folder lock, merge's printed commands
# and `geomint slurm --out` with a folder name that needs quoting, each run as a user would.
# Usage: sweep_io_test.sh GEOMINT CASE (namespaces | lock | merge_again | slurm_out); exit 77:
# skipped (unshare not permitted).
set -euo pipefail
geomint=$(realpath "$1")
case_name=$2
say() { echo "sweep_io $case_name: $*" >&2; }
fail() { say "FAILED: $*"; exit 1; }

tmp=$(mktemp -d /tmp/geomint-sweep-io.XXXXXX)
pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill "$pid" 2> /dev/null || true; done
  for pid in "${pids[@]}"; do wait "$pid" 2> /dev/null || true; done
  rm -rf "$tmp"
}
trap cleanup EXIT
# A folder name that a script must quote: a space and a command substitution, which would create
# the file PWNED if any script or printed command ran it unquoted.
work="$tmp/a b \$(touch PWNED)"
mkdir -p "$work/scene"
cd "$work"
scene="$work/scene/scene.toml"
out="$work/out"

# A scene of two runs (two units, so two shards) with series: unit 0 (block a) runs to t = $1,
# unit 1 (block b) to t = $2 (default $1), so shard 1/2 can end while shard 0/2 still runs; $3
# is timing_repeats (default 0).
write_scene() {
  echo 'title = "sweep io"' > "$scene"
  local label method t_end
  for block in "a stormer_verlet $1" "b symplectic_euler_a ${2:-$1}"; do
    read -r label method t_end <<< "$block"
    printf '[[runs]]\nlabel = "%s"\nproblems = ["pendulum"]\nmethods = ["%s"]\ndt = 1e-4\n' \
      "$label" "$method" >> "$scene"
    printf 't_end = %s\nseries_every = 1000\ntiming_repeats = %s\nmax_steps = 1000000000\n' \
      "$t_end" "${3:-0}" >> "$scene"
  done
}
# Waits (10 s at most) until a file matching the glob pattern exists.
wait_for() {
  for _ in $(seq 100); do
    compgen -G "$1" > /dev/null && return 0
    sleep 0.1
  done
  fail "no file $1 after 10 s"
}
no_pwned() { [ -z "$(find "$tmp" / -maxdepth 1 -name PWNED 2> /dev/null)" ] || fail "a path ran"; }

case $case_name in
namespaces)
  # Two shards into one folder from two PID namespaces, as from two nodes of a shared file system:
  # each namespace numbers its processes from 1, so a PID of one says nothing in the other.
  unshare --pid --fork --mount-proc true 2> /dev/null || { say "skipped: unshare not permitted"; exit 77; }
  write_scene 1000 1
  # Shard A's geomint gets PID ~10 in its namespace (processes started before it), shard B's 2:
  # A's PID is not alive in B's namespace.
  in_namespace() {
    local before=$1
    shift
    unshare --pid --fork --mount-proc bash -c \
      'for ((i = 0; i < $0; i++)); do /bin/true; done; "$@"; status=$?; exit $status' \
      "$before" "$geomint" sweep "$scene" --out "$out" --no-timing "$@"
  }
  in_namespace 8 --shard 0/2 2> "$tmp/a.log" &
  a=$!
  pids+=($a)
  wait_for "$out/series/a/stormer_verlet.csv.*.tmp"
  in_namespace 0 --shard 1/2 2> "$tmp/b.log" || fail "shard B exited $?: $(cat "$tmp/b.log")"
  kill -0 $a 2> /dev/null || fail "shard A ended before shard B: the shards did not overlap"
  wait $a || fail "shard A exited $?: $(cat "$tmp/a.log")"
  "$geomint" merge "$out" --scene "$scene" 2> "$tmp/merge.log" || fail "merge: $(cat "$tmp/merge.log")"
  for series in a/stormer_verlet b/symplectic_euler_a; do
    [ -s "$out/series/$series.csv" ] || fail "the series $series is lost: $(ls -R "$out/series")"
  done
  if grep -q ',error,' "$out/summary.csv"; then fail "error rows: $(grep ',error,' "$out/summary.csv")"; fi
  [ "$(grep -c ',ok,' "$out/summary.csv")" = 2 ] || fail "summary: $(cat "$out/summary.csv")"
  ! compgen -G "$out/series/*/*.tmp" > /dev/null || fail "temporaries left"
  say "both shards' series survived and merged"
  ;;
lock)
  write_scene 1000 1
  # A sweep holds the folder: a second sweep, and a shard, are refused at once naming it.
  "$geomint" sweep "$scene" --out "$out" --no-timing 2> "$tmp/a.log" &
  a=$!
  pids+=($a)
  wait_for "$out/series/a/*.tmp"
  status=0
  timeout 20 "$geomint" sweep "$scene" --out "$out" --no-timing 2> "$tmp/b.log" || status=$?
  [ $status = 2 ] || fail "a second sweep into the folder exited $status, not 2: $(cat "$tmp/b.log")"
  grep -q "in use by geomint sweep (pid $a on host $(hostname))" "$tmp/b.log" ||
    fail "the message does not name the holder: $(cat "$tmp/b.log")"
  status=0
  timeout 20 "$geomint" sweep "$scene" --out "$out" --shard 0/2 2> "$tmp/c.log" || status=$?
  [ $status = 2 ] || fail "a shard into the folder exited $status, not 2: $(cat "$tmp/c.log")"
  wait $a || fail "the first sweep exited $?: $(cat "$tmp/a.log")"
  [ ! -e "$out/.geomint.lock" ] || fail "the lock file outlived the sweep"
  [ "$(grep -c ',ok,' "$out/summary.csv")" = 2 ] || fail "summary: $(cat "$out/summary.csv")"
  # Shards of one sweep share the folder; a merge waits for none of them and is refused.
  rm -rf "$out"
  "$geomint" sweep "$scene" --out "$out" --shard 0/2 2> "$tmp/d.log" &
  d=$!
  pids+=($d)
  wait_for "$out/series/a/*.tmp"
  timeout 60 "$geomint" sweep "$scene" --out "$out" --shard 1/2 2> "$tmp/e.log" ||
    fail "a second shard was refused: $(cat "$tmp/e.log")"
  kill -0 $d 2> /dev/null || fail "shard 0/2 ended before shard 1/2: the shards did not overlap"
  status=0
  timeout 20 "$geomint" merge "$out" --scene "$scene" 2> "$tmp/f.log" || status=$?
  [ $status = 2 ] || fail "a merge while a shard runs exited $status, not 2: $(cat "$tmp/f.log")"
  wait $d || fail "shard 0/2 exited $?: $(cat "$tmp/d.log")"
  "$geomint" merge "$out" --scene "$scene" 2> "$tmp/g.log" || fail "merge: $(cat "$tmp/g.log")"
  say "a second sweep was refused naming the first; shards shared the folder"
  ;;
merge_again)
  # A shard failed; merge's printed commands, run as printed, finish the sweep (the output
  # folder is outside the scene's folder, so merge needs --scene).
  write_scene 1
  "$geomint" sweep "$scene" --out "$out" --shard 0/2 2> /dev/null
  status=0
  GEOMINT_FAIL_SHARD=1 "$geomint" sweep "$scene" --out "$out" --shard 1/2 2> /dev/null || status=$?
  [ $status = 1 ] || fail "the failing shard exited $status, not 1"
  status=0
  "$geomint" merge "$out" --scene "$scene" 2> "$tmp/merge.log" || status=$?
  [ $status = 1 ] || fail "merge with a shard missing exited $status: $(cat "$tmp/merge.log")"
  without_slurm=$(sed -n 's/^  (without Slurm: \(.*\))$/\1/p' "$tmp/merge.log")
  merge_again=$(sed -n 's/^then merge again: //p' "$tmp/merge.log")
  [ -n "$without_slurm" ] && [ -n "$merge_again" ] || fail "no commands in: $(cat "$tmp/merge.log")"
  geomint() { "$geomint" "$@"; }
  eval "$without_slurm" 2> /dev/null || fail "the printed shard command failed: $without_slurm"
  eval "$merge_again" 2> "$tmp/again.log" || fail "'$merge_again' exited $?: $(cat "$tmp/again.log")"
  [ "$(grep -c ',ok,' "$out/summary.csv")" = 2 ] || fail "summary: $(cat "$out/summary.csv")"
  no_pwned
  say "ran as printed: $merge_again"
  ;;
slurm_out)
  # geomint slurm --out: the scripts, shards, logs and tables all in the folder; run here
  # without Slurm (the array index from SLURM_ARRAY_TASK_ID, srun replaced by a pass-through).
  write_scene 1 1 1
  "$geomint" slurm "$scene" --shards 2 --out "$out" > "$tmp/printed.txt" 2> "$tmp/slurm.log" ||
    fail "geomint slurm --out exited $?: $(cat "$tmp/slurm.log")"
  printf '%s\n' "$out/sweep.sbatch" "$out/merge.sbatch" "$out/timing.sbatch" |
    diff - "$tmp/printed.txt" > /dev/null || fail "printed: $(cat "$tmp/printed.txt")"
  [ "$(ls -A "$work/scene")" = scene.toml ] || fail "written next to the scene: $(ls -A "$work/scene")"
  mkdir -p "$tmp/bin"
  printf '#!/bin/bash\nwhile [[ $1 == -* ]]; do shift; done\nexec "$@"\n' > "$tmp/bin/srun"
  chmod +x "$tmp/bin/srun"
  for i in 0 1; do
    SLURM_ARRAY_TASK_ID=$i bash "$out/sweep.sbatch" 2> /dev/null || fail "sweep.sbatch task $i"
  done
  [ -s "$out/shards/summary.1-of-2.csv" ] || fail "no shard in $out/shards"
  bash "$out/merge.sbatch" 2> "$tmp/merge.log" || fail "merge.sbatch: $(cat "$tmp/merge.log")"
  PATH="$tmp/bin:$PATH" bash "$out/timing.sbatch" 2> "$tmp/timing.log" ||
    fail "timing.sbatch: $(cat "$tmp/timing.log")"
  [ -d "$out/slurm-logs" ] || fail "no slurm-logs folder"
  [ "$(grep -c ',ok,' "$out/summary.csv")" = 2 ] || fail "summary: $(cat "$out/summary.csv")"
  grep -v '^#' "$out/summary.csv" | head -n 1 | tr , '\n' | grep -qx wall_s ||
    fail "timing.sbatch wrote no wall_s: $(cat "$out/summary.csv")"
  [ "$(ls -A "$work/scene")" = scene.toml ] || fail "written next to the scene: $(ls -A "$work/scene")"
  no_pwned
  say "sweep, merge and timing scripts ran into '$out'"
  ;;
*)
  fail "unknown case (namespaces, lock, merge_again, slurm_out)"
  ;;
esac
