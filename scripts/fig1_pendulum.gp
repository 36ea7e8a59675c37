# Fig. 1 of Kharevych et al. (SCA 2006): pendulum theta0 = 0.5, g/L = 1, h = 0.05.
# Run inside results/fig1_pendulum (scripts/reproduce.sh does); reads series/{short,long}/*.csv.
load scripts."/common.gp"
H0 = 1 - cos(0.5)
relerr(e) = abs(e - H0) / H0
short(m) = "series/short/".m.".csv"
long(m) = "series/long/".m.".csv"
names = "explicit_euler implicit_euler symplectic_euler_a symplectic_euler_b stormer_verlet"
long_names = "explicit_euler implicit_euler symplectic_euler_a stormer_verlet rk4"

do for [format in "png pdf"] {
  if (format eq "png") { set term @png_term } else { set term @pdf_term }

  set output "theta.".format
  set title "Pendulum angle, h = 0.05"
  set xlabel "t"; set ylabel "theta [rad]"; unset logscale
  set key outside right
  plot for [i=1:words(names)] short(word(names,i)) using "t":"q_0" with lines ls i title word(names,i)

  set output "phase.".format
  set title "Phase portrait (theta, theta-dot), h = 0.05, T = 50"
  set xlabel "theta"; set ylabel "theta-dot"
  set size ratio -1
  plot for [i=1:words(names)] short(word(names,i)) using "q_0":"p_0" with lines ls i title word(names,i)
  set size noratio

  set output "energy.".format
  set title "Relative energy error |H - H0|/H0, h = 0.05"
  set xlabel "t"; set ylabel "relative energy error"; set logscale y; set format y "1e%T"
  plot for [i=1:words(names)] short(word(names,i)) using "t":(relerr(column("energy"))) with lines ls i title word(names,i)

  set output "energy_long.".format
  set title "Relative energy error to T = 1e5 (every 500th step point)"
  set logscale x; set format x "1e%T"; set xrange [1:*]
  plot for [i=1:words(long_names)] long(word(long_names,i)) using "t":(relerr(column("energy"))) with lines ls i title word(long_names,i)
  unset logscale; set format x "% h"; set format y "% h"; set xrange [*:*]
}
