# Dissipation (docs/METHOD.md §2): damped oscillator energy against the exact decay, the energy error
# against h, and the angular-momentum drift of each force placement on the damped spring network.
# Run inside results/dissipation; reads series/decay, series/slots and summary.csv. Both problems
# are dimensionless (unit masses, omega = 1).
load scripts."/common.gp"
zeta = 0.1; w = 1.0; wd = w * sqrt(1 - zeta**2)
x(t) = exp(-zeta*w*t) * (cos(wd*t) + zeta*w/wd * sin(wd*t))
v(t) = -exp(-zeta*w*t) * w**2/wd * sin(wd*t)
exact_energy(t) = 0.5*v(t)**2 + 0.5*w**2*x(t)**2
methods = "del_rule_midpoint hp_alpha_0.5 implicit_euler explicit_euler"
prefixes = "del: hp: implicit_euler explicit_euler"  # canonical specs in summary.csv start so
decay(i, dt) = "series/decay/".word(methods, i)."__dt".dt.".csv"
slots = "minus,force_at=node plus,force_at=node split,force_at=node minus,force_at=midpoint plus,force_at=midpoint split,force_at=midpoint"
slot_file(i) = "series/slots/del_force_slot_".word(slots, i)[1:strstrt(word(slots, i), ",") - 1]."_force_at_".word(slots, i)[strstrt(word(slots, i), "=") + 1:].".csv"
# The six placements are variants of one method: family palette, the midpoint ones thick, and
# plus dashed so that it shows on minus where the two coincide.
slot_style(i) = word("42 44 46 41 47 48", i) + 0
slot_title(i) = "force_slot=".word(slots, i)
clip(x) = x > 1e-16 ? x : 1e-16
stats slot_file(1) using "angular_momentum_0" every ::0::0 nooutput; L0 = STATS_min
# summary.csv rows of the decay block, by canonical method name prefix.
select(name) = (strcol("label") eq "decay" && strstrt(strcol("method"), name) == 1) ? column("energy_err_max") : NaN

do for [format in "png pdf svg"] {
  if (format eq "png") { set term @png_term } else { if (format eq "pdf") { set term @pdf_term } else { set term @svg_term } }
  set termoption noenhanced
  set style line 41 lw 4; set style line 47 lw 2 dt (6,4)
  @key_above

  set output "energy.".format
  set title "Damped oscillator (zeta = 0.1), h = 0.2: energy against the exact decay"
  set xlabel "t (dimensionless)"; set ylabel "H(t) (dimensionless)"; set logscale y; set format y "1e%T"
  set label 1 "del:midpoint, hp:alpha=0.5 and the exact decay lie on one another\n(hp magenta dashes, exact black dashes)" at graph 0.02, graph 0.05 left font ",9" front
  plot for [i=1:words(methods)] decay(i, "0.2") using "t":"energy" with lines ls ms(word(methods, i)) title mtitle(word(methods, i)), \
       exact_energy(x) with lines lw 1 dt 2 lc rgb "black" title "exact"
  unset label 1

  set output "energy_error.".format
  set title "Damped oscillator: largest energy error to t = 30 against the step size"
  set xlabel "step size h (dimensionless)"; set ylabel "max |H(t) - H_exact(t)| / H0 (dimensionless)"; set logscale xy; set format x "% g"
  set xrange [0.04:0.25]; set xtics (0.05, 0.1, 0.2)
  set label 1 "del:midpoint and hp:alpha=0.5 coincide\n(hp's magenta diamonds on del's black squares)" at graph 0.97, graph 0.15 right font ",9"
  plot for [i=1:words(methods)] "summary.csv" using "dt":(select(word(prefixes, i))) with linespoints ls ms(word(methods, i)) title mtitle(word(methods, i)), \
       0.2*(x/0.1) with lines dt 2 lc rgb "black" title "slope 1", \
       2e-3*(x/0.1)**2 with lines dt 3 lc rgb "black" title "slope 2"
  unset logscale; set xrange [*:*]; set format x "% h"; unset label 1; set xtics autofreq

  set output "force_slot.".format
  set title "Damped spring network, del:midpoint, h = 0.01: angular momentum error per force placement\n(exact zeros drawn at 1e-16)"
  set xlabel "t (dimensionless)"; set ylabel "|L(t) - L(0)| (dimensionless)"; set logscale y; set format y "1e%T"
  set yrange [1e-16:1]
  set label 1 "minus and plus at the midpoint coincide\n(plus dashed on minus)" at graph 0.97, graph 0.7 right font ",9"
  plot for [i=1:words(slots)] slot_file(i) using "t":(clip(abs(column("angular_momentum_0") - L0))) with lines ls slot_style(i) title slot_title(i)
  unset label 1
  unset logscale; set format y "% h"; set yrange [*:*]

  set output "force_slot_signed.".format
  set title "Damped spring network, del:midpoint, h = 0.01: signed angular momentum error, force at q_{k+1/2}"
  set ylabel "L(t) - L(0) (dimensionless)"
  plot for [i=4:6] slot_file(i) using "t":(column("angular_momentum_0") - L0) with lines ls slot_style(i) title slot_title(i)
}
