# Shared gnuplot settings for geomint figures (docs/SCENES.md "Figures"): CSV input with `# ` provenance
# lines and a header row, names with underscores printed literally, and one fixed style per method.
set datafile separator comma
set datafile columnheaders
set key noenhanced
set termoption noenhanced
set grid lw 0.5 lc rgb "#dddddd"

# One shell word for a path in the commands of `system()` and `plot "< ..."`: the scripts folder
# sits in the clone, whose path may hold spaces, parentheses or quotes ("'" becomes '\'').
sh_quoted(s) = "'" . sh_escaped(s) . "'"
sh_escaped(s) = sh_escaped_at(s, strstrt(s, "'"))
sh_escaped_at(s, at) = at == 0 ? s : s[1:at - 1] . "'\\''" . sh_escaped(s[at + 1:])

# One colour, marker and dash per method in every figure of every scene. A method is found by
# the first key its name starts with: a spec ("hp:alpha=0.5,..."), a series file name
# ("hp_alpha_0.5") or a work-precision curve ("composition_yoshida4") all match. Keys must not
# be prefixes of one another. Line style i is the i-th key, from the 41st key on style i + 8 (41-48
# are the palette below); 99 is any method not listed.
method_keys = "explicit_euler implicit_euler symplectic_euler_a symplectic_euler_b stormer_verlet rk4 del hp newmark implicit_midpoint cvode_bdf cvode_adams odeint_dopri5 odeint_mclachlan4 gsl_rk8pd composition_yoshida4 composition_kahan_li8 gauss_s2 gauss_s3 lobatto3ab_s3 rattle composition_rattle_yoshida4 composition_rattle_kahan_li6 composition_rattle_kahan_li8 ida_index_2 ida_index_3 penalty shake rkn_nystrom4 rkn_dprkn6 rkn_dprkn8 rkn_adaptive_dprkn6 rkn_adaptive_dprkn8 mujoco_integrator_euler mujoco_integrator_rk4 mujoco_integrator_implicit ode_step_world ode_step_quick bullet_integrator_euler bullet_integrator_rk4 dart_integrator_world dart_integrator_euler dart_integrator_rk4"
method_titles = "explicit_euler implicit_euler symplectic_euler_a symplectic_euler_b stormer_verlet rk4 del:midpoint hp:alpha=0.5 newmark(1/4,1/2) implicit_midpoint cvode_bdf cvode_adams odeint_dopri5 odeint_mclachlan4 gsl_rk8pd yoshida4(verlet) kahan_li8(verlet) gauss_s2 gauss_s3 lobatto3ab_s3 rattle yoshida4(rattle) kahan_li6(rattle) kahan_li8(rattle) ida:index=2 ida:index=3 penalty:k=1e6(verlet) shake(rattle,no_velocity_projection) rkn:table=nystrom4 rkn:table=dprkn6 rkn:table=dprkn8 rkn_adaptive:pair=dprkn6 rkn_adaptive:pair=dprkn8 mujoco:integrator=euler mujoco:integrator=rk4 mujoco:integrator=implicit ode:step=world ode:step=quick bullet:integrator=euler bullet:integrator=rk4 dart:integrator=world dart:integrator=euler dart:integrator=rk4"
method_index(name) = sum [i=1:words(method_keys)] (strstrt(name, word(method_keys, i)) == 1 ? i : 0)
ms(name) = (method_found = method_index(name), method_found > 40 ? method_found + 8 : method_found > 0 ? method_found : 99)
mtitle(name) = (method_found = method_index(name), method_found > 0 ? word(method_titles, method_found) : name)
set style line 1  lw 2 lc rgb "#d62728" pt 5  ps 1.1          # explicit_euler: red, filled square
set style line 2  lw 2 lc rgb "#1f77b4" pt 6  ps 1.6          # implicit_euler: blue, large open circle
set style line 3  lw 2 lc rgb "#2ca02c" pt 9  ps 1.2          # symplectic_euler_a: green, filled triangle
set style line 4  lw 2 lc rgb "#a09a00" pt 11 ps 1.2 dt (5,3) # symplectic_euler_b: dark yellow, filled triangle down, dashed
set style line 5  lw 2 lc rgb "#ff7f0e" pt 7  ps 1.1          # stormer_verlet: orange, filled circle
set style line 6  lw 2 lc rgb "#9467bd" pt 13 ps 1.3          # rk4: purple, filled diamond
set style line 7  lw 2 lc rgb "#000000" pt 4  ps 1.4          # del: black, open square
set style line 8  lw 2 lc rgb "#e7298a" pt 12 ps 2.0 dt (6,4) # hp: magenta, open diamond, dashed (shows on top of del)
set style line 9  lw 2 lc rgb "#8c564b" pt 8  ps 1.4          # newmark: brown, open triangle
set style line 10 lw 2 lc rgb "#17becf" pt 10 ps 1.4          # implicit_midpoint: cyan, open triangle down
set style line 11 lw 2 lc rgb "#7f7f7f" pt 1  ps 1.5          # cvode_bdf: grey, plus
set style line 12 lw 2 lc rgb "#393b79" pt 2  ps 1.3          # cvode_adams: indigo, cross
set style line 13 lw 2 lc rgb "#b8860b" pt 3  ps 1.4          # odeint_dopri5: dark gold, star
set style line 14 lw 2 lc rgb "#843c39" pt 14 ps 1.4          # odeint_mclachlan4: dark red, open pentagon
set style line 15 lw 2 lc rgb "#00a087" pt 15 ps 1.3          # gsl_rk8pd: teal, filled pentagon
set style line 16 lw 2 lc rgb "#a55194" pt 7  ps 0.8 dt (2,2) # composition_yoshida4: plum, small dot, dotted
set style line 17 lw 2 lc rgb "#5b2c6f" pt 5  ps 0.8 dt (2,2) # composition_kahan_li8: dark plum, small square, dotted
set style line 18 lw 2 lc rgb "#637939" pt 4  ps 1.0 dt (8,3) # gauss_s2: dark olive, open square, long dashes
set style line 19 lw 2 lc rgb "#31a354" pt 6  ps 1.0 dt (8,3) # gauss_s3: mid green, open circle, long dashes
set style line 20 lw 2 lc rgb "#d6616b" pt 8  ps 1.0 dt (8,3) # lobatto3ab_s3: salmon, open triangle, long dashes
# Constrained methods (results/constraints): the constrained families share a hue with their
# unconstrained counterparts' neighbours but not their markers.
set style line 21 lw 2 lc rgb "#ff7f0e" pt 6  ps 1.3          # rattle: orange (Verlet's), open circle
set style line 22 lw 2 lc rgb "#a55194" pt 6  ps 0.9 dt (2,2) # composition_rattle_yoshida4: plum, open circle, dotted
set style line 23 lw 2 lc rgb "#2b8cbe" pt 12 ps 1.1 dt (4,2) # composition_rattle_kahan_li6: steel blue, open diamond, dashed
set style line 24 lw 2 lc rgb "#5b2c6f" pt 4  ps 0.9 dt (2,2) # composition_rattle_kahan_li8: dark plum, open square, dotted
set style line 25 lw 2 lc rgb "#7f7f7f" pt 1  ps 1.5          # ida_index_2: grey, plus
set style line 26 lw 2 lc rgb "#1f77b4" pt 2  ps 1.3 dt (5,3) # ida_index_3: blue, cross, dashed
set style line 27 lw 2 lc rgb "#d62728" pt 9  ps 1.2          # penalty: red, filled triangle
set style line 28 lw 2 lc rgb "#2ca02c" pt 11 ps 1.2 dt (5,3) # shake (rattle without velocity projection): green, dashed
# Runge-Kutta-Nystrom methods (results/work_precision*): the fixed-step ones in the explicit_rk
# family's purple-to-orange, the embedded pairs in the adaptive_geomint family's blues.
set style line 29 lw 2 lc rgb "#6a3d9a" pt 13 ps 0.9 dt (3,2) # rkn_nystrom4: violet, small filled diamond, dotted
set style line 30 lw 2 lc rgb "#1b9e77" pt 9  ps 1.0 dt (6,2) # rkn_dprkn6: sea green, filled triangle, dashed
set style line 31 lw 2 lc rgb "#d95f02" pt 5  ps 0.9          # rkn_dprkn8: dark orange, filled square
set style line 32 lw 2 lc rgb "#17becf" pt 8  ps 1.2 dt (4,2) # rkn_adaptive_dprkn6: cyan, open triangle, dashed
set style line 33 lw 2 lc rgb "#0868ac" pt 12 ps 1.3          # rkn_adaptive_dprkn8: dark blue, open diamond
# Physics engines (results/engines, docs/ENGINES.md): one colour per engine, one marker per
# integrator; MuJoCo dashed and Bullet dotted, so the two (equal to round-off where both are
# semi-implicit Euler or RK4) show on top of each other.
set style line 34 lw 2 lc rgb "#00897b" pt 4  ps 1.2 dt (6,3) # mujoco_integrator_euler: teal, open square, dashed
set style line 35 lw 2 lc rgb "#00897b" pt 12 ps 1.4 dt (6,3) # mujoco_integrator_rk4: teal, open diamond, dashed
set style line 36 lw 2 lc rgb "#00897b" pt 8  ps 1.3 dt (6,3) # mujoco_integrator_implicit: teal, open triangle, dashed
set style line 37 lw 2 lc rgb "#a0522d" pt 6  ps 1.3          # ode_step_world: sienna, open circle
set style line 38 lw 2 lc rgb "#a0522d" pt 2  ps 1.3          # ode_step_quick: sienna, cross
set style line 39 lw 2 lc rgb "#3949ab" pt 5  ps 0.8 dt (2,3) # bullet_integrator_euler: indigo blue, small filled square, dotted
set style line 40 lw 2 lc rgb "#3949ab" pt 13 ps 0.9 dt (2,3) # bullet_integrator_rk4: indigo blue, small filled diamond, dotted
set style line 49 lw 2 lc rgb "#c2185b" pt 4  ps 1.0 dt (8,3,2,3) # dart_integrator_world: crimson, open square, dash-dot
set style line 50 lw 2 lc rgb "#c2185b" pt 10 ps 1.2 dt (8,3,2,3) # dart_integrator_euler: crimson, open triangle down, dash-dot
set style line 51 lw 2 lc rgb "#c2185b" pt 3  ps 1.2 dt (8,3,2,3) # dart_integrator_rk4: crimson, asterisk, dash-dot
set style line 99 lw 1 lc rgb "#aaaaaa" pt 0                  # a method not in method_keys
# Curves that are not methods (a parameter family, step sizes, energies of one method, bodies):
# an ordered dark-to-light palette, styles 41-48, so they cannot be mistaken for a method.
set style line 41 lw 2 lc rgb "#440154" pt 7
set style line 42 lw 2 lc rgb "#46327e" pt 5
set style line 43 lw 2 lc rgb "#365c8d" pt 9
set style line 44 lw 2 lc rgb "#277f8e" pt 11
set style line 45 lw 2 lc rgb "#1fa187" pt 13
set style line 46 lw 2 lc rgb "#4ac16d" pt 7
set style line 47 lw 2 lc rgb "#8fc31f" pt 5
set style line 48 lw 2 lc rgb "#c9a800" pt 9
# Legends sit above the plot in rows, so they take neither width nor data area.
key_above = "set key outside top center horizontal maxrows 3 samplen 3 width 1 spacing 1.1"

