#!/usr/bin/env bash
# Regenerates golden/: small renders of every data/ scene (direct and path traced) with every sampler, and
# golden/manifest.txt (one render per line: file, then the render arguments; '#' lines record the toolchain).
# Legitimate only for a deliberate change of output: say why in the commit that updates golden/.
set -euo pipefail
bin=${1:-build/bayeslight}
cd "$(dirname "$0")/.."
samplers="uniform power bvh bound donikian bayes"
out=golden
mkdir -p "$out"
rm -f "$out"/*.pfm
manifest="$out/manifest.txt"
{
  echo "# bayeslight golden images: FILE ARGS... (rendered as: bayeslight render ARGS... -o golden/FILE)"
  echo "# compiler: $(${CXX:-g++} --version | head -n 1)"
  echo "# embree: $(dpkg-query -W -f='${Version}' libembree-dev 2>/dev/null || echo unknown), default device config; t/u/v recomputed in our own float code"
  echo "# flags: -O2 -ffp-contract=off (no -ffast-math, no -march=native)"
} >"$manifest"
for scene in cornell living_room plant_room hall; do
  for mode in direct path; do
    for s in $samplers; do
      file="${scene}_${mode}_${s}.pfm"
      args="data/$scene/$mode.json --sampler $s --width 40 --height 30 --spp 4 --threads 2 --quiet"
      "$bin" render $args -o "$out/$file"
      echo "$file $args" >>"$manifest"
    done
  done
done
# bayes past its fallback check (in the path-traced Cornell box at this size it falls back to power sampling after
# 485 spp: its check windows need 262144 samples).
file="cornell_path_bayes_fallback.pfm"
args="data/cornell/path.json --sampler bayes --width 40 --height 30 --spp 512 --threads 2 --quiet"
"$bin" render $args -o "$out/$file"
echo "$file $args" >>"$manifest"
# Independent samples at the first vertex (--independent-samples; the default stratifies them): the estimator of
# earlier releases, a learning and a fixed sampler, path traced.
for s in bound bayes; do
  file="plant_room_path_${s}_independent.pfm"
  args="data/plant_room/path.json --sampler $s --width 40 --height 30 --spp 4 --threads 2 --quiet --independent-samples"
  "$bin" render $args -o "$out/$file"
  echo "$file $args" >>"$manifest"
done
echo "wrote $(ls "$out"/*.pfm | wc -l) golden images and $manifest"
