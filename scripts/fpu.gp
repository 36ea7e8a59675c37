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
stop_of(j, i) = stopped_at[(j - 1) * words(methods) + i]
# Energies of one method are not methods: they take the family palette, I in black.
energy_names = "I1 I2 I3"

# Four panels that read at 1000 px: a squarer, larger canvas than common.gp's, 13-pt text, one
# shared key in a row above the panels (a key per panel would repeat it four times), the panels
# placed by hand: panel(k) sets the margins of panel k = 1..4 (row by row) in screen units.
resized(term, size, points) = term[1:strstrt(term, " size ")] . size . \
  sprintf(" font 'DejaVu Sans,%d'", points) . \
  (strstrt(term, " background ") > 0 ? term[strstrt(term, " background "):] : "")
png_fpu = resized(png_term, "size 1000,950", 13)
pdf_fpu = pdf_for_png(1000, 950, 13)
svg_fpu = resized(svg_term, "size 1000,950", 13)
panel_left(k) = (k % 2 == 1 ? 0.1 : 0.6)
panel_top(k) = (k <= 2 ? 0.83 : 0.41)
panel(k) = sprintf("set lmargin at screen %g; set rmargin at screen %g; set tmargin at screen %g; set bmargin at screen %g", \
  panel_left(k), panel_left(k) + 0.375, panel_top(k), panel_top(k) - 0.3)
# The key row: a plot with nothing but its key, drawn over the full width above the panels.
key_row = "set lmargin at screen 0.02; set rmargin at screen 0.98; set tmargin at screen 0.93; set bmargin at screen 0.88; " . \
  "unset border; unset tics; unset xlabel; unset ylabel; unset title; unset grid; unset logscale; set xrange [0:1]; set yrange [0:1]; " . \
  "set key at screen 0.5, 0.905 center center horizontal maxrows 1 samplen 2.5 width 2 box lc rgb '#cccccc'"
after_key_row = "set border; set tics; set grid"
energy_key = "plot for [k=1:3] NaN with lines ls (40 + 2*k - 1) lw 2.5 title word(energy_names, k), NaN with lines lw 2.5 lc rgb 'black' title 'I (their sum)'"
unset key

do for [format in "png pdf svg"] {
  if (format eq "png") { set term @png_fpu } else { if (format eq "pdf") { set term @pdf_fpu } else { set term @svg_fpu } }
  set termoption noenhanced

  # GNI Fig. 5.1 style: the exchange between the stiff springs at h*omega = 0.5, one panel each.
  set output "exchange.".format
  set multiplot title "Energies I1, I2, I3 of the three stiff springs and their sum I\nat h*omega = 0.5, omega = 50 (GNI section I.5.1)"
  @key_row; @energy_key; @after_key_row; unset key
  set xlabel "t (dimensionless)"; set ylabel "energy (dimensionless)"
  set xrange [0:200]; set yrange [0:1.25]; set xtics 50; set ytics 0.25
  do for [i=1:words(methods)] {
    eval panel(i)
    set title mtitle(word(methods, i)) font ",14"
    if (word(methods, i) eq "implicit_euler") {
      set label 1 "I damped from 1 to below 0.0011 from t = 0.5 on" at graph 0.5, 0.6 center front
    }
    plot for [k=1:3] file("h05", word(methods,i)) using "t":word(energy_names, k) with lines ls (40 + 2*k - 1) lw 2.5 notitle, \
         "" using "t":"I" with lines lw 2.5 lc rgb "black" notitle
    unset label 1
  }
  unset multiplot

  # The total oscillatory energy per step size on a log axis: symplectic methods keep it near 1,
  # dissipative ones lose decades of it, explicit ones beyond their limit stop (the curve ends).
  set output "total.".format
  set multiplot title "Total oscillatory energy I = I1 + I2 + I3 (exact flow: within 0.065 of 1)\nat four step sizes, omega = 50"
  @key_row
  plot for [i=1:words(methods)] NaN with lines ls ms(word(methods,i)) lw 2.5 title mtitle(word(methods,i))
  @after_key_row; unset key
  set xlabel "t (dimensionless)"; set ylabel "I (dimensionless)"; set xrange [0:200]; set xtics 50
  set logscale y; set format y "1e%T"; set yrange [1e-16:1e2]; set ytics 1e4; set mytics 4
  do for [j=1:words(labels)] {
    eval panel(j)
    set title "h*omega = ".word(homega, j) font ",14"
    # Runs that stopped: say so in the panel, since their curve is a few points at t = 0.
    note = ""
    do for [i=1:words(methods)] {
      if (stop_of(j, i) < t_end) {
        note = note . (strlen(note) > 0 ? "\n" : "") . mtitle(word(methods, i)) . \
          (stop_of(j, i) == 0 ? ": diverged in its first step" : sprintf(": diverged at t = %g", stop_of(j, i)))
      }
    }
    if (strlen(note) > 0) { set label 2 note at graph 0.97, 0.14 right front }
    plot for [i=1:words(methods)] file(word(labels,j), word(methods,i)) using "t":"I" \
         with lines ls ms(word(methods,i)) lw 2.5 notitle
    unset label 2
  }
  unset multiplot
  unset logscale; set format y "% h"; set mytics default

  # The HP midpoint at every step size: the exchange pattern degrades but I stays near 1.
  set output "exchange_hp.".format
  set multiplot title "hp:alpha=0.5 (the midpoint rule): I1, I2, I3 and I at four step sizes\nthe exchange between I1, I2, I3 slows and freezes as h grows; I stays near 1"
  @key_row; @energy_key; @after_key_row; unset key
  set xlabel "t (dimensionless)"; set ylabel "energy (dimensionless)"
  set xrange [0:200]; set yrange [0:1.25]; set xtics 50; set ytics 0.25
  do for [j=1:words(labels)] {
    eval panel(j)
    set title "h*omega = ".word(homega, j) font ",14"
    f = file(word(labels,j), "hp_alpha_0.5")
    plot for [k=1:3] f using "t":word(energy_names, k) with lines ls (40 + 2*k - 1) lw 2.5 notitle, \
         "" using "t":"I" with lines lw 2.5 lc rgb "black" notitle
  }
  unset multiplot
}
