# Symplecticity of the computed map (results/symplecticity/README.md): the finite-difference map
# defect ||J^T Omega J - Omega||_F / ||Omega||_F of every method, one row per method, one marker per
# problem and step, with the difference floor it is resolved against. Run inside
# results/symplecticity; reads summary.csv.
load scripts."/common.gp"
# Method specs hold commas: read the table with them written as ";" (scripts/csv_plain.awk).
table = "< awk -f ".sh_quoted(scripts."/csv.awk")." -f ".sh_quoted(scripts."/csv_plain.awk")." summary.csv"

# Rows, top to bottom: a method is the first prefix its spec starts with; "|" separates classes.
free_keys = "stormer_verlet position_verlet symplectic_euler_a del: hp:alpha=0.5; hp:alpha=0.25; implicit_midpoint gauss: lobatto3ab: composition:base=stormer_verlet;scheme=yoshida4 composition:base=hp_midpoint;scheme=yoshida4 odeint_velocity_verlet | explicit_euler implicit_euler newmark:beta=0.25;gamma=0.6 newmark:beta=0.25;gamma=0.5 hht: rk4 | adaptive_verlet odeint_dopri5 gsl_rk8pd cvode_bdf cvode_adams"
free_titles = "stormer_verlet position_verlet symplectic_euler_a del:midpoint hp:alpha=0.5 hp:alpha=0.25 implicit_midpoint gauss:s=2 lobatto3ab:s=3 yoshida4(verlet) yoshida4(hp_midpoint) odeint_velocity_verlet | explicit_euler implicit_euler newmark(1/4,0.6) newmark(1/4,1/2) hht:alpha=-0.3 rk4 | adaptive_verlet odeint_dopri5 gsl_rk8pd cvode_bdf cvode_adams"
free_classes = "symplectic: not~symplectic: adaptive~solvers~(the~map~is~their~integration~over~h):"
constrained_keys = "rattle: hp:alpha=0.5; del: composition:base=rattle;scheme=yoshida4 composition:base=rattle;scheme=kahan_li6 composition:base=hp_midpoint;scheme=yoshida4 composition:base=hp_midpoint;scheme=kahan_li6 penalty:base=implicit_midpoint | penalty:base=implicit_euler penalty:base=newmark penalty:base=rk4"
constrained_titles = "rattle hp:alpha=0.5 del:midpoint yoshida4(rattle) kahan_li6(rattle) yoshida4(hp_midpoint) kahan_li6(hp_midpoint) penalty:k=100(implicit_midpoint) | penalty:k=100(implicit_euler) penalty:k=100(newmark) penalty:k=1000(rk4)"
constrained_classes = "symplectic~on~T*Q_c: not~symplectic~(penalty~over~a~non-symplectic~base):"

# Row of a method in a list (1 = top; the "|" words count as gaps between classes), 0 if absent.
row_of(keys, name) = sum [i=1:words(keys)] (word(keys, i) ne "|" && strstrt(name, word(keys, i)) == 1 ? i : 0)
# The y axis counts downwards from the top row.
y_of(keys, name) = (r = row_of(keys, name), r > 0 ? words(keys) + 1 - r : NaN)

is_free = 'strcol("label")[1:11] ne "constrained" && strcol("label") ne "inexact"'
is_constrained = 'strcol("label")[1:11] eq "constrained"'
starts(s, prefix) = strstrt(s, prefix) == 1
# Problems (and Kepler's two steps) are not methods: the ordered palette, styles 41-47.
free_case(k) = (k == 1 ? starts(strcol("problem"), "kepler") && (strcol("dt") eq "" || column("dt") == 0.05) : \
  k == 2 ? starts(strcol("problem"), "kepler") && strcol("dt") ne "" && column("dt") == 0.025 : \
  k == 3 ? starts(strcol("problem"), "spring_chain") : starts(strcol("problem"), "henon_heiles"))
free_case_title(k) = word("Kepler~e=0.5,~h=0.05 Kepler~e=0.5,~h=0.025 FPU-beta~chain,~h=0.05 Henon-Heiles,~h=0.1", k)
constrained_case(k) = starts(strcol("problem"), word("cartesian_pendulum spherical_pendulum rod_chain", k))
constrained_case_title(k) = word("cartesian_pendulum spherical_pendulum rod_chain~(n=3)", k)
case_style(k) = 39 + 2 * k
# Word lists are split at spaces: "~" stands for a space inside one entry.
spaced(s) = system("printf '%s' '".s."' | tr '~' ' '")

