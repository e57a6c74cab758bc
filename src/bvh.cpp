// bvh: Embree 3 device/scene set-up (Embree-owned buffers), queries, and the alpha cut-out filter.
#include "bvh.h"

#include "errors.h"
#include "texture.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <stdexcept>
#include <string>

namespace bl {

namespace {

// Embree reports errors through this callback; the message is rethrown after the failing call.
void embree_error(void* user, RTCError code, const char* str) {
  auto* msg = static_cast<std::string*>(user);
  if (msg->empty()) *msg = "Embree error " + std::to_string(int(code)) + ": " + (str ? str : "");
}

// Rejects hits on transparent texels of map_d materials (alpha < 0.5), with our own barycentrics.
void alpha_filter(const RTCFilterFunctionNArguments* args) {
  const auto* scene = static_cast<const scene_data*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; i++) {
    if (args->valid[i] != -1) continue;
    unsigned prim = RTCHitN_primID(args->hit, args->N, i);
    int material = scene->mesh.tri_materials[prim];
    if (scene->mesh.materials[material].alpha_texture == invalid_id) continue;
    vec3f org = {RTCRayN_org_x(args->ray, args->N, i), RTCRayN_org_y(args->ray, args->N, i),
                 RTCRayN_org_z(args->ray, args->N, i)};
    vec3f dir = {RTCRayN_dir_x(args->ray, args->N, i), RTCRayN_dir_y(args->ray, args->N, i),
                 RTCRayN_dir_z(args->ray, args->N, i)};
    hit_info h = intersect_triangle(*scene, int(prim), org, dir);
    if (alpha_hole(*scene, int(prim), h.b1, h.b2)) args->valid[i] = 0;
  }
}

}  // namespace

bvh_data& bvh_data::operator=(bvh_data&& o) noexcept {
  std::swap(device, o.device);
  std::swap(scene, o.scene);
  std::swap(source, o.source);
  return *this;
}

bvh_data::~bvh_data() {
  if (scene) rtcReleaseScene(scene);
  if (device) rtcReleaseDevice(device);
}

bvh_data build_bvh(const scene_data& s) {
  bvh_data b;
  b.source = &s;
  // Default device config: thread count stays TBB's (a "threads=" setting would cap the whole process).
  b.device = rtcNewDevice(nullptr);
  if (!b.device) throw std::runtime_error("cannot create the Embree device (error " +
                                          std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
  std::string error;
  rtcSetDeviceErrorFunction(b.device, embree_error, &error);
  b.scene = rtcNewScene(b.device);
  rtcSetSceneBuildQuality(b.scene, RTC_BUILD_QUALITY_MEDIUM);
  // Robust (watertight) triangle tests: by default rays fell through the shared edge of two triangles where the
  // edge's float test rounds both ways (a review: a ground quad of side 2e6 lost 81 camera pixels along its diagonal,
  // 2e7 486 of 7168, and shadow rays leak the same way). No measurable cost here (medians of 3 alternating renders:
  // living room direct uniform 1.91 / 1.96 s, hall path bound 2.93 / 2.87, plant room path bayes 1.94 / 1.75 s).
  rtcSetSceneFlags(b.scene, RTC_SCENE_FLAG_ROBUST);
  const mesh_data& m = s.mesh;
  int n = triangle_count(m);
  if (n > 0) {
    RTCGeometry geom = rtcNewGeometry(b.device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                           3 * sizeof(float), m.positions.size()));
    auto* ib = static_cast<unsigned*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), n));
    if (!vb || !ib) throw std::runtime_error("Embree could not allocate geometry buffers: " + error);
    for (size_t i = 0; i < m.positions.size(); i++) {
      vb[3 * i + 0] = m.positions[i].x;
      vb[3 * i + 1] = m.positions[i].y;
      vb[3 * i + 2] = m.positions[i].z;
    }
    for (size_t i = 0; i < size_t(3) * n; i++) ib[i] = unsigned(m.tri_positions[i]);
    if (s.has_alpha) {
      rtcSetGeometryUserData(geom, const_cast<scene_data*>(&s));
      rtcSetGeometryIntersectFilterFunction(geom, alpha_filter);
      rtcSetGeometryOccludedFilterFunction(geom, alpha_filter);
    }
    rtcCommitGeometry(geom);
    rtcAttachGeometry(b.scene, geom);
    rtcReleaseGeometry(geom);
  }
  // Embree's commit sets flush-to-zero and denormals-are-zero on this thread while it builds; where that is the
  // thread's first use of TBB, TBB's implicit arena captures them, and every later parallel_for outside an explicit
  // arena (bayes' learning between passes, the regions' set-up) ran with them while the passes (their own arena) did
  // not: a prior mean below FLT_MIN became 0 there and its cluster unchoosable. Join TBB first, in this thread's mode.
  tbb::parallel_for(0, 1, [](int) {});
  rtcCommitScene(b.scene);
  if (!error.empty()) throw std::runtime_error(error);
  rtcSetDeviceErrorFunction(b.device, nullptr, nullptr);
  return b;
}

