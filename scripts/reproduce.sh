#!/usr/bin/env bash
# Regenerates results/<scene>/ for each scene named: runs the sweep, then the scene's gnuplot
# script (scripts/<scene>.gp, run inside the scene folder), then the results/README.md index.
# QUICK=1 runs the CI-sized variant into results/<scene>/quick/ instead; PLOTS=0 skips gnuplot;
# SWEEP=0 only redraws the figures from the CSVs already there.
set -euo pipefail
# A gnuplot string constant of $1: single quotes, an embedded one doubled (the clone's path may hold
# spaces, parentheses or quotes; the .gp scripts shell-quote it again for their awk commands).
gnuplot_string() { local quote="'"; printf "'%s'" "${1//$quote/$quote$quote}"; }
geomint=$(realpath "$1")
shift
root=$(cd "$(dirname "$0")/.." && pwd)
jobs=$(nproc 2>/dev/null || echo 2)
start=$(date +%s)
for scene in "$@"; do
  folder="$root/results/$scene"
  echo "== $scene" >&2
  scene_start=$(date +%s)
  if [ "${SWEEP:-1}" = 0 ]; then
    # SWEEP=0: redraw the figures from the committed CSVs, no run.
    out="$folder"
    [ "${QUICK:-0}" = 1 ] && out="$folder/quick"
  elif [ "${QUICK:-0}" = 1 ]; then
    (cd "$root" && "$geomint" sweep "results/$scene/scene.toml" --jobs "$jobs" --quick)
    out="$folder/quick"
  else
    (cd "$root" && "$geomint" sweep "results/$scene/scene.toml" --jobs "$jobs")
    out="$folder"
  fi
  # A scene's post-processing (scripts/<scene>.py, when there is one) derives its extra tables
  # from the sweep's CSVs, before the figures and the gates read them.
  if [ -f "$root/scripts/$scene.py" ]; then
    /usr/bin/python3 "$root/scripts/$scene.py" "$out"
  fi
  if [ "${PLOTS:-1}" = 1 ] && [ -f "$root/scripts/$scene.gp" ]; then
    # The figure footer names the build that computed the numbers: the `# geomint:` provenance
    # line of the scene's summary.csv (or of its first CSV), e.g. "0.1.0 (cd4c0e47a208)".
    provenance=""
    for table in "$out/summary.csv" "$out"/*.csv; do
      if [ -f "$table" ]; then
        provenance=$(sed -n 's/^# geomint: \([0-9A-Za-z._ ()-]*\)$/\1/p' "$table" | head -n 1)
        break
      fi
    done
    (cd "$out" && gnuplot -e "scripts=$(gnuplot_string "$root/scripts")" -e "provenance='$provenance'" \
      "$root/scripts/$scene.gp")
  fi
  echo "== $scene: $(( $(date +%s) - scene_start )) s" >&2
done
[ "${QUICK:-0}" = 1 ] || bash "$root/scripts/index-results.sh"
echo "reproduce: done in $(( $(date +%s) - start )) s" >&2
