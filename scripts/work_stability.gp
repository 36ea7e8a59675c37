# Work-stability diagrams (results/work_stability/README.md, issue 29 item 4): simulated time per
# CPU-second (and per force or Hessian evaluation) at each method's largest stable step, against
# stiffness, one panel per problem. Run inside results/work_stability; reads the curves/ that
# scripts/work_stability.py wrote from summary.csv and stability.csv.
load scripts."/common.gp"
set datafile separator whitespace
set datafile nocolumnheaders
explicit = "stormer_verlet rk4 composition_yoshida4 sprk_blanes_moan4"
implicit = "implicit_euler implicit_midpoint del hp newmark"
methods = explicit." ".implicit
# sprk has no style of its own in common.gp yet: a teal line with filled-star markers here.
style(m) = (m eq "sprk_blanes_moan4" ? 15 : ms(m))
words_stiff_spring = "stiff_spring (wall - k_soft - m - k_stiff - m): stiffness = k_stiff/k_soft"
words_fpu_stiff = "fpu_stiff (m = 3): stiffness = omega^2 (stiff springs omega^2/2)"

do for [format in "png pdf svg"] {
  if (format eq "png") { set term @png_term } else { if (format eq "pdf") { set term @pdf_term } else { set term @svg_term } }
  do for [measure in "cpu eval"] {
    set output (measure eq "cpu" ? "work_stability." : "work_stability_evals.").format
    set multiplot layout 1,2 title (measure eq "cpu" ? \
      "Simulated time per CPU-second at the largest stable step (capped at h = 0.3); fastest of 5 timed repeats, bars down by the IQR" : \
      "Simulated time per force + Hessian evaluation at the largest stable step (capped at h = 0.3)")
    set logscale xy; set format x "1e%T"; set format y "1e%T"
    set xlabel "stiffness (dimensionless)"
    set ylabel (measure eq "cpu" ? "simulated time / CPU second" : "simulated time / evaluation")
    set key bottom left font ",8" maxrows 5
    do for [problem in "stiff_spring fpu_stiff"] {
      set title (problem eq "stiff_spring" ? words_stiff_spring : words_fpu_stiff) font ",9"
      if (measure eq "cpu") {
        plot for [m in methods] "curves/".problem."__".m.".dat" using 1:2:3:4 \
             with yerrorlines ls style(m) title mtitle(m)
      } else {
        plot for [m in methods] "curves/".problem."__".m.".dat" using 1:5 \
             with linespoints ls style(m) title mtitle(m)
      }
    }
    unset multiplot
  }
}
