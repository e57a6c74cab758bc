#!/usr/bin/env bash
# relMSE at an equal sample count (learning quality without timing noise), against the cached reference of
# tools/eqtime.sh:  tools/eqspp.sh BIN SCENE_JSON SPP LABEL [render args for this run]
set -euo pipefail
bin=$1; scene=$2; spp=$3; label=$4; shift 4
W=${W:-320}; H=${H:-240}; REF_SPP=${REF_SPP:-2048}; REF_SAMPLER=${REF_SAMPLER:-bvh}; REF_ARGS=${REF_ARGS:-}
dir=$(dirname "$bin")/ref; mkdir -p "$dir"
key=$(echo "$scene $W $H $REF_SPP $REF_SAMPLER $REF_ARGS" | md5sum | cut -c1-12)
ref="$dir/$(basename "$(dirname "$scene")")_$(basename "$scene" .json)_$key.exr"
if [ ! -f "$ref" ]; then
  echo "reference: $REF_SAMPLER $REF_SPP spp -> $ref" >&2
  "$bin" render "$scene" --sampler "$REF_SAMPLER" --spp "$REF_SPP" --seed 987654321 --width "$W" --height "$H" $REF_ARGS -o "$ref" --quiet
fi
tmp=$(mktemp -d)
"$bin" render "$scene" --spp "$spp" --width "$W" --height "$H" $REF_ARGS "$@" --reference "$ref" --log "$tmp/l.csv" -o "$tmp/o.exr" --quiet
tail -n 1 "$tmp/l.csv" | awk -F, -v s="$label" '{printf "%-28s spp %5d  %6.2fs  relmse %.6g\n", s, $3, $4, $5}'
rm -rf "$tmp"
