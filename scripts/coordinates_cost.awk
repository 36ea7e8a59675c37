# Cost rows of results/coordinates/summary.csv -> curves/cost_<label>_<method>.dat with
# "n wall_s_per_step" (load scripts/csv.awk first; scripts/coordinates.gp runs it).
/^#/ { next }
{
  n = split_csv($0, f)
  if (!header_read) { for (i = 1; i <= n; i++) col[f[i]] = i; header_read = 1; next }
  label = f[col["label"]]
  if (label !~ /^cost_/) next
  links = 2
  if (match(f[col["problem"]], /[:,]n=[0-9]+/)) links = substr(f[col["problem"]], RSTART + 3, RLENGTH - 3) + 0
  method = f[col["method"]]; sub(/:.*/, "", method)
  if (f[col["wall_s"]] == "" || f[col["steps"]] + 0 == 0) next
  file = "curves/" label "_" method ".dat"
  # The first line is a header: common.gp reads column heads.
  if (!(file in seen)) { print "n wall_s_per_step" > file; seen[file] = 1 }
  print links, f[col["wall_s"]] / f[col["steps"]] > file
}