hit_info intersect_triangle(const scene_data& s, int tri, vec3f org, vec3f dir) {
  vec3f e1 = s.tri_e1[tri], e2 = s.tri_e2[tri];
  vec3f pvec = cross(dir, e2);
  float det = dot(e1, pvec);
  hit_info h;
  h.tri = tri;
  if (det == 0 || !std::isfinite(det)) {
    // Ray in the triangle's plane (Embree still reported a hit): take the centroid at its projection.
    vec3f c = s.tri_p0[tri] + (e1 + e2) * (1.0f / 3.0f);
    h.t = std::max(0.0f, dot(c - org, dir));
    h.b1 = h.b2 = 1.0f / 3.0f;
    h.p = interpolated_point(s, tri, h.b1, h.b2);
    return h;
  }
  float inv = 1.0f / det;
  vec3f tvec = org - s.tri_p0[tri];
  float b1 = dot(tvec, pvec) * inv;
  vec3f qvec = cross(tvec, e1);
  float b2 = dot(dir, qvec) * inv;
  float t = dot(e2, qvec) * inv;
  // Clamp onto the triangle: Embree's watertight test may accept hits our float test puts just outside.
  b1 = std::max(b1, 0.0f);
  b2 = std::max(b2, 0.0f);
  float sum = b1 + b2;
  if (sum > 1) {
    b1 /= sum;
    b2 /= sum;
  }
  h.t = std::max(t, 0.0f);
  h.b1 = b1;
  h.b2 = b2;
  // (see hit_info: 16 times the ray's scale; in scenes of ordinary proportions every point is interpolated)
  const vec3f p0 = s.tri_p0[tri];
  const float corners = std::max({max_abs_component(p0), max_abs_component(p0 + e1), max_abs_component(p0 + e2)});
  if (corners > 16 * (max_abs_component(org) + h.t)) {
    // The ray's distance to the plane of the triangle's exact corners and its point there, in double (each operation
    // rounds at double precision), then rounded to float: the float t above errs with the corners' rounding too (0.03
    // along the ray at a room on a ground quad of 1e6 tilted 30 degrees).
    vec3f c[3];
    for (int k = 0; k < 3; k++) c[k] = s.mesh.positions[size_t(s.mesh.tri_positions[3 * size_t(tri) + size_t(k)])];
    double e[2][3], n[3], w[3];
    for (int a = 0; a < 3; a++) {
      e[0][a] = double(c[1][a]) - double(c[0][a]);
      e[1][a] = double(c[2][a]) - double(c[0][a]);
      w[a] = double(c[0][a]) - double(org[a]);
    }
    n[0] = e[0][1] * e[1][2] - e[0][2] * e[1][1];
    n[1] = e[0][2] * e[1][0] - e[0][0] * e[1][2];
    n[2] = e[0][0] * e[1][1] - e[0][1] * e[1][0];
    const double nd = n[0] * double(dir.x) + n[1] * double(dir.y) + n[2] * double(dir.z);
    const double t = nd != 0 ? std::max((n[0] * w[0] + n[1] * w[1] + n[2] * w[2]) / nd, 0.0) : double(h.t);
    h.t = float(t);
    h.p = {float(double(org.x) + double(dir.x) * t), float(double(org.y) + double(dir.y) * t),
           float(double(org.z) + double(dir.z) * t)};
  } else {
    h.p = interpolated_point(s, tri, b1, b2);
  }
  return h;
}

