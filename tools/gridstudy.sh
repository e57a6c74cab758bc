#!/usr/bin/env bash
# Grid-resolution study (issue 4, the paper's test 3): bayes and bound on the many-light hall (direct only) with
# the region grid at 8, 16, 32, 64, 128 and 256 cells along the shortest axis, at equal time T seconds each, against
# the reference tools/eqtable.sh caches in $(dirname BIN)/ref (rendered there when missing; the image does not depend
# on the grid). Mean relMSE over SEEDS; the speed-up of bayes over bound is their error ratio at equal time.
# (A reference-free error from two seeds, used before, has a noisy denominator and mis-ranked settings.)
#   tools/gridstudy.sh BIN     (env: T seconds per render, default 8; W, H default 320x240; GRIDS; SCENE; SEEDS;
#                               REF_SPP_DIRECT, default 16384 as in eqtable.sh)
set -euo pipefail
bin=$1
cd "$(dirname "$0")/.."
. tools/ref_key.sh
T=${T:-8}; W=${W:-320}; H=${H:-240}; SEEDS=${SEEDS:-"11 22"}; REF_SPP_DIRECT=${REF_SPP_DIRECT:-16384}
scene=${SCENE:-hall}
grids=${GRIDS:-"8 16 32 64 128 256"}
json=data/$scene/direct.json
refdir=$(dirname "$bin")/ref; mkdir -p "$refdir"
# The reference eqtable.sh caches for the same scene, size and spp (keyed by ref_key: rendered again when the scene or
# the renderer's images change, never a stale one).
ref=$refdir/${scene}_direct_${W}x${H}_bayes_${REF_SPP_DIRECT}_$(ref_key "data/$scene" "${scene}_direct_*").exr
ensure_reference "$bin" "$json" bayes "$REF_SPP_DIRECT" "$W" "$H" "$ref"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
err() {  # mean relMSE over the seeds of one configuration
  local sum=0 n=0
  for seed in $SEEDS; do
    "$bin" render "$json" "$@" --time "$T" --seed "$seed" --width "$W" --height "$H" --reference "$ref" \
      --log "$tmp/l.csv" -o "$tmp/i.pfm" --quiet
    sum=$(awk -v s="$sum" -v e="$(tail -n 1 "$tmp/l.csv" | cut -d, -f5)" 'BEGIN { print s + e }'); n=$((n + 1))
  done
  awk -v s="$sum" -v n="$n" 'BEGIN { print s / n }'
}
echo "grid study: $json, ${W}x${H}, $T s per render, seeds $SEEDS, mean relMSE against $ref"
printf "  %5s  %12s  %12s  %8s\n" grid bayes bound speed-up
for g in $grids; do
  a=$(err --sampler bayes --grid "$g")
  b=$(err --sampler bound --grid "$g")
  awk -v g="$g" -v a="$a" -v b="$b" 'BEGIN { printf "  %5d  %12.5g  %12.5g  %7.2fx\n", g, a, b, b / a }'
done
