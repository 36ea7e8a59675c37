# Minimisation vs root finding for the HP midpoint step (docs/METHOD.md §4, claim 5): Newton iterations
# and wall time per step against h*omega_max on the stiff spring network. Run inside
# results/minimize_vs_newton; reads summary.csv. Both curves are hp:alpha=0.5: minimize in hp's
# colour (dashed, open circles, drawn last so it shows where the two coincide), newton in grey.
load scripts."/common.gp"
omega_max = 379.657  # spring_net:stiffness=10000,model=nonlinear at its initial state
# The pendulum and spinning-bar blocks are other problems (other omega_max): left out.
# gnuplot cuts the quoted method field at its first comma, so the solver is told apart by the
# line-search energy evaluations, which only solver=minimize makes.
net = '(strcol("label") eq "small" || strcol("label") eq "mid" || strcol("label") eq "large")'
is_min = 'column("energy_evals") > 0'
ok = 'strcol("status") eq "ok"'
attempted = '(column("steps") + (strcol("status") eq "ok" ? 0 : 1))'
its(minimize, good) = (@net && (@is_min) == minimize && (@ok) == good) ? column("newton_iters") / @attempted : NaN
wall(minimize) = (@net && (@is_min) == minimize && @ok) ? column("wall_s") / column("steps") : NaN

do for [format in "png pdf svg"] {
  if (format eq "png") { set term @png_term } else { if (format eq "pdf") { set term @pdf_term } else { set term @svg_term } }
  set termoption noenhanced
  set output "solvers.".format
  set multiplot layout 1,2 title "hp:alpha=0.5 on spring_net:stiffness=1e4,model=nonlinear (explicit limit h*omega_max = 1.89)"
  set logscale xy; set format x "% g"; set format y "% g"
  set xlabel "h * omega_max (dimensionless)"; set key top left
  # One more line under the x labels: the right panel's label would reach the provenance footer.
  set bmargin 4.5
  set style line 51 lw 2 lc rgb "#e7298a" pt 6 ps 1.8 dt 2
  set style line 52 lw 2 lc rgb "#555555" pt 5 ps 1.0
  set xrange [0.2:600]
  set arrow 1 from 1.89, graph 0 to 1.89, graph 1 nohead dt 2 lc rgb "gray"

  set label 1 "minimize converges here, but the\ntrajectory's energy error reaches 1e5-1e7" at graph 0.97, graph 0.45 right font ",9"
  set title "Newton iterations per attempted step"
  set ylabel "Newton iterations per step (dimensionless)"
  plot "summary.csv" using (column("dt")*omega_max):(its(0, 1)) with linespoints ls 52 title "newton (ok)", \
       "" using (column("dt")*omega_max):(its(0, 0)) with points ls 52 pt 4 ps 2 title "newton (failed: max_iter)", \
       "" using (column("dt")*omega_max):(its(1, 1)) with linespoints ls 51 title "minimize (ok)", \
       "" using (column("dt")*omega_max):(its(1, 0)) with points ls 51 pt 12 ps 2 title "minimize (failed)"

  unset label 1
  set title "Wall time per step (runs that finished)"
  set ylabel "wall time per step [s]"
  plot "summary.csv" using (column("dt")*omega_max):(wall(0)) with linespoints ls 52 title "newton", \
       "" using (column("dt")*omega_max):(wall(1)) with linespoints ls 51 title "minimize"
  unset multiplot
  unset arrow 1; unset logscale; set xrange [*:*]; set format x "% h"; set format y "% h"
}
