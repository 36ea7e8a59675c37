# Chaos indicators (issue 27 item 5, results/chaos/README.md): Poincare sections q1 = 0, p1 > 0 of
# one regular (E = 1/12) and one chaotic (E = 1/6) Henon-Heiles orbit, Stormer-Verlet h = 0.05 to
# t = 4000. Run inside results/chaos; reads series/henon_*_long/stormer_verlet.csv (dimensionless).
load scripts."/common.gp"
regular = "series/henon_regular_long/stormer_verlet.csv"
chaotic = "series/henon_chaotic_long/stormer_verlet.csv"

do for [format in "png pdf svg"] {
  if (format eq "png") { set term @png_term } else { if (format eq "pdf") { set term @pdf_term } else { set term @svg_term } }
  set termoption noenhanced
  @key_above

  set output "poincare.".format
  set title "Henon-Heiles Poincare section q1 = 0, p1 > 0 (Stormer-Verlet, h = 0.05, t <= 4000)"
  set xlabel "q2 (dimensionless)"; set ylabel "p2 (dimensionless)"
  plot chaotic using "q_1":"p_1" with points pt 7 ps 0.3 lc rgb "#d95f02" title "chaotic orbit, E = 1/6 (q2 = 0.1, p1 = 0.1)", \
       regular using "q_1":"p_1" with points pt 7 ps 0.4 lc rgb "#1b9e77" title "regular orbit, E = 1/12 (q2 = 0.1, p1 = 0.1): a closed curve"
}
