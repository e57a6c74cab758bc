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
# compare renders both for T s each (bound first: the baseline of its speed-up column) and writes the images
# (<sampler>.exr and .png), a false-colour error image of each, every pass's error (curves.csv), the plot of relMSE
# against time (error_vs_time.svg) and the equal-time table (summary.md).
echo "rendering $scene with the bound and the bayes sampler for $T s each"
"$bin" compare "$scene" --samplers bound,bayes --time "$T" --width "$W" --height "$H" --reference "$ref" \
  --reference-note "bayes, 2048 spp, seed 1000003" --out "$out"
echo
echo "error against time (relMSE vs the reference at $T s; every pass in $out/curves.csv):"
# The table's rows: sampler, spp, seconds, relMSE at T, speed-up over bound at equal time.
awk -F'|' '$2 ~ /^ (bound|bayes) $/ {
  for (i = 2; i <= 6; i++) gsub(/ /, "", $i)
  printf "  %-6s %5d spp in %6.2f s  relMSE %s  speed-up over bound %sx\n", $2, $3, $4, $5, $6
}' "$out/summary.md"
echo "report: $out/summary.md, plot: $out/error_vs_time.svg"
echo "images: $out/bayes.png (.exr), $out/bound.png (.exr); error images: $out/bayes_error.png, $out/bound_error.png"
