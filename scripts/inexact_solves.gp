# The cost of inexact solves (issue 27 item 2, results/inexact_solves/README.md): |energy_drift| and
# symplecticity_defect_map of hp on Kepler e = 0.5 against the Newton tolerance, one curve per solver
# variant, and the energy error of the elastic bar. Run inside results/inexact_solves; reads summary.csv.
load scripts."/common.gp"
# gnuplot cuts the quoted method field at its first comma, so a row's tolerance is looked up from
# its position inside its block: the lists below (-log10 tol) follow the methods of scene.toml.
tols(label) = label eq "kepler_short" ? "4 12 4 4" : \
  label eq "kepler_newton" ? "4 5 6 8 10 12 14" : \
  label eq "kepler_del" ? "4 8 12" : \
  label eq "kepler_midpoint" || label eq "kepler_solver_newton" ? "4 6 8 12" : \
  label eq "kepler_modified_newton" || label eq "kepler_cg" ? "4 6 8 10 12" : \
  label eq "bar_cg" ? "4 5 6 8 12" : \
  label eq "bar_modified_newton" ? "4 6 8 12" : \
  label eq "bar_newton" ? "4 8 12" : ""
# Row counter within the current block (reset when the label changes; rows of a block are adjacent).
previous = ""; position = 0
tol_of_row(label) = (position = (label eq previous ? position + 1 : 1), previous = label, \
  10.0**(-real(word(tols(label), position))))
ok = 'strcol("status") eq "ok"'
pick(label, value) = (strcol("label") eq label && @ok) ? value : NaN

blocks = "kepler_newton kepler_solver_newton kepler_modified_newton kepler_cg kepler_del kepler_midpoint"
titles = "hp_(LDLT,minimize) hp:solver=newton hp:modified_newton=true hp:linear_solver=cg del implicit_midpoint"
bar_blocks = "bar_newton bar_modified_newton bar_cg"
bar_titles = "hp_(LDLT) hp:modified_newton=true hp:linear_solver=cg"
# One style per solver variant (these are variants of one method, not methods).
set style line 61 lw 2 lc rgb "#e7298a" pt 12 ps 2.0 dt (6,4)
set style line 62 lw 2 lc rgb "#555555" pt 5  ps 0.9
set style line 63 lw 2 lc rgb "#1f77b4" pt 9  ps 1.3
set style line 64 lw 2 lc rgb "#2ca02c" pt 7  ps 1.1
set style line 65 lw 2 lc rgb "#000000" pt 4  ps 1.4
set style line 66 lw 2 lc rgb "#17becf" pt 10 ps 1.4
style_of(label) = label eq "kepler_newton" || label eq "bar_newton" ? 61 : \
  label eq "kepler_solver_newton" ? 62 : \
  label eq "kepler_modified_newton" || label eq "bar_modified_newton" ? 63 : \
  label eq "kepler_cg" || label eq "bar_cg" ? 64 : label eq "kepler_del" ? 65 : 66
set style line 69 lw 1.5 lc rgb "#999999" dt 2

do for [format in "png pdf svg"] {
  if (format eq "png") { set term @png_term } else { if (format eq "pdf") { set term @pdf_term } else { set term @svg_term } }
  set termoption noenhanced
  set output "inexact.".format
  set multiplot layout 1,3 title "Inexact solves: Kepler e = 0.5 at h = 0.2 to T = t_end (hp, and the same map by del and implicit_midpoint); elastic bar at h = 0.002"
  set logscale xy; set format x "1e%T"; set format y "1e%T"
  set xrange [3e-15:3e-4]
  set xlabel "Newton tolerance tol (dimensionless)"
  # One more line under the x labels: the right panel's label would reach the provenance footer.
  set bmargin 4.5
  set xtics 10000
  set key top left font ",8"

  set title "Kepler: energy drift"
  set ylabel "|energy_drift| (relative energy per unit time)"
  plot for [i=1:words(blocks)] "summary.csv" \
       using (tol_of_row(strcol("label"))):(pick(word(blocks, i), abs(column("energy_drift")))) \
       with linespoints ls (style_of(word(blocks, i))) title word(titles, i)

  set title "Kepler: defect of the computed map"
  set ylabel "symplecticity_defect_map (dimensionless)"
  plot for [i=1:words(blocks)] "summary.csv" \
       using (tol_of_row(strcol("label"))):(pick(word(blocks, i), column("symplecticity_defect_map"))) \
       with linespoints ls (style_of(word(blocks, i))) title word(titles, i), \
       "summary.csv" using (tol_of_row(strcol("label"))):(pick("kepler_newton", column("symplecticity_defect_map_fd_err"))) \
       with lines ls 69 title "finite-difference floor (hp)"

  set title "Elastic bar (24 dof): energy error"
  set key top left
  set ylabel "energy_err_max (relative)"
  plot for [i=1:words(bar_blocks)] "summary.csv" \
       using (tol_of_row(strcol("label"))):(pick(word(bar_blocks, i), column("energy_err_max"))) \
       with linespoints ls (style_of(word(bar_blocks, i))) title word(bar_titles, i)
  unset multiplot
  unset logscale; set xrange [*:*]; set xtics autofreq; set format x "% h"; set format y "% h"
}
