#!/usr/bin/env bash
# Reference-free equal-time error: renders SCENE twice (seeds 11 and 22) for T seconds and reports half the relMSE
# between the two images, an estimate of one render's relMSE that no reference noise inflates.
#   tools/selfvar.sh BIN SCENE_JSON T LABEL [render args]      (env: W H; T like "256spp" means --spp 256)
set -euo pipefail
bin=$1; scene=$2; T=$3; label=$4; shift 4
W=${W:-320}; H=${H:-240}
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
spp=""
for seed in 11 22; do
  budget="--time $T"; [[ "$T" == *spp ]] && budget="--spp ${T%spp}"
  "$bin" render "$scene" $budget --seed $seed --width "$W" --height "$H" "$@" -o "$tmp/$seed.pfm" --log "$tmp/$seed.csv" --quiet
  spp="$spp $(tail -n 1 "$tmp/$seed.csv" | cut -d, -f3)"
done
rel=$("$bin" diff "$tmp/11.pfm" "$tmp/22.pfm" | sed -n 's/relmse=\([^ ]*\).*/\1/p')
awk -v l="$label" -v r="$rel" -v s="$spp" 'BEGIN { printf "%-34s spp%-12s relmse/2 %.5g\n", l, s, r / 2 }'
