# Convergence of the high-order methods (results/order_high/README.md): final error against the
# step h on the pendulum, one panel per declared order with the reference slope h^p, the fitted
# order of each method in its key. Run inside results/order_high; reads order_points.csv, order.csv.
load scripts."/common.gp"
# Method specs hold commas: read the tables with them written as ";" (scripts/csv_plain.awk).
plain(file) = "< awk -f ".sh_quoted(scripts."/csv.awk")." -f ".sh_quoted(scripts."/csv_plain.awk")." ".file
points = plain("order_points.csv")
orders = "2 4 6 8"
# Methods of each panel, in the order of the tables (labels order2 ... order8 of scene.toml).
methods_of(p) = system("awk -f ".sh_quoted(scripts."/csv.awk")." -f ".sh_quoted(scripts."/csv_plain.awk")." order.csv | " . \
  "awk -F, '!/^#/ && $1 == \"order".p."\" { print $3 }' | tr '\\n' ' '")
fitted(p, m) = system("awk -f ".sh_quoted(scripts."/csv.awk")." -f ".sh_quoted(scripts."/csv_plain.awk")." order.csv | " . \
  "awk -F, '!/^#/ && $1 == \"order".p."\" && $3 == \"".m."\" { print $4 }'")
# A short name for the key: the scheme over its base, or the family and stage count.
# (Stormer-Verlet as "verlet", as common.gp's titles write it.)
base_of(m) = (b = m[strstrt(m, "base=") + 5:strstrt(m, ";") - 1], b eq "stormer_verlet" ? "verlet" : b)
short(m) = (strstrt(m, "composition:") == 1 ? m[strstrt(m, "scheme=") + 7:] . "(" . base_of(m) . ")" : \
  strstrt(m, ";s=") > 0 ? m[1:strstrt(m, ":") - 1] . " s=" . m[strstrt(m, ";s=") + 3:strstrt(m, ";s=") + 3] : m)
# The reference line h^p passes 3x above the panel's largest error at this step.
anchor_h(p) = (p == 8 ? 0.4 : 0.1)

png_big = "pngcairo noenhanced size 1000,900 font 'DejaVu Sans,12'"
pdf_big = pdf_for_png(1000, 900, 12)
svg_big = "svg noenhanced size 1000,900 font 'DejaVu Sans,12' background rgb 'white'"
panel_left(k) = (k % 2 == 1 ? 0.1 : 0.6)
panel_top(k) = (k <= 2 ? 0.88 : 0.43)
panel(k) = sprintf("set lmargin at screen %g; set rmargin at screen %g; set tmargin at screen %g; set bmargin at screen %g", \
  panel_left(k), panel_left(k) + 0.37, panel_top(k), panel_top(k) - 0.33)

do for [format in "png pdf svg"] {
  if (format eq "png") { set term @png_big } else { if (format eq "pdf") { set term @pdf_big } else { set term @svg_big } }
  set termoption noenhanced
  set output "order_high.".format
  set multiplot title "Convergence on pendulum:theta0=1.5 to T = 5: error |q(T) - q_exact(T)| against the step h\n(dashed: the declared order's slope h^p; key: each method's fitted order)"
  set logscale xy; set format x "%g"; set format y "1e%T"
  set xrange [0.005:2]; set yrange [1e-15:1e5]; set ytics 1e3
  set xlabel "step h (dimensionless time)"; set ylabel "error_final (rad)"
  # The key in the top left, above the data: the y axis runs on to 1e5, where no error reaches.
  set key top left opaque samplen 2 font ",11" spacing 1.1
  do for [k=1:words(orders)] {
    p = word(orders, k) + 0
    eval panel(k)
    set title sprintf("declared order %d", p) font ",13"
    list = methods_of(p)
    h0 = anchor_h(p)
    stats points using (strcol("label") eq sprintf("order%d", p) && abs(column("dt") - h0) < 1e-9 * h0 ? column("error_final") : NaN) nooutput
    c = 3 * STATS_max / h0**p
    plot for [i=1:words(list)] points using (strcol("label") eq sprintf("order%d", p) && strcol("method") eq word(list, i) ? column("dt") : NaN):"error_final" \
           with linespoints ls (40 + i) ps 1.3 title sprintf("%s: %s", short(word(list, i)), fitted(p, word(list, i))), \
         c * x**p with lines lw 2 dt 2 lc rgb "#555555" title sprintf("h^%d", p)
  }
  unset multiplot
}
