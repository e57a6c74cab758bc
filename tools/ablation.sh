#!/usr/bin/env bash
# Ablation of the bayes sampler's choices (issue 3, item 7): every switch against the defaults, at equal time,
# on the occluded direct-only scenes. Error is reference-free (tools/selfvar.sh: two seeds, half their relMSE).
# A ratio > 1 means the variant has that much more error than the defaults at equal time.
#   tools/ablation.sh BIN     (env: T seconds per render, default 6; SCENES; W, H default 320x240)
set -euo pipefail
bin=$1
cd "$(dirname "$0")/.."
T=${T:-6}
SCENES=${SCENES:-"living_room plant_room hall"}
variants=(
  "defaults|"
  "point prior (bound at every point)|--bayes-prior point"
  "mean PMF (no second moment)|--bayes-pmf mean"
  "no distance regression|--bayes-no-regression"
  "naive (no prior, plug-in moments)|--bayes-naive"
  "epsilon 0.05 (prior mixing)|--bayes-epsilon 0.05"
  "Beta(1, 1) on p0 (b0 1)|--bayes-b0 1"
  "b0 0.01|--bayes-b0 0.01"
  "no hierarchy|--bayes-hierarchy 0"
  "hierarchy 4|--bayes-hierarchy 4"
  "c 1 (prior CV 100%)|--bayes-c 1"
  "previous defaults (b0 1, c 1, hier. 4)|--bayes-b0 1 --bayes-c 1 --bayes-hierarchy 4"
  "max cut 16|--max-cut 16"
  "max cut 256|--max-cut 256"
  "bound sampler (reference point)|--sampler bound"
)
echo "ablation: direct only, ${W:-320}x${H:-240}, $T s per render, two seeds; relMSE/2 and ratio to the defaults"
for scene in $SCENES; do
  json=data/$scene/direct.json
  echo "  $scene"
  base=""
  for v in "${variants[@]}"; do
    label=${v%%|*}; args=${v#*|}
    [[ "$args" == *--sampler* ]] || args="--sampler bayes $args"
    e=$(tools/selfvar.sh "$bin" "$json" "$T" x $args | sed -n 's/.*relmse\/2 //p')
    [ -z "$base" ] && base=$e
    awk -v l="$label" -v e="$e" -v b="$base" 'BEGIN { printf "    %-36s %11.4g  %6.2fx\n", l, e, e / b }'
  done
done
