#!/usr/bin/env bash
# Post-processing for results/work_precision (issue 5), run by scripts/work_precision.gp inside
# the scene folder: reads summary.csv and writes
#   wp/<group>/<curve>.dat  wall_s error_final energy_err_max step (one file per method curve:
#                           a fixed-step method over dt, an adaptive one over tolerance),
#   wp/<group>.curves       the curve names of a group, wp/groups the groups,
#   time_to_error.md        per group and curve, the least wall time of an ok run with
#                           error_final <= 1e-3, 1e-6, 1e-9, and the fastest curve per level.
# A group is a label without its last _<part> (kepler_1e2_explicit -> kepler_1e2).
set -euo pipefail
summary=${1:-summary.csv}
rm -rf wp
mkdir -p wp
# split_csv comes from scripts/csv.awk; the program is read from the here-document.
awk -v out=wp -f "$(dirname "$0")/csv.awk" -f /dev/stdin "$summary" > time_to_error.md <<'AWK'
# Curve name: the method spec without its tolerances, file-name safe, library defaults dropped.
function curve_name(spec,    name, rest, parts, n, i, kept) {
  name = spec; rest = ""
  if (index(spec, ":") > 0) { name = substr(spec, 1, index(spec, ":") - 1); rest = substr(spec, index(spec, ":") + 1) }
  kept = name
  n = split(rest, parts, ",")
  for (i = 1; i <= n; i++) {
    if (parts[i] ~ /^(scheme|s)=/) { sub(/^scheme=/, "", parts[i]); sub(/=/, "", parts[i]); kept = kept "_" parts[i] }
  }
  return kept
}
function fmt_time(t) { return t == "" ? "-" : sprintf("%.3g s", t) }
/^#/ { next }
header == 0 { n = split_csv($0, h); for (i = 1; i <= n; i++) col[h[i]] = i; header = 1; next }
{
  split_csv($0, f)
  label = f[col["label"]]; group = label; sub(/_[^_]*$/, "", group)
  curve = curve_name(f[col["method"]])
  if (!(group in seen_group)) { seen_group[group] = 1; groups[++ngroups] = group }
  key = group SUBSEP curve
  if (!(key in seen_curve)) { seen_curve[key] = 1; curves[group] = curves[group] " " curve; problem[group] = f[col["problem"]] }
  if (f[col["status"]] != "ok" || f[col["wall_s"]] == "" || f[col["error_final"]] == "") next
  step = f[col["dt"]]
  if (step == "") { step = f[col["method"]]; sub(/.*rtol=/, "rtol=", step); sub(/,.*/, "", step) }
  system("mkdir -p " out "/" group)
  print f[col["wall_s"]], f[col["error_final"]], f[col["energy_err_max"]], step >> (out "/" group "/" curve ".dat")
  has_data[key] = 1; group_has_data[group] = 1
  wall = f[col["wall_s"]] + 0; err = f[col["error_final"]] + 0
  for (l = 1; l <= 3; l++) {
    if (err <= level[l] && (!((key, l) in best) || wall < best[key, l])) best[key, l] = wall
  }
}
BEGIN { level[1] = 1e-3; level[2] = 1e-6; level[3] = 1e-9 }
END {
  print "# Time to reach error X (least wall time of an ok run with error_final <= X)\n"
  print "Per group (problem and horizon) and method curve; - = not reached by any run in the sweep.\n"
  for (g = 1; g <= ngroups; g++) {
    group = groups[g]
    if (group in group_has_data) print group > (out "/groups")
    printf "## %s (%s)\n\n| method | <= 1e-3 | <= 1e-6 | <= 1e-9 |\n|---|---|---|---|\n", group, problem[group]
    nc = split(substr(curves[group], 2), names, " ")
    for (c = 1; c <= nc; c++) {
      key = group SUBSEP names[c]
      if (key in has_data) print names[c] > (out "/" group ".curves")
      printf "| %s | %s | %s | %s |\n", names[c], fmt_time((key, 1) in best ? best[key, 1] : ""),
             fmt_time((key, 2) in best ? best[key, 2] : ""), fmt_time((key, 3) in best ? best[key, 3] : "")
      for (l = 1; l <= 3; l++) {
        if (((key, l) in best) && (!((group, l) in winner_time) || best[key, l] < winner_time[group, l])) {
          winner_time[group, l] = best[key, l]; winner[group, l] = names[c]
        }
      }
    }
    printf "\nFastest: "
    for (l = 1; l <= 3; l++) {
      printf "%s<= %g: %s", (l > 1 ? "; " : ""), level[l],
             ((group, l) in winner) ? winner[group, l] " (" fmt_time(winner_time[group, l]) ")" : "none"
    }
    printf "\n\n"
  }
}
AWK
for file in wp/*/*.dat; do sort -g -o "$file" "$file"; done
