#!/usr/bin/env bash
# Writes results/README.md: every scene with its title, table, narrative (<scene>/README.md,
# written by hand) and figures.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
{
  echo "# Results"
  echo
  echo "Every folder is one scene: \`scene.toml\` (what ran), \`summary.csv\`/\`order.csv\` (the"
  echo "numbers, with provenance), \`table.md\` and the figures. Regenerate all with"
  echo "\`make reproduce-figures\`."
  for toml in "$root"/results/*/scene.toml; do
    folder=$(dirname "$toml")
    scene=$(basename "$folder")
    title=$(sed -n 's/^title *= *"\(.*\)"/\1/p' "$toml" | head -n 1)
    echo
    echo "## [$scene]($scene/) — $title"
    echo
    echo "Table: [$scene/table.md]($scene/table.md)"
    if [ -f "$folder/README.md" ]; then
      echo
      echo "Narrative and measured numbers: [$scene/README.md]($scene/README.md)"
    fi
    for png in "$folder"/*.png; do
      [ -f "$png" ] || continue
      echo
      echo "![$(basename "$png" .png)]($scene/$(basename "$png"))"
    done
  done
  # Benchmark results that are not harness scenes (no scene.toml): written by their own scripts.
  if [ -f "$root/results/scaling/scaling.csv" ]; then
    echo
    echo "## [scaling](scaling/) — cost per step against problem size (scripts/scaling.sh)"
    echo
    echo "Data: [scaling/scaling.csv](scaling/scaling.csv); narrative and measured numbers:"
    echo "[scaling/README.md](scaling/README.md)"
    echo
    echo "![scaling](scaling/scaling.png)"
  fi
} > "$root/results/README.md.tmp"
mv "$root/results/README.md.tmp" "$root/results/README.md"
