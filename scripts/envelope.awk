# Per-window maximum of |column - ref| / |ref| (docs/SCENES.md "Figures"): an envelope that shows energy
# drift without the false beats a sampled oscillation aliases into. Windows are log-spaced,
# per_decade to a decade, merged with the next until one spans at least min_width (one
# oscillation period) and holds min_count samples, so no window sees only part of an oscillation.
# Reads geomint series CSVs (`# ` provenance, header row) in order; a later file only adds rows
# past the last t already read, so a run written at every step supplies the early part of a long
# sparse one.
# Usage: awk -F, -v column=energy -v ref=H0 -v per_decade=10 -v min_width=6.4 -v min_count=5
#            -f envelope.awk FILE...
# Prints a CSV: header "t,max", then per window the midpoint of its samples' t and the maximum.
BEGIN { print "t,max" }
function flush() {
  printf "%.9g,%.9g\n", (first_t + last_t) / 2, best
  count = 0
}
FNR == 1 { header = 0 }
/^#/ { next }
!header {
  for (i = 1; i <= NF; i++) { if ($i == "t") tcol = i; if ($i == column) vcol = i }
  header = 1; next
}
{
  t = $tcol + 0
  if (t <= 0 || (seen && t <= last_t)) next
  w = int(log(t) / log(10) * per_decade + 1e6)
  if (count > 0 && w != window && count >= min_count && last_t - first_t >= min_width) flush()
  seen = 1; window = w
  value = ($vcol - ref) / ref; if (value < 0) value = -value
  if (count == 0 || value > best) best = value
  if (count == 0) first_t = t
  last_t = t; count++
}
# A last window too short to hold a whole oscillation would show a false dip: it is left out.
END { if (count >= min_count && last_t - first_t >= min_width) flush() }
