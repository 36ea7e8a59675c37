# Physics engines next to the paper's methods (results/engines/README.md): the pendulum's energy
# error at h = 1/60, 1/240, 1/1000 s, the engines as shipped beside the clean model, error against
# wall time, and joint chains against n. Run inside results/engines (scripts/reproduce.sh does);
# reads series/pendulum_*/ and the wp/ and chain/ tables of scripts/engines.py.
load scripts."/common.gp"

# pendulum:theta0=1,omega0=2pi: H0 = omega0^2 (1 - cos theta0); the energy oscillates with half
# the period 1.0663 s, so an envelope window spans at least 0.54 s.
H0 = (2 * pi)**2 * (1 - cos(1))
envelope(file) = sprintf("< awk -F, -v column=energy -v ref=%.17g -v per_decade=10 -v min_width=0.54 -v min_count=5 -f %s %s 2>/dev/null", H0, sh_quoted(scripts."/envelope.awk"), file)
clip(x) = x > 1e-17 ? x : 1e-17  # exact zeros drawn at 1e-17 on the log axes
# DART's integrator=euler runs at 1/60 s and in the orders and the stiff chain only (it takes the
# bounded error of its World::step): the tables have it; a drawn method has a series in every panel.
engines = "mujoco_integrator_euler mujoco_integrator_rk4 mujoco_integrator_implicit ode_step_world ode_step_quick bullet_integrator_euler bullet_integrator_rk4 dart_integrator_world dart_integrator_rk4"
pendulum_methods = engines." del hp stormer_verlet rk4 implicit_euler"
chain_methods = engines." del hp rk4"
shipped = "mujoco_integrator_euler ode_step_world ode_step_quick bullet_integrator_euler bullet_integrator_rk4 dart_integrator_world"
has(file) = system("test -f ".file." && echo 1") eq "1"
# A method absent from a table (a quick run without it) is drawn as nothing, not an error.
maybe(file) = has(file) ? file : "< printf 't,max\n'"
panels = "pendulum_h60 pendulum_h240 pendulum_h1000"
panel_titles = "h~=~1/60~s,~10^3~periods h~=~1/240~s,~10^3~periods h~=~1/1000~s,~10^2~periods"
spaced(s) = system("printf '%s' '".s."' | tr '~' ' '")

