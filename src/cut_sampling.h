// cut_sampling: light selection over a region's light cut, shared by the bound and bayes samplers.
// A shading point finds its region (the finest existing one), weighs the clusters of the region's cut, picks a
// cluster from the normalised weights, then a light inside the cluster by descending the tree proportionally to
// intensity. Invariants: the context holds the cdf it sampled from, so pmf(light) is exactly the probability
// sample() returned; a cluster's weight is 0 only when none of its lights can reach the point.
#pragma once

#include "light_sampler_types.h"
#include "light_tree.h"
#include "lights.h"
#include "region_grid.h"

#include <algorithm>
#include <cstdint>
#include <vector>

namespace bl {

// Largest cut a region may have (clusters, the sun included).
constexpr int max_cut_entries = 1025;

// Per shading point: its region and cut and the cdf over the cut's clusters.
struct cut_context {
  vec3f p, n;
  float albedo = 0;
  int pixel = invalid_id;      // (samplers that learn per pixel)
  uint64_t fine_key = ~uint64_t(0);  // the cell key looked up (fine, or coarse for deep vertices); ~0: none yet
  int region = 0;
  uint64_t region_key = 0;     // key of `region` (differs from fine_key while the fine cell has no region yet)
  int pair_base = 0;           // the region's first (region, cluster) pair
  int count = 0;               // clusters in the cut
  int tree_count = 0;          // of which tree nodes (the sun, if any, is last)
  const int* nodes = nullptr;  // the cut's node ids
  // The region's cut as located (bayes may weigh a point over the members instead: count, tree_count and nodes then
  // describe the members, each its own cluster, for that point only).
  int cut_count = 0, cut_tree_count = 0;
  const int* cut_nodes = nullptr;
  // Members (region_state): the region's member count (= pairs), their nodes, each cluster's first member, and
  // the cut's first column index (the region's cut_offset: group columns are indexed by it plus the cluster).
  int pair_count = 0;
  const int* members = nullptr;
  const int* member_begin = nullptr;
  int group_base = 0;
  const float* member_w = nullptr;  // bayes: the members' weight column a point chose from (inside a cluster)
  const float* group_w = nullptr;   // bayes: the clusters' column it weighed them by (their members' summed weights)
  const double* group_total = nullptr;  // bayes: per cluster, the members' total a member is chosen from
  double cdf[max_cut_entries + 1];
  // Control variates (bayes): whether they apply at this point, sum_j colour_j c_j and c_j per cluster, with c_j
  // the learned mean of cluster j's albedo-free sample (the integrator scales by (kd + ks) / pi).
  bool cv = false;
  vec3f cv_sum = {0, 0, 0};
  float cvg[max_cut_entries + 3];
  // The point factor of each cluster (bayes, region prior): 1 / d^2 times the receiver's cosine bound toward the
  // cluster; 0 behind the surface. A sample z = Y / factor is what the pair's statistics learn.
  float gfac[max_cut_entries + 3];
  // Recording cache (bayes): the row state's block of accumulators of the current region, valid while the same row
  // state (and generation of it) and region are recorded into.
  mutable const void* rec_owner = nullptr;
  mutable uint64_t rec_generation = 0;
  mutable int rec_base = -1;
  mutable int rec_block = 0;
};

// Fills the point and region part of a context. The region part is kept while the cell stays the same (contexts
// live for one pass, during which regions do not change).
// `cut_only`: the caller reads only the region's cut (the bound sampler), so with a shared cut the root serves.
void locate_region(cut_context& ctx, const region_state& regions, const shade_point& sp, bool cut_only = false);

// Bound-based weight of cluster `node` (a tree node or sun_cluster) at (p, n): its importance, as a
// distance-free numerator and inv_d2 = 1 / d^2 of the regression distance (1 for the sun).
inline float cluster_bound_parts(const light_tree_data& tree, const light_data& lights, int node, vec3f p, vec3f n,
                                 float sun_sin, float sun_cos, float& inv_d2) {
  if (node == sun_cluster) {
    inv_d2 = 1;
    return luminance(lights.sun_irradiance) * receiver_cos_bound(n, lights.sun_dir, sun_sin, sun_cos);
  }
  return node_importance_parts(tree, node, p, n, inv_d2);
}
inline float cluster_bound(const light_tree_data& tree, const light_data& lights, int node, vec3f p, vec3f n,
                           float sun_sin, float sun_cos) {
  float inv_d2;
  return cluster_bound_parts(tree, lights, node, p, n, sun_sin, sun_cos, inv_d2) * inv_d2;
}
// Distance used by the regression for a cluster: to its box centre, clamped below by its radius (sun: 1).
inline float cluster_distance(const light_tree_data& tree, int node, vec3f p) {
  if (node == sun_cluster) return 1;
  return std::max(length(p - node_center(tree, node)), node_radius(tree, node));
}

// Normalises non-negative weights (in cut order, positive ones floored as in fill_cdf) into ctx.cdf; false when
// no weight is positive and finite.
bool finish_cdf(cut_context& ctx, const double* weights);
// Probability of cluster j.
inline double cluster_pmf(const cut_context& ctx, int j) { return ctx.cdf[j + 1] - ctx.cdf[j]; }

// u's place inside a cell [lo, lo + width) that holds it, as a uniform in [0, 1): a stratified u stays stratified
// over what the cell's choice samples next. A cell narrower than 2^-20 leaves too few of u's 53 bits for a further
// descent: it takes `fresh` (an independent uniform) instead. Either way the result is uniform given the cell.
inline double place_in_cell(double u, double lo, double width, double fresh) {
  if (!(width >= 0x1p-20)) return fresh;
  return std::clamp((u - lo) / width, 0.0, 0x1.fffffffffffffp-1);
}

// Picks a cluster with u and a light inside it by intensity, from u's place inside the cluster's cell (u_inner for a
// cluster below 2^-20: place_in_cell).
light_choice sample_cut(const cut_context& ctx, const light_tree_data& tree, const light_data& lights, double u,
                        double u_inner);
// Index in the sorted node list [begin, end) of the node holding `leaf` (itself or an ancestor), or -1.
int holding_entry(const light_tree_data& tree, int leaf, const int* begin, const int* end);
// Probability that sample_cut picks `light`.
float cut_pmf(const cut_context& ctx, const light_tree_data& tree, const light_data& lights, int light);

// Fine region keys requested by one image row (NEE events at points whose fine region does not exist yet), as
// runs of (key, count).
struct region_requests {
  std::vector<uint64_t> keys;
  std::vector<uint32_t> counts;
  void clear() {
    keys.clear();
    counts.clear();
  }
  void add(const cut_context& ctx) {
    if (ctx.region_key == ctx.fine_key) return;
    if (!keys.empty() && keys.back() == ctx.fine_key) {
      counts.back()++;
      return;
    }
    keys.push_back(ctx.fine_key);
    counts.push_back(1);
  }
};
// Adds the rows' requests to the pending counts and creates the fine regions whose count reached
// region_params::min_samples, in key order (so the result does not depend on thread timing).
int create_requested_regions(region_state& regions, const light_tree_data& tree,
                             const std::vector<const region_requests*>& rows);

// The sun's half-angle as (sin, cos) for cos bounds.
void sun_half_angle(const light_data& lights, float& sin_out, float& cos_out);

}  // namespace bl
