// light_tree: a binary BVH over the emissive triangles storing, per node, the luminous intensity
// (sum of luminance(Le) * area), the bounding box and the cone bounding the emitters' normals (Conty
// Estevez & Kulla 2018). The sun is not in the tree: samplers treat it as a cluster of its own.
// Invariants: built deterministically (binned surface-area-orientation heuristic, ties broken by index);
// node 0 is the root; every interior node has two children; leaves hold exactly one light; parent[root]
// is invalid_id. Also holds the importance / bound functions that light selection evaluates on nodes.
#pragma once

#include "lights.h"
#include "math.h"

#include <vector>

namespace bl {

// Depth limits: SAOH splits down to max_sah_depth, median splits below (at most 2^40 lights fit).
constexpr int max_sah_depth = 64;
constexpr int max_tree_depth = 104;

// Per node, the 12 floats an importance evaluation reads, packed so that one node is one gather: the box centre,
// half the box diagonal, the normal cone's unit axis and the cosine and sine of its half-angle theta_o (-1 and 0
// at theta_o = pi: any normal), and the intensity (sum of luminance(Le) * area of the node's emitters). The only
// copy of these values (read them through the node_* accessors below).
struct node_pack {
  float cx, cy, cz, r, ax, ay, az, cos_o, sin_o, intensity, pad0, pad1;
};

// The tree as flat columns indexed by node id.
struct light_tree_data {
  std::vector<vec3f> lo, hi;          // bounding box
  std::vector<node_pack> packed;      // centre, radius, normal cone, intensity (see node_pack)
  std::vector<int> left, right;       // children (invalid_id for leaves)
  std::vector<int> parent;
  std::vector<int> light;             // leaf: its light id; interior: invalid_id
  std::vector<int> leaf_of_light;     // per triangle light id: its leaf node
  std::vector<double> left_prob;      // interior: probability of the left child when descending by intensity
  std::vector<vec3f> color;           // emission colour: RGB intensity / luminance intensity (luminance 1); empty
                                      // when built without colours
  bool two_sided = false;
  int depth = 0;                      // longest root-to-leaf path (edges)
};

inline vec3f node_center(const light_tree_data& t, int node) {
  const node_pack& q = t.packed[size_t(node)];
  return {q.cx, q.cy, q.cz};
}
inline float node_radius(const light_tree_data& t, int node) { return t.packed[size_t(node)].r; }
inline vec3f node_axis(const light_tree_data& t, int node) {
  const node_pack& q = t.packed[size_t(node)];
  return {q.ax, q.ay, q.az};
}
inline float node_cos_o(const light_tree_data& t, int node) { return t.packed[size_t(node)].cos_o; }
inline float node_sin_o(const light_tree_data& t, int node) { return t.packed[size_t(node)].sin_o; }
inline float node_intensity(const light_tree_data& t, int node) { return t.packed[size_t(node)].intensity; }

inline int node_count(const light_tree_data& t) { return int(t.light.size()); }
inline bool is_leaf(const light_tree_data& t, int node) { return t.light[size_t(node)] != invalid_id; }

// Builds the tree over the triangle lights of `lights` (empty tree when there are none). `colors`: also the emission
// colour column, which only the bayes sampler reads (12 bytes per node, and the pass that sums it).
light_tree_data build_light_tree(const light_data& lights, const scene_data& scene, bool colors = true);

// cos(max(0, a - b)) for angles given by (sin, cos), the clamped difference of pbrt-v4's light bounds.
inline float cos_sub_clamped(float sin_a, float cos_a, float sin_b, float cos_b) {
  return cos_a >= cos_b ? 1.0f : cos_a * cos_b + sin_a * sin_b;
}
inline float sin_sub_clamped(float sin_a, float cos_a, float sin_b, float cos_b) {
  return cos_a >= cos_b ? 0.0f : sin_a * cos_b - cos_a * sin_b;
}

// Upper bound of the emitter cosine (at the light) over every emitter of a node and every receiver
// direction within half-angle theta_b (given by sin_b, cos_b) of the unit direction w from the node's centre
// to the receiver. Zero when no emitter of the node can face any such receiver.
inline float node_emitter_cos_bound(const light_tree_data& t, int node, vec3f w, float sin_b, float cos_b) {
  const node_pack& q = t.packed[size_t(node)];
  float cos_w = dot(vec3f{q.ax, q.ay, q.az}, w);
  if (t.two_sided) cos_w = std::fabs(cos_w);
  float sin_w = safe_sqrt(1 - cos_w * cos_w);
  float co = q.cos_o, so = q.sin_o;
  float cos_wo = cos_sub_clamped(sin_w, cos_w, so, co);
  float sin_wo = sin_sub_clamped(sin_w, cos_w, so, co);
  float c = cos_sub_clamped(sin_wo, cos_wo, sin_b, cos_b);
  return c > 0 ? c : 0.0f;  // emitters radiate into their front hemisphere only (theta_e = pi / 2)
}

// Conservative receiver-side cosine bound: the receiver normal n against directions toward the node
// (unit w_to from the receiver to the centre) widened by theta_b.
inline float receiver_cos_bound(vec3f n, vec3f w_to, float sin_b, float cos_b) {
  float cos_i = dot(n, w_to);
  float sin_i = safe_sqrt(1 - cos_i * cos_i);
  float c = cos_sub_clamped(sin_i, cos_i, sin_b, cos_b);
  return c > 0 ? c : 0.0f;
}

// Importance of a node for a shading point (p, n) — an estimate of the unoccluded irradiance it can give:
// intensity * emitter cos bound * receiver cos bound / d^2, d the distance to the box centre clamped below by
// the box radius (Conty-Kulla / pbrt-v4 style). Zero only when the node provably cannot light the point.
// Returned in two parts: the distance-free numerator, and inv_d2 = 1 / d^2 (the regression's distance term).
inline float node_importance_parts(const light_tree_data& t, int node, vec3f p, vec3f n, float& inv_d2) {
  const node_pack& q = t.packed[size_t(node)];
  vec3f to_p = p - vec3f{q.cx, q.cy, q.cz};
  float d2 = length_sq(to_p);
  float r = q.r;
  inv_d2 = 1 / std::max(d2, r * r);
  float d = std::sqrt(d2);
  // Angle subtended by the node's bounding sphere seen from p (theta_b = pi inside it).
  float sin_b = 0, cos_b = -1;
  if (d > r) {
    sin_b = r / d;
    cos_b = safe_sqrt(1 - sin_b * sin_b);
  }
  vec3f w = d > 0 ? to_p / d : vec3f{0, 0, 1};
  float ce = node_emitter_cos_bound(t, node, w, sin_b, cos_b);
  if (ce == 0) return 0;
  float cr = receiver_cos_bound(n, -w, sin_b, cos_b);
  return q.intensity * ce * cr;
}
inline float node_importance(const light_tree_data& t, int node, vec3f p, vec3f n) {
  float inv_d2;
  float num = node_importance_parts(t, node, p, n, inv_d2);
  return num * inv_d2;
}

// Conservative bound of a node's unoccluded irradiance anywhere in the box [lo, hi] (any receiver normal):
// intensity * emitter cos bound over directions between the two boxes / squared box-to-box distance
// (clamped below by the square of the region's half diagonal so that nearby nodes rank first, not infinitely).
float node_region_bound(const light_tree_data& t, int node, vec3f lo, vec3f hi);
// The distance-free part of that bound: intensity * emitter cos bound over the directions between the node's and
// the box's bounding spheres; E d^2 of a receiver facing the node (E its irradiance, d the distance to the node's
// centre) is about this or less. The region-level prior mean of the bayes sampler.
float node_region_intensity(const light_tree_data& t, int node, vec3f lo, vec3f hi);

// Probability of the left child when descending by weights (il, ir): il / (il + ir) in double, kept inside
// [min_positive_share, 1 - min_positive_share] when both are positive so that no positive child starves.
inline double left_share(double il, double ir) {
  if (!(il + ir > 0)) return 0.5;
  double pl = il / (il + ir);
  if (il > 0 && ir > 0) pl = std::min(std::max(pl, 0x1p-40), 1 - 0x1p-40);
  return pl;
}

// Probability that descending from `node` proportionally to intensity reaches leaf `leaf` (product of
// the intensity ratios on the way; exactly what sample_by_intensity realises).
double intensity_descent_pmf(const light_tree_data& t, int node, int leaf);
// Descends from `node` to a leaf choosing children proportionally to intensity with uniform u (rescaled
// at every level); returns the leaf node and writes the probability of the path.
int sample_by_intensity(const light_tree_data& t, int node, double u, double& prob);

}  // namespace bl
