#!/usr/bin/env bash
# Grid-resolution study (issue 4, the paper's test 3): bayes and bound on the many-light hall (direct only) with
# the region grid at 8, 16, 32, 64, 128 and 256 cells along the shortest axis, at equal time T seconds each.
# Error is reference-free (tools/selfvar.sh: two seeds, half the relMSE between them), so no reference noise
# enters; the speed-up of bayes over bound is their error ratio at equal time.
#   tools/gridstudy.sh BIN     (env: T seconds per render, default 8; W, H default 320x240; GRIDS; SCENE)
set -euo pipefail
bin=$1
cd "$(dirname "$0")/.."
T=${T:-8}
scene=${SCENE:-data/hall/direct.json}
grids=${GRIDS:-"8 16 32 64 128 256"}
echo "grid study: $scene, ${W:-320}x${H:-240}, $T s per render (two seeds each), relMSE/2 between seeds"
printf "  %5s  %12s  %12s  %8s\n" grid bayes bound speed-up
for g in $grids; do
  a=$(tools/selfvar.sh "$bin" "$scene" "$T" x --sampler bayes --grid "$g" | sed -n 's/.*relmse\/2 //p')
  b=$(tools/selfvar.sh "$bin" "$scene" "$T" x --sampler bound --grid "$g" | sed -n 's/.*relmse\/2 //p')
  awk -v g="$g" -v a="$a" -v b="$b" 'BEGIN { printf "  %5d  %12.5g  %12.5g  %7.2fx\n", g, a, b, b / a }'
done
