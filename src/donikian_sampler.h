// donikian_sampler: the image-space adaptive baseline (after Donikian et al. 2006). At the first hit of a
// pixel's paths, light clusters (one scene-wide light cut) are chosen proportionally to a blend of the pixel's
// and its 8x8 block's estimates of each cluster's contribution, the weight moving from block to pixel as the
// pixel's samples accumulate, with a minimum probability per cluster; deeper vertices use the bound sampler.
// Invariants: estimates are frozen during a pass and folded between passes in image-row order (deterministic);
// every cluster keeps probability >= min_share / clusters at first hits, so the estimator stays unbiased.
#pragma once

#include "bound_sampler.h"
#include "cut_sampling.h"

#include <vector>

namespace bl {

// Options of the Donikian baseline.
struct donikian_params {
  int block = 8;              // block side in pixels
  double pixel_half = 8;      // pixel samples at which pixel and block estimates weigh the same
  double min_share = 0.05;    // total probability spread evenly over all clusters (the minimum per cluster)
};

// Per image row during a pass: each pixel's sums of cluster contribution estimates and its sample count.
struct donikian_row {
  region_requests requests;   // for the bound sampler of deeper vertices
  int y = -1;
  std::vector<float> sum;     // width * clusters: sum of Y / P(cluster) per chosen cluster
  std::vector<float> count;   // width: first-hit NEE samples
  void clear();
};

// The Donikian sampler; owns its estimates and a bound sampler for deeper vertices.
struct donikian_sampler {
  static constexpr bool learns = true;
  static constexpr int rows_per_state = 1;  // a row state holds one image row's pixel estimates
  using context = cut_context;
  using row_state = donikian_row;
  const light_tree_data* tree = nullptr;
  const light_data* lights = nullptr;
  bound_sampler deeper;           // vertices after the first hit
  donikian_params params;
  int width = 0, height = 0;
  std::vector<int> cut;           // the scene-wide cut (sorted node ids, then sun_cluster)
  int tree_count = 0;             // tree nodes in the cut
  std::vector<float> pixel_sum;   // width * height * clusters
  std::vector<float> pixel_count; // width * height
  std::vector<float> block_sum;   // blocks * clusters
  std::vector<float> block_count; // blocks
  float sun_sin = 0, sun_cos = 1;

  int clusters() const { return int(cut.size()); }
  void locate(context& ctx, const shade_point& sp) const {
    if (sp.depth > 1) deeper.locate(ctx, sp);
  }
  void prepare(context& ctx, const shade_point& sp) const;
  light_choice sample(const context& ctx, double u, double u_inner) const {
    return sample_cut(ctx, *tree, *lights, u, u_inner);
  }
  float pmf(const context& ctx, int light) const { return cut_pmf(ctx, *tree, *lights, light); }
  void record(row_state& row, const nee_event<context>& e) const;
  void sample_done(row_state&, int, vec3f) const {}
  void learn(std::vector<row_state>& rows);
  // Scales the pixel and block estimates (sums and counts alike) by `decay`.
  void begin_frame(double decay);
};

// Builds the sampler for an image of width x height over the tree (the bound sampler's regions come ready).
donikian_sampler make_donikian_sampler(const light_tree_data& tree, const light_data& lights, bound_sampler deeper,
                                       int width, int height, const donikian_params& params,
                                       const region_params& regions, const bbox3f& scene_bounds);

}  // namespace bl
