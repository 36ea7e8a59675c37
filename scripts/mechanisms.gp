# Mechanisms (results/mechanisms/README.md): the elastic rod's tip under a step end load against
# d'Alembert's triangle wave, the loop action next to the map defect, and Andrews' squeezer's
# error against wall time. Run inside
# results/mechanisms (scripts/reproduce.sh does); reads series/rod_*/ and summary.csv.
load scripts."/common.gp"
table = "< awk -f ".sh_quoted(scripts."/csv.awk")." -f ".sh_quoted(scripts."/csv_plain.awk")." summary.csv"

# L = 1, c = 1, F/EA = 1: the tip rises at speed 1 to 2 at t = 2 and falls back to 0 at t = 4.
dalembert(t) = (phase = t - 4 * floor(t / 4), phase <= 2 ? phase : 4 - phase)
rod_files = "rod_lumped/stormer_verlet__dt0.0078125 rod_lumped/stormer_verlet__dt0.00390625 rod_lumped/implicit_midpoint__dt0.0078125 rod_consistent/gauss_s_2__dt0.03125"
rod_titles = "stormer_verlet,~lumped,~Courant~1 stormer_verlet,~lumped,~Courant~1/2 implicit_midpoint,~lumped,~Courant~1 gauss:s=2,~consistent~(N~=~32),~Courant~1"
rod_series(i) = "series/".word(rod_files, i).".csv"
spaced(s) = system("printf '%s' '".s."' | tr '~' ' '")

# Loop action against map defect: one marker per method, symplectic ones at the round-off corner.
loop_keys = "stormer_verlet symplectic_euler_a implicit_midpoint gauss del hp composition explicit_euler implicit_euler rk4 odeint_dopri5 gsl_rk8pd cvode_adams"
loop_styles = "stormer_verlet symplectic_euler_a implicit_midpoint gauss_s2 del hp composition_yoshida4 explicit_euler implicit_euler rk4 odeint_dopri5 gsl_rk8pd cvode_adams"
clip(x) = x > 1e-17 ? x : 1e-17  # exact zeros drawn at 1e-17 on the log axes
is_loop(dummy) = strcol("label")[1:5] eq "loop_" || strcol("label")[1:5] eq "toda_"

do for [format in "png pdf svg"] {
  if (format eq "png") { set term @png_term } else { if (format eq "pdf") { set term @pdf_term } else { set term @svg_term } }
  set termoption noenhanced
  @key_above

  set output "rod_front.".format
  set title "Elastic rod (128 lumped or 32 consistent elements), tip under a step end load from rest (L = c = F/EA = 1)"
  set xlabel "t (units of L/c)"; set ylabel "tip displacement (units of FL/EA)"
  set xrange [0:8]; set yrange [-0.2:2.4]
  plot dalembert(x) with lines lw 4 lc rgb "#bbbbbb" title "d'Alembert (continuum)", \
       for [i=1:words(rod_files)] rod_series(i) using "t":"tip" with lines ls (40 + 2 * i) title spaced(word(rod_titles, i))

  set output "loop_action.".format
  set title "Loop action after one step against the map defect (Kepler, Henon-Heiles, Toda)"
  set xlabel "symplecticity_defect_map"; set ylabel "loop_action_err"
  set logscale xy; set format x "1e%T"; set format y "1e%T"
  set xrange [1e-16:1]; set yrange [1e-17:1]
  plot for [k=1:words(loop_keys)] table using (is_loop(0) && strstrt(strcol("method"), word(loop_keys, k)) == 1 ? clip(column("symplecticity_defect_map")) : NaN):(clip(column("loop_action_err"))) with points ls ms(word(loop_styles, k)) title mtitle(word(loop_styles, k))
  unset logscale; set format x "% h"; set format y "% h"; set xrange [*:*]; set yrange [*:*]

  # Andrews' squeezer: error against the Test Set reference at t = 0.03 against wall time, IDA's
  # two forms over rtol 1e-4 ... 1e-12 (one point per tolerance), and the fixed-step RATTLE, HP
  # and DEL midpoint steps on the mass M(q) over h = 1e-4 ... 1e-5 (one point per step).
  set output "andrews_wp.".format
  set title "andrews (IVP Test Set) to t = 0.03: error against the Test Set reference vs wall time\nIDA index 3 (rtol 1e-4 ... 1e-10) and index 2 (1e-4 ... 1e-12); rattle, hp, del:rule=midpoint at h = 1e-4 ... 1e-5"
  set xlabel "wall time [s]"; set ylabel "||(q,p) - reference|| at t = 0.03"
  set logscale xy; set format x "1e%T"; set format y "1e%T"
  plot table using (strcol("label") eq "andrews_ida" && strstrt(strcol("method"), "index=3") ? column("wall_s") : NaN):(column("error_final")) with points ls 41 ps 1.5 title "ida:index=3", \
       table using (strcol("label") eq "andrews_ida" && strstrt(strcol("method"), "index=2") ? column("wall_s") : NaN):(column("error_final")) with points ls 43 ps 1.5 title "ida:index=2", \
       for [m in "rattle hp del"] table using (strcol("label") eq "andrews_variational" && strstrt(strcol("method"), m.":") == 1 ? column("wall_s") : NaN):(column("error_final")) with linespoints ls (m eq "rattle" ? 44 : m eq "hp" ? 45 : 46) ps 1.2 title (m eq "del" ? "del:rule=midpoint" : m)
  unset logscale; set format x "% h"; set format y "% h"
}
