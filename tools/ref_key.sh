# shellcheck shell=bash
# Sourced by the bench scripts that cache references (eqtable.sh, eqtime.sh, flicker.sh, gridstudy.sh).
# ref_key DIR GLOB [WORDS...]: 12 hex digits of a hash over the scene files under DIR (its .json, .obj, .mtl and
# texture images, by their names relative to DIR, three levels deep; not renders or a reference cache kept there),
# the golden images matching golden/GLOB and the WORDS (size, spp, options). A reference cached under this key is rendered again when the scene changes or when the renderer changes
# its images (a change of output changes golden/, by the project's rule), instead of measuring against a stale one.
ref_key_root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
ref_key() {
  local dir=$1 glob=$2; shift 2
  { (cd "$dir" && find . -maxdepth 3 -type f \( -name '*.json' -o -iname '*.obj' -o -iname '*.mtl' -o -iname '*.png' \
        -o -iname '*.jpg' -o -iname '*.jpeg' -o -iname '*.tga' -o -iname '*.bmp' -o -iname '*.ppm' -o -iname '*.pgm' \
        -o -iname '*.hdr' -o -iname '*.psd' -o -iname '*.gif' \) -not -path './ref/*' -print0 |
      sort -z | xargs -0 -r sha256sum)
    (cd "$ref_key_root" && find golden -name "$glob" -type f -print0 | sort -z | xargs -0 -r sha256sum)
    echo "$*"; } | sha256sum | cut -c1-12
}
# ensure_reference BIN JSON SAMPLER SPP W H PATH [OPTIONS...]: renders the reference PATH (seed 987654321,
# independent of the measured renders' seeds; OPTIONS added to the render) unless it is cached, under a temporary name
# until it completes: an interrupted render writes the image of its passes so far, which must not be taken for the
# reference by the next run.
ensure_reference() {
  local bin=$1 json=$2 sampler=$3 spp=$4 w=$5 h=$6 path=$7
  shift 7
  [ -f "$path" ] && return 0
  echo "reference $path ($sampler, $spp spp)" >&2
  "$bin" render "$json" --sampler "$sampler" --spp "$spp" --seed 987654321 --width "$w" --height "$h" "$@" \
    -o "$path.part.exr" --quiet
  mv "$path.part.exr" "$path"
}
