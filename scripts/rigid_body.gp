# The tennis-racket flip on the momentum sphere (results/rigid_body, label flip): Π(t) of a few
# methods drawn on the sphere |Π| = |Π(0)|, and how far each leaves it, ||Π(t)|/|Π(0)| − 1|.
# Run inside results/rigid_body (scripts/reproduce.sh does); reads series/flip*/*.csv.
load scripts."/common.gp"
# Euler's equations write Π as y_0..y_2, the 9-coordinate body as Pi1..Pi3.
files = "flip/lie_poisson__dt0.04 flip/rk4__dt0.04 flip/quaternion__dt0.04 flip_cvode/cvode_bdf flip_attitude/rattle"
titles = "lie_poisson(h=0.04) rk4(h=0.04) quaternion(h=0.04) cvode_bdf(defaults) rattle(h=0.01)"
colours = "#000000 #9467bd #2ca02c #7f7f7f #ff7f0e"
dashes = "1 2 3 1 1"
series(i) = "series/".word(files, i).".csv"
pi_column(i, k) = (strstrt(word(files, i), "flip_attitude") == 1 ? sprintf("Pi%d", k) : sprintf("y_%d", k - 1))
radius(i) = sqrt(column(pi_column(i, 1))**2 + column(pi_column(i, 2))**2 + column(pi_column(i, 3))**2)
clip(x) = x > 1e-17 ? x : 1e-17  # exact zeros drawn at 1e-17 on the log axis

array R0[words(files)]
do for [i=1:words(files)] {
  stats series(i) using (radius(i)) every ::0::0 nooutput; R0[i] = STATS_min
}

do for [format in "png pdf svg"] {
  if (format eq "png") { set term @png_term } else { if (format eq "pdf") { set term @pdf_term } else { set term @svg_term } }
  set termoption noenhanced

  set output "sphere.".format
  set title "Tennis-racket flip, I = (1, 2, 2.5): Pi(t) on the momentum sphere |Pi| = ".sprintf("%.4f", R0[1])." over 10 flips"
  set parametric; set isosamples 24, 12; set hidden3d nooffset; set view 65, 30; set view equal xyz
  set xyplane relative 0
  set urange [0:2*pi]; set vrange [-pi/2:pi/2]
  set xlabel "Pi_1"; set ylabel "Pi_2"; set zlabel "Pi_3"; @key_above
  splot R0[1]*cos(u)*cos(v), R0[1]*sin(u)*cos(v), R0[1]*sin(v) with lines lc rgb "#dddddd" notitle, \
        for [i=1:words(files)] series(i) using (column(pi_column(i, 1))):(column(pi_column(i, 2))):(column(pi_column(i, 3))) with lines lw 2 lc rgb word(colours, i) dt int(word(dashes, i)) title word(titles, i)
  unset parametric; unset hidden3d; set view 60, 30, 1, 1; set xyplane relative 0.5
  unset zlabel

  set output "casimir.".format
  set title "Distance from the momentum sphere: | |Pi(t)|/|Pi(0)| - 1 |; exact zeros drawn at 1e-17"
  set xlabel "t (time units of 1/Omega_2(0))"; set ylabel "| |Pi(t)|/|Pi(0)| - 1 |"
  set logscale y; set format y "1e%T"; set yrange [1e-17:*]
  plot for [i=1:words(files)] series(i) using "t":(clip(abs(radius(i)/R0[i] - 1))) with lines lw 2 lc rgb word(colours, i) dt int(word(dashes, i)) title word(titles, i)
  unset logscale; set format y "% h"; set yrange [*:*]
}
