# Shared gnuplot settings for geomint figures: CSV input with `# ` provenance lines and a
# header row, names with underscores printed literally.
set datafile separator comma
set datafile columnheaders
set key noenhanced
set termoption noenhanced
set grid lw 0.5 lc rgb "#dddddd"
set style line 1 lw 2 lc rgb "#d62728"
set style line 2 lw 2 lc rgb "#1f77b4"
set style line 3 lw 2 lc rgb "#2ca02c"
set style line 4 lw 2 lc rgb "#9467bd"
set style line 5 lw 2 lc rgb "#ff7f0e"
set style line 6 lw 2 lc rgb "#8c564b"
set style line 7 lw 2 lc rgb "#e377c2"
set style line 8 lw 2 lc rgb "#7f7f7f"
# Every figure is written twice: PNG (README) and PDF (reports).
png_term = "pngcairo size 1000,650 font 'DejaVu Sans,11'"
pdf_term = "pdfcairo size 7in,4.5in font 'DejaVu Sans,9'"
