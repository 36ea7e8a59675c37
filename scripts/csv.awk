# CSV field splitting shared by the scenes' awk post-processing (scripts/work_precision_table.sh,
# scripts/constraints_curves.awk; the summary.csv format of docs/DESIGN.md): load it first with
# awk -f scripts/csv.awk -f PROGRAM.
# Splits one CSV line (fields may be "quoted", "" is a quote) into f[1..n].
function split_csv(line, f,    n, i, c, field, quoted) {
  n = 0; field = ""; quoted = 0
  for (i = 1; i <= length(line); i++) {
    c = substr(line, i, 1)
    if (quoted) {
      if (c == "\"") {
        if (substr(line, i + 1, 1) == "\"") { field = field "\""; i++ } else quoted = 0
      } else field = field c
    } else if (c == "\"") quoted = 1
    else if (c == ",") { f[++n] = field; field = "" }
    else field = field c
  }
  f[++n] = field
  return n
}
