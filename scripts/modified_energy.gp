# Modified energies (results/modified_energy/README.md): the error of H (slope 2) and of the modified
# energy H + h^2 H2 (slope 4) against the step h, one panel per problem, with RK4 (no correction)
# as the control. Run inside results/modified_energy; reads summary.csv.
load scripts."/common.gp"
# Method specs hold commas: read the table with them written as ";" (scripts/csv_plain.awk).
table = "< awk -f ".sh_quoted(scripts."/csv.awk")." -f ".sh_quoted(scripts."/csv_plain.awk")." summary.csv"
methods = "stormer_verlet position_verlet implicit_midpoint rk4"
# position_verlet has no style of its own in common.gp: a brown line with filled triangles here.
set style line 34 lw 2 lc rgb "#8c6d31" pt 9 ps 1.3
style(m) = (m eq "position_verlet" ? 34 : ms(m))
is_row(label, m) = (strcol("label") eq label && strstrt(strcol("method"), m) == 1)
problems = "pendulum kepler chain"
problem_title = "pendulum:theta0=1.2,omega0=1.7 kepler:e=0.5 FPU-beta~chain,~n~=~4,~mass~2.5"
spaced(s) = system("printf '%s' '".s."' | tr '~' ' '")

png_big = "pngcairo noenhanced size 1000,900 font 'DejaVu Sans,12'"
pdf_big = pdf_for_png(1000, 900, 12)
svg_big = "svg noenhanced size 1000,900 font 'DejaVu Sans,12' background rgb 'white'"
panel_left(k) = (k % 2 == 1 ? 0.1 : 0.6)
panel_top(k) = (k <= 2 ? 0.87 : 0.41)
panel(k) = sprintf("set lmargin at screen %g; set rmargin at screen %g; set tmargin at screen %g; set bmargin at screen %g", \
  panel_left(k), panel_left(k) + 0.37, panel_top(k), panel_top(k) - 0.33)

do for [format in "png pdf svg"] {
  if (format eq "png") { set term @png_big } else { if (format eq "pdf") { set term @pdf_big } else { set term @svg_big } }
  set termoption noenhanced
  set output "modified_energy.".format
  set multiplot title "Backward error analysis: the energy error falls like h^2, the error of the modified energy H + h^2 H2 like h^4\n(to t = 20; relative to |H(0)|; RK4 has no known correction: its energy error only)"
  set logscale xy; set format x "%g"; set format y "1e%T"; set yrange [1e-11:1e-1]; set ytics 1e2
  set xlabel "step h (dimensionless time)"; set ylabel "max |error| / |H(0)|"
  unset key
  do for [k=1:3] {
    p = word(problems, k)
    eval panel(k)
    set title spaced(word(problem_title, k)) font ",12"
    # Reference slopes through 3x the largest error at the middle step (the dt/2 rung).
    stats table using (strcol("label") eq p ? column("dt") : NaN) nooutput
    h_mid = STATS_max / 2; h_lo = STATS_min; h_hi = STATS_max
    set xrange [h_lo / 1.5:h_hi * 1.5]; set xtics (h_lo, h_mid, h_hi)
    stats table using (strcol("label") eq p && abs(column("dt") - h_mid) < 1e-9 ? column("energy_err_max") : NaN) nooutput
    c2 = 3 * STATS_max / h_mid**2
    stats table using (strcol("label") eq p && abs(column("dt") - h_mid) < 1e-9 && strcol("modified_energy_err_max") ne "" ? column("modified_energy_err_max") : NaN) nooutput
    c4 = STATS_max / 3 / h_mid**4
    set label 11 "h^2" at h_lo / 1.3, c2 * (h_lo / 1.3)**2 * 1.8 textcolor rgb "#555555"
    set label 12 "h^4" at h_lo / 1.3, c4 * (h_lo / 1.3)**4 / 4 textcolor rgb "#555555"
    plot for [m in methods] table using (is_row(p, m) ? column("dt") : NaN):"energy_err_max" with linespoints ls style(m), \
         for [m in methods] table using (is_row(p, m) && strcol("modified_energy_err_max") ne "" ? column("dt") : NaN):"modified_energy_err_max" \
           with linespoints ls style(m) dt 2 pt (style(m) == 34 ? 8 : style(m) == 5 ? 6 : 12), \
         c2 * x**2 with lines lw 1.5 lc rgb "#888888" dt 3, c4 * x**4 with lines lw 1.5 lc rgb "#888888" dt 3
    unset label 11; unset label 12
  }
  # The fourth panel holds the key: full method names and what solid and dashed mean.
  eval panel(4)
  unset border; unset tics; unset xlabel; unset ylabel; unset title; unset grid; unset logscale
  set xrange [0:1]; set yrange [0:1]
  set key at screen 0.72, 0.25 center center vertical samplen 4 spacing 1.4 font ",12" box lc rgb "#cccccc"
  plot for [m in methods] NaN with linespoints ls style(m) title (m eq "rk4" ? "rk4: energy H" : mtitle(m).": energy H"), \
       for [m in methods[1:strstrt(methods, " rk4") - 1]] NaN with linespoints ls style(m) dt 2 pt (style(m) == 34 ? 8 : style(m) == 5 ? 6 : 12) \
         title mtitle(m).": modified energy H + h^2 H2", \
       NaN with lines lw 1.5 lc rgb "#888888" dt 3 title "reference slopes h^2, h^4"
  set border; set tics; set grid
  unset key
  unset multiplot
}
