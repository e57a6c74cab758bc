#!/usr/bin/env bash
# `make run`: renders the living room (direct illumination) with the bayes sampler for a fixed time, with the
# non-adaptive bound sampler beside it, both against a reference rendered once by the project itself (bayes
# sampler, 2048 spp, its own seed; cached in build/demo/: an unbiased sampler whose reference adds the least noise
# to the measured error — a bvh reference of 512 spp had 20x the error of a 15 s bayes render), and reports error
# against time.
set -euo pipefail
bin=${1:-build/bayeslight}
cd "$(dirname "$0")/.."
scene=data/living_room/direct.json
W=${W:-320}; H=${H:-240}; T=${T:-10}
out=out/demo; cache=$(dirname "$bin")/demo
mkdir -p "$out" "$cache"
ref=$cache/living_room_direct_${W}x${H}_bayes_2048spp.exr
if [ ! -f "$ref" ]; then
  echo "rendering the reference once (bayes sampler, 2048 spp, seed 1000003) -> $ref"
  "$bin" render "$scene" --sampler bayes --spp 2048 --seed 1000003 --width "$W" --height "$H" -o "$ref"
fi
for s in bayes bound; do
  echo "rendering $scene with the $s sampler for $T s"
  "$bin" render "$scene" --sampler "$s" --time "$T" --width "$W" --height "$H" --reference "$ref" \
    --log "$out/living_room_$s.csv" -o "$out/living_room_$s.exr" -o "$out/living_room_$s.png"
done
echo
echo "error against time (relMSE vs the reference; full per-pass curves in $out/*.csv):"
for s in bayes bound; do
  tail -n 1 "$out/living_room_$s.csv" | awk -F, '{printf "  %-6s %5d spp in %6.2f s  relMSE %.5g (its last pass)\n", $1, $3, $4, $5}'
done
# Each render ends with the pass under way at T: the errors are compared at exactly T (interpolated between passes).
read -r b _ < <(awk -F, -v T="$T" -f tools/at_time.awk "$out/living_room_bayes.csv")
read -r n _ < <(awk -F, -v T="$T" -f tools/at_time.awk "$out/living_room_bound.csv")
awk -v b="$b" -v n="$n" -v T="$T" 'BEGIN { printf "  bayes speed-up over bound at equal time (relMSE at %g s): %.1fx\n", T, n / b }'
echo "images: $out/living_room_bayes.png (.exr), $out/living_room_bound.png (.exr)"
