# One system, two coordinate systems (results/coordinates/README.md): for each pair, the motion
# of both formulations mapped to Cartesian positions (left) and the relative energy error (right).
# Run inside results/coordinates (scripts/reproduce.sh does); reads series/<label>/*.csv.
load scripts."/common.gp"
clip(x) = x > 1e-16 ? x : 1e-16  # exact zeros drawn at 1e-16 on the log axis

# Rod chain parameters of the scene (rod_chain:...,length=0.9,length_ratio=1.4).
l1 = 0.9; l2 = 0.9 * 1.4
# Spherical pendulum (length=1.7).
ls_sp = 1.7

kc = "series/kepler/kepler_e_0.5__"
kp = "series/kepler/kepler_coordinates_polar_e_0.5__"
kepler_methods = "del gauss_s_2 rk4"
sph_cart = "rattle hp"
sph_ang = "del gauss_s_2 rk4"
chain_cart = "rattle ida_index_3_rtol_1e-8_atol_1e-10"
chain_joint = "del gauss_s_2 rk4 cvode_bdf_rtol_1e-10_atol_1e-12"

system("rm -rf curves && mkdir -p curves && awk -f ".sh_quoted(scripts."/csv.awk")." -f ".sh_quoted(scripts."/coordinates_cost.awk")." summary.csv")

# Initial energies, read before any log axis (they are negative).
stats "series/spherical_cartesian/rattle.csv" using "energy" every ::0::0 nooutput; Es = STATS_min
stats "series/chain_cartesian/rattle.csv" using "energy" every ::0::0 nooutput; Ec = STATS_min
stats "series/kepler/kepler_e_0.5__del.csv" using "energy" every ::0::0 nooutput; Ek = STATS_min

do for [format in "png pdf svg"] {
  if (format eq "png") { set term @png_term } else { if (format eq "pdf") { set term @pdf_term } else { set term @svg_term } }
  set termoption noenhanced

  # ---- Kepler ---------------------------------------------------------------------------
  set output "kepler.".format
  set multiplot layout 1,2 title "Kepler e = 0.5, h = 0.01, 10 periods: Cartesian (lines) and polar mapped to (r cos phi, r sin phi) (points)"
  set size ratio -1; set xlabel "x"; set ylabel "y"; set key bottom left font ",8"
  plot kc."del.csv" using "q_0":"q_1" with lines ls ms("del") title "del, Cartesian", \
       kp."del.csv" every 3 using (column("q_0")*cos(column("q_1"))):(column("q_0")*sin(column("q_1"))) with points pt 6 ps 0.4 lc rgb "red" title "del, polar", \
       kp."gauss_s_2.csv" every 5 using (column("q_0")*cos(column("q_1"))):(column("q_0")*sin(column("q_1"))) with points pt 1 ps 0.4 lc rgb "dark-green" title "gauss s=2, polar"
  set size noratio; set xlabel "t (dimensionless)"; set ylabel "|E(t) - E(0)| / |E(0)|"
  set logscale y; set format y "1e%T"; set yrange [1e-16:1]; set key top left font ",8"
  plot for [m in kepler_methods] kc.m.".csv" using "t":(clip(abs(column("energy")/Ek - 1))) with lines ls ms(m) title mtitle(m)." Cartesian", \
       for [m in kepler_methods] kp.m.".csv" using "t":(clip(abs(column("energy")/Ek - 1))) with lines ls ms(m) dt 2 lw 2 title mtitle(m)." polar"
  unset logscale; set format y "% h"; set yrange [*:*]
  unset multiplot

  # ---- Spherical pendulum -----------------------------------------------------------------
  set output "spherical.".format
  set multiplot layout 1,2 title "Spherical pendulum L = 1.7, m = 0.6, g = 2.3, h = 0.01: constrained Cartesian (lines) and angles mapped (points)"
  set size ratio -1; set xlabel "x"; set ylabel "y"; set key bottom left font ",8"
  plot "series/spherical_cartesian/rattle.csv" using "q_0":"q_1" with lines ls ms("rattle") title "rattle, Cartesian", \
       "series/spherical_angles/del.csv" every 3 using (ls_sp*sin(column("q_0"))*cos(column("q_1"))):(ls_sp*sin(column("q_0"))*sin(column("q_1"))) with points pt 6 ps 0.4 lc rgb "black" title "del, angles"
  set size noratio; set xlabel "t (dimensionless)"; set ylabel "|E(t) - E(0)| / |E(0)|"
  set logscale y; set format y "1e%T"; set yrange [1e-16:1]; set key top left font ",8"
  plot for [m in sph_cart] "series/spherical_cartesian/".m.".csv" using "t":(clip(abs(column("energy")/Es - 1))) with lines ls ms(m) title mtitle(m)." Cartesian", \
       for [m in sph_ang] "series/spherical_angles/".m.".csv" using "t":(clip(abs(column("energy")/Es - 1))) with lines ls ms(m) dt 2 lw 2 title mtitle(m)." angles"
  unset logscale; set format y "% h"; set yrange [*:*]
  unset multiplot

  # ---- Rod chain ----------------------------------------------------------------------------
  set output "chain.".format
  set multiplot layout 1,2 title "Rod chain n = 2 (m = 1.3, 0.78; l = 0.9, 1.26; g = 2), h = 0.01: Cartesian (lines) and joint angles mapped (points)"
  set xlabel "t (dimensionless)"; set ylabel "x of the tip"; set key bottom left font ",8"
  plot "series/chain_cartesian/rattle.csv" using "t":"q_2" with lines ls ms("rattle") title "rattle, Cartesian", \
       "series/chain_joint/del.csv" every 3 using "t":(l1*sin(column("q_0")) + l2*sin(column("q_1"))) with points pt 6 ps 0.5 lc rgb "black" title "del, joint", \
       "series/chain_joint/rk4.csv" every 3 using "t":(l1*sin(column("q_0")) + l2*sin(column("q_1"))) with points pt 1 ps 0.5 lc rgb "purple" title "rk4, joint"
  set ylabel "|E(t) - E(0)| / |E(0)|"
  set logscale y; set format y "1e%T"; set yrange [1e-16:1]; set key top left font ",8"
  plot for [m in chain_cart] "series/chain_cartesian/".m.".csv" using "t":(clip(abs(column("energy")/Ec - 1))) with lines ls ms(m) title mtitle(m)." Cartesian", \
       for [m in chain_joint] "series/chain_joint/".m.".csv" using "t":(clip(abs(column("energy")/Ec - 1))) with lines ls ms(m) dt 2 lw 2 title mtitle(m)." joint"
  unset logscale; set format y "% h"; set yrange [*:*]
  unset multiplot

  # ---- Cost per step against n ---------------------------------------------------------------
  set output "cost.".format
  set title "Cost per step against the number of links n: maximal (Cartesian + RATTLE) vs joint coordinates\nmedian of 5 timed runs of 20 steps; machine-dependent (the footer names the build)"
  set xlabel "n (links)"; set ylabel "wall time per step (s)"
  set logscale xy; set format y "1e%T"; set key top left font ",9"
  set datafile separator whitespace
  plot "curves/cost_cartesian_rattle.dat" using 1:2 with linespoints ls ms("rattle") title "rattle, Cartesian (2n positions, n constraints)", \
       "curves/cost_joint_del.dat" using 1:2 with linespoints ls ms("del") title "del, joint angles (n, dense M(theta))", \
       "curves/cost_joint_rk4.dat" using 1:2 with linespoints ls ms("rk4") title "rk4, joint angles"
  set datafile separator ","; unset logscale; set format y "% h"; unset title
}