# Method names as y tic labels; each class named in an empty row above its first method, with a
# dotted line above the name (the "|" words of a list are those rows; one more on top). Its labels
# are tags 101-109 (common.gp's footer is 999).
set_rows = 'set ytics scale 0 font ",11"; set ytics (); unset arrow; unset for [t=101:109] label t; ' . \
  'class = 1; set label 101 spaced(word(CLASSES, 1)) at graph 0.01, first words(KEYS) + 1 left front font ",11" textcolor rgb "#555555"; ' . \
  'do for [i=1:words(KEYS)] { if (word(KEYS, i) eq "|") { class = class + 1; ' . \
  '  set arrow from graph 0, first (words(KEYS) + 1.5 - i) to graph 1, first (words(KEYS) + 1.5 - i) nohead dt 2 lc rgb "#888888"; ' . \
  '  set label 100 + class spaced(word(CLASSES, class)) at graph 0.01, first (words(KEYS) + 1 - i) left front font ",11" textcolor rgb "#555555" ' . \
  '} else { set ytics add (word(TITLES, i) words(KEYS) + 1 - i) } }; ' . \
  'set yrange [0.4:words(KEYS) + 1.6]'

png_tall = "pngcairo noenhanced size 1000,1200 font 'DejaVu Sans,12'"
pdf_tall = pdf_for_png(1000, 1200, 12)
svg_tall = "svg noenhanced size 1000,1200 font 'DejaVu Sans,12' background rgb 'white'"

do for [format in "png pdf svg"] {
  if (format eq "png") { set term @png_tall } else { if (format eq "pdf") { set term @pdf_tall } else { set term @svg_tall } }
  set termoption noenhanced
  set output "map_defect.".format
  set multiplot title "Defect ||J^T Omega J - Omega||_F / ||Omega||_F of the computed one-step map, J by finite differences\n(filled and open markers: the defect; grey bars: its finite-difference floor, below which it is not resolved)"
  set logscale x; set format x "1e%T"; set xrange [1e-16:1]; set xtics 1e2
  set xlabel "symplecticity_defect_map (dimensionless)"
  set grid xtics noytics
  set lmargin at screen 0.27; set rmargin at screen 0.94
  set tmargin at screen 0.865; set bmargin at screen 0.43
  set key at screen 0.605, 0.915 center center horizontal maxrows 2 samplen 1 width 2 box lc rgb "#cccccc"
  KEYS = free_keys; TITLES = free_titles; CLASSES = free_classes
  @set_rows
  set title "Unconstrained problems" font ",13"
  plot for [k=1:4] table using (@is_free && free_case(k) ? column("symplecticity_defect_map_fd_err") : NaN):(y_of(free_keys, strcol("method"))):(0.3) \
         with yerrorbars pt 0 lw 3 lc rgb "#999999" notitle, \
       for [k=1:4] table using (@is_free && free_case(k) ? column("symplecticity_defect_map") : NaN):(y_of(free_keys, strcol("method"))) \
         with points ls case_style(k) pt (k == 2 ? 6 : 3 + 2 * k) ps 1.4 title spaced(free_case_title(k))

  set tmargin at screen 0.275; set bmargin at screen 0.075
  set key at screen 0.605, 0.325
  KEYS = constrained_keys; TITLES = constrained_titles; CLASSES = constrained_classes
  @set_rows
  set title "Constrained problems: the map on the constraint manifold T*Q_c, h = 0.02" font ",13"
  plot for [k=1:3] table using (@is_constrained && constrained_case(k) ? column("symplecticity_defect_map_fd_err") : NaN):(y_of(constrained_keys, strcol("method"))):(0.3) \
         with yerrorbars pt 0 lw 3 lc rgb "#999999" notitle, \
       for [k=1:3] table using (@is_constrained && constrained_case(k) ? column("symplecticity_defect_map") : NaN):(y_of(constrained_keys, strcol("method"))) \
         with points ls case_style(k) pt (3 + 2 * k) ps 1.4 title spaced(constrained_case_title(k))
  unset multiplot
}
