# Stiff FPU chain (GNI I.5.1): oscillatory energies I1, I2, I3 and their total I.
# Run inside results/fpu (scripts/reproduce.sh does); reads series/<h label>/<method>.csv.
load scripts."/common.gp"
methods = "stormer_verlet hp_alpha_0.5 implicit_euler rk4"
labels = "h05 h1 h2 h10"
homega = "0.5 1 2 10"
file(l, m) = "series/".l."/".m.".csv"

do for [format in "png pdf"] {
  if (format eq "png") { set term @png_term; set term pngcairo size 1100,750 } else { set term @pdf_term; set term pdfcairo size 8in,5.5in }
  set termoption noenhanced

  # GNI Fig. 5.1 style: the exchange between the stiff springs at h*omega = 0.5, one panel each.
  set output "exchange.".format
  set multiplot layout 2,2 title "Oscillatory energies I1, I2, I3 and I = I1+I2+I3, h*omega = 0.5"
  set xlabel "t"; set ylabel "I_j"; set yrange [0:1.3]; set key top right horizontal
  do for [i=1:words(methods)] {
    set title word(methods, i)
    plot file("h05", word(methods,i)) using "t":"I1" with lines ls 1 title "I1", \
         "" using "t":"I2" with lines ls 2 title "I2", \
         "" using "t":"I3" with lines ls 3 title "I3", \
         "" using "t":"I" with lines ls 4 title "I"
  }
  unset multiplot

  # The total oscillatory energy per step size: symplectic methods keep it near 1, dissipative
  # ones lose it, explicit ones beyond their limit stop (their curve ends at the failure).
  set output "total.".format
  set multiplot layout 2,2 title "Total oscillatory energy I, omega = 50"
  set ylabel "I"; set yrange [0:1.4]; set key bottom left
  do for [j=1:words(labels)] {
    set title "h*omega = ".word(homega, j)
    plot for [i=1:words(methods)] file(word(labels,j), word(methods,i)) using "t":"I" \
         with lines ls i title word(methods,i)
  }
  unset multiplot

  # The HP midpoint at every step size: the exchange pattern degrades but I stays near 1.
  set output "exchange_hp.".format
  set multiplot layout 2,2 title "hp:alpha=0.5 (midpoint): I1, I2, I3 and I at each h*omega"
  set ylabel "I_j"; set yrange [0:1.3]; set key top right horizontal
  do for [j=1:words(labels)] {
    set title "h*omega = ".word(homega, j)
    f = file(word(labels,j), "hp_alpha_0.5")
    plot f using "t":"I1" with lines ls 1 title "I1", "" using "t":"I2" with lines ls 2 title "I2", \
         "" using "t":"I3" with lines ls 3 title "I3", "" using "t":"I" with lines ls 4 title "I"
  }
  unset multiplot
}
