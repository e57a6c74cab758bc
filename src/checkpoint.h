// checkpoint: saving and restoring a render between passes (--checkpoint / --resume). A checkpoint holds the
// film sums, the pass count, the per-pass log, the counters, the light sampler's learned state and a fingerprint
// of the scene and every option that changes the image. Invariant: rendering is deterministic and the pass
// schedule depends only on the pass index, so a resumed render reaches exactly the bits of an uninterrupted one.
// Files are written atomically and end with a checksum; anything malformed is an input_error.
#pragma once

#include "light_sampler.h"
#include "render.h"
#include "scene.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace bl {

// Fingerprint of what a resumed render must share with the one that wrote the checkpoint: the loaded scene
// (geometry, materials, textures, camera, sun) and the options that affect pixels (size, depth, seed, sampler
// and its parameters). The spp target and time budget are not part of it (but for an animation's): a render may be
// resumed further. With the hash of each part, so that a refused resume names the parts that differ.
enum fingerprint_part : int {  // (from fp_learning_weights on: options of the sampler in use)
  fp_scene, fp_image_size, fp_max_depth, fp_seed, fp_sampler, fp_light_samples, fp_animation, fp_learning_weights,
  fp_regions, fp_bayes, fp_donikian, fp_part_count
};
struct render_fingerprint_data {
  uint64_t total = 0;                  // of everything, in order (what a checkpoint must match)
  uint64_t parts[fp_part_count] = {};  // of each part alone (a part with nothing in it: the hasher's start value)
};
render_fingerprint_data render_fingerprint(const scene_data& scene, const render_params& params);
// What part `part` covers, as a refusal names it.
const char* fingerprint_part_name(int part);

// Where an animation's checkpoint holds its frame index: after the magic (16 bytes), the version, the fingerprint and
// its parts, the reference hash, the sampler kind, the width and the height (tests edit it).
constexpr size_t checkpoint_frame_offset = 16 + 4 + 8 + 4 + 8 * fp_part_count + 8 + 4 + 4 + 4;

// The version of the checkpoint layout: a checkpoint of another one is refused (bayeslight --version says it).
uint32_t checkpoint_format_version();

// The checksum a checkpoint ends with, of everything before it (a guard against accidental damage, not a seal).
uint64_t checkpoint_checksum(std::string_view body);

// Hash of a reference image's size and pixels (0: no reference): which reference a checkpoint's logged errors
// were measured against. Not part of the fingerprint (the reference does not change the image).
uint64_t reference_hash(const image_data* reference);

// Writes a completed-pass state to path as write_file_atomic does: the result so far, the sampler's learned state
// and the hash of the reference the log's errors were measured against, then a checksum. In pieces, never the whole
// in memory (each write added its size to the process's memory, 100-200 MB in the living room; a review).
// `frames`: the render's (render_params::frames); an animation's checkpoint also holds result.frame.
void write_checkpoint(const std::string& path, const render_fingerprint_data& fingerprint, uint64_t reference,
                      const render_result& result, const light_sampler& sampler, int frames);
// Whether the regular file at path starts as a checkpoint does (false where it cannot be read): a render given it as
// --checkpoint without --resume would replace a saved render.
bool holds_checkpoint(const std::string& path);
// The number of passes of its frame that the checkpoint at path holds, read from its header alone (`frames`: the
// render's, render_params::frames); -1 where the file cannot be read as a checkpoint of this version (the resume
// then refuses it, naming why). An animation stopped before a frame's first pass saved that frame with none.
int saved_passes(const std::string& path, int frames);

// Restores a state written by write_checkpoint into a freshly built sampler of the same kind and the result;
// throws input_error naming `path` when the data are malformed or were written for another scene/options (naming
// the fingerprint's parts that differ).
// `params`: the render's, against whose pass weighting the film's weight is checked and whose frame count bounds
// an animation's frame. Returns the stored reference hash.
uint64_t decode_checkpoint(const std::string& bytes, const std::string& path,
                           const render_fingerprint_data& fingerprint, const render_params& params,
                           render_result& result, light_sampler& sampler);

}  // namespace bl
