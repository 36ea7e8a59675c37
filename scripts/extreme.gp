# Extreme cases (issue 4): heat map of log10 error_final per method (rows) and case (columns),
# labelled with the error and the force evaluations (cost); failures are grey with their status. Run inside results/extreme; reads summary.csv.
load scripts."/common.gp"
cases = "kepler_e0.9 kepler_e0.99 separatrix stiff_1e2 stiff_1e4 stiff_1e6 stiff_1e8"
# Canonical method specs start with these names (the heat map's rows, top to bottom).
methods = "stormer_verlet symplectic_euler_a del: hp: implicit_midpoint implicit_euler rk4 newmark cvode_bdf odeint_dopri5"
method_titles = "stormer_verlet symplectic_euler_a del:midpoint hp:alpha=0.5 implicit_midpoint implicit_euler rk4 newmark(1/4,1/2) cvode_bdf odeint_dopri5"
case_x(s) = sum [i=1:words(cases)] (s eq word(cases, i) ? i : 0)
method_y(s) = sum [i=1:words(methods)] (strstrt(s, word(methods, i)) == 1 ? i : 0)
ok(s) = s eq "ok"
# Blocks outside the heat map (the loosened-tolerance rows) have case_x = 0 and are skipped.
in_map(label, method) = case_x(label) > 0 && method_y(method) > 0
clip(e) = e < 1e-12 ? -12 : (e > 10 ? 1 : log10(e))

do for [format in "png pdf svg"] {
  if (format eq "png") { set term pngcairo size 1200,760 font 'DejaVu Sans,10' } else { if (format eq "pdf") { set term pdfcairo size 8in,5in font 'DejaVu Sans,8' } else { set term @svg_term; set term svg size 1200,760 } }
  set termoption noenhanced
  set output "heatmap.".format
  set title "Final error |(q, p) - exact| (colour, first line) and force evaluations (f) per method and case;\ngrey: failed, with its status and the time reached"
  set xrange [0.5:words(cases) + 0.5]; set yrange [words(methods) + 0.5:0.5]
  set xtics () ; set ytics ()
  do for [i=1:words(cases)] { set xtics add (word(cases, i) i) }
  do for [i=1:words(methods)] { set ytics add (word(method_titles, i) i) }
  set xtics nomirror; set ytics nomirror; unset grid
  set cbrange [-12:1]; set cblabel "log10 of |(q, p) - exact| at t_end (dimensionless)"
  set palette defined (-12 "#1a9850", -8 "#91cf60", -4 "#fee08b", -2 "#fc8d59", 1 "#d73027")
  set style fill solid 1.0 border lc rgb "white"
  unset key
  plot "summary.csv" using (in_map(strcol("label"), strcol("method")) && ok(strcol("status")) ? case_x(strcol("label")) : NaN):(method_y(strcol("method"))):(0.5):(0.5):(clip(column("error_final"))) with boxxyerror fc palette, \
       "" using (in_map(strcol("label"), strcol("method")) && !ok(strcol("status")) ? case_x(strcol("label")) : NaN):(method_y(strcol("method"))):(0.5):(0.5) with boxxyerror fc rgb "#bbbbbb", \
       "" using (in_map(strcol("label"), strcol("method")) ? case_x(strcol("label")) : NaN):(method_y(strcol("method"))):(ok(strcol("status")) ? sprintf("%.1e\n%d f", column("error_final"), column("force_evals")) : sprintf("%s\nat t=%g", strcol("status"), column("t_reached"))) with labels font ",8"
}
