#!/usr/bin/env bash
# `make perf` (docs/PERF.md): every benchmark program of BUILD_DIR/bench run with REPS repetitions
# on the benchmarks matching FILTER, each writing OUT/<program>.json (Google Benchmark JSON) with
# the provenance perf-compare prints: commit, compiler, CPU model, thread count.
set -euo pipefail
build="$1" out="$2" reps="$3" min_time="$4" filter="$5"
geomint="$build/geomint"
version="$("$geomint" --version)"                       # "geomint 0.1.0 (<commit>)"
commit="${version##*(}"; commit="${commit%)}"
cxx="$(sed -n 's/^CMAKE_CXX_COMPILER:[A-Z]*=//p' "$build/CMakeCache.txt" | head -1)"
compiler="$("${cxx:-c++}" --version 2>/dev/null | head -1 | tr ',' ' ' || echo '?')"
cpu="$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -1 | tr ',' ' ')"
threads="${GEOMINT_THREADS:-$(nproc)}"  # the default of problems/parallel.hpp
mkdir -p "$out"
ran=0
for program in "$build"/bench/bench_*; do
  [ -x "$program" ] || continue
  name="$(basename "$program")"
  if [ -z "$("$program" --benchmark_list_tests --benchmark_filter="$filter" 2>/dev/null)" ]; then
    continue
  fi
  echo "perf: $name" >&2
  "$program" --benchmark_filter="$filter" --benchmark_repetitions="$reps" \
    --benchmark_min_time="$min_time" --benchmark_out="$out/$name.json.tmp" \
    --benchmark_out_format=json \
    --benchmark_context="commit=$commit,compiler=$compiler,cpu_model=$cpu,threads=$threads" \
    > /dev/null
  mv "$out/$name.json.tmp" "$out/$name.json"
  ran=$((ran + 1))
done
if [ "$ran" -eq 0 ]; then
  echo "perf: no benchmark matches PERF_FILTER='$filter'" >&2
  exit 2
fi
echo "perf: $ran program(s) written to $out; compare with: $geomint perf-compare BASE_DIR $out" >&2
