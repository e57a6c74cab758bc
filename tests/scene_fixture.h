// scene_fixture: in-memory scenes for the tests of samplers and the integrator, built the way the renderer builds
// a loaded one (scene, BVH, lights, light tree), and the random points and directions the tests scatter over them.
#pragma once

#include "bvh.h"
#include "integrator.h"
#include "light_tree.h"
#include "lights.h"
#include "rng.h"
#include "scene.h"

#include <memory>

namespace bl::test {

// A scene and everything a sampler needs; heap-held, since bvh_data and render_inputs point into it.
struct test_scene {
  scene_data scene;
  bvh_data bvh;
  light_data lights;
  light_tree_data tree;
  render_inputs in;
};

// A camera at `eye` looking at `target` (not framed automatically).
inline camera_params fixed_camera(vec3f eye, vec3f target, float fov_y_deg = 45, vec3f up = {0, 1, 0}) {
  camera_params c;
  c.automatic = false;
  c.eye = eye;
  c.target = target;
  c.up = up;
  c.fov_y_deg = fov_y_deg;
  return c;
}

// A sun from `direction` (normalised here) with irradiance `e`.
inline sun_params test_sun(vec3f direction, vec3f e) {
  sun_params s;
  s.enabled = true;
  s.direction = normalize(direction);
  s.irradiance = e;
  return s;
}

// Builds `mesh` one-sided with the given camera and sun; `in` points at the result, with the camera at
// image × image pixels and render_inputs' defaults otherwise.
inline std::unique_ptr<test_scene> build_test_scene(mesh_data mesh, const camera_params& cam,
                                                    const sun_params& sun = {}, int image = 8) {
  auto t = std::make_unique<test_scene>();
  t->scene = build_scene(std::move(mesh), cam, sun, false, 1.0f);
  t->bvh = build_bvh(t->scene);
  t->lights = build_lights(t->scene);
  t->tree = build_light_tree(t->lights, t->scene);
  t->in.scene = &t->scene;
  t->in.bvh = &t->bvh;
  t->in.lights = &t->lights;
  t->in.camera = make_camera(t->scene.camera, image, image);
  return t;
}

// Float random numbers for scattering test geometry: uniform in [0, 1), log-uniform in [lo, hi), a uniform
// direction, a uniform point in a box.
inline float unif(pcg32& r) { return uint_to_unit(r()); }
// A 53-bit uniform from two draws, as the integrator gives a light sampler (vertex_randoms::u53): a cluster's choice
// leaves its rescaled u to the descent inside it, which needs more bits than a float has.
inline double unif53(pcg32& r) {
  vertex_randoms v;
  v.raw[dim_light_select] = r();
  v.raw[dim_light_select_lo] = r();
  return v.u53(dim_light_select, dim_light_select_lo);
}
inline float log_uniform(pcg32& r, float lo, float hi) { return lo * std::pow(hi / lo, unif(r)); }
inline vec3f random_unit(pcg32& r) {
  float z = 1 - 2 * unif(r), phi = 2 * pi_f * unif(r);
  float s = safe_sqrt(1 - z * z);
  return {s * std::cos(phi), s * std::sin(phi), z};
}
inline vec3f random_in(pcg32& r, vec3f lo, vec3f hi) {
  return {lo.x + (hi.x - lo.x) * unif(r), lo.y + (hi.y - lo.y) * unif(r), lo.z + (hi.z - lo.z) * unif(r)};
}

}  // namespace bl::test
