#!/usr/bin/env bash
# Figure footer (issue 28, citation kit): scripts/reproduce.sh passes the `# geomint:` provenance
# line of a scene's CSV to gnuplot, and scripts/common.gp draws it on every figure. Runs
# reproduce.sh with SWEEP=0 on a scratch copy of scripts/ holding one demo scene drawn as SVG
# (text, so the footer can be read back), then a provenance line with a quote, which must give no
# footer rather than reach gnuplot's command line. Usage: footer_test.sh SOURCE_DIR SCRATCH_DIR
set -euo pipefail
source_dir=$1
scratch=$2
command -v gnuplot > /dev/null || { echo "footer_test: gnuplot not installed" >&2; exit 77; }
rm -rf "$scratch"
mkdir -p "$scratch/scripts" "$scratch/results/footer_demo"
cp "$source_dir/scripts/common.gp" "$source_dir/scripts/reproduce.sh" \
  "$source_dir/scripts/index-results.sh" "$scratch/scripts/"
cat > "$scratch/scripts/footer_demo.gp" <<'GP'
load scripts."/common.gp"
set terminal svg size 400,300
set output "demo.svg"
plot "summary.csv" using "dt":"error" with linespoints
GP
printf 'title = "footer demo"\n' > "$scratch/results/footer_demo/scene.toml"
write_table() {
  printf '# geomint: %s\n# scene: footer_demo\ndt,error\n0.1,1e-3\n0.05,2.5e-4\n' "$1" \
    > "$scratch/results/footer_demo/summary.csv"
}
write_table "0.1.0 (abc123def456)"
SWEEP=0 bash "$scratch/scripts/reproduce.sh" /bin/true footer_demo 2> "$scratch/log"
if ! grep -q "geomint 0.1.0 (abc123def456)" "$scratch/results/footer_demo/demo.svg"; then
  echo "footer_test: demo.svg has no footer 'geomint 0.1.0 (abc123def456)'" >&2
  cat "$scratch/log" >&2
  exit 1
fi
write_table "0.1.0 (x'); system('touch pwned'); print('"
SWEEP=0 bash "$scratch/scripts/reproduce.sh" /bin/true footer_demo 2> "$scratch/log"
if [ -e "$scratch/results/footer_demo/pwned" ] || grep -q "pwned" "$scratch/results/footer_demo/demo.svg"; then
  echo "footer_test: a quote in the provenance line reached gnuplot" >&2
  exit 1
fi
echo "footer_test: footer drawn from the CSV's provenance; a hostile line is dropped"
