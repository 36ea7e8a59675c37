# Convergence: global error at T = 5 against dt, one panel per problem, with reference slopes.
# Run inside results/order_basic; reads order_points.csv. Both problems are dimensionless.
load scripts."/common.gp"
methods = "explicit_euler implicit_euler symplectic_euler_a symplectic_euler_b stormer_verlet rk4"
# Matched through the method map, not by equality: gnuplot cuts a quoted field at its first comma
# ("implicit_euler:max_iter=50,tol=1e-12" reads as "implicit_euler:max_iter=50").
select(label, method) = (strcol("label") eq label && method_index(strcol("method")) == method_index(method) && strcol("status") eq "ok") ? column("error_final") : NaN

do for [format in "png pdf svg"] {
  if (format eq "png") { set term @png_term } else { if (format eq "pdf") { set term @pdf_term } else { set term @svg_term } }
  do for [label in "pendulum kepler"] {
    set output "order_".label.".".format
    set title "Global error at t = 5 against the step size: ".(label eq "pendulum" ? "pendulum, theta0 = 1.5" : "Kepler orbit, e = 0.6")
    set xlabel "step size h (dimensionless)"; set ylabel "||(q,p) - exact|| at t = 5 (dimensionless)"
    set logscale xy; set format x "1e%T"; set format y "1e%T"
    @key_above
    ref = (label eq "pendulum") ? 0.1 : 0.02
    set xrange [ref/600:ref*1.5]
    set label 1 "implicit_euler (open circles) lies on explicit_euler at small h,\nsymplectic_euler_b (dashed) on symplectic_euler_a" at graph 0.98, graph 0.2 right font ",9" front
    plot for [i=1:words(methods)] "order_points.csv" using "dt":(select(label, word(methods,i))) \
           with linespoints ls ms(word(methods,i)) title mtitle(word(methods,i)), \
         1e-1*(x/ref) with lines lw 1 dt 2 lc rgb "black" title "slope 1", \
         1e-3*(x/ref)**2 with lines lw 1 dt 3 lc rgb "black" title "slope 2", \
         1e-5*(x/ref)**4 with lines lw 1 dt 4 lc rgb "black" title "slope 4"
    unset label 1
  }
}
