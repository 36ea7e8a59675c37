#!/usr/bin/env bash
# The top-level Makefile's own behaviour (docs/TESTING.md "Fresh machine"): a clone under a folder
# whose path has a `$` is refused before anything runs, and `make test` marks its phases in order.
# Usage: makefile_test.sh SOURCE_DIR
set -euo pipefail
source_dir=$1
# Run from `make test`, the environment carries the outer make's flags and command-line variables.
unset MAKEFLAGS MFLAGS MAKELEVEL
work=$(mktemp -d "${TMPDIR:-/tmp}/geomint-makefile.XXXXXX")
trap 'rm -rf "$work"' EXIT
failures=0

# 1. `$(x)` in the path: exit 2 and a message naming the folder, for any target, with nothing run.
dollar="$work/clone \$(x) here"
mkdir -p "$dollar"
cp "$source_dir/Makefile" "$dollar/"
status=0
output=$(make -C "$dollar" test 2>&1) || status=$?
if [ $status -ne 2 ] || ! grep -qF "contains '\$'" <<< "$output" ||
   ! grep -qF "$dollar" <<< "$output" || [ -e "$dollar/build" ]; then
  echo "FAIL: make test under '$dollar' exited $status (want 2 with the message): $output"
  failures=$((failures + 1))
fi

# 2. The phase markers of `make test`, in the order the phases run; the sub-makes skip the build.
plan=$(make -C "$source_dir" -n test BUILD_DIR="$work/build" 2>&1)
phases=$(sed -n 's/^sh scripts\/make-phase.sh \([a-z]*\) .*/\1/p' <<< "$plan" | tr '\n' ' ')
if [ "$phases" != "install configure build tests gates report external end " ]; then
  echo "FAIL: make test's phase markers are '$phases'"
  failures=$((failures + 1))
fi
if [ "$(grep -c 'TEST_BUILT=1' <<< "$plan")" -ne 3 ]; then
  echo "FAIL: make test's three sub-makes do not all skip the build: $plan"
  failures=$((failures + 1))
fi
# `make build` alone prints no markers.
if make -C "$source_dir" -n build BUILD_DIR="$work/build" 2>&1 | grep -q make-phase; then
  echo "FAIL: make build prints phase markers"
  failures=$((failures + 1))
fi

# 3. A marker line: its fields, as scripts/fresh-machine-test.sh reads them.
line=$(sh "$source_dir/scripts/make-phase.sh" build "$(date +%s.%N)")
if ! grep -qE '^make-phase: build at [0-9:]{8} epoch [0-9.]+ elapsed [0-9.]+ s cpu [0-9.?]+ s$' \
     <<< "$line"; then
  echo "FAIL: marker line '$line'"
  failures=$((failures + 1))
fi
[ $failures -eq 0 ] && echo "makefile_test: all checks passed"
exit $((failures > 0))
