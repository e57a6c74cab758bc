// light_sampler: the closed set of light-selection strategies for NEE (SPEC.md section 7) and their
// construction by name. The contract each member satisfies is described in light_sampler_types.h.
#pragma once

#include "bayes_sampler.h"
#include "bound_sampler.h"
#include "bvh_sampler.h"
#include "donikian_sampler.h"
#include "light_sampler_types.h"
#include "light_tree.h"
#include "lights.h"
#include "region_grid.h"
#include "scene.h"
#include "simple_samplers.h"

#include <string>
#include <variant>

namespace bl {

struct render_inputs;

// The closed set.
using light_sampler =
    std::variant<uniform_sampler, power_sampler, bvh_sampler, bound_sampler, donikian_sampler, bayes_sampler>;

// Options of light selection (ablation switches of the adaptive samplers included).
struct sampler_params {
  sampler_kind kind = sampler_kind::bayes;
  region_params regions;
  bayes_params bayes;
  donikian_params donikian;
};

// Whether a sampler kind uses the light tree.
bool needs_light_tree(sampler_kind kind);

// The region options a render of `params.kind` uses (bound, donikian, bayes): --max-cut within max_cut_entries,
// members only for bayes with the region prior (automatic: 128 in direct illumination, max_depth 1, else none), the
// automatic pair budget resolved for an image of `pixels` pixels (what a checkpoint's fingerprint compares: options
// that resolve alike render alike).
region_params effective_region_params(const sampler_params& params, int max_depth, int64_t pixels);

// A warning, or "" : where a region sampler's fine cells come out coarser than its grid asks for (at most 2^20 cells
// fit along the longest axis of `bounds`, a room on a ground reaching 1e7; or cells of a few ulps far from the
// origin), which the regions then learn too little to serve (a handful of `lights` share one cut, and bound then reads
// no region; bayes with one light reads none). `given_grid`: the grid came from --grid.
std::string coarse_grid_warning(const sampler_params& params, int max_depth, int64_t pixels, const bbox3f& bounds,
                                const light_data& lights, bool given_grid);

// Builds the sampler of `params.kind`; `tree` must outlive it. Region-based samplers discover the regions of the
// camera's first hits up front (one ray per pixel centre). Throws usage_error for a kind this build lacks.
light_sampler make_light_sampler(const sampler_params& params, const render_inputs& in, const light_tree_data& tree);

// Memory held by a sampler's learned or per-region state (regions, cuts, statistics), in bytes.
size_t sampler_memory_bytes(const light_sampler& s);

}  // namespace bl
