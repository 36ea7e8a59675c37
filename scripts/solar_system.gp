# Outer solar system (GNI I.2.4): energy and angular-momentum error over 1e6 days, and the orbits.
# Run inside results/solar_system (scripts/reproduce.sh does); reads series/{h10,h100,orbits}/.
# Units: AU, days, solar masses; the relative errors are dimensionless.
load scripts."/common.gp"
methods = "stormer_verlet symplectic_euler_a hp_alpha_0.5 rk4"
file(l, m) = "series/".l."/".m.".csv"
# |L| of the initial state (GNI Table 2.1 data), for the relative angular-momentum error.
L0 = 6.0782528363529986e-05
names = "Sun Jupiter Saturn Uranus Neptune Pluto"
max(a, b) = a > b ? a : b
# Initial energy and angular momentum: the first row of any run (all start from Table 2.1).
first = file("h10", "stormer_verlet")
envelope(f) = sprintf("< awk -F, -v column=energy -v ref=%.17g -v per_decade=10 -v min_width=4333 -v min_count=5 -f %s %s 2>/dev/null", E0, sh_quoted(scripts."/envelope.awk"), f)
stats first using "energy" every ::0::0 nooutput; E0 = STATS_min
stats first using "angular_momentum_0" every ::0::0 nooutput; L0x = STATS_min
stats first using "angular_momentum_1" every ::0::0 nooutput; L0y = STATS_min
stats first using "angular_momentum_2" every ::0::0 nooutput; L0z = STATS_min

do for [format in "png pdf svg"] {
  if (format eq "png") { set term @png_term; set term pngcairo size 1100,500 } else { if (format eq "pdf") { set term @pdf_term; set term pdfcairo size 8in,3.6in } else { set term @svg_term; set term svg size 1100,500 } }
  set termoption noenhanced

  # Relative energy error, both step sizes side by side on log-log axes: bounded oscillation for
  # the symplectic methods, linear drift for RK4. The series are sampled about once per Jupiter
  # period, so the curves are the per-window maximum (scripts/envelope.awk), not the samples.
  set output "energy.".format
  set multiplot layout 1,2 title "Relative energy error, outer solar system: largest value per window\n(one tenth of a decade, at least one Jupiter period and 5 samples)"
  set xlabel "t [days]"; set ylabel "max |H - H0| / |H0| in the window"
  set logscale xy; set format x "1e%T"; set format y "1e%T"; set xrange [1e4:1.2e6]
  set key below horizontal
  do for [h in "10 100"] {
    set title "h = ".h." days"
    plot for [i=1:words(methods)] envelope(file("h".h, word(methods,i))) \
         using 1:2 with linespoints ls ms(word(methods,i)) pn 8 title mtitle(word(methods,i))
  }
  unset multiplot

  # Relative angular-momentum error |L - L0|/|L0| (round-off for the symplectic methods).
  set output "angular_momentum.".format
  set multiplot layout 1,2 title "Relative angular-momentum error |L - L0|/|L0|"
  set ylabel "|L - L0| / |L0| (dimensionless)"; set yrange [1e-17:*]; set xrange [4e3:1.2e6]
  do for [h in "10 100"] {
    set title "h = ".h." days"
    plot for [i=1:words(methods)] file("h".h, word(methods,i)) \
         using "t":(max(1e-17, sqrt((column("angular_momentum_0") - L0x)**2 + \
                                   (column("angular_momentum_1") - L0y)**2 + \
                                   (column("angular_momentum_2") - L0z)**2) / L0)) \
         with lines ls ms(word(methods,i)) title mtitle(word(methods,i))
  }
  unset multiplot
  unset logscale; set format x "% h"; set format y "% h"; set xrange [*:*]; set yrange [*:*]

  # Heliocentric orbits projected on the x-y plane (Stormer-Verlet, h = 10 days, 2e5 days); the
  # barycentre drifts because GNI's initial data do not have zero total momentum.
  if (format eq "png") { set term pngcairo size 800,800 } else { if (format eq "pdf") { set term pdfcairo size 6in,6in } else { set term @svg_term; set term svg size 800,800 } }
  set termoption noenhanced
  set output "orbits.".format
  set title "Heliocentric orbits, x-y projection (stormer_verlet, h = 10 days, T = 2e5 days)"
  set xlabel "x - x_Sun [AU]"; set ylabel "y - y_Sun [AU]"; set size ratio -1; set key inside top right vertical
  plot for [b=1:5] file("orbits", "stormer_verlet") \
       using (column(sprintf("q_%d", 3*b)) - column("q_0")):(column(sprintf("q_%d", 3*b+1)) - column("q_1")) \
       with lines ls word("41 43 45 47 48", b) + 0 title word(names, b+1), \
       "+" using (0):(0) every ::0::0 with points pt 7 ps 2 lc rgb "#d62728" title "Sun"
  set size noratio
}
