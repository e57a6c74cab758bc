#!/usr/bin/env bash
# Equal-time relMSE of several samplers on one scene against a cached reference.
#   tools/eqtime.sh BIN SCENE_JSON SECONDS "uniform power bvh bound bayes" [extra render args]
# The reference (bvh sampler, REF_SPP spp, its own seed) is cached in build/ref/ keyed by the scene's files, the
# goldens, size, spp and options (tools/ref_key.sh).
set -euo pipefail
bin=$1; scene=$2; secs=$3; samplers=$4; shift 4
extra="$*"
W=${W:-320}; H=${H:-240}; REF_SPP=${REF_SPP:-1024}; REF_SAMPLER=${REF_SAMPLER:-bvh}
dir=$(dirname "$bin")/ref; mkdir -p "$dir"
. "$(dirname "$0")/ref_key.sh"
# A data/ scene's own goldens; any other scene, every golden (a change of output anywhere renders it again).
name=$(basename "$(dirname "$scene")"); glob='*'
[ "$(cd "$(dirname "$scene")" 2>/dev/null && pwd)" = "$ref_key_root/data/$name" ] && glob="${name}_*"
key=$(ref_key "$(dirname "$scene")" "$glob" "$(basename "$scene") $W $H $REF_SPP $REF_SAMPLER $extra")
ref="$dir/$(basename "$(dirname "$scene")")_$(basename "$scene" .json)_$key.exr"
# shellcheck disable=SC2086  # $extra: words on purpose
ensure_reference "$bin" "$scene" "$REF_SAMPLER" "$REF_SPP" "$W" "$H" "$ref" $extra
tmp=$(mktemp -d)
for s in $samplers; do
  "$bin" render "$scene" --sampler "$s" --time "$secs" --width "$W" --height "$H" $extra --reference "$ref" \
    --log "$tmp/$s.csv" -o "$tmp/$s.exr" --quiet
  tail -n 1 "$tmp/$s.csv" | awk -F, -v s="$s" '{printf "%-8s spp %5d  %6.2fs  relmse %.6g\n", s, $3, $4, $5}'
done
rm -rf "$tmp"
