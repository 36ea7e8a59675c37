#!/usr/bin/env bash
# Times `make test` as a new user runs it on a fresh Debian 12 machine (docs/TESTING.md "Fresh
# machine"): a minimal Debian 12 root (debootstrap minbase plus git and make) in a chroot, this
# repository's HEAD cloned into a folder whose name has a space and parentheses, then `make test`
# as root, which installs the packages itself. Prints each phase's wall and CPU seconds and the
# load. First checks that a clone under a folder with `$(x)` in its name, which CMake cannot build
# in, is refused with a message.
#
# usage (root): scripts/fresh-machine-test.sh [ROOT]       ROOT defaults to /work/fresh-root
#   FRESH_MIRROR   Debian mirror (default: the first URI of /etc/apt/sources.list.d/debian.sources,
#                  else http://deb.debian.org/debian)
#   FRESH_BASE     where the bootstrapped base is kept between runs (default: ROOT.base)
#   FRESH_REV      the commit to clone (default: HEAD)
#   BUDGET_<PHASE> seconds allowed per phase (install, configure, build, tests, gates, report,
#                  external); the run is stopped and fails when one is exceeded
# Exit code: make's, or 124 when a phase ran out of its budget, 2 on bad use.
set -euo pipefail

repo=$(cd "$(dirname "$0")/.." && pwd)
root=${1:-/work/fresh-root}
base=${FRESH_BASE:-$root.base}
rev=${FRESH_REV:-HEAD}
mirror=${FRESH_MIRROR:-$(sed -n 's/^URIs: *\([^ ]*debian\)$/\1/p' \
  /etc/apt/sources.list.d/debian.sources 2>/dev/null | head -n 1)}
