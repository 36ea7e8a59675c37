# Articulated chains (results/articulated/README.md): wall time per step against the number of
# links n, log-log, one curve per cost block and method, with slope-1 and slope-3 reference lines.
# Run inside results/articulated; reads curves/*.csv (scripts/articulated.py writes them).
load scripts."/common.gp"
files = system("ls curves")
# A curve's method is the part of its file name after "__" (the style key), its block the part
# before it: the articulated_chain block is marked so, the other blocks are the rod chain.
method_of(f) = f[strstrt(f, "__") + 2:strlen(f) - 4]
block_of(f) = f[1:strstrt(f, "__") - 1]
title_of(f) = mtitle(method_of(f)) . (block_of(f) eq "cost_articulated" ? " (articulated_chain)" : \
  (block_of(f) eq "cost_dense" ? " (dense Newton)" : ""))
# References through RK4's cost at n = 64 (slope 1) and the dense DEL step's at n = 16 (slope 3).
stats "curves/cost_recursive__rk4.csv" using (column("n") == 64 ? column("wall_s_per_step") : NaN) nooutput
c1 = STATS_min / 64
stats "curves/cost_dense__del.csv" using (column("n") == 16 ? column("wall_s_per_step") : NaN) nooutput
c3 = STATS_min / 16**3

do for [format in "png pdf svg"] {
  if (format eq "png") { set term @png_term } else { if (format eq "pdf") { set term @pdf_term } else { set term @svg_term } }
  set termoption noenhanced
  set output "cost.".format
  set title "Wall time per step against the number of links n\n(rod chain, h = 1/240; median of 3 timed runs, one thread on a shared machine)"
  set xlabel "links n"; set ylabel "seconds per step"
  set logscale xy; set format y "1e%T"; set xrange [3:1400]; set yrange [5e-7:2e-2]; set xtics (4, 16, 64, 256, 1024)
  set key outside right top font ",10"
  set rmargin 30
  plot for [f in files] "curves/".f using "n":"wall_s_per_step" with linespoints ls ms(method_of(f)) \
         dt 1 + 2 * (block_of(f) eq "cost_articulated") + 3 * (block_of(f) eq "cost_dense") title title_of(f), \
       c1 * x with lines lw 1 dt (4,4) lc rgb "#888888" title "slope 1 (O(n))", \
       (x <= 100 ? c3 * x**3 : 1/0) with lines lw 1 dt (2,2) lc rgb "#444444" title "slope 3 (O(n^3))"
  unset output
}
