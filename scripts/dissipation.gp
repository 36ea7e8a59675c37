# Dissipation (docs/METHOD.md §2): damped oscillator energy against the exact decay, the energy error
# against h, and the angular-momentum drift of each force placement on the damped spring network.
# Run inside results/dissipation; reads series/decay, series/slots and summary.csv.
load scripts."/common.gp"
zeta = 0.1; w = 1.0; wd = w * sqrt(1 - zeta**2)
x(t) = exp(-zeta*w*t) * (cos(wd*t) + zeta*w/wd * sin(wd*t))
v(t) = -exp(-zeta*w*t) * w**2/wd * sin(wd*t)
exact_energy(t) = 0.5*v(t)**2 + 0.5*w**2*x(t)**2
methods = "del_rule_midpoint hp_alpha_0.5 implicit_euler explicit_euler"
specs = "del:rule=midpoint hp:alpha=0.5 implicit_euler explicit_euler"
prefixes = "del: hp: implicit_euler explicit_euler"  # canonical specs in summary.csv start so
decay(i, dt) = "series/decay/".word(methods, i)."__dt".dt.".csv"
slots = "minus,force_at=node plus,force_at=node split,force_at=node minus,force_at=midpoint plus,force_at=midpoint split,force_at=midpoint"
slot_file(i) = "series/slots/del_force_slot_".word(slots, i)[1:strstrt(word(slots, i), ",") - 1]."_force_at_".word(slots, i)[strstrt(word(slots, i), "=") + 1:].".csv"
clip(x) = x > 1e-16 ? x : 1e-16
stats slot_file(1) using "angular_momentum_0" every ::0::0 nooutput; L0 = STATS_min
# summary.csv rows of the decay block, by canonical method name prefix.
select(name) = (strcol("label") eq "decay" && strstrt(strcol("method"), name) == 1) ? column("energy_err_max") : NaN

do for [format in "png pdf"] {
  if (format eq "png") { set term @png_term } else { set term @pdf_term }
  set termoption noenhanced
  set key outside right

  set output "energy.".format
  set title "Damped oscillator (zeta = 0.1), h = 0.2: energy against the exact decay"
  set xlabel "t"; set ylabel "H(t)"; set logscale y; set format y "1e%T"
  plot for [i=1:words(methods)] decay(i, "0.2") using "t":"energy" with lines ls i title word(specs, i), \
       exact_energy(x) with lines lw 1 dt 2 lc rgb "black" title "exact"

  set output "energy_error.".format
  set title "Largest |H(t) - H_exact(t)| / H0 to T = 30 against h"
  set xlabel "h"; set ylabel "energy error"; set logscale xy; set format x "% g"
  set xrange [0.04:0.25]
  plot for [i=1:words(specs)] "summary.csv" using "dt":(select(word(prefixes, i))) with linespoints ls i pt 7 title word(specs, i), \
       0.2*(x/0.1) with lines dt 2 lc rgb "black" title "slope 1", \
       2e-3*(x/0.1)**2 with lines dt 3 lc rgb "black" title "slope 2"
  unset logscale; set xrange [*:*]; set format x "% h"

  set output "force_slot.".format
  set title "Damped spring network, del:rule=midpoint, h = 0.01: |L(t) - L(0)| per force placement"
  set xlabel "t"; set ylabel "|L(t) - L(0)|"; set logscale y; set format y "1e%T"
  set yrange [1e-16:*]
  plot for [i=1:words(slots)] slot_file(i) using "t":(clip(abs(column("angular_momentum_0") - L0))) with lines ls i title "force_slot=".word(slots, i)
  unset logscale; set format y "% h"; set yrange [*:*]

  set output "force_slot_signed.".format
  set title "Damped spring network, del, h = 0.01: signed L(t) - L(0), impulse at q_{k+1/2}"
  set ylabel "L(t) - L(0)"
  plot for [i=4:6] slot_file(i) using "t":(column("angular_momentum_0") - L0) with lines ls i title "force_slot=".word(slots, i)
}
