// scene_checks: load-time warnings about a scene's lights (scene_checks.h).
#include "scene_checks.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace bl {

void warn_about_lights(const std::string& name, const scene_data& scene, const bvh_data& bvh, const light_data& lights) {
  if (lights.count == 0)
    std::fprintf(stderr, "%s: warning: the scene has no emitters (the image is black)\n", name.c_str());
  if (lights.tri_count > 0) {
    // Rays leave a surface by at least 1e-6 of the largest coordinate there (what the hit point's rounding needs). A
    // light whose size is below that, far from the origin, is stepped over: warn when that holds for the median
    // light (the offset over the size, per light triangle at its centroid).
    std::vector<float> ratio;
    for (int t : lights.tri) {
      vec3f c = triangle_centroid(scene, t);
      ratio.push_back(min_ray_epsilon(scene, t, c) / std::sqrt(scene.tri_area[size_t(t)]));
    }
    std::nth_element(ratio.begin(), ratio.begin() + ratio.size() / 2, ratio.end());
    if (ratio[ratio.size() / 2] >= 1)
      std::fprintf(stderr,
                   "%s: warning: the lights are so far from the origin for their size that rays leave surfaces by "
                   "%.3g times the median light's size: their light is lost (the image is too dark); move the "
                   "scene nearer the origin\n",
                   name.c_str(), double(ratio[ratio.size() / 2]));
  }
  if (lights.tri_count > 0) {
    emitter_on_surface on = find_emitters_on_surfaces(bvh, scene, lights.tri);
    if (on.count > 0) {
      const std::vector<material_data>& mats = scene.mesh.materials;
      auto material_of = [&](int t) {
        int m = scene.mesh.tri_materials[size_t(t)];
        return m >= 0 && size_t(m) < mats.size() && !mats[size_t(m)].name.empty() ? "\"" + mats[size_t(m)].name + "\""
                                                                              : std::string("the default material");
      };
      vec3f c = triangle_centroid(scene, on.emitter);
      std::fprintf(stderr,
                   "%s: warning: %d emitting triangle%s on another surface (%s at (%.6g, %.6g, %.6g) on a triangle "
                   "of %s): rays meet either of two coincident faces, so the light near that surface differs between "
                   "samplers and depths; move the emitter off the surface (by 1e-4 of the scene's size)\n",
                   name.c_str(), on.count, on.count == 1 ? " lies" : "s lie", material_of(on.emitter).c_str(), double(c.x),
                   double(c.y), double(c.z), material_of(on.surface).c_str());
    }
  }
}

}  // namespace bl
