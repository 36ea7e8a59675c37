# Scaling figure (issue 9 item 4; docs/METHODS.md "Scale"): CPU seconds per step against dof, log-log, for
# Stormer-Verlet and the HP midpoint step on spring_chain and on elastic_bar (HP per linear
# solver), with a slope-1 reference. Run inside results/scaling; reads scaling.csv, written by
# bench_scaling --csv (scripts/scaling.sh).
load scripts."/common.gp"
series = "verlet_chain hp_chain verlet_bar hp_bar_ldlt hp_bar_cholmod hp_bar_cg"
titles = "stormer_verlet/spring_chain hp/spring_chain stormer_verlet/elastic_bar hp/elastic_bar/ldlt hp/elastic_bar/cholmod hp/elastic_bar/cg"
# The reference line c*dof runs a factor 3 below the cheapest cost per dof of the explicit chain.
stats "scaling.csv" using (strcol("series") eq "verlet_chain" ? column("seconds_per_step") / column("dof") : NaN) nooutput
ref_c = STATS_min / 3

do for [format in "png pdf svg"] {
  if (format eq "png") { set term @png_term } else { if (format eq "pdf") { set term @pdf_term } else { set term @svg_term } }
  set termoption noenhanced
  set output "scaling.".format
  set title "Cost of one step against problem size (process CPU s; implicit steps at h = 20 x the explicit limit)"
  set xlabel "dof"; set ylabel "CPU seconds per step"
  set logscale xy; set format x "1e%T"; set format y "1e%T"
  @key_above
  plot for [i=1:words(series)] "scaling.csv" using (strcol("series") eq word(series, i) ? column("dof") : NaN):"seconds_per_step" \
         with linespoints ls (40 + i) title word(titles, i), \
       ref_c * x with lines lw 1 dt (4,4) lc rgb "#888888" title "slope 1 (cost proportional to dof)"
  unset output
}
