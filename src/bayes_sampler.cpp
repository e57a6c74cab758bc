// bayes_sampler: posterior cluster weights per shading point, observation recording, learning between passes.
#include "bayes_sampler.h"

#include "cluster_bounds.h"

#include <xmmintrin.h>

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
  if (params.second_moment) {
    // Four clusters at a time in float: w = sqrt(max((w2 v + w1 g) v + w0 g^2, wc v^2)), v = scale * bound.
    alignas(16) float wf[max_cut_entries + 3];
    const __m128 scale4 = _mm_set1_ps(float(scale)), zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f);
    for (int j0 = 0; j0 < ctx.count; j0 += 4) {
      __m128 c[4];
      for (int k = 0; k < 4; k++)
        c[k] = _mm_loadu_ps(&stats.weight[base + size_t(std::min(j0 + k, ctx.count - 1))].w2);
      _MM_TRANSPOSE4_PS(c[0], c[1], c[2], c[3]);  // now w2, w1, w0, wc of the four pairs
      __m128 inv = _mm_loadu_ps(inv_d2 + j0);
      __m128 bound = _mm_mul_ps(_mm_loadu_ps(num + j0), inv);
      __m128 v = _mm_mul_ps(scale4, bound);
      __m128 g = params.distance_regression ? inv : one;
      __m128 val = _mm_add_ps(_mm_mul_ps(_mm_add_ps(_mm_mul_ps(c[0], v), _mm_mul_ps(c[1], g)), v),
                              _mm_mul_ps(_mm_mul_ps(c[2], g), g));
      __m128 wv = _mm_sqrt_ps(_mm_max_ps(val, _mm_mul_ps(_mm_mul_ps(c[3], v), v)));
      wv = _mm_and_ps(_mm_cmpgt_ps(v, zero), wv);  // a cluster that cannot reach the point weighs 0
      _mm_store_ps(wf + j0, wv);
      _mm_storeu_ps(num + j0, bound);  // keep the bound for mixing and the fallback
    }
    for (int j = 0; j < ctx.count; j++) {
      w[j] = wf[j];
      b[j] = num[j];
      sum_w += w[j];
      sum_b += b[j];
    }
  } else {
    for (int j = 0; j < ctx.count; j++) {
      double bound = double(num[j]) * inv_d2[j];
      double g = params.distance_regression ? inv_d2[j] : 1.0;
      w[j] = eval_weight(stats.weight[base + size_t(j)], params, scale * bound, g);
      b[j] = bound;
      sum_w += w[j];
      sum_b += b[j];
    }
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
