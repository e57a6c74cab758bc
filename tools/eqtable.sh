#!/usr/bin/env bash
# Equal-time table: every sampler on every data/ scene (direct and path traced) for T seconds against a cached
# high-sample reference, with the speed-up of bayes over bound and over bvh (relMSE ratio at equal time).
#   tools/eqtable.sh BIN   (env: T seconds per render, W H image size, SCENES, MODES, SAMPLERS, REF_SPP_DIRECT,
#                           REF_SPP_PATH, REF_SAMPLER, OPTS: options added to every timed render, e.g.
#                           OPTS="--light-samples 2"; references cached in $(dirname BIN)/ref)
# A cached reference's name carries a hash of the scene's files and of its golden images in that mode (ref_key.sh):
# a change to the scene, or one of the renderer that changes images, renders a new reference.
# References: REF_SAMPLER (default bayes: the lowest-variance unbiased sampler here, so its reference adds the least
# noise to every measured error; a bvh reference of equal spp has 5-50x its relMSE on the occluded scenes), seed
# 987654321 (independent of the renders' seeds). That the bayes reference is unbiased is checked by the unit tests
# (bayes/bound/uniform estimate the same image) and can be seen here with REF_SAMPLER=bvh: the table's
# rankings stay, only the noise floor rises.
set -euo pipefail
bin=$1
cd "$(dirname "$0")/.."
. tools/ref_key.sh
T=${T:-10}; W=${W:-320}; H=${H:-240}
SCENES=${SCENES:-"cornell living_room plant_room hall"}; MODES=${MODES:-"direct path"}
SAMPLERS=${SAMPLERS:-"uniform power bvh bound donikian bayes"}
# 16384 spp direct: a reference's own error adds to every measured relMSE; with 4096 spp it added ~15 % to bayes's
# figure at 10 s (bayes reaches 600-700 spp there) and next to nothing to the fixed samplers' (README). 4096 spp
# path traced: a 1024-spp reference's own relMSE was 22 % of bayes's figure at 10 s in the Cornell box, 9 % in the
# living room and the plant room (README).
REF_SPP_DIRECT=${REF_SPP_DIRECT:-16384}; REF_SPP_PATH=${REF_SPP_PATH:-4096}; REF_SAMPLER=${REF_SAMPLER:-bayes}
refdir=$(dirname "$bin")/ref; mkdir -p "$refdir"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
printf "| scene | mode | %s | bayes/bound | bayes/bvh |\n" "$(echo $SAMPLERS | sed 's/ / | /g')"
printf "|---|---|%s---|---|\n" "$(for s in $SAMPLERS; do printf -- '---|'; done)"
for scene in $SCENES; do
  for mode in $MODES; do
    json=data/$scene/$mode.json
    spp=$REF_SPP_DIRECT; [ "$mode" = path ] && spp=$REF_SPP_PATH
    key=$(ref_key "data/$scene" "${scene}_${mode}_*")
    ref=$refdir/${scene}_${mode}_${W}x${H}_${REF_SAMPLER}_${spp}_${key}.exr
    ensure_reference "$bin" "$json" "$REF_SAMPLER" "$spp" "$W" "$H" "$ref"
    row="| $scene | $mode |"
    declare -A err=()
    for s in $SAMPLERS; do
      # shellcheck disable=SC2086  # OPTS: words on purpose
      "$bin" render "$json" --sampler "$s" --time "$T" --width "$W" --height "$H" --reference "$ref" \
        --log "$tmp/$s.csv" -o "$tmp/$s.exr" --quiet ${OPTS:-}
      read -r e n < <(awk -F, -v T="$T" -f tools/at_time.awk "$tmp/$s.csv")
      err[$s]=$e
      row="$row $(printf '%.4g' "$e") ($n spp at T) |"
    done
    r1=$(awk -v a="${err[bound]:-0}" -v b="${err[bayes]:-1}" 'BEGIN{printf "%.2fx", a/b}')
    r2=$(awk -v a="${err[bvh]:-0}" -v b="${err[bayes]:-1}" 'BEGIN{printf "%.2fx", a/b}')
    echo "$row $r1 | $r2 |"
    unset err
  done
done
