# Long runs (results/long_run): Brouwer's law with and without compensated summation, and the
# energy drift of adaptive Verlet. Run inside the scene folder (scripts/reproduce.sh does); reads
# series/{kepler_roundoff,solar_roundoff,solar_roundoff_com,kepler_adaptive}/. Errors are relative (dimensionless).
load scripts."/common.gp"
file(l, m) = "series/".l."/".m.".csv"
# Per-window maximum of |H - H0|/|H0| (scripts/envelope.awk); width = one orbital period.
envelope_at(f, width, ref) = sprintf("< awk -F, -v column=energy -v ref=%.17g -v per_decade=10 -v min_width=%g -v min_count=5 -f %s %s 2>/dev/null", ref, width, sh_quoted(scripts."/envelope.awk"), f)
envelope(f, width) = envelope_at(f, width, H0)
plain = "composition_scheme_kahan_li8"
compensated = "composition_scheme_kahan_li8_compensated_true"

do for [format in "png pdf svg"] {
  if (format eq "png") { set term @png_term; set term pngcairo size 1100,500 } else { if (format eq "pdf") { set term @pdf_term; set term pdfcairo size 8in,3.6in } else { set term @svg_term; set term svg size 1100,500 } }
  set termoption noenhanced

  # Brouwer's law: the plain composition's round-off error grows like sqrt(t) (dashed guide through
  # its first window); the compensated one stays at a few ulps.
  set output "brouwer.".format
  set multiplot layout 1,2 title "Round-off in the energy, 8th-order composition (kahan_li8 over Stormer-Verlet):\nlargest |H - H0|/|H0| per window, plain and compensated summation"
  set logscale xy; set format x "1e%T"; set format y "1e%T"
  set ylabel "max |H - H0| / |H0| (dimensionless)"
  eval key_above
  do for [panel=1:2] {
    label = panel == 1 ? "kepler_roundoff" : "solar_roundoff"
    width = panel == 1 ? 6.3 : 4333
    set title panel == 1 ? "Kepler e = 0.6, h = 0.01" : "outer solar system, h = 10 days"
    set xlabel panel == 1 ? "t (dimensionless, period 2 pi)" : "t [days]"
    stats file(label, plain) using "energy" every ::0::0 nooutput; H0 = STATS_min
    stats envelope(file(label, plain), width) using 1 every ::0::0 nooutput; t1 = STATS_min
    stats envelope(file(label, plain), width) using 2 every ::0::0 nooutput; e1 = STATS_min
    if (panel == 1) {
      plot envelope(file(label, plain), width) using 1:2 with linespoints ls 41 pn 12 title "plain summation", \
           envelope(file(label, compensated), width) using 1:2 with linespoints ls 46 pn 12 title "compensated (Kahan)", \
           e1 * sqrt(x / t1) with lines lw 1 dt (6,4) lc rgb "#555555" title "slope 1/2 (Brouwer's law)"
    } else {
      # The centre-of-mass frame runs have their own H0 (the drift's kinetic energy is gone).
      stats file("solar_roundoff_com", plain) using "energy" every ::0::0 nooutput; H0_com = STATS_min
      plot envelope(file(label, plain), width) using 1:2 with linespoints ls 41 pn 12 title "plain, given frame (drifts 68 AU)", \
           envelope(file(label, compensated), width) using 1:2 with linespoints ls 46 pn 12 title "compensated, given frame", \
           envelope_at(file("solar_roundoff_com", plain), width, H0_com) using 1:2 with linespoints lw 2 lc rgb "#d62728" pt 6 pn 12 title "plain, centre-of-mass frame", \
           envelope_at(file("solar_roundoff_com", compensated), width, H0_com) using 1:2 with linespoints lw 2 lc rgb "#9467bd" pt 8 pn 12 title "compensated, centre-of-mass frame", \
           e1 * sqrt(x / t1) with lines lw 1 dt (6,4) lc rgb "#555555" title "slope 1/2 (Brouwer's law)"
    }
  }
  unset multiplot

  # Adaptive steps against structure: the controller's run starts more accurate and then drifts
  # past the fixed step of the same mean size, whose error stays bounded.
  if (format eq "png") { set term pngcairo size 1000,650 } else { if (format eq "pdf") { set term pdfcairo size 7in,4.5in } else { set term @svg_term; set term svg size 1000,650 } }
  set termoption noenhanced
  set output "adaptive.".format
  set title "Kepler e = 0.6: adaptive_verlet (rtol = 1e-4) against Stormer-Verlet at its mean step (h = 0.0075)\nlargest |H - H0|/|H0| per window"
  set xlabel "t (dimensionless, period 2 pi)"
  stats file("kepler_adaptive", "stormer_verlet") using "energy" every ::0::0 nooutput; H0 = STATS_min
  plot envelope(file("kepler_adaptive", "adaptive_verlet_rtol_1e-4_atol_1e-10_max_steps_100000000"), 6.3) using 1:2 with linespoints ls 30 lw 2 lc rgb "#7f7f7f" pt 1 pn 12 title "adaptive_verlet, rtol = 1e-4", \
       envelope(file("kepler_adaptive", "stormer_verlet"), 6.3) using 1:2 with linespoints ls ms("stormer_verlet") pn 12 title "stormer_verlet, h = 0.0075"
}
