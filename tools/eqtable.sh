#!/usr/bin/env bash
# Equal-time table: every sampler on every data/ scene (direct and path traced) for T seconds against a cached
# high-sample reference, with the speed-up of bayes over bound and over bvh (relMSE ratio at equal time).
#   tools/eqtable.sh BIN   (env: T seconds per render, W H image size, SCENES, MODES, SAMPLERS, REF_SPP_DIRECT,
#                           REF_SPP_PATH; references: bvh sampler, seed 987654321, cached in $(dirname BIN)/ref)
set -euo pipefail
bin=$1
cd "$(dirname "$0")/.."
T=${T:-10}; W=${W:-320}; H=${H:-240}
SCENES=${SCENES:-"cornell living_room plant_room hall"}; MODES=${MODES:-"direct path"}
SAMPLERS=${SAMPLERS:-"uniform power bvh bound donikian bayes"}
REF_SPP_DIRECT=${REF_SPP_DIRECT:-4096}; REF_SPP_PATH=${REF_SPP_PATH:-2048}
refdir=$(dirname "$bin")/ref; mkdir -p "$refdir"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
printf "| scene | mode | %s | bayes/bound | bayes/bvh |\n" "$(echo $SAMPLERS | sed 's/ / | /g')"
printf "|---|---|%s---|---|\n" "$(for s in $SAMPLERS; do printf -- '---|'; done)"
for scene in $SCENES; do
  for mode in $MODES; do
    json=data/$scene/$mode.json
    spp=$REF_SPP_DIRECT; [ "$mode" = path ] && spp=$REF_SPP_PATH
    ref=$refdir/${scene}_${mode}_${W}x${H}_bvh_${spp}.exr
    if [ ! -f "$ref" ]; then
      echo "reference $ref (bvh, $spp spp)" >&2
      "$bin" render "$json" --sampler bvh --spp "$spp" --seed 987654321 --width "$W" --height "$H" -o "$ref" --quiet
    fi
    row="| $scene | $mode |"
    declare -A err=()
    for s in $SAMPLERS; do
      "$bin" render "$json" --sampler "$s" --time "$T" --width "$W" --height "$H" --reference "$ref" \
        --log "$tmp/$s.csv" -o "$tmp/$s.exr" --quiet
      e=$(tail -n 1 "$tmp/$s.csv" | cut -d, -f5); n=$(tail -n 1 "$tmp/$s.csv" | cut -d, -f3)
      err[$s]=$e
      row="$row $(printf '%.4g' "$e") ($n spp) |"
    done
    r1=$(awk -v a="${err[bound]:-0}" -v b="${err[bayes]:-1}" 'BEGIN{printf "%.2fx", a/b}')
    r2=$(awk -v a="${err[bvh]:-0}" -v b="${err[bayes]:-1}" 'BEGIN{printf "%.2fx", a/b}')
    echo "$row $r1 | $r2 |"
    unset err
  done
done
