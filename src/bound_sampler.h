// bound_sampler: the paper's non-adaptive baseline (after Wang et al. 2009) — per region, the clusters of the
// region's light cut are chosen proportionally to their unoccluded contribution bound at the shading point;
// inside a cluster, lights by intensity. It "learns" only where the regions are (it requests the fine
// regions its shading points reach); its probabilities never depend on samples' values.
#pragma once

#include "cut_sampling.h"

#include <vector>

namespace bl {

// The bound sampler; owns its regions, reads a light tree it does not own.
struct bound_sampler {
  static constexpr bool learns = true;
  static constexpr int rows_per_state = 1;  // image rows per region-request state
  using context = cut_context;
  using row_state = region_requests;
  const light_tree_data* tree = nullptr;
  const light_data* lights = nullptr;
  region_state regions;
  float sun_sin = 0, sun_cos = 1;

  void locate(context& ctx, const shade_point& sp) const { locate_region(ctx, regions, sp, true); }
  void prepare(context& ctx, const shade_point& sp) const;
  light_choice sample(const context& ctx, double u, double u_inner) const {
    return sample_cut(ctx, *tree, *lights, u, u_inner);
  }
  float pmf(const context& ctx, int light) const { return cut_pmf(ctx, *tree, *lights, light); }
  // With a cut shared by every region (a handful of lights) regions change nothing: none are requested.
  void record(row_state& row, const nee_event<context>& e) const {
    if (!regions.shared_cut) row.add(*e.context);
  }
  void sample_done(row_state&, int, vec3f) const {}
  void learn(std::vector<row_state>& rows);
  void begin_frame(double) {}  // regions and cuts do not depend on the sun's direction
};

}  // namespace bl
