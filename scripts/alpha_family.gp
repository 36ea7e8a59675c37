# The alpha family (docs/METHOD.md §1, §4, §7): largest stable h*omega against 1/|1/2 - alpha|, and the
# convergence of each alpha on the pendulum. Run inside results/alpha_family; reads stability.csv
# and order_points.csv. Both problems are dimensionless; the alpha values form a family, drawn in
# common.gp's ordered palette (styles 41-48), not in the method styles.
load scripts."/common.gp"
alphas = "0 0.1 0.25 0.4 0.5 0.6 0.75 1"
hp(name) = strstrt(name, "hp:") == 1
bracketed(col) = (strcol("label") eq "alpha" && hp(strcol("method")) && strcol("status") eq "bracketed") ? column(col) : NaN
to_max(col) = (strcol("label") eq "alpha" && hp(strcol("method")) && strcol("status") eq "stable_to_max") ? column(col) : NaN
# gnuplot cuts a quoted CSV field at its first comma: strcol("method") is "hp:alpha=0.25".
order_point(a) = (strcol("method") eq "hp:alpha=".a && strcol("status") eq "ok") ? column("error_final") : NaN

do for [format in "png pdf svg"] {
  if (format eq "png") { set term @png_term } else { if (format eq "pdf") { set term @pdf_term } else { set term @svg_term } }
  set termoption noenhanced
  @key_above

  set output "stability.".format
  set title "hp:alpha on the harmonic oscillator: largest stable h*omega"
  set xlabel "alpha (dimensionless)"; set ylabel "largest stable h*omega (dimensionless)"
  set logscale y; set format y "% g"; set xrange [-0.05:1.05]; set yrange [1:2000]
  set samples 1001
  plot 1/abs(0.5 - x) with lines lw 1.5 lc rgb "black" title "predicted 1/|1/2 - alpha|", \
       "stability.csv" using "alpha":(bracketed("homega_max_measured")) with points ls 41 pt 7 ps 1.5 title "measured (bisection)", \
       "stability.csv" using "alpha":(to_max("homega_max_measured")) with points ls 46 pt 9 ps 2 title "stable up to the top of the search range"
  unset logscale; set xrange [*:*]; set yrange [*:*]

  set output "order.".format
  set title "hp:alpha, pendulum theta0 = 1.5: global error at t = 5 against the step size"
  set xlabel "step size h (dimensionless)"; set ylabel "||(q,p) - exact|| at t = 5 (dimensionless)"
  set logscale xy; set format x "1e%T"; set format y "1e%T"; set xrange [5e-4:0.2]
  set label 1 "alpha and 1 - alpha give the same error here: the pairs 0 and 1,\n0.25 and 0.75, 0.4 and 0.6 lie on one another" at graph 0.03, graph 0.93 left font ",9"
  plot for [i=1:words(alphas)] "order_points.csv" using "dt":(order_point(word(alphas, i))) with linespoints ls (40 + i) title "alpha = ".word(alphas, i), \
       0.3*(x/0.1) with lines dt 2 lc rgb "black" title "slope 1", \
       3e-3*(x/0.1)**2 with lines dt 3 lc rgb "black" title "slope 2"
  unset logscale; set format x "% h"; set format y "% h"; set xrange [*:*]; unset label 1
}
