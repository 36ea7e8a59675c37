# Work-precision (issue 5): error_final and energy_err_max against wall time, one figure pair per
# problem and horizon, every method curve on the same log-log axes (fixed-step methods over dt,
# adaptive ones over tolerance). Run inside results/work_precision; the data files under wp/ and
# time_to_error.md are written first by scripts/work_precision_table.sh from summary.csv.
load scripts."/common.gp"
system("bash ".scripts."/work_precision_table.sh summary.csv")
set datafile separator whitespace
set datafile nocolumnheaders
groups = system("cat wp/groups")
# Each group (problem_horizon) in words, for the titles.
group_keys = "pendulum_1e2 pendulum_1e4 kepler_1e2 kepler_1e4 solar_1e2 fpu_1e2 pleiades_t3"
group_words = "pendulum_(theta0_=_1.5),_100_periods_(t_=_730) pendulum_(theta0_=_1.5),_10^4_periods_(t_=_73000) Kepler_(e_=_0.6),_100_periods_(t_=_630) Kepler_(e_=_0.6),_10^4_periods_(t_=_63000) outer_solar_system,_100_Jupiter_periods_(t_=_433000_days) stiff_FPU_chain_(omega_=_50),_t_=_200 Pleiades_(IVP_Test_Set_plei),_t_=_3"
group_index(g) = sum [i=1:words(group_keys)] (word(group_keys, i) eq g ? i : 0)
underscores_to_spaces(s) = (r = "", sum [i=1:strlen(s)] (r = r.(s[i:i] eq "_" ? " " : s[i:i]), 0), r)
group_title(g) = group_index(g) > 0 ? underscores_to_spaces(word(group_words, group_index(g))) : g

do for [format in "png pdf"] {
  if (format eq "png") { set term @png_term } else { set term @pdf_term }
  do for [group in groups] {
    curves = system("cat wp/".group.".curves")
    file(c) = "wp/".group."/".c.".dat"
    set logscale xy; set format x "1e%T"; set format y "1e%T"
    @key_above
    set xlabel "wall time [s]"

    set output "wp_".group."_error.".format
    set title "Final global error against wall time: ".group_title(group) noenhanced
    set ylabel "||(q,p) - exact or reference|| at t_end (problem units)" noenhanced
    plot for [i=1:words(curves)] file(word(curves,i)) using 1:2 with linespoints ls ms(word(curves,i)) \
         title word(curves,i)

    set output "wp_".group."_energy.".format
    set title "Largest relative energy error against wall time: ".group_title(group) noenhanced
    set ylabel "max |H - H0| / |H0| (dimensionless)"
    plot for [i=1:words(curves)] file(word(curves,i)) using 1:3 with linespoints ls ms(word(curves,i)) \
         title word(curves,i)
  }
}
