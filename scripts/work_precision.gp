# Work-precision (issue 5): error_final and energy_err_max against wall time, one figure pair per
# problem and horizon, every method curve on the same log-log axes (fixed-step methods over dt,
# adaptive ones over tolerance). Run inside results/work_precision; the data files under wp/ and
# time_to_error.md are written first by scripts/work_precision_table.sh from summary.csv.
load scripts."/common.gp"
system("bash ".scripts."/work_precision_table.sh summary.csv")
set datafile separator whitespace
set datafile nocolumnheaders
groups = system("cat wp/groups")
set style line 9 lw 2 lc rgb "#bcbd22"
set style line 10 lw 2 lc rgb "#17becf"
set style line 11 lw 2 lc rgb "#000000"
set style line 12 lw 2 lc rgb "#aec7e8"
set style line 13 lw 2 lc rgb "#ffbb78"
set style line 14 lw 2 lc rgb "#98df8a"
set style line 15 lw 2 lc rgb "#ff9896"

do for [format in "png pdf"] {
  if (format eq "png") { set term @png_term } else { set term @pdf_term }
  do for [group in groups] {
    curves = system("cat wp/".group.".curves")
    file(c) = "wp/".group."/".c.".dat"
    set logscale xy; set format x "1e%T"; set format y "1e%T"
    set key outside right
    set xlabel "wall time [s]"

    set output "wp_".group."_error.".format
    set title "Final global error vs wall time: ".group." (1e2/1e4 = periods)" noenhanced
    set ylabel "||(q,p) - exact or reference|| at t_end" noenhanced
    plot for [i=1:words(curves)] file(word(curves,i)) using 1:2 with linespoints ls ((i-1)%15+1) \
         pt (i <= 8 ? 7 : 5) title word(curves,i)

    set output "wp_".group."_energy.".format
    set title "Maximum relative energy error vs wall time: ".group noenhanced
    set ylabel "max |H - H0| / |H0|"
    plot for [i=1:words(curves)] file(word(curves,i)) using 1:3 with linespoints ls ((i-1)%15+1) \
         pt (i <= 8 ? 7 : 5) title word(curves,i)
  }
}
