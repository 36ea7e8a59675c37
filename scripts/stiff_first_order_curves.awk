# scd-against-wall-time curves of results/stiff_first_order (docs/PROBLEMS.md "Stiff first-order
# references"): from summary.csv, one file curves/<group>_<method>.dat ("wall_s scd" per ok row
# with an scd, in file order) per label group (vdpol, rober: the label up to its first "_") and
# method name (the spec up to ":"), and curves/<group>.list naming them.
# Usage: awk -f stiff_first_order_curves.awk summary.csv (inside the scene folder, curves/ exists)
/^#/ { next }
{
  # Commas inside quoted fields (method specs) become ";" so that -F, splitting works in any awk.
  line = ""; quoted = 0
  for (i = 1; i <= length($0); ++i) {
    c = substr($0, i, 1)
    if (c == "\"") { quoted = !quoted; continue }
    line = line ((quoted && c == ",") ? ";" : c)
  }
  n = split(line, field, ",")
  if (!header_done) {
    for (i = 1; i <= n; ++i) column[field[i]] = i
    header_done = 1
    next
  }
  if (field[column["status"]] != "ok" || field[column["scd"]] == "") next
  group = field[column["label"]]; sub(/_.*/, "", group)
  method = field[column["method"]]; sub(/:.*/, "", method)
  name = group "_" method
  if (!(name in seen)) { seen[name] = 1; print method >> ("curves/" group ".list") }
  print field[column["wall_s"]], field[column["scd"]] >> ("curves/" name ".dat")
}
