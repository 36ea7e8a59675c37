#!/usr/bin/env bash
# Installs the Debian 12 packages geomint builds with (docs/DESIGN.md §8). Idempotent: installs only
# what is missing, waits for the dpkg lock, never pulls recommends. As non-root it prints the
# exact command to run and exits 1. `install-deps.sh sanitize` installs clang 14 with its sanitizer
# and libFuzzer runtimes, which only `make sanitize-build`, `test-sanitize` and `fuzz` use (not
# `make test`: 14 packages, 48 MB to download, docs/TESTING.md "Fresh clone");
# `install-deps.sh cluster` installs the local single-node Slurm that `make test-cluster` runs
# (docs/CLUSTER.md "Running on a cluster") instead. dpkg unpacks with --force-unsafe-io (no fsync
# per file: most of the install's time on a fresh machine, docs/TESTING.md "Fresh machine");
# INSTALL_SAFE_IO=1 keeps dpkg's default.
set -euo pipefail

PACKAGES=(
  g++ cmake make pkg-config
  libeigen3-dev libsundials-dev libgsl-dev libboost-dev
  gnuplot-nox libtomlplusplus-dev libcli11-dev libfmt-dev nlohmann-json3-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libsuitesparse-dev libmetis-dev libopenblas-dev libhypre-dev
  python3 ccache
  libxml2-utils tidy chromium python3-yaml python3-jsonschema
  libcmark-gfm-dev libcmark-gfm-extensions-dev
  pybind11-dev python3-dev python3-numpy python3-pandas python3-pytest
  libmujoco-dev libode-dev libbullet-dev libdart-dev
)
if [ "${1:-}" = cluster ]; then
  shift
  PACKAGES=(slurmctld slurmd slurm-client munge)
elif [ "${1:-}" = sanitize ]; then
  shift
  PACKAGES=(clang libclang-rt-14-dev)
fi

missing=()
for pkg in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$pkg")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  [ "${1:-}" = "--quiet" ] || echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi

cmd="apt-get update && apt-get install -y --no-install-recommends ${missing[*]}"
if [ "$(id -u)" -ne 0 ]; then
  echo "install-deps: missing Debian packages: ${missing[*]}" >&2
  echo "install-deps: run as root:" >&2
  echo "  sudo sh -c '$cmd'" >&2
  exit 1
fi

wait_for_dpkg_lock() {
  command -v fuser >/dev/null 2>&1 || return 0  # apt itself waits too (Lock::Timeout)
  local waited=0
  while fuser /var/lib/dpkg/lock-frontend /var/lib/dpkg/lock >/dev/null 2>&1; do
    [ $waited -eq 0 ] && echo "install-deps: waiting for the dpkg lock..." >&2
    sleep 2
    waited=$((waited + 2))
    if [ $waited -ge 600 ]; then
      echo "install-deps: dpkg lock still held after 600 s" >&2
      exit 1
    fi
  done
}

echo "install-deps: installing ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
wait_for_dpkg_lock
apt-get update -q
wait_for_dpkg_lock
# dpkg's fsync of every unpacked file (and its rename dance) waits on the disk's cache flush: on a
# fresh machine that is most of the install time, while the CPU idles. A power loss during the
# install may then leave some of these packages' files empty; `apt-get install --reinstall` of
# them repairs it. Nothing else on the system is affected.
unsafe_io=(-o DPkg::Options::=--force-unsafe-io)
[ "${INSTALL_SAFE_IO:-0}" = 1 ] && unsafe_io=()
apt-get install -y -q --no-install-recommends -o DPkg::Lock::Timeout=600 "${unsafe_io[@]}" \
  "${missing[@]}"
