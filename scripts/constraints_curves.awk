# Post-processing for results/constraints (scripts/constraints.gp runs it inside the scene folder
# on summary.csv): writes curves/car_axis_<curve>.dat (wall_s error_final), curves/car_axis.list
# (the curve names, keys of the method map in scripts/common.gp) and curves/penalty_<dt>.dat
# (k constraint_err_max energy_err_max, ok runs only).
# split_csv comes from scripts/csv.awk (awk -f csv.awk -f constraints_curves.awk).
# rattle, composition_rattle_<scheme>, ida_index_<2|3>; anything else keeps its registry name.
function curve_name(spec,    name, scheme) {
  name = spec; sub(/:.*/, "", name)
  if (name == "composition") { scheme = spec; sub(/.*scheme=/, "", scheme); sub(/,.*/, "", scheme); return "composition_rattle_" scheme }
  if (name == "ida") { sub(/.*index=/, "", spec); sub(/,.*/, "", spec); return "ida_index_" spec }
  return name
}
/^#/ { next }
header == 0 { n = split_csv($0, h); for (i = 1; i <= n; i++) col[h[i]] = i; header = 1; next }
{
  split_csv($0, f)
  if (f[col["status"]] != "ok") next
  label = f[col["label"]]; method = f[col["method"]]
  if (label ~ /^car_axis/ && f[col["wall_s"]] != "" && f[col["error_final"]] != "") {
    curve = curve_name(method)
    if (!(curve in seen)) { seen[curve] = 1; list = list " " curve }
    print f[col["wall_s"]], f[col["error_final"]] >> ("curves/car_axis_" curve ".dat")
  }
  if (label == "penalty" && method ~ /^penalty/) {
    k = method; sub(/.*k=/, "", k); sub(/,.*/, "", k)
    print k, f[col["constraint_err_max"]], f[col["energy_err_max"]] >> ("curves/penalty_" f[col["dt"]] ".dat")
  }
}
END { print list > "curves/car_axis.list" }
