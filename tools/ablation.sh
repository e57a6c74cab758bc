#!/usr/bin/env bash
# Ablation of the bayes sampler's choices (issue 3, item 7): every switch against the defaults, at equal time, on the
# occluded direct-only scenes, against the references tools/eqtable.sh caches in $(dirname BIN)/ref (rendered there
# when missing). Mean relMSE over SEEDS; a ratio > 1 means the variant has that much more error than the defaults.
#   tools/ablation.sh BIN     (env: T seconds per render, default 6; SCENES; SEEDS, default "11 22"; W, H 320x240;
#                              REF_SPP_DIRECT, the references' spp, default 16384 as in eqtable.sh)
set -euo pipefail
bin=$1
cd "$(dirname "$0")/.."
T=${T:-6}; W=${W:-320}; H=${H:-240}; SEEDS=${SEEDS:-"11 22"}; REF_SPP_DIRECT=${REF_SPP_DIRECT:-16384}
SCENES=${SCENES:-"living_room plant_room hall"}
variants=(
  "defaults|"
  "point prior (bound at every point)|--bayes-prior point"
  "no orientation factor (1/d^2 only)|--bayes-no-orientation"
  "no BSDF factor (glossy points weighed as diffuse)|--bayes-no-bsdf-factor"
  "equal pass weights|--pass-weighting 0"
  "no control variates|--bayes-no-cv"
  "mean PMF (no second moment)|--bayes-pmf mean"
  "no distance regression|--bayes-no-regression"
  "naive (no prior, plug-in moments)|--bayes-naive"
  "epsilon 0.05 (prior mixing)|--bayes-epsilon 0.05"
  "Beta(1, 0.03) on p0 (a0 1: the last defaults)|--bayes-a0 1"
  "Beta(1, 1) on p0|--bayes-a0 1 --bayes-b0 1"
  "no hierarchy|--bayes-hierarchy 0"
  "no mean hierarchy|--bayes-no-mean-hierarchy"
  "c 1 (prior CV 100%)|--bayes-c 1"
  "earlier defaults (a0 1, b0 1, c 1, hier. 4)|--bayes-a0 1 --bayes-b0 1 --bayes-c 1 --bayes-hierarchy 4"
  "max cut 256|--max-cut 256"
  "no members (one per cluster)|--cut-members 0"
  "256 members per region|--cut-members 256"
  "independent samples (no stratified first vertex)|--independent-samples"
  "bound sampler (reference point)|--sampler bound"
)
refdir=$(dirname "$bin")/ref; mkdir -p "$refdir"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
echo "ablation: direct only, ${W}x${H}, $T s per render, seeds $SEEDS; mean relMSE and ratio to the defaults"
for scene in $SCENES; do
  json=data/$scene/direct.json
  ref=$refdir/${scene}_direct_${W}x${H}_bayes_${REF_SPP_DIRECT}.exr
  [ -f "$ref" ] || "$bin" render "$json" --sampler bayes --spp "$REF_SPP_DIRECT" --seed 987654321 --width "$W" --height "$H" -o "$ref" --quiet
  echo "  $scene"
  base=""
  for v in "${variants[@]}"; do
    label=${v%%|*}; args=${v#*|}
    [[ "$args" == *--sampler* ]] || args="--sampler bayes $args"
    sum=0; n=0
    for seed in $SEEDS; do
      "$bin" render "$json" $args --time "$T" --seed "$seed" --width "$W" --height "$H" --reference "$ref" \
        --log "$tmp/l.csv" -o "$tmp/i.pfm" --quiet
      sum=$(awk -v s="$sum" -v e="$(tail -n 1 "$tmp/l.csv" | cut -d, -f5)" 'BEGIN { print s + e }'); n=$((n + 1))
    done
    e=$(awk -v s="$sum" -v n="$n" 'BEGIN { print s / n }')
    [ -z "$base" ] && base=$e
    awk -v l="$label" -v e="$e" -v b="$base" 'BEGIN { printf "    %-40s %11.4g  %6.2fx\n", l, e, e / b }'
  done
done
