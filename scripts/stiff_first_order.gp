# Stiff first-order references (issue 11): significant correct digits (scd) at the IVP Test Set's
# end time against wall time, one panel per problem (VDPOL, ROBER), one curve per method over its
# tolerances or steps. Run inside results/stiff_first_order; reads summary.csv through
# scripts/stiff_first_order_curves.awk.
load scripts."/common.gp"
system("rm -rf curves && mkdir curves && awk -f ".sh_quoted(scripts."/stiff_first_order_curves.awk")." summary.csv")
set datafile separator whitespace
set datafile nocolumnheaders
titles = "vdpol rober"
palette = "#7f7f7f #1f77b4 #2ca02c #d62728 #9467bd #00a087 #b8860b #393b79 #e7298a #8c564b"
words_vdpol = "VDPOL (van der Pol, epsilon = 1e-6), t = 2"
words_rober = "ROBER (Robertson), t = 1e11"

do for [format in "png pdf svg"] {
  if (format eq "png") { set term @png_term } else { if (format eq "pdf") { set term @pdf_term } else { set term @svg_term } }
  set output "scd_vs_wall.".format
  set multiplot layout 1,2 title "Significant correct digits against wall time (IVP Test Set references)"
  set logscale x; set format x "1e%T"
  set xlabel "wall time [s]"; set ylabel "scd = -log10 max relative component error"
  set key bottom right
  do for [group in titles] {
    methods = system("cat curves/".group.".list")
    set title (group eq "vdpol" ? words_vdpol : words_rober)
    plot for [i=1:words(methods)] "curves/".group."_".word(methods, i).".dat" using 1:2 \
         with linespoints lw 2 pt i lc rgb word(palette, i) title word(methods, i)
  }
  unset multiplot
}
