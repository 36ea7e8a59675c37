# Work-precision (issues 5, 29): error_final, error_max, energy_err_max and |phase_err| against
# wall time, and error_final against force evaluations and steps, one figure set per problem and horizon, every method curve
# on the same log-log axes (fixed-step methods over dt, adaptive ones over tolerance). A point is
# the median of the timed repeats; its horizontal bar runs from the fastest repeat to median + IQR
# (which bounds the third quartile). Thick translucent lines: the best-of-family fronts (the runs
# of a family that no cheaper run of that family beats). Black crosses: runs that ended at their
# wall-clock budget (status timeout), at the seconds spent and the top of the diagram's data.
# Every wall-time diagram of a group spans the same time range, the final and the maximum error
# diagrams the same error range (wp/<group>.scale). Run inside results/work_precision (or
# work_precision_full); the data files under wp/ and time_to_error.md are written first by
# scripts/work_precision_table.sh from summary.csv.
load scripts."/common.gp"
system("bash ".sh_quoted(scripts."/work_precision_table.sh")." summary.csv")
set datafile separator whitespace
set datafile nocolumnheaders
groups = system("cat wp/groups")
# Each group (problem_horizon) in words, for the titles.
group_keys = "pendulum_1e2 pendulum_1e4 kepler_1e2 kepler_1e4 solar_1e2 fpu_1e2 pleiades_t3"
group_words = "pendulum_(theta0_=_1.5),_100_periods_(t_=_730) pendulum_(theta0_=_1.5),_10^4_periods_(t_=_73000) Kepler_(e_=_0.6),_100_periods_(t_=_630) Kepler_(e_=_0.6),_10^4_periods_(t_=_63000) outer_solar_system,_100_Jupiter_periods_(t_=_433000_days) stiff_FPU_chain_(omega_=_50),_t_=_200 Pleiades_(IVP_Test_Set_plei),_t_=_3"
group_index(g) = sum [i=1:words(group_keys)] (word(group_keys, i) eq g ? i : 0)
underscores_to_spaces(s) = (r = "", sum [i=1:strlen(s)] (r = r.(s[i:i] eq "_" ? " " : s[i:i]), 0), r)
group_title(g) = group_index(g) > 0 ? underscores_to_spaces(word(group_words, group_index(g))) : g
# One translucent colour per family (integrators/integrator.cpp method_families()).
family_keys = "explicit_symplectic explicit_rk implicit_variational implicit_other adaptive_geomint adaptive_library"
family_index(f) = sum [i=1:words(family_keys)] (word(family_keys, i) eq f ? i : 0)
set style line 51 lw 7 lc rgb "#a0ff7f0e"  # explicit_symplectic: orange
set style line 52 lw 7 lc rgb "#a09467bd"  # explicit_rk: purple
set style line 53 lw 7 lc rgb "#a0e7298a"  # implicit_variational: magenta
set style line 54 lw 7 lc rgb "#a08c564b"  # implicit_other: brown
set style line 55 lw 7 lc rgb "#a017becf"  # adaptive_geomint: cyan
set style line 56 lw 7 lc rgb "#a0393b79"  # adaptive_library: indigo
fs(f) = 50 + family_index(f)

