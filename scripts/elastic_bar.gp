# Elastic bar scene (docs/METHOD.md §6): energy of the clamped swing, damped energy at three steps,
# the free bar's momenta, and the deformed bar at a few times. Run inside results/elastic_bar;
# reads series/{swing,swing_verlet,damped,spin,shapes}/*.csv.
load scripts."/common.gp"
swing(m) = "series/swing/".m.".csv"
swing_names = "hp_alpha_0.5 del_rule_midpoint implicit_euler newmark_beta_0.25_gamma_0.5"
swing_titles = "hp:alpha=0.5 del:midpoint implicit_euler newmark(1/4,1/2)"
damped_steps = "0.005 0.01 0.02"
spin_names = "hp_alpha_0.5_solver_minimize implicit_euler stormer_verlet"
# First data row's energy: H0 of each series.
H0 = 37.19625000000001
# Mesh of the default bar (8 x 2 x 2 cells of 0.125 x 0.1 x 0.1, clamped face x = 0 not in q):
# the awk filter turns each state row of the shapes series into polylines (the 9 longitudinal
# node lines and the 9 cross-section outlines), one gnuplot data set per row.
nx = 8; ny = 2; nz = 2; hx = 0.125; hy = 0.1; hz = 0.1
bar_lines = sprintf("< awk -F, -v OFS=, -v nx=%d -v ny=%d -v nz=%d -v hx=%g -v hy=%g -v hz=%g -f %s/bar_lines.awk series/shapes/hp_alpha_0.5.csv 2>/dev/null", nx, ny, nz, hx, hy, hz, scripts)

do for [format in "png pdf"] {
  if (format eq "png") { set term @png_term } else { set term @pdf_term }
  set termoption noenhanced

  set output "energy.".format
  set title "Clamped bar under gravity: relative energy error |H - H0|/H0 (h = 0.01; Verlet h = 0.004)"
  set xlabel "t [s]"; set ylabel "|H - H0| / H0"; set logscale y; set format y "1e%T"
  set key outside right
  plot for [i=1:words(swing_names)] swing(word(swing_names, i)) using "t":(abs(column("energy") - H0) / H0) with lines ls i title word(swing_titles, i), \
       "series/swing_verlet/stormer_verlet__dt0.004.csv" using "t":(abs(column("energy") - H0) / H0) with lines ls 5 title "stormer_verlet h=0.004"
  unset logscale; set format y "% h"

  set output "damped.".format
  set title "Damped bar (nu = 0.05), hp:alpha=0.5: total energy at three step sizes"
  set xlabel "t [s]"; set ylabel "H [J]"
  plot for [i=1:words(damped_steps)] "series/damped/hp_alpha_0.5__dt".word(damped_steps, i).".csv" using "t":"energy" with lines ls i title "h = ".word(damped_steps, i)

  set output "spin.".format
  set title "Free spinning bar (h = 0.004): drift of the momenta |J(t) - J(0)|"
  set xlabel "t [s]"; set ylabel "absolute error"; set logscale y; set format y "1e%T"
  set yrange [1e-17:1]
  spin(m) = "series/spin/".m.".csv"
  plot for [i=1:words(spin_names)] spin(word(spin_names, i)) using "t":(L = sqrt((column("angular_momentum_0") - 0.8755359185767151)**2 + (column("angular_momentum_1") + 3.021314666011959)**2 + (column("angular_momentum_2") - 2.056810333988043)**2), L < 1e-17 ? 1e-17 : L) with lines ls i title word(spin_names, i)." angular", \
       for [i=1:words(spin_names)] spin(word(spin_names, i)) using "t":(P = sqrt(column("momentum_0")**2 + column("momentum_1")**2 + (column("momentum_2") - 6.718750000000004)**2), P < 1e-17 ? 1e-17 : P) with lines ls i dt 2 title word(spin_names, i)." linear"
  unset logscale; set format y "% h"; set yrange [*:*]

  set output "shapes.".format
  set title "Clamped bar released under gravity, hp:alpha=0.5, h = 0.01: t = 0, 0.25, ..., 1.5 s"
  set xlabel "x"; set ylabel "y"; set zlabel "z"
  set view 80, 20, 1, 1; set view equal xyz; set xyplane at -1.1
  set xrange [-0.1:1.1]; set yrange [-0.2:0.4]; set zrange [-1.1:0.3]; set ytics 0.2
  set key outside right
  splot for [k=0:6] bar_lines index k using 1:2:3 with lines ls (k + 1) title sprintf("t = %.2f", 0.25 * k)
  set view 60, 30, 1, 1; set view noequal; set xrange [*:*]; set yrange [*:*]; set zrange [*:*]
  set ytics autofreq
}
