# Structure (results/structure/README.md): energy error against the defect of the computed map for
# symplectic, non-symplectic and energy-preserving methods on three problems, and the phase error of
# each at equal cost on Kepler. Run inside results/structure; reads summary.csv.
load scripts."/common.gp"
# Method specs hold commas: read the table with them written as ";" (scripts/csv_plain.awk).
table = "< awk -f ".sh_quoted(scripts."/csv.awk")." -f ".sh_quoted(scripts."/csv_plain.awk")." summary.csv"

# The three classes are not methods: the ordered palette (styles 41-48), one marker each. A row's
# class is the suffix of its label (<problem>_symplectic, _nonsymplectic, _energy).
class_suffix = "_symplectic _nonsymplectic _energy"
class_title = "symplectic~(stormer_verlet,~del,~hp,~yoshida4,~gauss~s=1,2) not~symplectic~(rk4,~implicit_euler,~cvode_bdf,~adaptive_verlet) energy-preserving~(avf,~projection~over~gauss~s=1,2)"
class_style(c) = word("41 44 48", c) + 0
class_point(c) = word("7 5 9", c) + 0
ends_with(s, tail) = strlen(s) >= strlen(tail) && s[strlen(s) - strlen(tail) + 1:] eq tail
in_class(prefix, c) = (label = strcol("label"), label[1:strlen(prefix)] eq prefix && \
  ends_with(label, word(class_suffix, c)) && !(c == 1 && ends_with(label, "_nonsymplectic")))
spaced(s) = system("printf '%s' '".s."' | tr '~' ' '")
problem_prefix = "kepler henon chain"
problem_title = "Kepler~e~=~0.6,~t~=~3~(h~=~0.02,~0.01) Henon-Heiles,~t~=~50~(h~=~0.1,~0.05) FPU-beta~chain,~t~=~50~(h~=~0.1,~0.05)"

# The equal-cost rows (labels kepler_cost_<method>), top to bottom, with their class.
cost_rows = "stormer_verlet composition hp gauss_s1 gauss_s2 rk4 avf projection projection_standard projection_s2 projection_s2_standard"
cost_titles = "stormer_verlet~(h~=~0.001) yoshida4(verlet)~(0.003) hp:alpha=0.5~(0.005) gauss:s=1~(0.006) gauss:s=2~(0.0095) rk4~(0.004) avf:nodes=8~(0.045) projection:s=1,symmetric~(0.06) projection:s=1,standard~(0.011) projection:s=2,symmetric~(0.042) projection:s=2,standard~(0.012)"
cost_class(r) = (r <= 5 ? 1 : r == 6 ? 2 : 3)
cost_row(label) = sum [r=1:words(cost_rows)] ("kepler_cost_".word(cost_rows, r) eq label ? words(cost_rows) + 1 - r : 0)
# Two rows' 100-period phase moved past the phase tracker's search window between checkpoints:
# their summary.csv values are wrapped angles (results/structure/README.md explains it under the
# phase error at equal cost), so they are marked, not plotted.
phase_lost(label) = (label eq "kepler_cost_avf" || label eq "kepler_cost_projection")

png_big = "pngcairo noenhanced size 1000,1000 font 'DejaVu Sans,12'"
pdf_big = pdf_for_png(1000, 1000, 12)
svg_big = "svg noenhanced size 1000,1000 font 'DejaVu Sans,12' background rgb 'white'"
# Three scatter panels in a row, the equal-cost panel below them at full width (its method names
# need the room); panel(k) sets the margins of panel k in screen units.
panel(k) = (k <= 3 ? sprintf("set lmargin at screen %g; set rmargin at screen %g; set tmargin at screen 0.8; set bmargin at screen 0.55", \
  0.1 + 0.3 * (k - 1), 0.1 + 0.3 * (k - 1) + 0.26) : \
  "set lmargin at screen 0.36; set rmargin at screen 0.96; set tmargin at screen 0.4; set bmargin at screen 0.08")

do for [format in "png pdf svg"] {
  if (format eq "png") { set term @png_big } else { if (format eq "pdf") { set term @pdf_big } else { set term @svg_big } }
  set termoption noenhanced
  set output "structure.".format
  set multiplot title "Energy preservation is not symplecticity: max energy error against the defect ||J^T Omega J - Omega||_F / ||Omega||_F\nof the computed one-step map (top); phase error at equal cost, 4.8e5-6.3e5 force + Hessian evaluations (bottom)"
  set key at screen 0.5, 0.875 center center vertical maxrows 3 samplen 1 width 1 box lc rgb "#cccccc" font ",11"
  set logscale xy; set format x "1e%T"; set format y "1e%T"
  # Tic labels kept off the panel edges, where the next panel's would meet them.
  set xrange [1e-15:10]; set yrange [1e-16:10]; set xtics ("1e-12" 1e-12, "1e-8" 1e-8, "1e-4" 1e-4, "1" 1); set ytics 1e4
  set xlabel "map defect (dimensionless)"
  do for [p=1:3] {
    eval panel(p)
    set title spaced(word(problem_title, p)) font ",11"
    if (p > 1) { unset key; unset ylabel; set format y "" } else { set ylabel "energy_err_max (relative)" }
    plot for [c=1:3] table using (in_class(word(problem_prefix, p), c) ? column("symplecticity_defect_map") : NaN):"energy_err_max" \
      with points ls class_style(c) pt class_point(c) ps 1.6 title spaced(word(class_title, c))
  }

  eval panel(4)
  unset logscale y; set format y "% h"; set yrange [0.4:words(cost_rows) + 0.6]
  set format x "1e%T"
  set ytics scale 0 font ",11"; set ytics ()
  do for [r=1:words(cost_rows)] { set ytics add (spaced(word(cost_titles, r)) words(cost_rows) + 1 - r) }
  set xrange [1e-7:1]; set xtics 10 autofreq
  set xlabel "|phase error| after 100 periods (rad)"; unset ylabel
  set title "Kepler e = 0.6, 100 periods, equal cost (step h)" font ",12"
  set grid xtics noytics
  set label 1 "phase lost: wrapped by the tracker (README)" at 1.5e-7, first cost_row("kepler_cost_avf") left textcolor rgb "#555555" font ",11"
  set label 2 "phase lost: wrapped by the tracker (README)" at 1.5e-7, first cost_row("kepler_cost_projection") left textcolor rgb "#555555" font ",11"
  unset key
  plot for [c=1:3] table using (strcol("label")[1:12] eq "kepler_cost_" && !phase_lost(strcol("label")) && cost_class(words(cost_rows) + 1 - cost_row(strcol("label"))) == c ? abs(column("phase_err")) : NaN):(cost_row(strcol("label"))) \
    with points ls class_style(c) pt class_point(c) ps 1.6 notitle
  unset label 1; unset label 2
  unset multiplot
}
