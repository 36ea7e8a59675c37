#!/usr/bin/env bash
# Post-processing for results/work_precision and work_precision_full, run by
# scripts/work_precision.gp inside the scene folder: reads summary.csv and writes
#   wp/<group>/<curve>.dat  one line per ok run of a method curve (a fixed-step method over dt, an
#                           adaptive one over tolerance), columns:
#                           1 wall_s (median of the timed repeats)  2 error_final  3 energy_err_max
#                           4 dt or rtol  5 wall_s_min  6 wall_s + wall_s_iqr (>= the third
#                           quartile, since Q1 <= median)  7 force_evals  8 steps  9 wall_s_iqr
#                           10 error_max  11 |phase_err| (radians; nan when the problem has none)
#   wp/<group>/timeouts.dat one line per run that ended as status timeout (its wall_budget_s
#                           spent, in the metric or the timing pass): 1 wall_s (the seconds spent)
#                           2-5 the group's largest error_final, error_max, energy_err_max and
#                           |phase_err| over its ok runs (the marker sits at the top of each
#                           diagram: the run reached no error level)  6 the curve
#   wp/<group>/front_<family>_<x>.dat  the best-of-family front against x = wall, evals, steps:
#                           the runs of one family (summary.csv's `family` column) that no faster
#                           (cheaper) run of the family beats in error_final; same columns.
#   wp/<group>.curves, wp/<group>.families, wp/groups  the names the figure script iterates.
#   wp/<group>.scale        the group's common scale: wall-time range of every point, bar and
#                           timeout, and the error range over error_final and error_max.
#   time_to_error.md        per group and curve, the least median wall time of an ok run with
#                           error_final <= 1e-2, 1e-4, 1e-6, 1e-8, 1e-10 with that run's IQR;
#                           a curve with timed-out runs that
#                           reaches a level in no run shows "timeout" there (did not reach,
#                           explicitly); each group lists its timed-out runs; the fastest curve
#                           per level; and the goal (best
#                           geomint method against best library solver at 1e-8 on Kepler 10^2,
#                           10^4 and 10^5 and on the outer solar system).
# A group is a label without its last _<part> (kepler_1e2_explicit -> kepler_1e2).
set -euo pipefail
summary=${1:-summary.csv}
rm -rf wp
mkdir -p wp
# split_csv comes from scripts/csv.awk; the program is read from the here-document.
# Who implements each method: the provider column of docs/METHODS.md's table, which
# scripts/readme_tables.py writes from integrators/registry.def (and tests/cli_test.cpp keeps in
# step with it), so no method name prefix decides which side of the goal a method is on.
methods_md="$(cd "$(dirname "$0")/.." && pwd)/docs/METHODS.md"
awk -v out=wp -v methods_md="$methods_md" -f "$(dirname "$0")/csv.awk" -f /dev/stdin "$summary" > time_to_error.md <<'AWK'
# Curve name: the method name and its scheme, s, table or pair (tolerances and library defaults
# dropped), file-name safe.
function curve_name(spec,    name, rest, parts, n, i, kept) {
  name = spec; rest = ""
  if (index(spec, ":") > 0) { name = substr(spec, 1, index(spec, ":") - 1); rest = substr(spec, index(spec, ":") + 1) }
  kept = name
  n = split(rest, parts, ",")
  for (i = 1; i <= n; i++) {
    if (parts[i] ~ /^(scheme|s|table|pair)=/) { sub(/^(scheme|table|pair)=/, "", parts[i]); sub(/=/, "", parts[i]); kept = kept "_" parts[i] }
  }
  return kept
}
# The provider of each method name, from the rows between <!-- methods:begin/end -->:
# "| `cvode_bdf` | library:SUNDIALS | ...".
function read_providers(    line, inside, cells, name, count) {
  while ((getline line < methods_md) > 0) {
    if (line ~ /<!-- methods:begin -->/) inside = 1
    else if (line ~ /<!-- methods:end -->/) inside = 0
    else if (inside && line ~ /^\| `[a-z0-9_]+` \| /) {
      split(line, cells, / \| /); name = cells[1]; gsub(/^\| `|`$/, "", name); provider[name] = cells[2]; count++
    }
  }
  close(methods_md)
  if (count == 0) { print "no method table with a provider column in " methods_md > "/dev/stderr"; failed = 1; exit 2 }
}
# A library wrapper: its registry entry's provider is library:NAME (a method the table does not
# list, a user's, is not one).
function library(spec,    name) { name = spec; sub(/:.*/, "", name); return provider[name] ~ /^library:/ }
# A column's cell, nan when the column is absent or empty (a problem without that metric).
function cell(name) { return (name in col) && f[col[name]] != "" ? f[col[name]] : "nan" }
# The largest value of diagram y axis a over a group's ok runs: where its timeout markers sit.
function top(group, a, v) {
  if (v == "nan" || v + 0 <= 0) return
  if (!((group, a) in ymax) || v + 0 > ymax[group, a]) ymax[group, a] = v + 0
  if (!((group, a) in ymin) || v + 0 < ymin[group, a]) ymin[group, a] = v + 0
}
# The wall-time extent of a group over every point and bar drawn (timeouts included).
function span(group, lo, hi) {
  if (!(group in xmin) || lo < xmin[group]) xmin[group] = lo
  if (!(group in xmax) || hi > xmax[group]) xmax[group] = hi
}
function top_or_one(group, a) { return ((group, a) in ymax) ? sprintf("%.6g", ymax[group, a]) : 1 }
function fmt_time(t) { return t == "" ? "-" : sprintf("%.3g s", t) }
function fmt_cell(key, l) {
  if (!((key, l) in best)) return (key in timeouts) ? "timeout" : "-"
  return sprintf("%.3g s (IQR %.2g)", best[key, l], best_iqr[key, l])
}
# The least median wall time to error <= X over the runs of one curve, with its spread.
function consider(key, l, wall, iqr, lo) {
  if (!((key, l) in best) || wall < best[key, l]) { best[key, l] = wall; best_iqr[key, l] = iqr; best_min[key, l] = lo }
}
/^#/ { next }
header == 0 {
  n = split_csv($0, h); for (i = 1; i <= n; i++) col[h[i]] = i; header = 1
  if (!("family" in col) || !("wall_s_iqr" in col)) { print "summary.csv has no family or wall_s_iqr column: rerun the sweep" > "/dev/stderr"; exit 2 }
  next
}
{
  split_csv($0, f)
  label = f[col["label"]]; group = label; sub(/_[^_]*$/, "", group)
  curve = curve_name(f[col["method"]])
  if (!(group in seen_group)) { seen_group[group] = 1; groups[++ngroups] = group }
  key = group SUBSEP curve
  if (!(key in seen_curve)) { seen_curve[key] = 1; curves[group] = curves[group] " " curve; problem[group] = f[col["problem"]]; is_library[key] = library(f[col["method"]]) }
  step = f[col["dt"]]
  if (step == "") { step = f[col["method"]]; sub(/.*rtol=/, "rtol=", step); sub(/,.*/, "", step) }
  # A run that spent its wall-clock budget: a point at the seconds spent, not a hole.
  if (f[col["status"]] == "timeout" && f[col["wall_s"]] != "") {
    timeouts[key] = timeouts[key] + 1
    span(group, f[col["wall_s"]] + 0, f[col["wall_s"]] + 0)
    timeout_lines[group] = timeout_lines[group] sprintf("%s %s\n", f[col["wall_s"]], curve)
    timeout_list[group] = timeout_list[group] sprintf("%s at %s: %s s; ", curve, step, f[col["wall_s"]])
    next
  }
  if (f[col["status"]] != "ok" || f[col["wall_s"]] == "" || f[col["error_final"]] == "") next
  system("mkdir -p " out "/" group)
  wall = f[col["wall_s"]] + 0; iqr = f[col["wall_s_iqr"]] + 0; lo = f[col["wall_s_min"]] + 0
  err = f[col["error_final"]] + 0
  emax = cell("error_max"); phase = cell("phase_err"); if (phase != "nan" && phase + 0 < 0) phase = substr(phase, 2)
  line = sprintf("%s %s %s %s %s %.17g %s %s %s %s %s", f[col["wall_s"]], f[col["error_final"]], f[col["energy_err_max"]], step,
                 f[col["wall_s_min"]], wall + iqr, f[col["force_evals"]] == "" ? "nan" : f[col["force_evals"]], f[col["steps"]], f[col["wall_s_iqr"]],
                 emax, phase)
  span(group, lo, wall + iqr)
  top(group, 1, err); top(group, 2, emax); top(group, 3, cell("energy_err_max")); top(group, 4, phase)
  print line >> (out "/" group "/" curve ".dat")
  family = f[col["family"]]
  if (!((group, family) in seen_family)) { seen_family[group, family] = 1; print family >> (out "/" group ".families") }
  print line >> (out "/" group "/family_" family ".pts")
  has_data[key] = 1; group_has_data[group] = 1
  for (l = 1; l <= nlevels; l++) if (err <= level[l]) consider(key, l, wall, iqr, lo)
}
BEGIN { read_providers(); nlevels = split("1e-2 1e-4 1e-6 1e-8 1e-10", level, " "); for (l = 1; l <= nlevels; l++) level[l] += 0; goal_level = 4 }
END {
  if (failed) exit 2
  print "# Time to reach error X (least median wall time of an ok run with error_final <= X)\n"
  print "Per group (problem and horizon) and method curve: the median wall time of the timed repeats"
  print "of the cheapest run that reaches X, with that run's interquartile range (IQR, seconds);"
  print "- = not reached by any run in the sweep; timeout = not reached, and some of the curve's runs"
  print "ended at their wall-clock budget (scene key wall_budget_s) before t_end.\n"
  for (g = 1; g <= ngroups; g++) {
    group = groups[g]
    if (group in group_has_data) print group > (out "/groups")
    printf "## %s (%s)\n\n| method |", group, problem[group]
    for (l = 1; l <= nlevels; l++) printf " <= %g |", level[l]
    printf "\n|---|"; for (l = 1; l <= nlevels; l++) printf "---|"; printf "\n"
    nc = split(substr(curves[group], 2), names, " ")
    for (c = 1; c <= nc; c++) {
      key = group SUBSEP names[c]
      if (key in has_data) print names[c] > (out "/" group ".curves")
      printf "| %s |", names[c]
      for (l = 1; l <= nlevels; l++) printf " %s |", fmt_cell(key, l)
      printf "\n"
      for (l = 1; l <= nlevels; l++) {
        if (((key, l) in best) && (!((group, l) in winner_time) || best[key, l] < winner_time[group, l])) {
          winner_time[group, l] = best[key, l]; winner[group, l] = names[c]
        }
        side = is_library[key] ? "library" : "geomint"
        if (((key, l) in best) && (!((group, l, side) in side_time) || best[key, l] < side_time[group, l, side])) {
          side_time[group, l, side] = best[key, l]; side_iqr[group, l, side] = best_iqr[key, l]
          side_min[group, l, side] = best_min[key, l]; side_name[group, l, side] = names[c]
        }
      }
    }
    if (group in timeout_list) {
      printf "\nTimed out (wall_budget_s spent before t_end: reached no level): %s\n", substr(timeout_list[group], 1, length(timeout_list[group]) - 2)
      system("mkdir -p " out "/" group)
      n = split(timeout_lines[group], tl, "\n")
      for (i = 1; i < n; i++) {
        split(tl[i], parts, " ")
        printf "%s %s %s %s %s %s\n", parts[1], top_or_one(group, 1), top_or_one(group, 2), top_or_one(group, 3), top_or_one(group, 4), parts[2] > (out "/" group "/timeouts.dat")
      }
    }
    # One scale per group: every wall-time diagram spans the same x range, and the final and the
    # maximum error diagrams the same y range (a factor 2 of margin), so curves compare across them.
    if (group in xmin && ((group, 1) in ymin)) {
      elo = ymin[group, 1]; ehi = ymax[group, 1]
      if (((group, 2) in ymin) && ymin[group, 2] < elo) elo = ymin[group, 2]
      if (((group, 2) in ymax) && ymax[group, 2] > ehi) ehi = ymax[group, 2]
      printf "%.6g %.6g %.6g %.6g\n", xmin[group] / 2, xmax[group] * 2, elo / 2, ehi * 2 > (out "/" group ".scale")
    }
    printf "\nFastest: "
    for (l = 1; l <= nlevels; l++) {
      printf "%s<= %g: %s", (l > 1 ? "; " : ""), level[l],
             ((group, l) in winner) ? winner[group, l] " (" fmt_time(winner_time[group, l]) ")" : "none"
    }
    printf "\n\n"
  }
  # Issue 29 item 5: the best geomint method's time to 1e-8 over the best library solver's.
  # Range: the extreme ratios the two runs' spreads allow, from (fastest geomint repeat) /
  # (median + IQR of the library run) to (median + IQR of the geomint run) / (fastest library
  # repeat).
  print "## Goal (geomint <= 0.5x the best library): time to error_final <= 1e-8, geomint / library\n"
  for (g = 1; g <= ngroups; g++) {
    group = groups[g]
    # Kepler at every horizon the scenes run (10^2 is the goal's; the longer ones say where it
    # stands when the horizon grows), and the outer solar system.
    if (group !~ /^(kepler_1e[0-9]+|solar_1e2)$/) continue
    G = group SUBSEP goal_level SUBSEP "geomint"; L = group SUBSEP goal_level SUBSEP "library"
    if (!(G in side_time) || !(L in side_time)) {
      printf "- %s: not measurable (%s reaches 1e-8 in this sweep).\n", group,
             !(G in side_time) && !(L in side_time) ? "neither side" : (!(G in side_time) ? "no geomint method" : "no library solver")
      continue
    }
    ratio = side_time[G] / side_time[L]
    low = side_min[G] / (side_time[L] + side_iqr[L]); high = (side_time[G] + side_iqr[G]) / side_min[L]
    printf "- %s: best geomint %s %s (IQR %.2g) / best library %s %s (IQR %.2g) = **%.2f×** (range %.2f–%.2f×): goal <= 0.5× %s.\n",
           group, side_name[G], fmt_time(side_time[G]), side_iqr[G], side_name[L], fmt_time(side_time[L]), side_iqr[L],
           ratio, low, high, ratio <= 0.5 ? (high <= 0.5 ? "MET" : "met by the medians but not over the whole range") : "NOT met"
  }
}
AWK
for file in wp/*/*.dat; do sort -g -o "$file" "$file"; done
# Best-of-family fronts: sort a family's runs by the x column, keep each run whose error is below
# every cheaper one's.
for points in wp/*/family_*.pts; do
  [ -e "$points" ] || continue
  family=$(basename "$points" .pts); family=${family#family_}
  for axis in wall:1 evals:7 steps:8; do
    sort -g -k"${axis#*:}","${axis#*:}" "$points" |
      awk 'NR == 1 || $2 + 0 < best { print; best = $2 + 0 }' \
        > "$(dirname "$points")/front_${family}_${axis%:*}.dat"
  done
  rm "$points"
done
