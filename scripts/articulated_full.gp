# Articulated chains, long form (results/articulated_full/README.md): the wall time per step of
# the long runs (MuJoCo at 256 and 1024 links, ODE's world step at 256, the dense DEL step at 128;
# large points) on the curves of results/articulated (lines), log-log.
# Run inside results/articulated_full; reads long_curves/*.csv (scripts/articulated_full.py) and
# ../articulated/curves/*.csv.
load scripts."/common.gp"
short_files = system("ls ../articulated/curves")
long_files = system("ls long_curves")
method_of(f) = f[strstrt(f, "__") + 2:strlen(f) - 4]
block_of(f) = f[1:strstrt(f, "__") - 1]

do for [format in "png pdf svg"] {
  if (format eq "png") { set term @png_term } else { if (format eq "pdf") { set term @pdf_term } else { set term @svg_term } }
  set termoption noenhanced
  set output "cost_long.".format
  set title "Wall time per step against n: the long runs (points) on the curves of results/articulated\n(rod chain, h = 1/240; MuJoCo and DART at 1024: (120-step - 24-step run) / 96, no model build)"
  set xlabel "links n"; set ylabel "seconds per step"
  set logscale xy; set format y "1e%T"; set xrange [3:1400]; set yrange [5e-7:1]; set xtics (4, 16, 64, 256, 1024)
  set key outside right top font ",10"
  set rmargin 30
  plot for [f in short_files] "../articulated/curves/".f using "n":"wall_s_per_step" with lines ls ms(method_of(f)) \
         dt 1 + 2 * (block_of(f) eq "cost_articulated") title mtitle(method_of(f)) . (block_of(f) eq "cost_articulated" ? " (articulated_chain)" : ""), \
       for [f in long_files] "long_curves/".f using "n":"wall_s_per_step" with points ls ms(method_of(f)) ps 2.5 \
         title mtitle(method_of(f))." (long form)"
  unset output
}
