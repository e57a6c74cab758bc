// lights: the emitters of a scene — every triangle with non-zero Ke, and the sun — as flat columns.
// Invariants: light ids are dense: 0..tri_count-1 are emissive triangles in scene triangle order, the sun
// (if any) is id tri_count. Point sampling and its pdf sit side by side; pdfs are solid angle at the
// shading point. A sample that cannot contribute (behind a one-sided emitter, zero distance) has pdf 0.
#pragma once

#include "math.h"
#include "scene.h"

#include <vector>

namespace bl {

// All emitters of a scene.
struct light_data {
  std::vector<int> tri;         // per emissive triangle: scene triangle
  std::vector<vec3f> radiance;  // per emissive triangle: Le
  std::vector<float> power;     // per light (sun included): luminance power, for the power sampler
  std::vector<int> light_of_tri;  // per scene triangle: its light id or invalid_id
  int tri_count = 0;            // emissive triangles
  int count = 0;                // tri_count + (sun ? 1 : 0)
  bool two_sided = false;
  // Per triangle light, with two_sided: it emits from its front only (a face with a reversed twin, scene.h);
  // empty when none does.
  std::vector<uint8_t> front_only;
  // The sun: a distant disk of uniform radiance seen under half-angle theta_max.
  int sun = invalid_id;         // its light id, or invalid_id
  vec3f sun_dir;                // unit, from the scene toward the sun
  vec3f sun_radiance;           // irradiance / (pi sin^2 theta_max)
  vec3f sun_irradiance;
  float sun_one_minus_cos = 0;  // 1 - cos(theta_max)
  frame3f sun_frame;
};

// Collects the emitters of a scene.
light_data build_lights(const scene_data& scene);
// Points the sun (if any) along `direction` as a scene file states it (normalised exactly as loading and
// build_lights do), keeping everything else; for animations.
void set_sun_direction(light_data& lights, vec3f direction);

// A point (or, for the sun, a direction) sampled on one light as seen from a shading point.
struct light_sample {
  vec3f wi;                 // unit direction from the shading point toward the light
  float dist = inf_f;       // distance to the sampled point (inf for the sun)
  vec3f le;                 // radiance arriving along -wi
  float pdf = 0;            // solid-angle pdf given the light; 0 = no possible contribution
  vec3f p, n;               // the point and the emitter's geometric normal (triangles only)
  int tri = invalid_id;     // the emitter's triangle (invalid for the sun)
};

// Samples a point of light `light` seen from x with uniforms (u, v). A triangle that x sees under a solid angle of
// at least spherical_min_solid_angle is sampled uniformly in that solid angle (Arvo 1995: pdf 1 / omega, so the
// estimate carries neither the 1/d^2 nor the emitter's cosine, which uniform points spread over orders of magnitude
// for a point close to a large emitter); any other triangle uniformly by area (pdf d^2 / (cos_l area)).
light_sample sample_light_point(const light_data& lights, const scene_data& scene, int light, vec3f x, float u,
                                float v);

// Where solid-angle sampling starts: a sample costs about 160 ns more by solid angle than by area (BM_light_point),
// and below 0.1 sr the 1/d^2 and cosine of a uniform point on a triangle vary little unless it is nearly edge-on (the
// relative variance of one area sample's irradiance stays under a few percent face-on). In a room lit by panels near
// its surfaces, 0.1 sr gave a lower relMSE at equal time than 0.3 (by 1.2x with bound, 1.6x with bayes) and about
// the same as 0.03, which also samples most of the Cornell box's points by solid angle for no gain. Where it ends:
// within spherical_max_gap of 2 pi (a point a hair above a triangle's inside, the spherical triangle nearly a
// hemisphere, its angles all near pi) the float sine and cosine of the sampled area leave the warp too little
// precision: area sampling again (unbiased, but heavy-tailed there). The warp matched Lambert's formula up to
// 2 pi - 0.0014 (1e-4 under a 1 m triangle).
inline constexpr float spherical_min_solid_angle = 0.1f;
inline constexpr float spherical_max_gap = 0.001f;
inline constexpr float spherical_max_solid_angle = 2 * pi_f - spherical_max_gap;
// The rule compares the thresholds' half-angle tangents (no arctangent for a triangle it leaves to area sampling):
// tan(spherical_min_solid_angle / 2) and tan(spherical_max_gap / 2).
inline constexpr float spherical_min_tan_half = 0.050041708375538792f;
inline constexpr float spherical_max_cot_half = 0.00050000004166667088f;

// The solid angle under which x sees scene triangle t when it is to be sampled by solid angle from x (between
// spherical_min_solid_angle and spherical_max_solid_angle, and x not within a sliver's width of two of its edge
// lines: lights.cpp), else 0. A function of x and t alone, so that sampling and the pdf a BSDF hit evaluates for MIS
// always agree.
float spherical_solid_angle(const scene_data& scene, int t, vec3f x);

// Solid-angle pdf of a uniform point on a triangle of area `area` at distance dist, emitter cosine cos_l > 0.
inline float triangle_area_pdf(float area, float dist, float cos_l) {
  return area > 0 ? dist * dist / (cos_l * area) : 0;
}

// Solid-angle pdf of sampling, from x, the point of triangle light `light` at distance dist whose emitter cosine is
// cos_l (the emitting side's; 0 or less: none).
inline float triangle_light_pdf(const scene_data& scene, const light_data& lights, int light, vec3f x, float dist,
                                float cos_l) {
  if (!(cos_l > 0)) return 0;
  int t = lights.tri[light];
  float omega = spherical_solid_angle(scene, t, x);
  if (omega > 0) return 1 / omega;
  return triangle_area_pdf(scene.tri_area[t], dist, cos_l);
}
// Radiance an emissive triangle sends toward a ray that hit its front (front=true) or back side.
inline bool emits_both_sides(const light_data& lights, int light) {
  return lights.two_sided && (lights.front_only.empty() || !lights.front_only[size_t(light)]);
}
inline vec3f emitted_radiance(const light_data& lights, int light, bool front) {
  return front || emits_both_sides(lights, light) ? lights.radiance[light] : vec3f{0, 0, 0};
}
// Whether a direction (unit length) lies inside the sun's disk: |dir - sun_dir|^2 = 2 (1 - cos) for unit vectors,
// without the cancellation of 1 - dot near 1 (which took every direction within 2.4e-4 rad for a disk of 0.01
// degrees, 170 times its solid angle, while NEE samples the true cone).
inline bool in_sun_disk(const light_data& lights, vec3f dir) {
  if (lights.sun == invalid_id) return false;
  vec3f d = dir - lights.sun_dir;
  return dot(d, d) <= 2 * lights.sun_one_minus_cos;
}

}  // namespace bl
