# Charged particle (results/charged_particle/README.md): the relative energy error along the helix
# in a uniform B over 1000 gyrations (series/), and the largest energy and canonical angular
# momentum errors of every method in each field (summary.csv). Run inside results/charged_particle.
load scripts."/common.gp"
# Method specs hold commas: read the table with them written as ";" (scripts/csv_plain.awk).
table = "< awk -f ".sh_quoted(scripts."/csv.awk")." -f ".sh_quoted(scripts."/csv_plain.awk")." summary.csv"
# boris has no style of its own in common.gp: a dark green line with filled circles here; the
# tight CVODE BDF run shares cvode_bdf's grey, dashed.
set style line 34 lw 2 lc rgb "#006d2c" pt 7 ps 1.1
set style line 35 lw 2 lc rgb "#7f7f7f" pt 1 ps 1.5 dt (6,3)
runs = "helix/boris helix/del helix/implicit_midpoint helix/rk4 helix_cvode/cvode_bdf helix_cvode/cvode_bdf_rtol_1e-10_atol_1e-12 helix_cvode/cvode_adams_rtol_1e-10_atol_1e-12"
run_titles = "boris del:midpoint implicit_midpoint rk4 cvode_bdf~(rtol~1e-8,~atol~1e-10) cvode_bdf~(rtol~1e-10,~atol~1e-12) cvode_adams~(rtol~1e-10,~atol~1e-12)"
run_style(i) = (i == 1 ? 34 : i == 6 ? 35 : ms(word(runs, i)[strstrt(word(runs, i), "/") + 1:]))
spaced(s) = system("printf '%s' '".s."' | tr '~' ' '")
period = 12.4666375  # 2 pi / |omega| of the helix (scene.toml)
# E(0) of each series, to make its error relative.
array energy0[words(runs)]
do for [i=1:words(runs)] {
  stats "series/".word(runs, i).".csv" using "energy" every ::0::0 nooutput
  energy0[i] = STATS_min
}

# Bottom panel: one row per field, one marker per method; energy (filled) and the canonical
# angular momentum about the field axis (open) where it is conserved.
fields = "helix electron bottle bottle_mu"
field_titles = "helix,~uniform~B~(1000~gyrations) electron~in~1~T~(SI,~1000~gyrations) magnetic~bottle~(100~gyrations) adiabatic~bottle~(1000~gyrations)"
cp_methods = "boris del implicit_midpoint rk4"
field_y(label) = sum [f=1:words(fields)] (label eq word(fields, f) ? words(fields) + 1 - f : 0)
offset(m) = (strstrt(m, "boris") == 1 ? 0.24 : strstrt(m, "del") == 1 ? 0.08 : strstrt(m, "implicit_midpoint") == 1 ? -0.08 : -0.24)

png_big = "pngcairo noenhanced size 1000,1000 font 'DejaVu Sans,12'"
pdf_big = pdf_for_png(1000, 1000, 12)
svg_big = "svg noenhanced size 1000,1000 font 'DejaVu Sans,12' background rgb 'white'"

do for [format in "png pdf svg"] {
  if (format eq "png") { set term @png_big } else { if (format eq "pdf") { set term @pdf_big } else { set term @svg_big } }
  set termoption noenhanced
  set output "charged_particle.".format
  set multiplot title "Charged particle: Boris and the variational integrators keep the energy to round-off. Top: helix in a uniform B\n(m = 2.5, q = -0.7, B = 1.8, |omega| = 0.504, h*omega = 0.2), relative energy error along the run; bottom: per field"

  set lmargin at screen 0.11; set rmargin at screen 0.97; set tmargin at screen 0.835; set bmargin at screen 0.54
  unset title
  # (The loop's previous format left the bottom panel's axes behind.)
  unset logscale x; set format x "% h"; set grid xtics ytics
  set logscale y; set format y "1e%T"; set yrange [1e-17:1]; set ytics 1e2 scale default font ""
  set xrange [0:1000]; set xtics 100
  set xlabel "t / (2 pi / |omega|)   (gyrations)"; set ylabel "|E(t) - E(0)| / |E(0)|"
  set key at screen 0.54, 0.885 center center horizontal maxrows 4 samplen 2.5 width 1 font ",11"
  plot for [i=1:words(runs)] "series/".word(runs, i).".csv" using ($1 / period):(abs(column("energy") - energy0[i]) / abs(energy0[i])) \
    with lines ls run_style(i) lw 2 title spaced(word(run_titles, i))

  set lmargin at screen 0.36; set rmargin at screen 0.97; set tmargin at screen 0.38; set bmargin at screen 0.09
  set title "Largest error over the run, per field" font ",13"
  # The electron's angular momentum is in SI units (changes below 1e-31 kg m^2/s): off this scale.
  set label 21 "x p_y - y p_x in SI units: off scale" at graph 0.5, first field_y("electron") center textcolor rgb "#555555" font ",11"
  set xrange [1e-16:1]; set logscale x; set format x "1e%T"; set xtics 1e2
  unset logscale y; set format y "% h"; set yrange [0.5:words(fields) + 0.5]
  set ytics scale 0 font ",11"; set ytics ()
  do for [f=1:words(fields)] { set ytics add (spaced(word(field_titles, f)) words(fields) + 1 - f) }
  set xlabel "max relative energy error (filled), max |change of x p_y - y p_x| (open)"; unset ylabel
  set grid xtics noytics
  set key at screen 0.6, 0.44 center center horizontal maxrows 1 samplen 1 width 1 font ",11"
  plot for [m in cp_methods] table using (strstrt(strcol("method"), m) == 1 ? column("energy_err_max") : NaN):(field_y(strcol("label")) + offset(m)) \
         with points ls (m eq "boris" ? 34 : ms(m)) pt (m eq "boris" ? 7 : m eq "del" ? 5 : m eq "implicit_midpoint" ? 11 : 13) ps 1.6 title (m eq "del" ? "del:midpoint" : m), \
       for [m in cp_methods] table using (strstrt(strcol("method"), m) == 1 && strcol("angular_momentum_err_max") ne "" ? column("angular_momentum_err_max") : NaN):(field_y(strcol("label")) + offset(m)) \
         with points ls (m eq "boris" ? 34 : ms(m)) pt (m eq "boris" ? 6 : m eq "del" ? 4 : m eq "implicit_midpoint" ? 10 : 12) ps 1.6 notitle
  unset label 21
  unset multiplot
}
