// bvh: owns the Embree 3 device and scene; answers closest-hit and occlusion queries.
// Invariants: only hit/miss and the primitive id come from Embree (they are identical on every x86-64 CPU);
// distance, barycentrics and the point are recomputed by `intersect_triangle` in our own code (float; double for the
// point on a huge triangle), also inside the alpha cut-out filter, so images never depend on Embree's ISA-specific
// arithmetic.
#pragma once

#include "math.h"
#include "scene.h"

#include <embree3/rtcore.h>

namespace bl {

// The Embree device and scene of one scene_data (move-only; releases both on destruction).
struct bvh_data {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  const scene_data* source = nullptr;
  bvh_data() = default;
  bvh_data(const bvh_data&) = delete;
  bvh_data& operator=(const bvh_data&) = delete;
  bvh_data(bvh_data&& o) noexcept { *this = std::move(o); }
  bvh_data& operator=(bvh_data&& o) noexcept;
  ~bvh_data();
};

// Builds the acceleration structure; `scene` must outlive the result (the alpha filter reads it).
bvh_data build_bvh(const scene_data& scene);

// A closest hit: triangle, distance along the (unit) ray direction, barycentrics of corners 1 and 2, and the point.
// The point is interpolated from the corners, except on a triangle whose corners lie far beyond the ray's own scale
// (more than 16 (|org| + t)): there the corners' rounding (a ground quad reaching 1e6 around a room errs by a tenth
// of a unit at the room) would slide the point along the surface, out from under a wall or across a shadow's edge,
// so it is the ray's point on the plane of the exact corners, computed in double and rounded once.
struct hit_info {
  int tri = invalid_id;
  float t = 0, b1 = 0, b2 = 0;
  vec3f p = {0, 0, 0};
};

// Closest hit of the ray org + t*dir, t in (tnear, tmax); tri == invalid_id on a miss.
hit_info intersect(const bvh_data& bvh, vec3f org, vec3f dir, float tmax = inf_f, float tnear = 0);
// Whether anything blocks the segment org + t*dir, t in (0, tmax).
bool occluded(const bvh_data& bvh, vec3f org, vec3f dir, float tmax);

// Emitter triangles that lie on another surface: a triangle parallel to the emitter, other than the emitter's reversed
// twin (the other face of one sheet, which rays resolve), whose plane passes within rounding (min_ray_epsilon) of the
// emitter's centroid and which holds that point (not in a cut-out hole); an emitting one too. Rays meet either of two
// coincident faces (Embree reports one at the same distance), while a shadow ray ends off the emitter in front of
// both: such a lamp's light near the surface depends on the sampler and the depth (a review: 18 % less path traced
// than in direct illumination); a lamp over a lamp is sampled as both and seen as either. `emitters`: the emitting
// triangles. Returns how many emitters do, and one of them with the surface it lies on.
struct emitter_on_surface {
  int count = 0;
  int emitter = invalid_id, surface = invalid_id;
};
emitter_on_surface find_emitters_on_surfaces(const bvh_data& bvh, const scene_data& scene,
                                             const std::vector<int>& emitters);

// Our own ray/triangle distance and barycentrics (Moller-Trumbore in float), clamped onto the triangle, and the point
// (hit_info: on a triangle far larger than the ray's scale, distance and point from the exact corners' plane in double).
hit_info intersect_triangle(const scene_data& scene, int tri, vec3f org, vec3f dir);

}  // namespace bl
