# Stiff FPU chain (GNI I.5.1): oscillatory energies I1, I2, I3 and their total I.
# Run inside results/fpu (scripts/reproduce.sh does); reads series/<h label>/<method>.csv.
# Unit masses and omega = 50 in GNI's scaling: t and the energies are dimensionless.
load scripts."/common.gp"
methods = "stormer_verlet hp_alpha_0.5 implicit_euler rk4"
labels = "h05 h1 h2 h10"
homega = "0.5 1 2 10"
file(l, m) = "series/".l."/".m.".csv"
t_end = 200
# Where each run's series ends: an explicit method beyond its stability limit stops early.
array stopped_at[words(labels) * words(methods)]
do for [j=1:words(labels)] {
  do for [i=1:words(methods)] {
    stats file(word(labels, j), word(methods, i)) using "t" nooutput
    stopped_at[(j - 1) * words(methods) + i] = STATS_max
  }
}
run_title(j, i) = mtitle(word(methods, i)) . \
  (stopped_at[(j - 1) * words(methods) + i] >= t_end ? "" : \
   stopped_at[(j - 1) * words(methods) + i] == 0 ? " (diverged in its first step)" : \
   sprintf(" (diverged at t = %g)", stopped_at[(j - 1) * words(methods) + i]))
# Energies of one method are not methods: they take the family palette, I in black.
energy_names = "I1 I2 I3"

do for [format in "png pdf svg"] {
  if (format eq "png") { set term @png_term; set term pngcairo size 1100,750 } else { if (format eq "pdf") { set term @pdf_term; set term pdfcairo size 8in,5.5in } else { set term @svg_term; set term svg size 1100,750 } }
  set termoption noenhanced

  # GNI Fig. 5.1 style: the exchange between the stiff springs at h*omega = 0.5, one panel each.
  set output "exchange.".format
  set multiplot layout 2,2 title "Oscillatory energies I1, I2, I3 of the stiff springs and their sum I, h*omega = 0.5"
  set xlabel "t (dimensionless)"; set ylabel "I_j (dimensionless)"; set yrange [0:1.3]
  set key top right horizontal opaque box lc rgb "#cccccc" samplen 2
  do for [i=1:words(methods)] {
    set title mtitle(word(methods, i))
    plot for [k=1:3] file("h05", word(methods,i)) using "t":word(energy_names, k) with lines ls (40 + 2*k - 1) title word(energy_names, k), \
         "" using "t":"I" with lines lw 2 lc rgb "black" title "I"
  }
  unset multiplot

  # The total oscillatory energy per step size on a log axis: symplectic methods keep it near 1,
  # dissipative ones lose decades of it, explicit ones beyond their limit stop (the curve ends).
  set output "total.".format
  set multiplot layout 2,2 title "Total oscillatory energy I = I1 + I2 + I3 (exact: within 0.065 of 1), omega = 50"
  set ylabel "I (dimensionless)"; set logscale y; set format y "1e%T"; set yrange [1e-16:1e2]
  set key bottom left opaque box lc rgb "#cccccc" samplen 2 maxrows 4
  do for [j=1:words(labels)] {
    set title "h*omega = ".word(homega, j)
    plot for [i=1:words(methods)] file(word(labels,j), word(methods,i)) using "t":"I" \
         with lines ls ms(word(methods,i)) title run_title(j, i)
  }
  unset multiplot
  unset logscale; set format y "% h"

  # The HP midpoint at every step size: the exchange pattern degrades but I stays near 1.
  set output "exchange_hp.".format
  set multiplot layout 2,2 title "hp:alpha=0.5 (midpoint): I1, I2, I3 and I at each h*omega"
  set ylabel "I_j (dimensionless)"; set yrange [0:1.3]
  set key top right horizontal opaque box lc rgb "#cccccc" samplen 2 maxrows 1
  do for [j=1:words(labels)] {
    set title "h*omega = ".word(homega, j)
    f = file(word(labels,j), "hp_alpha_0.5")
    plot for [k=1:3] f using "t":word(energy_names, k) with lines ls (40 + 2*k - 1) title word(energy_names, k), \
         "" using "t":"I" with lines lw 2 lc rgb "black" title "I"
  }
  unset multiplot
}
