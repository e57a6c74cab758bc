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
  # At each scene's own settings (640x480, 64 spp: what a render gets by default), then the bayes/bound summary.
  for sc in cornell living_room plant_room hall; do
    for s in bound bayes; do
      echo "== profile: data/$sc/direct.json, $s (the scene's own size and spp)"
      "$bin" profile "data/$sc/direct.json" --sampler "$s" | tee "$tmp/prof_${sc}_$s.txt" | tail -n +2
    done
  done
  echo "== profile summary (direct only): NEE samples/s of bayes over bound, fraction of raw Embree, learning share"
  for sc in cornell living_room plant_room hall; do
    rate() { sed -n 's/.*NEE samples (\([0-9.]*\) M\/s).*/\1/p' "$tmp/prof_${sc}_$1.txt"; }
    frac() { sed -n 's/.*fraction of the raw shadow-ray limit: \([0-9.]*\).*/\1/p' "$tmp/prof_${sc}_$1.txt"; }
    learn() { sed -n 's/.*between-pass learning: \([0-9.]*\)%.*/\1/p' "$tmp/prof_${sc}_$1.txt"; }
    mem() { sed -n 's/.*pairs, \([0-9.]*\) bytes per pair.*/\1/p' "$tmp/prof_${sc}_$1.txt"; }
    printf "  %-12s one run: bayes/bound %s (%s / %s M NEE/s)  raw fraction bayes %s bound %s  learning bayes %s%% bound %s%%  bytes/pair %s\n" \
      "$sc" "$(awk -v a="$(rate bayes)" -v b="$(rate bound)" 'BEGIN { printf "%.2f", a / b }')" "$(rate bayes)" "$(rate bound)" \
      "$(frac bayes)" "$(frac bound)" "$(learn bayes)" "$(learn bound)" "$(mem bayes)"
  done
  # The machine is shared: the speed ratio again as the median of ROUNDS interleaved plain renders of each.
  rounds=${ROUNDS:-3}
  echo "== bayes over bound, NEE samples/s: median of $rounds interleaved renders each (the scene's own size and spp)"
  for sc in cornell living_room plant_room hall; do
    : >"$tmp/r_bound"; : >"$tmp/r_bayes"
    for ((k = 0; k < rounds; k++)); do
      for s in bound bayes; do
        "$bin" render "data/$sc/direct.json" --sampler "$s" -o "$tmp/r.pfm" 2>&1 |
          sed -n 's/^rendered .*, \([0-9.]*\) M NEE samples\/s).*/\1/p' >>"$tmp/r_$s"
      done
    done
    med() { sort -g "$1" | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }
    printf "  %-12s bayes %s, bound %s M NEE/s: %s\n" "$sc" "$(med "$tmp/r_bayes")" "$(med "$tmp/r_bound")" \
      "$(awk -v a="$(med "$tmp/r_bayes")" -v b="$(med "$tmp/r_bound")" 'BEGIN { printf "%.2f", a / b }')"
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
