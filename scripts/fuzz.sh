#!/usr/bin/env bash
# Runs the libFuzzer targets of fuzz/ (docs/TESTING.md "Sanitizers and fuzzing") for a bounded time each.
#   scripts/fuzz.sh BUILD_DIR SECONDS [TARGET...]     TARGET: spec scene gates (default: all)
# Seeds: fuzz/corpus/<target>/ (committed, read only); new inputs go to
# BUILD_DIR/fuzz/corpus/<target>/, crash/timeout/leak inputs to BUILD_DIR/fuzz/artifacts/<target>/,
# the log to BUILD_DIR/fuzz/<target>.log. Exits 1 on the first finding, with the log's tail.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:?usage: fuzz.sh BUILD_DIR SECONDS [TARGET...]}
seconds=${2:?usage: fuzz.sh BUILD_DIR SECONDS [TARGET...]}
shift 2
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(spec scene gates)
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
for target in "${targets[@]}"; do
  binary="$build/fuzz/${target}_fuzzer"
  [ -x "$binary" ] || { echo "fuzz: $binary not built (make fuzz-build)" >&2; exit 2; }
  work="$build/fuzz/corpus/$target"
  artifacts="$build/fuzz/artifacts/$target"
  log="$build/fuzz/$target.log"
  mkdir -p "$work" "$artifacts"
  dict=()
  [ -f "$root/fuzz/$target.dict" ] && dict=(-dict="$root/fuzz/$target.dict")
  start=$(date +%s)
  # -timeout: a single input taking 10 s is a hang; -rss_limit_mb: a parser must not need 2 GB.
  if ! "$binary" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
      "${dict[@]}" -artifact_prefix="$artifacts/" "$work" "$root/fuzz/corpus/$target" \
      > "$log" 2>&1; then
    tail -n 60 "$log" >&2
    echo "fuzz: $target: FINDING (input in $artifacts/, log $log)" >&2
    exit 1
  fi
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log")
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -n 1 | cut -d' ' -f2)
  corpus=$(grep -o 'corp: [0-9]*/[0-9a-zA-Z]*' "$log" | tail -n 1 | cut -d' ' -f2)
  echo "fuzz: $target: ${runs:-?} executions in $(( $(date +%s) - start )) s, coverage ${cov:-?}" \
       "edges, corpus ${corpus:-?} (inputs/bytes), 0 findings"
done
