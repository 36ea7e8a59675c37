# Momentum maps on the free spring network (claim 1): |P(t) - P(0)| and |L(t) - L(0)| against t.
# Run inside results/momentum (scripts/reproduce.sh does); reads series/net/*.csv. The network's
# units are dimensionless (unit node mass, spacing 1). del comes before hp: hp's dashes show on it.
load scripts."/common.gp"
files = "del_rule_midpoint hp_alpha_0.5 stormer_verlet newmark_beta_0.25_gamma_0.5 implicit_euler rk4"
series(i) = "series/net/".word(files, i).".csv"
clip(x) = x > 1e-16 ? x : 1e-16  # exact zeros drawn at 1e-16 on the log axis

array P0x[words(files)]; array P0y[words(files)]; array L0[words(files)]
do for [i=1:words(files)] {
  stats series(i) using "momentum_0" every ::0::0 nooutput; P0x[i] = STATS_min
  stats series(i) using "momentum_1" every ::0::0 nooutput; P0y[i] = STATS_min
  stats series(i) using "angular_momentum_0" every ::0::0 nooutput; L0[i] = STATS_min
}

do for [format in "png pdf svg"] {
  if (format eq "png") { set term @png_term } else { if (format eq "pdf") { set term @pdf_term } else { set term @svg_term } }
  set termoption noenhanced
  set xlabel "t (dimensionless)"; set logscale y; set format y "1e%T"; @key_above
  set yrange [1e-16:*]
  set label 2 "every method keeps P to round-off here\n(linear momentum is a linear invariant)" at graph 0.02, graph 0.9 left font ",9" front

  set output "linear.".format
  set title "Linear momentum error (|P(0)| = 19.4), h = 0.01; exact zeros drawn at 1e-16"
  set ylabel "|P(t) - P(0)| (dimensionless)"
  plot for [i=1:words(files)] series(i) using "t":(clip(sqrt((column("momentum_0") - P0x[i])**2 + (column("momentum_1") - P0y[i])**2))) with lines ls ms(word(files, i)) title mtitle(word(files, i))

  unset label 2
  set output "angular.".format
  set label 1 "del:midpoint and hp:alpha=0.5 coincide to round-off:\nhp's magenta dashes lie on del's black line" at graph 0.02, graph 0.3 left font ",9" front
  set title "Angular momentum error (L(0) = 323), h = 0.01; exact zeros drawn at 1e-16"
  set ylabel "|L(t) - L(0)| (dimensionless)"
  plot for [i=1:words(files)] series(i) using "t":(clip(abs(column("angular_momentum_0") - L0[i]))) with lines ls ms(word(files, i)) title mtitle(word(files, i))
  unset logscale; set format y "% h"; set yrange [*:*]; unset label 1
}
