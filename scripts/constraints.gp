# Holonomic constraints (PAPER.md §3 claim 3, issue 10; docs/METHOD.md §3): constraint drift at
# position and velocity level and the energy error against t over 10^5 steps, car axis
# work-precision against the IVP Test Set reference, the penalty contrast over k. Run inside
# results/constraints (scripts/reproduce.sh does); reads series/{chain,pendulum}/*.csv and
# summary.csv (through awk: gnuplot cuts a quoted spec at its first comma).
load scripts."/common.gp"
# Series file -> style key of the method map (the SHAKE variant would otherwise match "rattle").
files = "rattle rattle_velocity_projection_false composition_base_rattle_scheme_yoshida4 penalty_k_1e6 ida_index_2 ida_index_3"
keys = "rattle shake composition_rattle_yoshida4 penalty ida_index_2 ida_index_3"
series(run, i) = "series/".run."/".word(files, i).".csv"
clip(x) = x > 1e-17 ? x : 1e-17  # exact zeros drawn at 1e-17 on the log axis
problem_title(run) = run eq "chain" ? "rod_chain:n=2 (double pendulum, chaotic)" : "cartesian_pendulum (theta0 = 0.5, length 1)"

# summary.csv -> curves/<group>_<curve>.dat: car axis (wall_s error_final) and penalty
# (k constraint_err_max energy_err_max) per step size.
system("rm -rf curves && mkdir -p curves && awk -f ".sh_quoted(scripts."/csv.awk")." -f ".sh_quoted(scripts."/constraints_curves.awk")." summary.csv")

do for [format in "png pdf svg"] {
  if (format eq "png") { set term @png_term } else { if (format eq "pdf") { set term @pdf_term } else { set term @svg_term } }
  set termoption noenhanced

  do for [run in "chain pendulum"] {
    set output "drift_".run.".".format
    set multiplot layout 2,1 title "Constraint residuals against t, h = 1e-3, 10^5 steps: ".problem_title(run)." (IDA adaptive, default tolerances)"
    set logscale y; set format y "1e%T"; set yrange [1e-17:1]
    eval key_above
    set xlabel "t (dimensionless)"
    set ylabel "max |g(q)| (length)"
    plot for [i=1:words(files)] series(run, i) using "t":(clip(column("constraint_err"))) with lines ls ms(word(keys, i)) title mtitle(word(keys, i))
    set key off
    set ylabel "max |G M^-1 p| (length / time)"
    plot for [i=1:words(files)] series(run, i) using "t":(clip(column("constraint_vel_err"))) with lines ls ms(word(keys, i)) title mtitle(word(keys, i))
    unset multiplot
    unset logscale; set format y "% h"; set yrange [*:*]

    array E0[words(files)]
    do for [i=1:words(files)] { stats series(run, i) using "energy" every ::0::0 nooutput; E0[i] = STATS_min }
    set output "energy_".run.".".format
    set title "Relative energy error against t, h = 1e-3: ".problem_title(run)."; exact zeros at 1e-17"
    set logscale y; set format y "1e%T"; set yrange [1e-17:1]
    eval key_above
    set ylabel "|H - H0| / |H0|"
    plot for [i=1:words(files)] series(run, i) using "t":(clip(abs(column("energy") - E0[i]) / abs(E0[i]))) with lines ls ms(word(keys, i)) title mtitle(word(keys, i))
    unset logscale; set format y "% h"; set yrange [*:*]
  }

  set datafile separator whitespace; set datafile nocolumnheaders
  curves = system("cat curves/car_axis.list")
  set output "car_axis_wp.".format
  set title "car_axis (IVP Test Set) to t = 3: error against the Test Set reference vs wall time\nfixed steps h = 4e-3 ... 1.25e-4; IDA over rtol 1e-4 ... 1e-10; the reference's own error is ~3.5e-13"
  set logscale xy; set format x "1e%T"; set format y "1e%T"
  eval key_above
  set xlabel "wall time [s]"; set ylabel "||(q,p) - reference|| at t = 3 (length)"
  plot for [i=1:words(curves)] "curves/car_axis_".word(curves, i).".dat" using 1:2 with linespoints ls ms(word(curves, i)) title mtitle(word(curves, i))
  unset logscale; set format x "% h"; set format y "% h"

  set output "penalty.".format
  set title "Penalty contrast on cartesian_pendulum:theta0=1.2 (Stormer-Verlet base, t = 2): constraint error ~ 1/k;\nat h = 1e-3 the added stiffness sqrt(k/m) breaks Verlet's h*omega < 2 beyond k ~ 4e6 (missing points: diverged)"
  set logscale xy; set format x "1e%T"; set format y "1e%T"
  set key top right
  set xlabel "penalty stiffness k"; set ylabel "max |g(q)| and max |H - H0|/|H0|"
  plot "curves/penalty_1e-05.dat" using 1:2 with linespoints ls 41 title "max |g|, h = 1e-5", \
       "curves/penalty_0.001.dat" using 1:2 with points ls 45 ps 2 title "max |g|, h = 1e-3", \
       "curves/penalty_1e-05.dat" using 1:3 with linespoints ls 43 dt (4,2) title "energy error, h = 1e-5", \
       2.64 / x with lines lc rgb "#aaaaaa" dt 3 title "2.64 / k"
  unset logscale; set format x "% h"; set format y "% h"
  set datafile separator comma; set datafile columnheaders
}
