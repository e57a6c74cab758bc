// bound_sampler: cluster weights = bounds at the shading point; regions created between passes.
#include "bound_sampler.h"

namespace bl {

void bound_sampler::prepare(context& ctx, const shade_point& sp) const {
  locate_region(ctx, regions, sp);
  if (ctx.count == 1) {
    ctx.cdf[0] = 0;
    ctx.cdf[1] = 1;
    return;
  }
  double w[max_cut_entries];
  for (int j = 0; j < ctx.count; j++)
    w[j] = cluster_bound(*tree, *lights, ctx.nodes[j], sp.p, sp.n, sun_sin, sun_cos);
  finish_cdf(ctx, w);
}

void bound_sampler::learn(std::vector<row_state>& rows) {
  std::vector<const region_requests*> r;
  for (const row_state& row : rows) r.push_back(&row);
  create_requested_regions(regions, *tree, r);
}

}  // namespace bl