# Every figure is written three times: PNG (the scenes' README.md), PDF (reports) and SVG (the
# results site, `geomint report`, which shows the SVG where one exists).
png_term = "pngcairo noenhanced size 1000,650 font 'DejaVu Sans,11'"
pdf_term = "pdfcairo noenhanced size 7in,4.5in font 'DejaVu Sans,9'"
svg_term = "svg noenhanced size 1000,650 font 'DejaVu Sans,11' background rgb 'white'"
# A PDF laid out exactly as the PNG of w x h px with the same font: pngcairo draws an N-pt font at
# 96 dpi (4/3 N px), so the PDF's page is w x h at 0.75 pt per px. The layout checks of the SVG
# (tests/figures/figure_layout_check.py, at the PNG's text size) then hold for the PDF as well.
pdf_for_png(w, h, points) = sprintf("pdfcairo noenhanced size %.3fin,%.3fin font 'DejaVu Sans,%g'", \
  w * 0.75 / 72, h * 0.75 / 72, points)

# Footer (issue 28, citation kit): every figure names the geomint version and commit that computed
# its numbers. scripts/reproduce.sh passes the `# geomint:` provenance line of the scene's CSVs as
# `provenance`; label tag 999 is reserved for it (scripts use small tags and unset only those).
if (exists("provenance") && strlen(provenance) > 0) {
  set label 999 sprintf("geomint %s", provenance) at screen 0.995, 0.012 right front \
      font ",7" textcolor rgb "#707070" noenhanced
}