namespace {

struct on_surface_query {
  const scene_data* scene;
  int emitter;
  vec3f c;     // the emitter's centroid
  float tol;   // how far from a plane c still lies on it
  int found = invalid_id;
};

// rtcPointQuery's callback, for each triangle whose bounds reach the query sphere.
bool on_surface_candidate(RTCPointQueryFunctionArguments* args) {
  auto* q = static_cast<on_surface_query*>(args->userPtr);
  const int t = int(args->primID);
  const scene_data& s = *q->scene;
  // (Another emitter too: a lamp drawn over a lamp is sampled as both while a ray meets either.)
  if (q->found != invalid_id || t == q->emitter) return false;
  // The emitter's reversed twin (a lamp written back to back with a face of another material) is the other face of
  // one sheet: a ray meets the face turned toward it (intersect), nothing random there.
  if (!s.tri_twin.empty() && (s.tri_twin[size_t(q->emitter)] == t || s.tri_twin[size_t(t)] == q->emitter)) return false;
  const vec3f n = s.tri_ng[size_t(t)], v = q->c - s.tri_p0[size_t(t)];
  if (std::fabs(dot(n, s.tri_ng[size_t(q->emitter)])) < 0.9999f || std::fabs(dot(n, v)) > q->tol) return false;
  // c's barycentrics in t's plane.
  const vec3f e1 = s.tri_e1[size_t(t)], e2 = s.tri_e2[size_t(t)];
  const float d11 = dot(e1, e1), d12 = dot(e1, e2), d22 = dot(e2, e2), v1 = dot(v, e1), v2 = dot(v, e2);
  const float den = d11 * d22 - d12 * d12;
  if (!(den > 0)) return false;
  const float b1 = (d22 * v1 - d12 * v2) / den, b2 = (d11 * v2 - d12 * v1) / den;
  if (!(b1 >= 0 && b2 >= 0 && b1 + b2 <= 1) || alpha_hole(s, t, b1, b2)) return false;
  q->found = t;
  return false;  // (the query's radius is unchanged)
}

}  // namespace

emitter_on_surface find_emitters_on_surfaces(const bvh_data& bvh, const scene_data& scene,
                                             const std::vector<int>& emitters) {
  // One query per emitter, in parallel (an emitter inside a fan of 16000 triangles meets them all: 100000 such lamps
  // took 10.7 s on 2 threads); the first in emitter order is the one named.
  std::vector<int> found(emitters.size(), invalid_id);
  tbb::parallel_for(size_t(0), emitters.size(), [&](size_t i) {
    const int e = emitters[i];
    on_surface_query q{&scene, e, {}, 0};
    q.c = triangle_centroid(scene, e);
    q.tol = min_ray_epsilon(scene, e, q.c);
    RTCPointQuery pq;
    pq.x = q.c.x, pq.y = q.c.y, pq.z = q.c.z;
    pq.time = 0;
    pq.radius = q.tol;
    RTCPointQueryContext ctx;
    rtcInitPointQueryContext(&ctx);
    rtcPointQuery(bvh.scene, &pq, &ctx, on_surface_candidate, &q);
    found[i] = q.found;
  });
  emitter_on_surface r;
  for (size_t i = 0; i < emitters.size(); i++)
    if (found[i] != invalid_id && r.count++ == 0) r.emitter = emitters[i], r.surface = found[i];
  return r;
}

hit_info intersect(const bvh_data& b, vec3f org, vec3f dir, float tmax, float tnear) {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRayHit rh;
  rh.ray.org_x = org.x;
  rh.ray.org_y = org.y;
  rh.ray.org_z = org.z;
  rh.ray.tnear = tnear;
  rh.ray.dir_x = dir.x;
  rh.ray.dir_y = dir.y;
  rh.ray.dir_z = dir.z;
  rh.ray.time = 0;
  rh.ray.tfar = tmax;
  rh.ray.mask = 0xffffffffu;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(b.scene, &ctx, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return {};
  int tri = int(rh.hit.primID);
  const scene_data& s = *b.source;
  hit_info h = intersect_triangle(s, tri, org, dir);
  // Of two faces of one sheet (reversed twins, at the same distance), the ray meets the one facing it: Embree
  // reports either, and from its back a lamp's face would be black while its twin emits toward the ray. Not where
  // the twin has a hole of its cut-out (the filter passed the ray through it to this face).
  if (!s.tri_twin.empty() && s.tri_twin[size_t(tri)] != invalid_id && dot(s.tri_ng[size_t(tri)], dir) > 0) {
    hit_info w = intersect_triangle(s, s.tri_twin[size_t(tri)], org, dir);
    if (!(s.has_alpha && alpha_hole(s, w.tri, w.b1, w.b2))) h = w;
  }
  return h;
}

bool occluded(const bvh_data& b, vec3f org, vec3f dir, float tmax) {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRay r;
  r.org_x = org.x;
  r.org_y = org.y;
  r.org_z = org.z;
  r.tnear = 0;
  r.dir_x = dir.x;
  r.dir_y = dir.y;
  r.dir_z = dir.z;
  r.time = 0;
  r.tfar = tmax;
  r.mask = 0xffffffffu;
  r.id = 0;
  r.flags = 0;
  rtcOccluded1(b.scene, &ctx, &r);
  return r.tfar < 0;  // Embree sets tfar to -inf when the segment is blocked
}

}  // namespace bl
