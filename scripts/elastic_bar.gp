# Elastic bar scene (docs/METHOD.md §6): energy of the clamped swing, damped energy at three steps,
# the free bar's momenta, and the deformed bar at a few times. Run inside results/elastic_bar;
# reads series/{swing,swing_verlet,damped,spin,shapes}/*.csv. SI units (E = 1e5 Pa, rho = 1000
# kg/m^3, g = 9.81 m/s^2): t in s, lengths in m, energies in J.
load scripts."/common.gp"
swing(m) = "series/swing/".m.".csv"
# del before hp: the two coincide here, and hp's dashes show on del's line.
swing_names = "del_rule_midpoint hp_alpha_0.5 implicit_euler newmark_beta_0.25_gamma_0.5"
damped_steps = "0.005 0.01 0.02"
spin_names = "hp_alpha_0.5_solver_minimize implicit_euler stormer_verlet"
# First data row's energy: H0 of each series.
H0 = 37.19625000000001
# Mesh of the default bar (8 x 2 x 2 cells of 0.125 x 0.1 x 0.1, clamped face x = 0 not in q):
# the awk filter turns each state row of the shapes series into polylines (the 9 longitudinal
# node lines and the 9 cross-section outlines), one gnuplot data set per row.
nx = 8; ny = 2; nz = 2; hx = 0.125; hy = 0.1; hz = 0.1
bar_lines = sprintf("< awk -F, -v OFS=, -v nx=%d -v ny=%d -v nz=%d -v hx=%g -v hy=%g -v hz=%g -f %s series/shapes/hp_alpha_0.5.csv 2>/dev/null", nx, ny, nz, hx, hy, hz, sh_quoted(scripts."/bar_lines.awk"))

do for [format in "png pdf svg"] {
  if (format eq "png") { set term @png_term } else { if (format eq "pdf") { set term @pdf_term } else { set term @svg_term } }
  set termoption noenhanced

  set output "energy.".format
  set title "Clamped bar under gravity: relative energy error (h = 0.01 s; stormer_verlet h = 0.004 s, its limit is near 0.005 s)"
  set xlabel "t [s]"; set ylabel "|H - H0| / H0 (dimensionless)"; set logscale y; set format y "1e%T"
  @key_above
  set label 1 "del:midpoint and hp:alpha=0.5 coincide (hp's magenta dashes on del's black line)" at graph 0.02, graph 0.03 left font ",9" front
  plot for [i=1:words(swing_names)] swing(word(swing_names, i)) using "t":(abs(column("energy") - H0) / H0) with lines ls ms(word(swing_names, i)) title mtitle(word(swing_names, i)), \
       "series/swing_verlet/stormer_verlet__dt0.004.csv" using "t":(abs(column("energy") - H0) / H0) with lines ls ms("stormer_verlet") title "stormer_verlet, h = 0.004 s"
  unset logscale; set format y "% h"; unset label 1

  set output "damped.".format
  set title "Damped bar (nu = 0.05 s), hp:alpha=0.5: total energy at three step sizes"
  set xlabel "t [s]"; set ylabel "H [J]"
  # Step sizes of one method: the family palette, the finest dashed on top.
  plot for [i=words(damped_steps):1:-1] "series/damped/hp_alpha_0.5__dt".word(damped_steps, i).".csv" using "t":"energy" with lines ls (40 + 3*i - 2) dt 1 + (i == 1) title "h = ".word(damped_steps, i)." s"

  set output "spin.".format
  # Two panels rather than two dash styles per method: every method keeps its own style.
  set multiplot layout 1,2 title "Free spinning bar, h = 0.004 s: drift of the momenta (exact zeros drawn at 1e-17)"
  set xlabel "t [s]"; set logscale y; set format y "1e%T"
  set yrange [1e-17:1]; set key inside top right opaque box lc rgb "#cccccc" samplen 2
  spin(m) = "series/spin/".m.".csv"
  set title "angular momentum"; set ylabel "|J(t) - J(0)| [kg m^2/s]"
  plot for [i=1:words(spin_names)] spin(word(spin_names, i)) using "t":(L = sqrt((column("angular_momentum_0") - 0.8755359185767151)**2 + (column("angular_momentum_1") + 3.021314666011959)**2 + (column("angular_momentum_2") - 2.056810333988043)**2), L < 1e-17 ? 1e-17 : L) with lines ls ms(word(spin_names, i)) title mtitle(word(spin_names, i))
  set title "linear momentum"; set ylabel "|P(t) - P(0)| [kg m/s]"
  plot for [i=1:words(spin_names)] spin(word(spin_names, i)) using "t":(P = sqrt(column("momentum_0")**2 + column("momentum_1")**2 + (column("momentum_2") - 6.718750000000004)**2), P < 1e-17 ? 1e-17 : P) with lines ls ms(word(spin_names, i)) title mtitle(word(spin_names, i))
  unset multiplot
  unset logscale; set format y "% h"; set yrange [*:*]

  set output "shapes.".format
  set title "Clamped bar released under gravity, hp:alpha=0.5, h = 0.01 s: t = 0, 0.25, ..., 1.5 s"
  set xlabel "x [m]"; set ylabel "y [m]"; set zlabel "z [m]" offset -3, 0
  set view 80, 20, 1, 1; set view equal xyz; set xyplane at -1.1
  set xrange [-0.1:1.1]; set yrange [-0.2:0.4]; set zrange [-1.1:0.3]; set ytics 0.2
  set key outside right vertical nobox noopaque maxrows auto
  splot for [k=0:6] bar_lines index k using 1:2:3 with lines ls (41 + k) title sprintf("t = %.2f", 0.25 * k)
  set view 60, 30, 1, 1; set view noequal; set xrange [*:*]; set yrange [*:*]; set zrange [*:*]
  set ytics autofreq
}
