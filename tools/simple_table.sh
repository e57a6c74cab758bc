#!/usr/bin/env bash
# Scenes with nothing to learn (tools/simple_scenes.py): bayes against the best fixed sampler (uniform, power, bvh,
# bound), at equal time or equal spp, mean relMSE over RUNS seeds (bayeslight compare), against a reference of
# `power` cached in $(dirname BIN)/simple. The promise tested: bayes at 0.9x of the best fixed sampler or better.
# An SPP that is a power of two flatters the fixed samplers here: their one stratified light set then picks each of
# 2^k equal lights alike (64 lamps, power, direct: 84x its independent samples' relMSE at 64 spp, 6x at 96).
#   tools/simple_table.sh BIN   (env: SCENES, MODES "direct path", T seconds (default 3) or SPP (equal spp instead),
#                                RUNS (default 3), REF_SPP_DIRECT (8192), REF_SPP_PATH (2048))
set -euo pipefail
bin=$(realpath "$1")
cd "$(dirname "$0")/.."
dir=$(dirname "$bin")/simple
mkdir -p "$dir"
python3 tools/simple_scenes.py "$dir"
SCENES=${SCENES:-"one_quad two_lamps grid64 split128 split450 sun sun_lamp ring32 glossy16"}
MODES=${MODES:-"direct path"}
T=${T:-3}; RUNS=${RUNS:-3}; SPP=${SPP:-}
REF_SPP_DIRECT=${REF_SPP_DIRECT:-8192}; REF_SPP_PATH=${REF_SPP_PATH:-2048}
budget="--time $T"; [ -n "$SPP" ] && budget="--spp $SPP"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
echo "| scene | mode | best fixed: relMSE (spp) | bayes: relMSE (spp) | best fixed / bayes |"
echo "|---|---|---|---|---|"
for scene in $SCENES; do
  for mode in $MODES; do
    depth=1 refspp=$REF_SPP_DIRECT
    [ "$mode" = path ] && depth=5 refspp=$REF_SPP_PATH
    # The reference's name holds a hash of the scene's files (a changed generator renders a new one).
    key=$(cat "$dir/$scene.json" "$dir/$scene.obj" "$dir/$scene.mtl" | sha256sum | cut -c1-12)
    ref=$dir/ref_${scene}_${mode}_${refspp}_$key.exr
    [ -f "$ref" ] || "$bin" render "$dir/$scene.json" --sampler power --spp "$refspp" --max-depth "$depth" \
      --seed 987654321 --quiet -o "$ref"
    # shellcheck disable=SC2086  # budget: two words on purpose
    "$bin" compare "$dir/$scene.json" --reference "$ref" $budget --runs "$RUNS" --max-depth "$depth" --quiet \
      --samplers uniform,power,bvh,bound,bayes --out "$tmp/$scene.$mode" > /dev/null
    # Rows of summary.md: | sampler | spp | seconds | relMSE ± sd | ...
    awk -F'|' -v scene="$scene" -v mode="$mode" '
      function trim(s) { gsub(/^ +| +$/, "", s); return s }
      $2 ~ /^ (uniform|power|bvh|bound|bayes) $/ && !seen[trim($2)]++ {
        s = trim($2); split(trim($5), e, " "); err[s] = e[1] + 0; spp[s] = trim($3)
        if (s != "bayes" && (best == "" || err[s] < err[best])) best = s
      }
      END {
        if (best == "" || !("bayes" in err) || err["bayes"] <= 0) { print "| " scene " | " mode " | ? | ? | ? |"; exit }
        printf "| %s | %s | %s %.3e (%s) | %.3e (%s) | %.2fx |\n", scene, mode, best, err[best], spp[best],
               err["bayes"], spp["bayes"], err[best] / err["bayes"]
      }' "$tmp/$scene.$mode/summary.md"
  done
done
