# shellcheck shell=bash
# Sourced by the bench scripts that cache references (eqtable.sh, eqtime.sh, flicker.sh).
# ref_key DIR GLOB [WORDS...]: 12 hex digits of a hash over every file under DIR (the scene: its .json, .obj, .mtl,
# textures, by their names relative to DIR), the golden images matching golden/GLOB and the WORDS (size, spp,
# options). A reference cached under this key is rendered again when the scene changes or when the renderer changes
# its images (a change of output changes golden/, by the project's rule), instead of measuring against a stale one.
ref_key_root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
ref_key() {
  local dir=$1 glob=$2; shift 2
  { (cd "$dir" && find . -type f -print0 | sort -z | xargs -0 -r sha256sum)
    (cd "$ref_key_root" && find golden -name "$glob" -type f -print0 | sort -z | xargs -0 -r sha256sum)
    echo "$*"; } | sha256sum | cut -c1-12
}
