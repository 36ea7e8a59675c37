#!/usr/bin/env bash
# results/scaling/ (issue 9 item 4; docs/METHODS.md "Scale"): the reduced sizes of bench/bench_scaling.cpp
# (spring_chain to 10^5 dof, elastic_bar to 10^4 tets; under a minute on 2 cores) into
# scaling.csv with provenance, then the log-log figure (scripts/scaling.gp). The largest sizes
# (10^6 dof, 2*10^5 tets) run only under `make bench`. Usage: scaling.sh BUILD_DIR
set -euo pipefail
# A gnuplot string constant of $1: single quotes, an embedded one doubled (the clone's path may hold
# spaces, parentheses or quotes; the .gp scripts shell-quote it again for their awk commands).
gnuplot_string() { local quote="'"; printf "'%s'" "${1//$quote/$quote$quote}"; }
build=$(realpath "$1")
root=$(cd "$(dirname "$0")/.." && pwd)
out="$root/results/scaling"
start=$(date +%s)
echo "== scaling" >&2
mkdir -p "$out"
"$build/bench/bench_scaling" --csv "$out/scaling.csv" --benchmark_min_time=0.1 >&2
if [ "${PLOTS:-1}" = 1 ]; then
  # Footer as in scripts/reproduce.sh: the build that measured scaling.csv.
  provenance=$(sed -n 's/^# geomint: \([0-9A-Za-z._ ()-]*\)$/\1/p' "$out/scaling.csv" | head -n 1)
  (cd "$out" && gnuplot -e "scripts=$(gnuplot_string "$root/scripts")" -e "provenance='$provenance'" \
    "$root/scripts/scaling.gp")
fi
echo "== scaling: $(( $(date +%s) - start )) s" >&2
