// scene: the renderable scene — the loaded mesh plus per-triangle columns derived once, camera and sun.
// Invariants: built once, then read-only (`scene_data`). Triangle t's columns (tri_p0, tri_e1, tri_e2,
// tri_ng, tri_area) are computed in float from the mesh and are what every intersection and shading
// computation uses, so results never depend on Embree's ISA-specific arithmetic.
#pragma once

#include "math.h"
#include "obj_io.h"
#include "scene_desc.h"

#include <string>
#include <vector>

namespace bl {

// Everything the renderer reads about the scene.
struct scene_data {
  mesh_data mesh;
  std::vector<vec3f> tri_p0, tri_e1, tri_e2;  // corner 0 and edges p1-p0, p2-p0
  std::vector<vec3f> tri_ng;                  // unit geometric normal, cross(e1, e2) direction (CCW front)
  std::vector<float> tri_area;
  std::vector<uint8_t> material_emissive;     // per material: Ke non-zero
  std::vector<float> tri_extent;              // sum over axes of |normal_a| max |corner_a|, at most the largest
                                              // |corner coordinate| (ray offsets: how far the corners' rounding
                                              // moves an interpolated point off the plane)
  // Per triangle: its reversed twin (the same corners in the opposite order: the other face of a two-faced sheet,
  // e.g. a lamp emitting on both sides from two faces), or invalid_id; empty when no triangle has one.
  std::vector<int> tri_twin;
  bbox3f bounds;
  camera_params camera;
  sun_params sun;
  bool two_sided_emitters = false;
  bool has_alpha = false;                     // some material has a map_d cut-out
  bool eye_on_a_plane = false;                // the camera's eye lies on some triangle's plane (on_plane_of)
};

// Builds the scene of a scene description (loads the OBJ; frames the camera when automatic).
scene_data build_scene(const scene_desc& desc, float aspect);
// Builds a scene from an in-memory mesh (tests, generators).
scene_data build_scene(mesh_data mesh, const camera_params& camera, const sun_params& sun, bool two_sided,
                       float aspect);

// Surface point of a hit: everything shading needs, all in our own float maths.
struct surface_point {
  vec3f p;         // position
  vec3f ng;        // unit geometric normal, facing the incoming ray's origin side
  vec3f ns;        // unit shading normal, same side as ng
  vec2f uv;        // texture coordinates (0 when the mesh has none)
  int tri = invalid_id;
  int material = invalid_id;
  bool front = true;  // the ray arrived on the front (CCW) side of the triangle
};

// The point of triangle tri at barycentrics (b1, b2).
inline vec3f interpolated_point(const scene_data& scene, int tri, float b1, float b2) {
  return scene.tri_p0[size_t(tri)] + scene.tri_e1[size_t(tri)] * b1 + scene.tri_e2[size_t(tri)] * b2;
}
// The centroid of triangle tri.
inline vec3f triangle_centroid(const scene_data& scene, int tri) {
  return scene.tri_p0[size_t(tri)] + (scene.tri_e1[size_t(tri)] + scene.tri_e2[size_t(tri)]) * (1.0f / 3);
}
// Point p, at barycentrics (b1, b2) of triangle tri, seen by a ray with direction `dir`.
surface_point eval_surface(const scene_data& scene, int tri, float b1, float b2, vec3f p, vec3f dir);
// Barycentric point (b1, b2) of triangle tri seen by a ray with direction `dir`.
inline surface_point eval_surface(const scene_data& scene, int tri, float b1, float b2, vec3f dir) {
  return eval_surface(scene, tri, b1, b2, interpolated_point(scene, tri, b1, b2), dir);
}
// Texture coordinates of triangle tri at barycentrics (b1, b2) ((0, 0) without vt).
vec2f surface_uv(const scene_data& scene, int tri, float b1, float b2);
// Whether that point is a hole of its material's map_d cut-out (alpha < 0.5): no hit, no shadow, no emission.
bool alpha_hole(const scene_data& scene, int tri, float b1, float b2);

// Distance to offset a ray origin at p, a point of triangle tri, off its surface: a share of p's largest coordinate,
// and at least a share of the triangle's own coordinates along its normal (tri_extent: a point near the origin on a
// huge tilted triangle is interpolated from corners far from it and errs off its plane by their rounding; on a huge
// floor at y = 0 its y is exact). Per triangle, so that far geometry (a ground plane reaching 1e8) does not move rays
// off the small things near the origin by more than their size, nor, when the ground is also the floor, off the floor.
inline float ray_epsilon(const scene_data& scene, int tri, vec3f p) {
  return 2e-5f * std::max(max_abs_component(p), 0.5f * scene.tri_extent[size_t(tri)]);
}
// p moved off its surface along the normal n toward the side of direction d, by eps.
inline vec3f offset_along(vec3f p, vec3f n, vec3f d, float eps) {
  return dot(n, d) >= 0 ? p + n * eps : p - n * eps;
}
inline vec3f offset_ray_origin(const scene_data& scene, int tri, vec3f p, vec3f n, vec3f d) {
  return offset_along(p, n, d, ray_epsilon(scene, tri, p));
}
// The least offset off a surface: 1/20 of ray_epsilon (8 to 17 float ulps of p's largest coordinate, and 4 to 8 of
// its triangle's tri_extent: what the hit point's rounding needs; a point near the origin interpolated from corners of size 1
// errs by more than half an ulp of 1, and a floor of 0.4 ulps let a tilted tile shadow itself under a low sun). Rays start this far off (shadow rays) or count hits from this height on (continuation
// rays), so that a lamp or an occluder closer to a surface than ray_epsilon is not stepped over.
inline float min_ray_epsilon(const scene_data& scene, int tri, vec3f p) { return 0.05f * ray_epsilon(scene, tri, p); }
// Whether point q lies on the plane of triangle tri, within what rounding can put between them (a camera's first hit
// skips a triangle whose plane holds the eye: integrator.h, camera_hit).
inline bool on_plane_of(const scene_data& scene, int tri, vec3f q) {
  vec3f v = q - scene.tri_p0[size_t(tri)];
  return std::fabs(dot(scene.tri_ng[size_t(tri)], v)) <= min_ray_epsilon(scene, tri, q) + 1e-6f * max_abs_component(v);
}

}  // namespace bl
