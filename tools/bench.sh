#!/usr/bin/env bash
# `make bench`: throughput of the renderer against the raw ray-casting limit, microbenchmarks, and the
# equal-time error table of every sampler on every data/ scene. Long; references are cached in BUILD/ref.
#   tools/bench.sh BIN BUILD   (env: BENCH_SECTIONS="throughput micro eqtable", T, W, H: see eqtable.sh)
set -euo pipefail
bin=$1; build=$2
cd "$(dirname "$0")/.."
sections=${BENCH_SECTIONS:-"throughput micro eqtable"}
scene=data/living_room/direct.json
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
if [[ " $sections " == *" throughput "* ]]; then
  echo "== render throughput: $scene, 320x240, 32 spp, direct illumination (camera + shadow rays per second)"
  for s in uniform bayes; do
    for t in 1 2; do
      printf "  %-8s threads %d: " "$s" "$t"
      "$bin" render "$scene" --sampler "$s" --spp 32 --threads "$t" --width 320 --height 240 -o "$tmp/t.pfm" 2>&1 \
        | sed -n 's/.*(\(.*\)).*/\1/p' | head -n 1 || true
    done
  done
fi
if [[ " $sections " == *" micro "* ]] && [ -x "$build/bayeslight_bench" ]; then
  echo "== raw Embree limit on the same scene (Google Benchmark; items/s = rays/s)"
  "$build/bayeslight_bench" --benchmark_min_time=1
fi
if [[ " $sections " == *" eqtable "* ]]; then
  echo "== equal-time relMSE (T=${T:-10} s per render; lower is better)"
  tools/eqtable.sh "$bin"
fi
