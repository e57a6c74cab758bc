// scene_checks: warnings about a loaded scene that rendering cannot fix: no emitters, lights too small for float where
// they are, emitters drawn on other surfaces. Each names the scene file; none changes the image.
#pragma once

#include "bvh.h"
#include "lights.h"
#include "scene.h"

#include <string>

namespace bl {

// Prints the warnings that hold for the scene `name` (its file) on stderr.
void warn_about_lights(const std::string& name, const scene_data& scene, const bvh_data& bvh, const light_data& lights);

}  // namespace bl