do for [format in "png pdf svg"] {
  if (format eq "png") { set term @png_term } else { if (format eq "pdf") { set term @pdf_term } else { set term @svg_term } }
  set termoption noenhanced

  # Fig. 1 with the engines: one panel per step, one shared key above them.
  set output "energy.".format
  set multiplot title "Pendulum (theta0 = 1 rad, period 1.07 s): largest relative energy error per window, engines and geomint" font ",12"
  # The shared key: an empty plot across the width of the three panels.
  set lmargin at screen 0.09; set rmargin at screen 0.96; set tmargin at screen 0.93; set bmargin at screen 0.78
  unset logscale; unset border; unset tics; unset xlabel; unset ylabel; unset title; set xrange [0:1]; set yrange [0:1]
  set key inside center center horizontal maxrows 3 samplen 3 width 1 spacing 1.1 font ",10"
  plot for [i=1:words(pendulum_methods)] NaN with linespoints ls ms(word(pendulum_methods, i)) title mtitle(word(pendulum_methods, i))
  unset key; set border; set tics
  set logscale xy; set format x "1e%T"; set format y "1e%T"
  set yrange [1e-12:10]; set xrange [0.5:2e3]
  set xlabel "t [s]"
  set tmargin at screen 0.70; set bmargin at screen 0.10
  do for [p=1:3] {
    set lmargin at screen 0.09 + (p - 1) * 0.30; set rmargin at screen 0.09 + (p - 1) * 0.30 + 0.27
    set title spaced(word(panel_titles, p))
    if (p == 1) { set ylabel "max |H - H0| / H0 in the window"; set format y "1e%T" } else { unset ylabel; set format y "" }
    if (p == 3) { set xrange [0.05:2e2] }
    plot for [i=1:words(pendulum_methods)] envelope(maybe("series/".word(panels, p)."/".word(pendulum_methods, i).".csv")) using 1:(clip($2)) with linespoints ls ms(word(pendulum_methods, i)) pn 8 title mtitle(word(pendulum_methods, i))
  }
  unset multiplot
  set xrange [*:*]; set yrange [*:*]; set tmargin; set bmargin; set lmargin; set rmargin; set format y "1e%T"

  # The engines as shipped (dashed, same marker) beside the clean model, h = 1/60 s.
  set output "shipped.".format
  @key_above
  set title "Engines as shipped (thin lines) and clean (thick lines), pendulum at h = 1/60 s"
  set ylabel "max |H - H0| / H0 in the window"
  set xrange [0.5:2e3]; set yrange [1e-8:10]
  plot for [i=1:words(shipped)] envelope(maybe("series/pendulum_h60/".word(shipped, i).".csv")) using 1:(clip($2)) with linespoints ls ms(word(shipped, i)) pn 8 title mtitle(word(shipped, i))." clean", \
       for [i=1:words(shipped)] envelope(maybe("series/pendulum_h60_shipped/".word(shipped, i)."_defaults_shipped.csv")) using 1:(clip($2)) with linespoints ls ms(word(shipped, i)) lw 1 pn 8 title mtitle(word(shipped, i))." shipped"
  set xrange [*:*]; set yrange [*:*]

  # Work-precision: final error against wall time over the step ladder (5 periods).
  set output "wp.".format
  set title "Pendulum, 5 periods, h = 1/30 ... 1/3840 s: final error against wall time (median of 3)"
  set xlabel "wall time [s]"; set ylabel "||(q, p) - exact|| at t = 5.33 s"
  set yrange [1e-14:*]
  plot for [i=1:words(pendulum_methods)] maybe("wp/".word(pendulum_methods, i).".csv") using "wall_s":(clip(column("error_final"))) with linespoints ls ms(word(pendulum_methods, i)) title mtitle(word(pendulum_methods, i))
  set yrange [*:*]

  # Joint chains: energy error and cost per step against the number of links.
  set output "chain.".format
  set multiplot title "Joint chains rod_chain:coordinates=joint, theta = 0.3, h = 1/240 s over 1 s" font ",12"
  set lmargin at screen 0.08; set rmargin at screen 0.96; set tmargin at screen 0.93; set bmargin at screen 0.83
  unset logscale; unset border; unset tics; unset xlabel; unset ylabel; unset title; set xrange [0:1]; set yrange [0:1]
  set key inside center center horizontal maxrows 2 samplen 3 width 1 spacing 1.1 font ",10"
  plot for [i=1:words(chain_methods)] NaN with linespoints ls ms(word(chain_methods, i)) title mtitle(word(chain_methods, i))
  unset key; set border; set tics
  set tmargin at screen 0.76; set bmargin at screen 0.10
  set xlabel "links n"; set logscale x 2; set logscale y; set format x "%g"; set format y "1e%T"; set xrange [1.6:80]
  do for [p=1:2] {
    set lmargin at screen 0.09 + (p - 1) * 0.48; set rmargin at screen 0.09 + (p - 1) * 0.48 + 0.39
    if (p == 1) {
      set title "energy error"; set ylabel "max |H - H0| / |H0|"; set yrange [1e-17:1]
      plot for [i=1:words(chain_methods)] maybe("chain/".word(chain_methods, i).".csv") using "n":(clip(column("energy_err_max"))) with linespoints ls ms(word(chain_methods, i)) notitle
    } else {
      set title "cost per step (timing pass, median of 3)"; set ylabel "wall time per step [us]"; set yrange [*:*]
      plot for [i=1:words(chain_methods)] maybe("chain/".word(chain_methods, i).".csv") using "n":"us_per_step" with linespoints ls ms(word(chain_methods, i)) notitle
    }
  }
  unset multiplot
  unset logscale; set format x "% h"; set format y "% h"; set xrange [*:*]; set yrange [*:*]
  set tmargin; set bmargin; set lmargin; set rmargin
}
