# Fig. 1 of Kharevych et al. (SCA 2006): pendulum theta0 = 0.5, g/L = 1, h = 0.05.
# Run inside results/fig1_pendulum (scripts/reproduce.sh does); reads series/{short,long}/*.csv.
# Time is in units of sqrt(L/g), so t, h and the energy errors are dimensionless.
load scripts."/common.gp"
H0 = 1 - cos(0.5)
relerr(e) = abs(e - H0) / H0
short(m) = "series/short/".m.".csv"
long(m) = "series/long/".m.".csv"
names = "explicit_euler implicit_euler symplectic_euler_a symplectic_euler_b stormer_verlet"
long_names = "explicit_euler implicit_euler symplectic_euler_a stormer_verlet rk4"
# Long-run envelope: max |H - H0|/H0 per window (10 per decade, at least one pendulum period
# 6.38 wide); the short run (every step to t = 50, same trajectory) supplies the early windows.
envelope(m) = sprintf("< awk -F, -v column=energy -v ref=%.17g -v per_decade=10 -v min_width=6.4 -v min_count=5 -f %s %s %s 2>/dev/null", \
                      H0, sh_quoted(scripts."/envelope.awk"), (system("test -f ".short(m)." && echo 1") eq "1" ? short(m) : ""), long(m))
# The explicit Euler spiral is the widest curve of the phase portrait: the axes hold all of it.
stats short("explicit_euler") using "q_0":"p_0" nooutput
phase_extent = 1.05 * (abs(STATS_min_x) > STATS_max_x ? abs(STATS_min_x) : STATS_max_x)
phase_extent_y = 1.05 * (abs(STATS_min_y) > STATS_max_y ? abs(STATS_min_y) : STATS_max_y)

do for [format in "png pdf svg"] {
  if (format eq "png") { set term @png_term } else { if (format eq "pdf") { set term @pdf_term } else { set term @svg_term } }
  @key_above

  set output "theta.".format
  set title "Pendulum angle, h = 0.05"
  set xlabel "t (dimensionless, units of sqrt(L/g))"; set ylabel "theta [rad]"; unset logscale
  plot for [i=1:words(names)] short(word(names,i)) using "t":"q_0" with lines ls ms(word(names,i)) title mtitle(word(names,i))

  set output "phase.".format
  set title "Phase portrait, h = 0.05, t = 0 to 50"
  set xlabel "theta [rad]"; set ylabel "dtheta/dt [rad per unit of t]"
  set size ratio -1
  set xrange [-phase_extent:phase_extent]; set yrange [-phase_extent_y:phase_extent_y]
  plot for [i=1:words(names)] short(word(names,i)) using "q_0":"p_0" with lines ls ms(word(names,i)) title mtitle(word(names,i))
  set size noratio; set xrange [*:*]; set yrange [*:*]

  set output "energy.".format
  set title "Relative energy error, h = 0.05"
  set xlabel "t (dimensionless)"; set ylabel "|H - H0| / H0 (dimensionless)"; set logscale y; set format y "1e%T"
  set label 1 "symplectic_euler_a and _b have the same energy error (b dashed on a)" at graph 0.02, graph 0.05 left font ",9" front
  plot for [i=1:words(names)] short(word(names,i)) using "t":(relerr(column("energy"))) with lines ls ms(word(names,i)) title mtitle(word(names,i))
  unset label 1

  set output "energy_long.".format
  set title "Relative energy error to t = 100000 (about 16000 periods), h = 0.05:\nlargest value per window (a tenth of a decade, at least one period and 5 samples)"
  set xlabel "t (dimensionless)"; set ylabel "max |H - H0| / H0 in the window"
  set logscale x; set format x "1e%T"; set xrange [3:1.5e5]
  plot for [i=1:words(long_names)] envelope(word(long_names,i)) using 1:2 with linespoints ls ms(word(long_names,i)) pn 12 title mtitle(word(long_names,i))
  unset logscale; set format x "% h"; set format y "% h"; set xrange [*:*]
}
