# Convergence: global error at T = 5 against dt, one panel per problem, with reference slopes.
# Run inside results/order_basic; reads order_points.csv.
load scripts."/common.gp"
methods = "explicit_euler implicit_euler symplectic_euler_a symplectic_euler_b stormer_verlet rk4"
select(label, method) = (strcol("label") eq label && strcol("method") eq method && strcol("status") eq "ok") ? column("error_final") : NaN

do for [format in "png pdf"] {
  if (format eq "png") { set term @png_term } else { set term @pdf_term }
  do for [label in "pendulum kepler"] {
    set output "order_".label.".".format
    set title "Global error at T = 5 (".label.")"
    set xlabel "dt"; set ylabel "||(q,p) - exact||"
    set logscale xy; set format x "1e%T"; set format y "1e%T"
    set key outside right
    ref = (label eq "pendulum") ? 0.1 : 0.02
    set xrange [ref/600:ref*1.5]
    plot for [i=1:words(methods)] "order_points.csv" using "dt":(select(label, word(methods,i))) \
           with linespoints ls i pt 7 title word(methods,i), \
         1e-1*(x/ref) with lines dt 2 lc rgb "black" title "slope 1", \
         1e-3*(x/ref)**2 with lines dt 3 lc rgb "black" title "slope 2", \
         1e-5*(x/ref)**4 with lines dt 4 lc rgb "black" title "slope 4"
  }
}