do for [format in "png pdf svg"] {
  if (format eq "png") { set term @png_term } else { if (format eq "pdf") { set term @pdf_term } else { set term @svg_term } }
  do for [group in groups] {
    curves = system("cat wp/".group.".curves")
    families = system("cat wp/".group.".families")
    file(c) = "wp/".group."/".c.".dat"
    scale = system("cat wp/".group.".scale 2>/dev/null")
    timeout_file = "wp/".group."/timeouts.dat"
    has_timeouts = system("test -s ".timeout_file." && echo 1 || echo 0") + 0
    # The timeout markers (column y of timeouts.dat) as the tail of a plot command run by eval;
    # empty when the group has none, so that no plot opens a missing file.
    marker(y) = has_timeouts ? sprintf(", '%s' using 1:%d with points pt 2 ps 2 lw 2 lc rgb 'black' title 'timeout (wall_budget_s spent: reached no error)' noenhanced", timeout_file, y) : ""
    if (words(scale) == 4) { set xrange [word(scale,1)+0:word(scale,2)+0] } else { set autoscale x }
    front(f, x) = "wp/".group."/front_".f."_".x.".dat"
    set logscale xy; set format x "1e%T"; set format y "1e%T"
    @key_above
    set xlabel "wall time [s] (median of the timed repeats; bar: fastest repeat to median + IQR)"

    if (words(scale) == 4) { set yrange [word(scale,3)+0:word(scale,4)+0] } else { set autoscale y }
    set output "wp_".group."_error.".format
    set title "Final global error against wall time: ".group_title(group) noenhanced
    set ylabel "||(q,p) - exact or reference|| at t_end (problem units)" noenhanced
    eval('plot for [i=1:words(families)] front(word(families,i), "wall") using 1:2 with lines ls fs(word(families,i)) \
           title "front: ".word(families,i), \
         for [i=1:words(curves)] file(word(curves,i)) using 1:2:5:6 with xerrorbars ls ms(word(curves,i)) notitle, \
         for [i=1:words(curves)] file(word(curves,i)) using 1:2 with lines ls ms(word(curves,i)) title word(curves,i)'.marker(2))

    set output "wp_".group."_error_max.".format
    set title "Maximum global error over the step points against wall time: ".group_title(group) noenhanced
    set ylabel "max_k ||(q,p)_k - exact or reference|| (problem units)" noenhanced
    eval('plot for [i=1:words(curves)] file(word(curves,i)) using 1:10:5:6 with xerrorbars ls ms(word(curves,i)) notitle, \
         for [i=1:words(curves)] file(word(curves,i)) using 1:10 with lines ls ms(word(curves,i)) title word(curves,i)'.marker(3))
    set autoscale y

    set output "wp_".group."_energy.".format
    set title "Largest relative energy error against wall time: ".group_title(group) noenhanced
    set ylabel "max |H - H0| / |H0| (dimensionless)"
    eval('plot for [i=1:words(curves)] file(word(curves,i)) using 1:3:5:6 with xerrorbars ls ms(word(curves,i)) notitle, \
         for [i=1:words(curves)] file(word(curves,i)) using 1:3 with lines ls ms(word(curves,i)) title word(curves,i)'.marker(4))

    # Problems with an exact periodic solution only (phase_err: harness/observers.cpp PhaseObserver).
    if (system("awk '$11 != \"nan\" { n++ } END { print n + 0 }' wp/".group."/*.dat") + 0 > 0) {
      set output "wp_".group."_phase.".format
      set title "Phase error at t_end against wall time: ".group_title(group) noenhanced
      set ylabel "|phase_err| = 2 pi |tau| / T (radians)" noenhanced
      eval('plot for [i=1:words(curves)] file(word(curves,i)) using 1:11:5:6 with xerrorbars ls ms(word(curves,i)) notitle, \
           for [i=1:words(curves)] file(word(curves,i)) using 1:11 with lines ls ms(word(curves,i)) title word(curves,i)'.marker(5))
    }

    set autoscale x
    set output "wp_".group."_work.".format
    set multiplot layout 1,2 title "Final global error against work (no timing noise): ".group_title(group) noenhanced
    set key outside top center horizontal maxrows 4 samplen 2 width 0 spacing 1.0 font ",7"
    set title ""
    set ylabel "||(q,p) - exact or reference|| at t_end" noenhanced
    set xlabel "force evaluations"
    plot for [i=1:words(families)] front(word(families,i), "evals") using 7:2 with lines ls fs(word(families,i)) \
           title "front: ".word(families,i), \
         for [i=1:words(curves)] file(word(curves,i)) using 7:2 with linespoints ls ms(word(curves,i)) title word(curves,i)
    set xlabel "steps (accepted)"
    plot for [i=1:words(families)] front(word(families,i), "steps") using 8:2 with lines ls fs(word(families,i)) \
           title "front: ".word(families,i), \
         for [i=1:words(curves)] file(word(curves,i)) using 8:2 with linespoints ls ms(word(curves,i)) title word(curves,i)
    unset multiplot
  }
}
