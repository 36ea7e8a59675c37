#!/usr/bin/env bash
# Installs geomint from an existing build into a temporary prefix, then configures, builds and
# tests examples/external_method against it with its own CMake configure, as a user would
# (docs/VERIFY.md "Verify your own integrator"; run by `make test`). Usage: test-external.sh [BUILD_DIR]
# Exit code: 0 when the install, the example's build and every one of its tests succeed.
set -euo pipefail
build_dir=${1:-build}
source_dir=$(cd "$(dirname "$0")/.." && pwd)
jobs=${JOBS:-2}
work=$(mktemp -d "${TMPDIR:-/tmp}/geomint-external.XXXXXX")
# Kept for inspection when something failed.
trap 'status=$?; if [[ $status == 0 ]]; then rm -rf "$work"; else echo "test-external: see $work" >&2; fi' EXIT

cmake --install "$build_dir" --prefix "$work/prefix" > "$work/install.log" ||
  { cat "$work/install.log"; echo "test-external: cmake --install failed" >&2; exit 1; }
# The example compiles through the launcher the build uses (the environment's, or the ccache that
# `make configure` set up), so that a second run recompiles nothing.
launcher=()
build_launcher=$(sed -n 's/^CMAKE_CXX_COMPILER_LAUNCHER:[A-Z]*=//p' "$build_dir/CMakeCache.txt")
if [[ -n "${CMAKE_CXX_COMPILER_LAUNCHER:-}" ]]; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER="$CMAKE_CXX_COMPILER_LAUNCHER")
elif [[ -n "$build_launcher" ]]; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER="$build_launcher")
fi
cmake -S "$source_dir/examples/external_method" -B "$work/build" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$work/prefix" "${launcher[@]}" > "$work/configure.log" ||
  { cat "$work/configure.log"; echo "test-external: configure against the prefix failed" >&2; exit 1; }
cmake --build "$work/build" -j "$jobs" > "$work/build.log" ||
  { cat "$work/build.log"; echo "test-external: the example did not build" >&2; exit 1; }
"$work/prefix/bin/geomint" --version
# The Python package (docs/PYTHON.md), when the build has it: imported from the prefix's
# site-packages by Debian's python3, outside the source and build trees, and run once.
python_dir=$(sed -n 's/^GEOMINT_PYTHON_INSTALL_DIR:STRING=//p' "$build_dir/CMakeCache.txt")
if [[ -n "$python_dir" ]]; then
  (cd "$work" && PYTHONPATH="$work/prefix/$python_dir" /usr/bin/python3 -c '
import geomint, sys
assert geomint.__file__.startswith(sys.argv[1]), geomint.__file__
run = geomint.run("pendulum", "stormer_verlet", dt=0.1, t_end=1.0)
assert run.status == "ok", run.row
print("test-external: python package geomint from", sys.argv[1], "ran", run)
' "$work/prefix") || { echo "test-external: the installed Python package failed" >&2; exit 1; }
fi
(cd "$work/build" && ctest --output-on-failure -j "$jobs") ||
  { echo "test-external: the example's tests failed" >&2; exit 1; }
echo "test-external: examples/external_method built and passed against $work/prefix"
