#!/usr/bin/env bash
# `make test-cluster` (docs/CLUSTER.md "Running on a cluster", issue 16): a real single-node Slurm on this
# machine runs a committed scene through `geomint slurm --submit` with 8 shards, and the merged,
# timed tables must equal a single-machine sweep (timings and dates aside); then, into a folder
# of its own (`--out`), one shard is made to fail, resubmitted alone and merged with the commands
# merge's message prints, and the tables are checked again.
# Needs root (it installs the Debian packages and starts munged, slurmctld and slurmd, every one
# stopped by PID on exit). Usage: test-cluster.sh [GEOMINT_BINARY] [SCENE_NAME]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
geomint=$(realpath "${1:-$root/build/geomint}")
scene_name=${2:-fig1_pendulum}
shards=8
start=$(date +%s)
say() { echo "test-cluster: $*" >&2; }
fail() { say "FAILED: $*"; exit 1; }

if [ "$(id -u)" -ne 0 ]; then
  fail "needs root: it starts munged, slurmctld and slurmd (run: sudo make test-cluster)"
fi
bash "$root/scripts/install-deps.sh" cluster --quiet

work=$(mktemp -d /tmp/geomint-cluster.XXXXXX)
chmod 711 "$work"  # munged wants its socket's folders searchable by every user
pids=()
cleanup() {
  local status=$?
  for ((i = ${#pids[@]} - 1; i >= 0; i--)); do kill "${pids[i]}" 2>/dev/null || true; done
  for pid in "${pids[@]}"; do
    for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.2; done
    kill -9 "$pid" 2>/dev/null || true
  done
  if [ $status -ne 0 ]; then
    for log in "$work"/*.log "$work"/scene/"$scene_name"/quick/slurm-logs/*; do
      [ -f "$log" ] && { echo "== $log"; tail -n 20 "$log"; } >&2
    done
  fi
  rm -rf "$work"
}
trap cleanup EXIT

# Daemons: private munge key and socket, a generated slurm.conf (no systemd, no accounting
# daemon, cgroup auto-detection, this node's line from `slurmd -C`), all in foreground so that $!
# is the daemon's PID.
head -c 1024 /dev/urandom > "$work/munge.key"
chmod 400 "$work/munge.key"
/usr/sbin/munged --foreground --force --socket="$work/munge.sock" --key-file="$work/munge.key" \
  --pid-file="$work/munged.pid" --seed-file="$work/munged.seed" --log-file="$work/munged.log" \
  2>> "$work/munged.log" &
pids+=($!)
for _ in $(seq 50); do [ -S "$work/munge.sock" ] && break; sleep 0.1; done
mkdir -p "$work/state" "$work/spool"
export SLURM_CONF="$work/slurm.conf"
port=$((20000 + RANDOM % 20000))  # not the default 6817/6818, which a real Slurm may hold
cat > "$SLURM_CONF" <<EOF
ClusterName=geomint-test
SlurmctldHost=$(hostname -s)(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$work/munge.sock
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/affinity
MpiDefault=none
ReturnToService=2
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
JobCompType=jobcomp/none
DependencyParameters=kill_invalid_depend
MinJobAge=600
$(slurmd -C | head -n 1) State=UNKNOWN
PartitionName=test Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
printf 'CgroupPlugin=autodetect\nIgnoreSystemd=yes\n' > "$work/cgroup.conf"
/usr/sbin/slurmctld -D -f "$SLURM_CONF" 2>> "$work/slurmctld.log" &
pids+=($!)
/usr/sbin/slurmd -D -f "$SLURM_CONF" 2>> "$work/slurmd.log" &
pids+=($!)
for _ in $(seq 60); do
  [ "$(sinfo -h -N -o %T 2>/dev/null)" = idle ] && break
  sleep 0.5
done
[ "$(sinfo -h -N -o %T 2>/dev/null)" = idle ] || fail "the node did not become idle in 30 s"
say "Slurm up (node idle) after $(($(date +%s) - start)) s"

# The scene is a copy of a committed one (its quick variant), so nothing lands in results/;
# the scripts cd to the repository, where results/references lives.
scene="$work/scene/$scene_name/scene.toml"
out="$work/scene/$scene_name/quick"
mkdir -p "$(dirname "$scene")"
cp "$root/results/$scene_name/scene.toml" "$scene"
cd "$root"
"$geomint" sweep "$scene" --quick 2> /dev/null  # the command the timed merge names
mkdir -p "$work/local"
cp "$out"/*.csv "$out/table.md" "$work/local/"
rm -rf "$out"

# Waits until every job named has left the queue; prints each one's final state.
wait_jobs() {
  local deadline=$(($(date +%s) + 120))
  while squeue -h -j "$(IFS=,; echo "$*")" 2>/dev/null | grep -q .; do
    [ "$(date +%s)" -lt $deadline ] || fail "jobs $* still queued after 120 s"
    sleep 0.5
  done
  for job in "$@"; do
    echo "$job:$(scontrol show job "$job" | grep -o 'JobState=[A-Z_]*' | head -n 1 | cut -d= -f2)"
  done
}
# True when every "job:STATE" given ends COMPLETED.
all_completed() { ! echo "$@" | tr ' ' '\n' | grep -qv ':COMPLETED$'; }
submitted_ids() { sed -n 's/.* as job \([0-9]*\)$/\1/p' "$1" | tr '\n' ' '; }

# The merged and timed tables against the single-machine ones: equal but for timings and dates.
compare_tables() {
  /usr/bin/python3 - "${1:-$work/local}" "$out" <<'EOF'
import csv, io, sys
# Machine-dependent: the timing columns (wall_s and its statistics wall_s_min, wall_s_iqr,
# wall_s_repeats) and the dates (provenance, and the "How to cite" block of table.md).
def timing(name): return name.strip().startswith("wall_s")
def normal(path):
    text = open(path).read()
    lines = [l for l in text.splitlines() if not l.startswith("# date: ")
             and not l.startswith("| date | ") and not l.startswith("> geomint ")]
    if path.endswith(".md"):
        out, walls = [], []
        for line in lines:
            cells = line.split("|")
            if line.startswith("|") and any(timing(c) for c in cells):
                walls = [k for k, c in enumerate(cells) if timing(c)]
            if not line.startswith("|"): walls = []
            for k in walls:
                if k < len(cells): cells[k] = ""
            out.append("|".join(cells))
        return out
    head = [l for l in lines if l.startswith("#")]
    rows = list(csv.reader(io.StringIO("\n".join(l for l in lines if not l.startswith("#")))))
    walls = [k for k, name in enumerate(rows[0]) if timing(name)]
    for row in rows[1:]:
        for k in walls: row[k] = ""
    return head + rows
bad = []
for name in ["summary.csv", "table.md"]:
    a, b = normal(f"{sys.argv[1]}/{name}"), normal(f"{sys.argv[2]}/{name}")
    if a != b:
        first = next((k for k, (x, y) in enumerate(zip(a, b)) if x != y), min(len(a), len(b)))
        show = lambda rows: rows[first] if first < len(rows) else "(no line)"
        bad.append(f"{name} (first difference, line {first + 1}: local {show(a)!r}, "
                   f"merged {show(b)!r})")
if bad: sys.exit("differ from the single-machine sweep: " + "; ".join(bad))
EOF
}

# 1. The whole cycle: 8 shards, merge, pinned timing.
cycle_start=$(date +%s)
"$geomint" slurm "$scene" --quick --shards $shards --submit > /dev/null 2> "$work/submit1.txt"
read -r -a jobs <<< "$(submitted_ids "$work/submit1.txt")"
[ ${#jobs[@]} -eq 3 ] || fail "geomint slurm --submit did not submit 3 jobs: $(cat "$work/submit1.txt")"
states=$(wait_jobs "${jobs[@]}")
cycle=$(($(date +%s) - cycle_start))
all_completed $states || fail "jobs ended: $(echo $states)"
compare_tables || fail "cycle 1 tables"
grep -q '^# command: geomint sweep .* --quick$' "$out/summary.csv" || fail "command line"
say "cycle of $shards shards + merge + timing: ${cycle} s; merged tables equal the local sweep"

# 2. One shard fails (as a crashed node would), into a folder of its own (`--out`, outside the
# scene's folder): merge refuses, naming it; its printed commands, run as printed, resubmit only
# that shard and merge again.
out="$work/out"
"$geomint" sweep "$scene" --quick --out "$out" 2> /dev/null  # the command this merge names
mkdir -p "$work/local_out"
cp "$out"/*.csv "$out/table.md" "$work/local_out/"
rm -rf "$out"
scene_files=$(cd "$(dirname "$scene")" && find . -type f | sort | xargs md5sum)
GEOMINT_FAIL_SHARD=3 "$geomint" slurm "$scene" --quick --shards $shards --out "$out" --submit \
  > /dev/null 2> "$work/submit2.txt"
read -r -a jobs <<< "$(submitted_ids "$work/submit2.txt")"
wait_jobs "${jobs[@]}" > /dev/null
[ "$(cd "$(dirname "$scene")" && find . -type f | sort | xargs md5sum)" = "$scene_files" ] ||
  fail "slurm --out wrote into the scene's folder"
status=0
"$geomint" merge "$out" --scene "$scene" 2> "$work/merge.txt" || status=$?
[ $status -eq 1 ] || fail "merge with shard 3 missing exited $status, not 1"
grep -q 'shard 3/8: summary.3-of-8.csv is missing' "$work/merge.txt" || fail "merge did not name shard 3"
resubmit=$(grep -o 'sbatch --array=[0-9,]* [^ ]*sweep.sbatch' "$work/merge.txt")
[ "$resubmit" = "sbatch --array=3 $out/sweep.sbatch" ] || fail "resubmission: $resubmit"
merge_again=$(sed -n 's/^then merge again: //p' "$work/merge.txt")
say "merge refused as it should: $(head -n 2 "$work/merge.txt" | tail -n 1 | sed 's/^ *//')"
sweep_job=$(${resubmit/sbatch/sbatch --parsable})
states=$(wait_jobs "$sweep_job")
all_completed $states || fail "resubmitted shard ended: $(echo $states)"
geomint() { "$geomint" "$@"; }
eval "$merge_again" 2> "$work/merge_again.txt" || fail "'$merge_again' failed: $(cat "$work/merge_again.txt")"
timing_job=$(sbatch --parsable "$out/timing.sbatch")
states=$(wait_jobs "$timing_job")
all_completed $states || fail "timing job ended: $(echo $states)"
compare_tables "$work/local_out" || fail "tables after the resubmission"
grep -q '^# command: geomint sweep .* --quick --out .*$' "$out/summary.csv" || fail "command line"
say "resubmitted shard 3 alone, merged as merge printed; tables in --out equal the local sweep"
say "passed in $(($(date +%s) - start)) s (the 8-shard cycle: ${cycle} s)"
