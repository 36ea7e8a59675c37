# Momentum maps on the free spring network (claim 1): |P(t) - P(0)| and |L(t) - L(0)| against t.
# Run inside results/momentum (scripts/reproduce.sh does); reads series/net/*.csv.
load scripts."/common.gp"
files = "del_rule_midpoint hp_alpha_0.5 stormer_verlet newmark_beta_0.25_gamma_0.5 implicit_euler rk4"
titles = "del:rule=midpoint hp:alpha=0.5 stormer_verlet newmark(1/4,1/2) implicit_euler rk4"
series(i) = "series/net/".word(files, i).".csv"
clip(x) = x > 1e-16 ? x : 1e-16  # exact zeros drawn at 1e-16 on the log axis

array P0x[words(files)]; array P0y[words(files)]; array L0[words(files)]
do for [i=1:words(files)] {
  stats series(i) using "momentum_0" every ::0::0 nooutput; P0x[i] = STATS_min
  stats series(i) using "momentum_1" every ::0::0 nooutput; P0y[i] = STATS_min
  stats series(i) using "angular_momentum_0" every ::0::0 nooutput; L0[i] = STATS_min
}

do for [format in "png pdf"] {
  if (format eq "png") { set term @png_term } else { set term @pdf_term }
  set termoption noenhanced
  set xlabel "t"; set logscale y; set format y "1e%T"; set key outside right
  set yrange [1e-16:*]

  set output "linear.".format
  set title "Linear momentum error |P(t) - P(0)| (|P(0)| = 19.4), h = 0.01"
  set ylabel "|P(t) - P(0)|"
  plot for [i=1:words(files)] series(i) using "t":(clip(sqrt((column("momentum_0") - P0x[i])**2 + (column("momentum_1") - P0y[i])**2))) with lines ls i title word(titles, i)

  set output "angular.".format
  set title "Angular momentum error |L(t) - L(0)| (L(0) = 323), h = 0.01"
  set ylabel "|L(t) - L(0)|"
  plot for [i=1:words(files)] series(i) using "t":(clip(abs(column("angular_momentum_0") - L0[i]))) with lines ls i title word(titles, i)
  unset logscale; set format y "% h"; set yrange [*:*]
}
