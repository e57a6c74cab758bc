// bound_sampler: cluster weights = bounds at the shading point; regions created between passes.
#include "bound_sampler.h"

#include "cluster_bounds.h"

namespace bl {

void bound_sampler::prepare(context& ctx, const shade_point& sp) const {
  locate_region(ctx, regions, sp, true);
  if (ctx.count == 1) {
    ctx.cdf[0] = 0;
    ctx.cdf[1] = 1;
    return;
  }
  float num[max_cut_entries + 3], inv_d2[max_cut_entries + 3];
  eval_node_bounds(*tree, ctx.nodes, ctx.tree_count, sp.p, sp.n, num, inv_d2);
  double w[max_cut_entries];
  for (int j = 0; j < ctx.tree_count; j++) w[j] = num[j] * inv_d2[j];
  if (ctx.tree_count < ctx.count) w[ctx.tree_count] = cluster_bound(*tree, *lights, sun_cluster, sp.p, sp.n, sun_sin, sun_cos);
  finish_cdf(ctx, w);
}

void bound_sampler::learn(std::vector<row_state>& rows) {
  if (regions.shared_cut) return;
  std::vector<const region_requests*> r;
  for (const row_state& row : rows) r.push_back(&row);
  create_requested_regions(regions, *tree, r);
}

}  // namespace bl
