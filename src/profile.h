// profile: `bayeslight profile` — where the time of a render goes, stage by stage (ns per NEE sample and share),
// against the limit of the ray caster: a raw Embree rtcOccluded1 benchmark on the same scene with as many shadow
// rays as the render traced, on the same number of threads.
#pragma once

#include "bvh.h"
#include "lights.h"
#include "render.h"
#include "scene.h"

#include <string>

namespace bl {

// Renders the scene twice with the same options (plain, then with stage timers), runs the raw occlusion
// benchmark, and returns the report as text (a table and a few lines).
std::string profile_render(const scene_data& scene, const bvh_data& bvh, const light_data& lights,
                           const render_params& params, const std::string& title);

}  // namespace bl
