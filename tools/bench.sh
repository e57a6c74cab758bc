#!/usr/bin/env bash
# `make bench`: throughput of the renderer against the raw ray-casting limit, microbenchmarks, and the
# equal-time error table of every sampler on every data/ scene. Long; references are cached in BUILD/ref.
#   tools/bench.sh BIN BUILD   (env: BENCH_SECTIONS, default "throughput micro profile stress grid frames eqtable";
#                               T, W, H: see eqtable.sh; GRID_T: seconds per grid-study render)
# Sections: throughput (camera + shadow rays/s at 1 and 2 threads), micro (Google Benchmark: raw Embree limit,
# region lookup, PMF build, posterior, reduction, tree build), profile (bayeslight profile of every data/ scene,
# direct only, bayes and bound), stress (generated scenes with 10^5 and 10^6 emitters: load, build, render,
# memory), grid (grid-resolution study on the hall), frames (animation flicker), eqtable (equal-time relMSE).
set -euo pipefail
bin=$1; build=$2
cd "$(dirname "$0")/.."
sections=${BENCH_SECTIONS:-"throughput micro profile stress grid frames eqtable"}
scene=data/living_room/direct.json
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
if [[ " $sections " == *" throughput "* ]]; then
  echo "== render throughput: $scene, 320x240, 32 spp, direct illumination (camera + shadow rays per second)"
  for s in uniform bayes; do
    for t in 1 2; do
      printf "  %-8s threads %d: " "$s" "$t"
      "$bin" render "$scene" --sampler "$s" --spp 32 --threads "$t" --width 320 --height 240 -o "$tmp/t.pfm" 2>&1 \
        | sed -n 's/^rendered [^(]*(\([^)]*\)).*/\1/p' | head -n 1 || true
    done
  done
fi
if [[ " $sections " == *" micro "* ]] && [ -x "$build/bayeslight_bench" ]; then
  echo "== raw Embree limit on the same scene (Google Benchmark; items/s = rays/s)"
  "$build/bayeslight_bench" --benchmark_min_time=1
fi
if [[ " $sections " == *" profile "* ]]; then
  for sc in cornell living_room plant_room hall; do
    for s in bound bayes; do
      echo "== profile: data/$sc/direct.json, $s, 320x240, 32 spp"
      "$bin" profile "data/$sc/direct.json" --sampler "$s" --width 320 --height 240 --spp 32 | tail -n +2
    done
  done
fi
if [[ " $sections " == *" stress "* ]]; then
  for n in 100000 1000000; do
    echo "== stress scene: $n emissive triangles (tools/stress_scene.py), 160x120, 4 spp, direct"
    [ -f "$build/stress/$n/direct.json" ] || python3 tools/stress_scene.py "$n" "$build/stress/$n" >/dev/null
    for s in bvh bound bayes; do
      echo "  $s:"
      "$bin" render "$build/stress/$n/direct.json" --sampler "$s" -o "$tmp/stress.pfm" 2>&1 | sed 's/^/    /'
    done
  done
fi
if [[ " $sections " == *" grid "* ]]; then
  echo "== grid-resolution study (bayes vs bound, hall direct)"
  T=${GRID_T:-8} tools/gridstudy.sh "$bin"
fi
if [[ " $sections " == *" frames "* ]]; then
  echo "== temporal coherence (animated sun, living room direct)"
  tools/flicker.sh "$bin" "$build"
fi
if [[ " $sections " == *" eqtable "* ]]; then
  echo "== equal-time relMSE (T=${T:-10} s per render; lower is better)"
  tools/eqtable.sh "$bin"
fi
