# A CSV table re-emitted with every field's own commas written as ";", for gnuplot, whose strcol()
# stops at the first comma even inside a quoted field. Load after csv.awk:
# awk -f scripts/csv.awk -f scripts/csv_plain.awk summary.csv
/^#/ { print; next }
{
  n = split_csv($0, f)
  line = ""
  for (i = 1; i <= n; i++) {
    gsub(/,/, ";", f[i])
    line = line (i > 1 ? "," : "") f[i]
  }
  print line
}
