# Work-stability diagrams (results/work_stability/README.md, issue 29 item 4): simulated time per
# CPU-second (and per force or Hessian evaluation) at each method's largest stable step, against
# stiffness, one panel per problem and stiffness axis. Run inside results/work_stability; reads the
# curves/ that scripts/work_stability.py wrote from summary.csv and stability.csv.
load scripts."/common.gp"
set datafile separator whitespace
set datafile nocolumnheaders
explicit = "stormer_verlet rk4 composition_yoshida4 sprk_blanes_moan4"
implicit = "implicit_euler implicit_midpoint del hp newmark"
methods = explicit." ".implicit
# The bar runs a subset (results/work_stability/scene.toml): no curve files for the others.
methods_bar = "stormer_verlet rk4 composition_yoshida4 implicit_euler implicit_midpoint hp newmark"
# sprk has no style of its own in common.gp yet: a teal line with filled-star markers here.
style(m) = (m eq "sprk_blanes_moan4" ? 15 : ms(m))
words_stiff_spring = "stiff_spring (wall - k_soft - m - k_stiff - m): stiffness = k_stiff/k_soft"
words_fpu_stiff = "fpu_stiff (m = 3): stiffness = omega^2 (stiff springs omega^2/2)"
words_elastic_bar_young = "elastic_bar, 192 tets, bent, no gravity: stiffness = E"
words_elastic_bar_mesh = "elastic_bar, E = 1e4, 4n x n x n cells, n = 1, 2, 3: omega_max^2"
xlabel_of(panel) = (panel eq "elastic_bar_young" ? "Young's modulus E (Pa)" : \
  (panel eq "elastic_bar_mesh" ? "omega_max^2 at the initial state (1/s^2)" : "stiffness (dimensionless)"))
title_of(panel) = (panel eq "stiff_spring" ? words_stiff_spring : (panel eq "fpu_stiff" ? words_fpu_stiff : \
  (panel eq "elastic_bar_young" ? words_elastic_bar_young : words_elastic_bar_mesh)))

# common.gp's terminals with twice the height, for the 2 x 2 panels (cairo refuses a second size).
tall(term, size) = term[1:strstrt(term, " size ")] . size . term[strstrt(term, " font "):]
png_tall = tall(png_term, "size 1000,1150")
pdf_tall = pdf_for_png(1000, 1150, 11)
svg_tall = tall(svg_term, "size 1000,1150")

do for [format in "png pdf svg"] {
  if (format eq "png") { set term @png_tall } else { if (format eq "pdf") { set term @pdf_tall } else { set term @svg_tall } }
  do for [measure in "cpu eval"] {
    set output (measure eq "cpu" ? "work_stability." : "work_stability_evals.").format
    # Two title lines (one would run past the canvas edges), and panels placed by hand so the
    # bottom row's x labels keep a line of their own above the provenance footer.
    set multiplot layout 2,2 title (measure eq "cpu" ? \
      "Simulated time per CPU-second at the largest stable step (step capped at h = 0.3, bar 0.1)\nfastest of 5 timed repeats (bar: 3), error bars down by the interquartile range" : \
      "Simulated time per force + Hessian evaluation at the largest stable step\n(step capped at h = 0.3, bar 0.1)") \
      margins screen 0.085, 0.98, 0.075, 0.9 spacing screen 0.1, 0.1
    set logscale xy; set format x "1e%T"; set format y "1e%T"
    set ylabel (measure eq "cpu" ? "simulated time / CPU second" : "simulated time / evaluation")
    # The key sits in the bottom of each panel, below the data: extend every y range downwards.
    set key bottom left font ",9" maxrows 5
    set offsets 0, 0, 0, graph 0.25
    do for [panel in "stiff_spring fpu_stiff elastic_bar_young elastic_bar_mesh"] {
      set title title_of(panel) font ",10"
      set xlabel xlabel_of(panel)
      list = (panel[1:11] eq "elastic_bar" ? methods_bar : methods)
      if (measure eq "cpu") {
        plot for [m in list] "curves/".panel."__".m.".dat" using 1:2:3:4 \
             with yerrorlines ls style(m) title mtitle(m)
      } else {
        plot for [m in list] "curves/".panel."__".m.".dat" using 1:5 \
             with linespoints ls style(m) title mtitle(m)
      }
    }
    unset multiplot
  }
}
