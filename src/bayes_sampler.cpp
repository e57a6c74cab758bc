// bayes_sampler: posterior cluster weights per shading point, observation recording, learning between passes.
#include "bayes_sampler.h"

#include "cluster_bounds.h"

namespace bl {

void bayes_sampler::prepare(context& ctx, const shade_point& sp) const {
  locate_region(ctx, regions, sp);
  if (ctx.count == 1) {
    // One cluster: its probability is 1 whatever was learned (and nothing is recorded for it).
    ctx.cdf[0] = 0;
    ctx.cdf[1] = 1;
    return;
  }
  size_t base = size_t(regions.pair_offset[size_t(ctx.region)]);
  // Prior scale: a Lambertian point of albedo a turns irradiance E into radiance a E / pi.
  double scale = (sp.albedo > 0 ? sp.albedo : 1.0f) * inv_pi_f;
  float num[max_cut_entries + 3], inv_d2[max_cut_entries + 3];
  eval_node_bounds(*tree, ctx.nodes, ctx.tree_count, sp.p, sp.n, num, inv_d2);
  if (ctx.tree_count < ctx.count)
    num[ctx.tree_count] = cluster_bound_parts(*tree, *lights, sun_cluster, sp.p, sp.n, sun_sin, sun_cos,
                                              inv_d2[ctx.tree_count]);
  double w[max_cut_entries], b[max_cut_entries];
  double sum_w = 0, sum_b = 0;
  for (int j = 0; j < ctx.count; j++) {
    double bound = double(num[j]) * inv_d2[j];
    double g = params.distance_regression ? inv_d2[j] : 1.0;
    w[j] = eval_weight(stats.weight[base + size_t(j)], params, scale * bound, g);
    b[j] = bound;
    sum_w += w[j];
    sum_b += b[j];
  }
  // Defensive mixing with the bound pmf (always a little for the naive ablation, which can starve clusters).
  double eps = params.prior ? params.epsilon : std::max(params.epsilon, 1e-3);
  if (eps > 0 && sum_w > 0 && sum_b > 0)
    for (int j = 0; j < ctx.count; j++) w[j] = (1 - eps) * w[j] / sum_w + eps * b[j] / sum_b;
  // Overflowing weights (absurd radiance scales) fall back to the bound pmf rather than stopping NEE.
  if (!finish_cdf(ctx, w)) finish_cdf(ctx, b);
}

void bayes_sampler::record(row_state& row, const nee_event<context>& e) const {
  const cut_context& ctx = *e.context;
  row.requests.add(regions, ctx);
  int j = e.choice.cluster;
  if (j < 0 || ctx.count == 1) return;
  double z = e.value;
  if (z > 0 && params.distance_regression) {
    double d = cluster_distance(*tree, ctx.nodes[j], ctx.p);
    z *= d * d;
  }
  row.add(regions.pair_offset[size_t(ctx.region)] + j, z);
}

void bayes_sampler::begin_frame(double decay) {
  if (decay >= 1) return;
  decay_stats(stats, decay, params);
  refresh_weights(stats, &regions.pair_parent, params);
}

void bayes_sampler::learn(std::vector<row_state>& rows) {
  if (frozen) return;
  merge_rows(stats, rows, params, params.hierarchy > 0 ? &regions.pair_parent : nullptr);
  std::vector<const region_requests*> r;
  for (const row_state& row : rows) r.push_back(&row.requests);
  create_requested_regions(regions, *tree, r);
  resize_stats(stats, regions.pairs, params);
  // Fold each pair's (hierarchical) p1 into its sampling weight: one sequential sweep over the pairs.
  refresh_weights(stats, &regions.pair_parent, params);
}

}  // namespace bl
