#!/usr/bin/env bash
# Temporal coherence (issue 4, the paper's test 4): the living room with the sun moving over N frames
# (sun.direction_end), rendered by bayes, bound and donikian at equal spp per frame with statistics carried
# across frames (--frame-decay, default 0.5). Per-frame relMSE against per-frame references (REF_SAMPLER, default
# bayes for the lowest reference noise, REF_SPP spp, seed 99, rendered frame by frame from scratch, cached in BUILD/ref under a key of the scene's files and goldens), and a flicker measure: the mean over frames of |relMSE(f) - relMSE(f-1)|, i.e. how much
# the error jumps from one frame to the next (the paper's concern: learned distributions that change abruptly).
#   tools/flicker.sh BIN BUILD    (env: FRAMES default 8, SPP per frame default 16, REF_SPP default 2048, REF_SAMPLER, W, H)
set -euo pipefail
bin=$1; build=$2
cd "$(dirname "$0")/.."
frames=${FRAMES:-8}; spp=${SPP:-16}; ref_spp=${REF_SPP:-2048}; ref_sampler=${REF_SAMPLER:-bayes}; W=${W:-160}; H=${H:-120}
dir=$(pwd)/data/living_room
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
# The direct-only living room with the sun sweeping 20 degrees of azimuth (130 to 110).
sed -e "s#\"living_room.obj\"#\"$dir/living_room.obj\"#" \
    -e 's#"direction": \[\([^]]*\)\],#"direction": [\1], "direction_end": [0.6040, 0.7660, -0.2198],#' \
    "$dir/direct.json" >"$tmp/anim.json"
grep -q direction_end "$tmp/anim.json" || { echo "flicker: could not make the animated scene" >&2; exit 1; }
. tools/ref_key.sh
refdir=$build/ref/flicker_${W}x${H}_${frames}f_${ref_sampler}_${ref_spp}_$(ref_key data/living_room 'living_room_direct_*')
if [ ! -f "$refdir/done" ]; then
  mkdir -p "$refdir"
  echo "flicker: rendering references ($frames frames, $ref_sampler, $ref_spp spp) into $refdir" >&2
  # --frame-decay 0: every reference frame learns from scratch (no dependence on the previous frames).
  "$bin" render "$tmp/anim.json" --frames "$frames" --sampler "$ref_sampler" --spp "$ref_spp" --width "$W" \
    --height "$H" --seed 99 --frame-decay 0 --quiet -o "$refdir/ref_%04d.pfm"
  touch "$refdir/done"
fi
echo "animation: living room direct, $frames frames, ${W}x${H}, $spp spp per frame, references $ref_sampler $ref_spp spp"
printf "  %-9s %s  %s\n" sampler "mean relMSE" "flicker (mean |relMSE(f) - relMSE(f-1)|)   per-frame relMSE"
for s in bayes bound donikian; do
  "$bin" render "$tmp/anim.json" --frames "$frames" --sampler "$s" --spp "$spp" --width "$W" --height "$H" --quiet \
    -o "$tmp/${s}_%04d.pfm" --reference "$refdir/ref_%04d.pfm" --log "$tmp/${s}_%04d.csv"
  for f in $(seq 0 $((frames - 1))); do tail -n 1 "$(printf "$tmp/${s}_%04d.csv" "$f")" | cut -d, -f5; done >"$tmp/$s.err"
  awk -v s="$s" '{ e[NR] = $1; sum += $1; if (NR > 1) { d = $1 - e[NR - 1]; fl += (d < 0 ? -d : d) } }
    END { line = ""; for (i = 1; i <= NR; i++) line = line sprintf(" %.3g", e[i]);
          printf "  %-9s %11.4g  %11.4g%s\n", s, sum / NR, (NR > 1 ? fl / (NR - 1) : 0), "     " line }' "$tmp/$s.err"
done