mirror=${mirror:-http://deb.debian.org/debian}
declare -A budget=(
  [install]=${BUDGET_INSTALL:-900} [configure]=${BUDGET_CONFIGURE:-180}
  [build]=${BUDGET_BUILD:-2400} [tests]=${BUDGET_TESTS:-1200} [gates]=${BUDGET_GATES:-600}
  [report]=${BUDGET_REPORT:-300} [external]=${BUDGET_EXTERNAL:-600}
)
# The clone's folder name tests the quoting of every script `make test` runs.
clone_dir='/root/fresh clone (x)/geomint'
dollar_dir='/root/dollar $(x)/geomint'
marker=.geomint-fresh-machine-test  # marks a root this script made, so that it may replace it

if [ "$(id -u)" -ne 0 ]; then
  echo "fresh-machine-test: needs root (debootstrap, chroot, mounts)" >&2
  exit 2
fi
command -v debootstrap > /dev/null || {
  echo "fresh-machine-test: needs debootstrap: apt-get install -y debootstrap" >&2
  exit 2
}
if [ -e "$root" ] && [ ! -e "$root/$marker" ]; then
  echo "fresh-machine-test: $root exists and was not made by this script; give another ROOT" >&2
  exit 2
fi

# The base: bootstrapped once (about 3 minutes), then copied for each run, so that every run
# starts from the same untouched system. Its apt sources are a default Debian 12 install's.
if [ ! -e "$base/$marker" ]; then
  rm -rf "$base"
  echo "fresh-machine-test: debootstrap minbase bookworm + git make from $mirror into $base" >&2
  timeout 1200 debootstrap --variant=minbase --include=git,make bookworm "$base" "$mirror" \
    > "$base.debootstrap.log" 2>&1 || { tail -n 20 "$base.debootstrap.log"; exit 1; }
  rm -f "$base/etc/apt/sources.list"
  cat > "$base/etc/apt/sources.list.d/debian.sources" <<EOF
Types: deb
URIs: $mirror
Suites: bookworm bookworm-updates
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg

Types: deb
URIs: ${mirror%/debian}/debian-security
Suites: bookworm-security
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
EOF
  # debootstrap leaves its package downloads in the cache; a fresh machine has none.
  rm -f "$base"/var/cache/apt/archives/*.deb
  touch "$base/$marker"
fi

rm -rf "$root"
timeout 600 cp -a "$base" "$root"
cp /etc/resolv.conf "$root/etc/resolv.conf"

mounted=()
make_pid=
cleanup() {
  local status=$?
  # Only the process group this script started, by its id.
  if [ -n "$make_pid" ] && kill -0 "$make_pid" 2> /dev/null; then
    kill -- "-$make_pid" 2> /dev/null || true
    sleep 2
  fi
  local i
  for ((i = ${#mounted[@]} - 1; i >= 0; i--)); do
    umount -R "${mounted[i]}" 2> /dev/null || umount -R -l "${mounted[i]}" || true
  done
  exit "$status"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

mount -t proc proc "$root/proc" && mounted+=("$root/proc")
mount --rbind /sys "$root/sys" && mount --make-rslave "$root/sys" && mounted+=("$root/sys")
# /dev with its submounts (/dev/pts, /dev/shm: Chromium needs shared memory).
mount --rbind /dev "$root/dev" && mount --make-rslave "$root/dev" && mounted+=("$root/dev")

mkdir -p "$root$(dirname "$clone_dir")"
git clone -q --no-local "$repo" "$root$clone_dir"
git -C "$root$clone_dir" checkout -q "$(git -C "$repo" rev-parse "$rev")"
commit=$(git -C "$root$clone_dir" rev-parse --short=12 HEAD)

# A `$` in the path: refused before anything runs (exit 2, the message names the folder).
mkdir -p "$root$(dirname "$dollar_dir")"
git clone -q --no-local "$root$clone_dir" "$root$dollar_dir"
dollar_status=0
dollar_out=$(chroot "$root" /bin/bash -c 'cd "$1" && make test' make-test "$dollar_dir" 2>&1) ||
  dollar_status=$?
if [ $dollar_status -ne 2 ] || ! grep -qF "contains '\$'" <<< "$dollar_out"; then
  echo "fresh-machine-test: make test under '$dollar_dir' exited $dollar_status: $dollar_out" >&2
  exit 1
fi
echo "fresh-machine-test: refused as it should: $dollar_out"
rm -rf "$root$(dirname "$dollar_dir")"

log="$root/root/make-test.log"
packages_before=$(chroot "$root" dpkg-query -W -f='${Status}\n' | grep -c 'install ok installed')
echo "fresh-machine-test: $(date -u '+%F %T') UTC, commit $commit, load: $(uptime)"
echo "fresh-machine-test: $packages_before packages in the base; make test in '$clone_dir'"
load_start=$(cut -d' ' -f1-3 /proc/loadavg)

# `make test` as root in the chroot, with the environment of a login shell, in a process group of
# its own so that a phase over its budget can be stopped as a whole.
setsid /usr/bin/time -v -o "$root/root/make-test.time" \
  env -i HOME=/root LANG=C.UTF-8 TERM=dumb PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
  chroot "$root" /bin/bash -c 'cd "$1" && make test' make-test "$clone_dir" > "$log" 2>&1 &
make_pid=$!

phase=start
phase_start=$(date +%s)
status=0
while kill -0 "$make_pid" 2> /dev/null; do
  sleep 5
  current=$(sed -n 's/^make-phase: \([a-z]*\) .*/\1/p' "$log" | tail -n 1)
  if [ -n "$current" ] && [ "$current" != "$phase" ]; then
    echo "fresh-machine-test: $(date -u +%T) phase $current"
    phase=$current
    phase_start=$(date +%s)
  fi
  limit=${budget[$phase]:-}
  if [ -n "$limit" ] && [ $(($(date +%s) - phase_start)) -gt "$limit" ]; then
    echo "fresh-machine-test: phase $phase ran over its budget of $limit s; stopping make" >&2
    kill -- "-$make_pid" 2> /dev/null || true
    status=124
    break
  fi
done
if [ $status -eq 0 ]; then
  wait "$make_pid" || status=$?
fi
make_pid=

tail -n 15 "$log"
echo
echo "fresh-machine-test: make test exit code $status; log $log"
echo "fresh-machine-test: load average at start $load_start, at end $(cut -d' ' -f1-3 /proc/loadavg)"
grep -E '^(Need to get|After this operation)' "$log" || true
packages_after=$(chroot "$root" dpkg-query -W -f='${Status}\n' | grep -c 'install ok installed')
echo "fresh-machine-test: packages installed by make test: $((packages_after - packages_before))"
# Per phase: wall and CPU seconds between consecutive markers (CPU: user + sys of the recipes
# make had finished, load-independent).
echo "| phase | wall s | CPU s |"
echo "|---|---|---|"
awk 'BEGIN { n = 0 } /^make-phase: / { name[n] = $2; wall[n] = $8; cpu[n] = $11; n++ }
     END { for (i = 0; i + 1 < n; i++)
             printf "| %s | %.1f | %.1f |\n", name[i], wall[i+1] - wall[i], cpu[i+1] - cpu[i];
           if (n > 0) printf "| total (make test) | %.1f | %.1f |\n", wall[n-1], cpu[n-1] }' "$log"
grep -E 'Elapsed|User time|System time|Maximum resident' "$root/root/make-test.time" || true
exit $status
