# The long form of results/engines (results/engines/README.md): the pendulum's energy error over
# 10^4 periods at h = 1/60, 1/240, 1/1000 s, and the engines as shipped beside the clean model.
# Run inside results/engines_full (scripts/reproduce.sh does); reads series/pendulum_*/.
load scripts."/common.gp"

H0 = (2 * pi)**2 * (1 - cos(1))
envelope(file) = sprintf("< awk -F, -v column=energy -v ref=%.17g -v per_decade=10 -v min_width=0.54 -v min_count=5 -f %s %s 2>/dev/null", H0, sh_quoted(scripts."/envelope.awk"), file)
clip(x) = x > 1e-17 ? x : 1e-17  # exact zeros drawn at 1e-17 on the log axes
engines = "mujoco_integrator_euler mujoco_integrator_rk4 mujoco_integrator_implicit ode_step_world ode_step_quick bullet_integrator_euler bullet_integrator_rk4 dart_integrator_world dart_integrator_euler dart_integrator_rk4"
pendulum_methods = engines." del hp stormer_verlet rk4 implicit_euler"
shipped = "mujoco_integrator_euler ode_step_world ode_step_quick bullet_integrator_euler bullet_integrator_rk4 dart_integrator_world"
has(file) = system("test -f ".file." && echo 1") eq "1"
maybe(file) = has(file) ? file : "< printf 't,max\n'"
panels = "pendulum_h60 pendulum_h240 pendulum_h1000"
panel_titles = "h~=~1/60~s h~=~1/240~s h~=~1/1000~s"
spaced(s) = system("printf '%s' '".s."' | tr '~' ' '")

do for [format in "png pdf svg"] {
  if (format eq "png") { set term @png_term } else { if (format eq "pdf") { set term @pdf_term } else { set term @svg_term } }
  set termoption noenhanced
  # Fig. 1 with the engines: one panel per step, one shared key above them.
  set output "energy_long.".format
  set multiplot title "Pendulum (theta0 = 1 rad, period 1.07 s) over 10^4 periods: largest relative energy error per window" font ",12"
  # The shared key: an empty plot across the width of the three panels.
  set lmargin at screen 0.09; set rmargin at screen 0.96; set tmargin at screen 0.93; set bmargin at screen 0.78
  unset logscale; unset border; unset tics; unset xlabel; unset ylabel; unset title; set xrange [0:1]; set yrange [0:1]
  set key inside center center horizontal maxrows 3 samplen 3 width 1 spacing 1.1 font ",10"
  plot for [i=1:words(pendulum_methods)] NaN with linespoints ls ms(word(pendulum_methods, i)) title mtitle(word(pendulum_methods, i))
  unset key; set border; set tics
  set logscale xy; set format x "1e%T"; set format y "1e%T"
  set yrange [1e-12:10]; set xrange [0.5:2e4]
  set xlabel "t [s]"
  set tmargin at screen 0.70; set bmargin at screen 0.10
  do for [p=1:3] {
    set lmargin at screen 0.09 + (p - 1) * 0.30; set rmargin at screen 0.09 + (p - 1) * 0.30 + 0.27
    set title spaced(word(panel_titles, p))
    if (p == 1) { set ylabel "max |H - H0| / H0 in the window"; set format y "1e%T" } else { unset ylabel; set format y "" }
    plot for [i=1:words(pendulum_methods)] envelope(maybe("series/".word(panels, p)."/".word(pendulum_methods, i).".csv")) using 1:(clip($2)) with linespoints ls ms(word(pendulum_methods, i)) pn 8 title mtitle(word(pendulum_methods, i))
  }
  unset multiplot
  set xrange [*:*]; set yrange [*:*]; set tmargin; set bmargin; set lmargin; set rmargin; set format y "1e%T"

  # The engines as shipped (dashed, same marker) beside the clean model, h = 1/60 s.
  set output "shipped_long.".format
  @key_above
  set title "Engines as shipped (thin lines) and clean (thick lines), pendulum at h = 1/60 s, 10^4 periods"
  set ylabel "max |H - H0| / H0 in the window"
  set xrange [0.5:2e4]; set yrange [1e-8:10]
  plot for [i=1:words(shipped)] envelope(maybe("series/pendulum_h60/".word(shipped, i).".csv")) using 1:(clip($2)) with linespoints ls ms(word(shipped, i)) pn 8 title mtitle(word(shipped, i))." clean", \
       for [i=1:words(shipped)] envelope(maybe("series/pendulum_h60_shipped/".word(shipped, i)."_defaults_shipped.csv")) using 1:(clip($2)) with linespoints ls ms(word(shipped, i)) lw 1 pn 8 title mtitle(word(shipped, i))." shipped"
  set xrange [*:*]; set yrange [*:*]

  unset logscale; set format x "% h"; set format y "% h"; set xrange [*:*]; set yrange [*:*]
}
