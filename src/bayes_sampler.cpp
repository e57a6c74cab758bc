// bayes_sampler: posterior cluster weights per shading point, observation recording, learning between passes.
#include "bayes_sampler.h"

#include "cluster_bounds.h"
#include "sampling.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <emmintrin.h>
#include <xmmintrin.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <new>

namespace bl {

namespace {

// Prior scale of a point: a Lambertian point of albedo a turns irradiance E into radiance a E / pi.
double point_scale(float albedo) { return double((albedo > 0 ? albedo : 1.0f) * inv_pi_f); }

// Least receiver cosine factor of a cluster the front test keeps (it stays possible, and z = Y / factor bounded).
constexpr float orientation_floor = 1e-3f;

// The Phong lobe's factor of a glossy point toward four bounding spheres, each seen at cosine cos_a from the mirror
// direction with angular radius asin(sin_t) (sin_t >= 1: the point is inside): gloss_base + gloss_peak times a bound
// of the lobe's largest value over the sphere's directions, at least orientation_floor (a cluster the front test keeps
// stays possible, and z = Y / factor bounded). With c the largest cosine to the mirror direction over the sphere,
// c^n <= exp(-n (1 - c)) <= (1 + n (1 - c) / 256)^-256: eight squarings and a division, no pow (a few per cent looser
// than c^n where the lobe matters, 1.6x at 0.1 below its peak when n = 100); and the lobe's term is at most its
// average over the sphere's solid angle (below).
__m128 gloss_factor4(const shade_point& sp, __m128 cos_a, __m128 sin_t) {
  const __m128 one = _mm_set1_ps(1.0f), zero = _mm_setzero_ps();
  __m128 inside = _mm_cmpge_ps(sin_t, one);
  sin_t = _mm_min_ps(sin_t, one);
  __m128 cos_t = _mm_sqrt_ps(_mm_max_ps(zero, _mm_sub_ps(one, _mm_mul_ps(sin_t, sin_t))));
  __m128 sin_a = _mm_sqrt_ps(_mm_max_ps(zero, _mm_sub_ps(one, _mm_mul_ps(cos_a, cos_a))));
  __m128 c = _mm_add_ps(_mm_mul_ps(cos_a, cos_t), _mm_mul_ps(sin_a, sin_t));  // cos(angle - radius)
  __m128 full = _mm_or_ps(inside, _mm_cmpge_ps(cos_a, cos_t));                 // the mirror direction hits the sphere
  c = _mm_or_ps(_mm_and_ps(full, one), _mm_andnot_ps(full, _mm_min_ps(c, one)));
  __m128 t = _mm_add_ps(one, _mm_mul_ps(_mm_set1_ps(sp.ns * (1.0f / 256)), _mm_sub_ps(one, c)));
  for (int k = 0; k < 8; k++) t = _mm_mul_ps(t, t);  // t^256 (inf far off the lobe: the bound is then 0)
  __m128 lobe = _mm_mul_ps(_mm_set1_ps(sp.gloss_peak), _mm_div_ps(one, t));
  // A lobe narrower than the sphere's solid angle W = 2 pi (1 - cos_t) gives at most its integral (ks's share times
  // pi) spread over W on average: a sharp lobe's peak is no model of a cluster's mean (a mirror would weigh a lamp
  // it meets 1e29 times its diffuse light, and starve the rest).
  __m128 cap = _mm_div_ps(_mm_mul_ps(sin_t, sin_t), _mm_add_ps(one, cos_t));  // 1 - cos_t without cancellation
  __m128 one_minus_cos_t = _mm_or_ps(_mm_and_ps(inside, one), _mm_andnot_ps(inside, cap));
  __m128 spread = _mm_div_ps(_mm_set1_ps(0.5f * (1 - sp.gloss_base)), _mm_max_ps(one_minus_cos_t, _mm_set1_ps(1e-30f)));
  __m128 f = _mm_add_ps(_mm_set1_ps(sp.gloss_base), _mm_min_ps(lobe, spread));
  return _mm_max_ps(f, _mm_set1_ps(orientation_floor));
}

// The floor of a cluster's positive member weights: min_positive_share of `raw`, the cluster's column (the sum of
// those weights), so that, as in fill_cdf, no member that can contribute rounds to probability zero. (Its draw
// rescales u's place in the cluster's cell, which holds about pj 2^53 values of u: a floored member of a floored
// cluster, below 2^-53 of the total, is drawn at that resolution rather than at its pmf; README, "All are unbiased".)
double member_floor(float raw) { return std::isfinite(raw) ? double(raw) * min_positive_share : 0.0; }
// The total weight of the n members w[0..n) of a cluster, each positive weight floored at `floor`.
double members_total(const float* w, int n, double floor) {
  double total = 0;
  for (int k = 0; k < n; k++)
    if (w[k] > 0) total += std::max(double(w[k]), floor);
  return total;
}

}  // namespace

void bayes_sampler::prepare(context& ctx, const shade_point& sp) const {
  ctx.cv = false;
  if (fallback) return;  // power sampling: no region, no weights
  locate_region(ctx, regions, sp);
  ctx.count = ctx.cut_count, ctx.tree_count = ctx.cut_tree_count, ctx.nodes = ctx.cut_nodes;
  if (ctx.pair_count == 1) {
    // One cluster of one member: its probability is 1 whatever was learned (and nothing is recorded for it).
    ctx.cdf[0] = 0;
    ctx.cdf[1] = 1;
    return;
  }
  if (params.region_prior) {
    prepare_region_prior(ctx, sp);
    return;
  }
  size_t base = size_t(ctx.pair_base);
  double scale = point_scale(sp.albedo);
  float num[max_cut_entries + 3], inv_d2[max_cut_entries + 3];
  eval_node_bounds(*tree, ctx.nodes, ctx.tree_count, sp.p, sp.n, num, inv_d2);
  if (ctx.tree_count < ctx.count)
    num[ctx.tree_count] = cluster_bound_parts(*tree, *lights, sun_cluster, sp.p, sp.n, sun_sin, sun_cos,
                                              inv_d2[ctx.tree_count]);
  for (int j = ctx.count; j < ((ctx.count + 3) & ~3); j++)  // padding lanes, read four at a time below
    num[j] = 0, inv_d2[j] = 1;
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

void bayes_sampler::prepare_region_prior(context& ctx, const shade_point& sp, bool cv_allowed) const {
  // w_j = W_j g_j with g_j = 1 / max(|p - c_j|^2, r_j^2) (1 without the regression), and 0 when the cluster's
  // bounding sphere lies entirely behind the surface: dot(n, p - c_j) >= r_j (plus a rounding slack), where no
  // light of it can give a non-zero sample (the BSDF is zero below the geometric tangent plane). Four tree
  // clusters at a time; the sun (last, if any) is zero when its whole disk is below the tangent plane.
  // With members (a cluster of several), a cluster weighs the sum of its members' W (gw, gw_cv) and c_j of its
  // members at the point is their cv times the cluster's factor g; the member is chosen in sample_members. A glossy
  // point multiplies g by the lobe's factor (gloss_factor4), and where the region has members weighs them instead of
  // its clusters, each as a cluster of its own.
  size_t base = size_t(ctx.pair_base);
  const bool gloss = params.bsdf_factor && sp.gloss_peak > 0;
  ctx.cv = params.control_variate && (sp.last || params.cv_every_vertex) && !gloss && cv_allowed;
  if (gloss && ctx.pair_count != ctx.count && ctx.pair_count <= max_cut_entries) {
    // A glossy point weighs every member as its own cluster (with its own lobe factor): which lights a highlight
    // mirrors changes faster across a region than the members' region-wide weights can follow.
    ctx.tree_count = ctx.pair_count - (ctx.cut_tree_count < ctx.cut_count ? 1 : 0);
    ctx.count = ctx.pair_count;
    ctx.nodes = ctx.members;
  }
  const bool grouped = ctx.pair_count != ctx.count;
  // (Inside a cluster members are chosen by their weights as capped there: bayes_stats::mw.)
  ctx.member_w = (grouped ? (ctx.cv ? stats.mw_cv.data() : stats.mw.data())
                          : (ctx.cv ? stats.w_cv.data() : stats.w.data())) + base;
  if (grouped) {
    // sample_members reads the chosen cluster's bounds, its members' weights and the chosen member's node right after
    // this: fetch the region's (consecutive, a few cache lines) while the weights below are computed.
    auto fetch = [](const void* p) { _mm_prefetch(static_cast<const char*>(p), _MM_HINT_T0); };
    for (int k = 0; k < ctx.pair_count; k += 16) fetch(ctx.member_w + k), fetch(ctx.members + k);
    for (int k = 0; k < ctx.count; k += 16) fetch(ctx.member_begin + k);
  }
  const float* W = grouped ? (ctx.cv ? stats.gw_cv.data() : stats.gw.data()) + ctx.group_base : ctx.member_w;
  ctx.group_w = W;
  ctx.group_total = grouped ? (ctx.cv ? stats.gtot_cv.data() : stats.gtot.data()) + ctx.group_base : nullptr;
  const float* cvj = grouped ? stats.gcv.data() + ctx.group_base : stats.cv.data() + base;
  const float* mu0 = stats.mu0.data() + base;
  // The prior model's weight of cluster j at g = 1: the sum of its members' mu0.
  auto cluster_mu0 = [&](int j) {
    if (!grouped) return double(mu0[j]);
    int e = j + 1 < ctx.count ? ctx.member_begin[j + 1] : ctx.pair_count;
    double m = 0;
    for (int k = ctx.member_begin[j]; k < e; k++) m += double(mu0[k]);
    return m;
  };
  // sum_m colour_m cv_m of each cluster (its members' c_m = cv_m g_j share the factor g_j).
  const vec3f* gcol = grouped ? stats.gcol.data() + ctx.group_base : nullptr;
  if (gcol && ctx.cv)  // (read below only for clusters with a learned mean, after their factors: fetched now)
    for (int j = 0; j < ctx.count; j += 5) _mm_prefetch(reinterpret_cast<const char*>(gcol + j), _MM_HINT_T0);
  // The weights, in double for the cdf, converted as each group of four is computed (w[count, count + 3): padding,
  // never read).
  alignas(16) double w[max_cut_entries + 3];
  float* gf = ctx.gfac;
  const int tc = ctx.tree_count;
  const __m128 px = _mm_set1_ps(sp.p.x), py = _mm_set1_ps(sp.p.y), pz = _mm_set1_ps(sp.p.z);
  const __m128 nx = _mm_set1_ps(sp.n.x), ny = _mm_set1_ps(sp.n.y), nz = _mm_set1_ps(sp.n.z);
  const __m128 rx = _mm_set1_ps(sp.refl.x), ry = _mm_set1_ps(sp.refl.y), rz = _mm_set1_ps(sp.refl.z);
  const __m128 one = _mm_set1_ps(1.0f), slack = _mm_set1_ps(1e-5f);
  const __m128 orient_floor = _mm_set1_ps(orientation_floor), tiny = _mm_set1_ps(1e-30f);
  const __m128 abs_mask = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
  const bool regression = params.distance_regression;
  const bool orientation = params.orientation;
  const __m128 zero = _mm_setzero_ps();
  int front_mask = 0;  // some cluster can reach the point
  vec3f cv_sum = {0, 0, 0};
  // Unseen clusters (bayes_params::unseen_cap; + 16 padding, so four flags are read at any j0): which lanes hold one,
  // and the heaviest weight of the others.
  const uint8_t* unseen = grouped ? stats.gunseen.data() + ctx.group_base : stats.unseen.data() + base;
  const __m128i zi = _mm_setzero_si128(), lane_index = _mm_setr_epi32(0, 1, 2, 3);
  __m128 seen_v = zero;
  int unseen_mask = 0;
  for (int j0 = 0; j0 < tc; j0 += 4) {
    // (cx, cy, cz, r) of four nodes (missing lanes repeat the last node; their results are never read).
    __m128 c0 = _mm_loadu_ps(&tree->packed[size_t(ctx.nodes[std::min(j0 + 0, tc - 1)])].cx);
    __m128 c1 = _mm_loadu_ps(&tree->packed[size_t(ctx.nodes[std::min(j0 + 1, tc - 1)])].cx);
    __m128 c2 = _mm_loadu_ps(&tree->packed[size_t(ctx.nodes[std::min(j0 + 2, tc - 1)])].cx);
    __m128 c3 = _mm_loadu_ps(&tree->packed[size_t(ctx.nodes[std::min(j0 + 3, tc - 1)])].cx);
    _MM_TRANSPOSE4_PS(c0, c1, c2, c3);  // now cx, cy, cz, r
    __m128 dx = _mm_sub_ps(px, c0), dy = _mm_sub_ps(py, c1), dz = _mm_sub_ps(pz, c2);
    __m128 d2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
    __m128 g = regression ? _mm_div_ps(one, _mm_max_ps(d2, _mm_mul_ps(c3, c3))) : one;
    __m128 dn = _mm_add_ps(_mm_add_ps(_mm_mul_ps(nx, dx), _mm_mul_ps(ny, dy)), _mm_mul_ps(nz, dz));
    __m128 l1 = _mm_add_ps(_mm_add_ps(_mm_and_ps(dx, abs_mask), _mm_and_ps(dy, abs_mask)), _mm_and_ps(dz, abs_mask));
    __m128 front = _mm_cmplt_ps(dn, _mm_add_ps(c3, _mm_mul_ps(slack, l1)));
    if (orientation) {
      // Receiver cosine factor toward the cluster's bounding sphere: (r - n.(p - c)) / d = cos theta_i + r / d,
      // theta_i the angle between n and the direction to the centre, clamped to [orientation_floor, 1] (so that
      // every cluster the front test keeps stays possible, and z = Y / factor stays bounded).
      __m128 c = _mm_div_ps(_mm_sub_ps(c3, dn), _mm_max_ps(_mm_sqrt_ps(d2), tiny));
      g = _mm_mul_ps(g, _mm_min_ps(one, _mm_max_ps(c, orient_floor)));
    }
    if (gloss) {
      // The lobe's factor toward the four spheres (centre at -(dx, dy, dz) from the point, radius c3); a point at a
      // centre (d = 0) is inside its sphere.
      __m128 d = _mm_max_ps(_mm_sqrt_ps(d2), tiny);
      __m128 rd = _mm_add_ps(_mm_add_ps(_mm_mul_ps(rx, dx), _mm_mul_ps(ry, dy)), _mm_mul_ps(rz, dz));
      __m128 cos_a = _mm_max_ps(_mm_set1_ps(-1.0f), _mm_min_ps(one, _mm_div_ps(_mm_sub_ps(zero, rd), d)));
      g = _mm_mul_ps(g, gloss_factor4(sp, cos_a, _mm_div_ps(c3, d)));
    }
    g = _mm_and_ps(front, g);
    _mm_storeu_ps(gf + j0, g);
    const __m128 wv = _mm_mul_ps(_mm_loadu_ps(W + j0), g);
    _mm_store_pd(w + j0, _mm_cvtps_pd(wv));
    _mm_store_pd(w + j0 + 2, _mm_cvtps_pd(_mm_movehl_ps(wv, wv)));
    const int lanes = tc - j0 >= 4 ? 0xf : (1 << (tc - j0)) - 1;  // the lanes of real clusters
    front_mask |= _mm_movemask_ps(_mm_cmpgt_ps(g, zero)) & lanes;
    {
      uint32_t f4;
      std::memcpy(&f4, unseen + j0, 4);
      const __m128i fi = _mm_unpacklo_epi16(_mm_unpacklo_epi8(_mm_cvtsi32_si128(int(f4)), zi), zi);
      const __m128 un = _mm_castsi128_ps(_mm_cmpgt_epi32(fi, zi));
      const __m128 real = _mm_castsi128_ps(_mm_cmpgt_epi32(_mm_set1_epi32(tc - j0), lane_index));
      unseen_mask |= _mm_movemask_ps(un) & lanes;
      seen_v = _mm_max_ps(seen_v, _mm_andnot_ps(un, _mm_and_ps(real, wv)));
    }
    if (ctx.cv) {
      // c_j = (E[1 - p0] k_j) g_j, zero behind the surface like the weight, and their colour-weighted sum in
      // cluster order (most pairs have no control variate: c_j = 0, skipped four at a time).
      __m128 c = _mm_mul_ps(_mm_loadu_ps(cvj + j0), g);
      _mm_storeu_ps(ctx.cvg + j0, c);
      for (int m = _mm_movemask_ps(_mm_cmpneq_ps(c, zero)) & lanes; m != 0; m &= m - 1) {
        int j = j0 + __builtin_ctz(unsigned(m));
        if (grouped) cv_sum += gcol[j] * gf[j];
        else cv_sum += cluster_color(ctx, j) * ctx.cvg[j];
      }
    }
  }
  if (tc < ctx.count) {
    float front = dot(sp.n, lights->sun_dir) > -sun_sin - 1e-6f ? 1.0f : 0.0f;
    float cos_bound = orientation ? receiver_cos_bound(sp.n, lights->sun_dir, sun_sin, sun_cos) : 1.0f;
    gf[tc] = front * std::min(1.0f, std::max(cos_bound, orientation_floor));
    if (gloss)
      gf[tc] *= _mm_cvtss_f32(gloss_factor4(sp, _mm_set1_ps(dot(sp.refl, lights->sun_dir)), _mm_set1_ps(sun_sin)));
    w[tc] = double(W[tc] * gf[tc]);
    front_mask |= gf[tc] > 0;
    if (ctx.cv) {
      int sun_member = ctx.pair_count - 1;  // the sun: its cluster's only member, the last
      ctx.cvg[tc] = stats.cv[base + size_t(sun_member)] * gf[tc];
      if (ctx.cvg[tc] != 0) cv_sum += cluster_color(ctx, sun_member) * ctx.cvg[tc];
    }
  }
  if (ctx.cv && !is_finite(cv_sum)) {
    // Learned means times this point's factors overflow float (absurd radiance scales): weigh it without them.
    prepare_region_prior(ctx, sp, false);
    return;
  }
  ctx.cv_sum = cv_sum;
  if (front_mask == 0) {
    // Every cluster lies behind the surface: no light can be sampled (what the fallbacks below would also find).
    std::fill(ctx.cdf, ctx.cdf + ctx.count + 1, 0.0);
    return;
  }
  // Unseen clusters (bayes_params::unseen_cap: neither their members nor their coarse parents showed a non-zero
  // sample in unseen_cap samples) weigh at most the heaviest cluster at this point that has shown one. (Their prior
  // mean, the bound, keeps them far above it where a lamp far brighter than the others is shut away from the
  // region.) The flags and the others' heaviest weight came with the weights above (a loop of its own here, with the
  // maximum's dependency chain, added a quarter to the hall's PMF build).
  const bool sun_unseen = tc < ctx.count && unseen[tc];
  if (unseen_mask != 0 || sun_unseen) {
    alignas(16) float lane_max[4];
    _mm_store_ps(lane_max, seen_v);
    double seen_max = std::max(std::max(lane_max[0], lane_max[1]), std::max(lane_max[2], lane_max[3]));
    if (tc < ctx.count && !sun_unseen) seen_max = std::max(seen_max, w[tc]);
    if (seen_max > 0)
      for (int j = 0; j < ctx.count; j++) w[j] = unseen[j] ? std::min(w[j], seen_max) : w[j];
  }
  // Defensive mixing with the prior-only pmf (mu0 g: the region's bound model; always a little for the naive
  // ablation, which can starve clusters).
  double eps = params.prior ? params.epsilon : std::max(params.epsilon, 1e-3);
  if (eps > 0) {
    double sum_w = 0, sum_b = 0;
    for (int j = 0; j < ctx.count; j++) sum_w += w[j], sum_b += cluster_mu0(j) * gf[j];
    if (sum_w > 0 && sum_b > 0)
      for (int j = 0; j < ctx.count; j++) w[j] = (1 - eps) * w[j] / sum_w + eps * cluster_mu0(j) * gf[j] / sum_b;
  }
  if (finish_cdf(ctx, w)) return;
  // Overflowing weights (absurd radiance scales) fall back to the prior model, then to every cluster in front (the
  // members then still follow their weights).
  for (int j = 0; j < ctx.count; j++) w[j] = cluster_mu0(j) * gf[j];
  if (finish_cdf(ctx, w)) return;
  for (int j = 0; j < ctx.count; j++) w[j] = gf[j] > 0 ? 1.0 : 0.0;
  finish_cdf(ctx, w);
}

void bayes_sampler::record(row_state& row, const nee_event<context>& e) const {
  if (fallback) return;
  if (!px_delta.empty()) {
    // Had power sampling (probability q) chosen this event's light instead of p, the event would have added a p / q
    // (same MIS weight): its second moment E_p[(a p / q)^2 q / p] = E_p[a^2 p / q], against the learned estimator's
    // own added_total^2 (control variate included). The means agree, so the difference is the variance's.
    double a = e.added, p = e.choice.prob;
    double q = power.pmf({}, e.choice.light);
    double with_power = a == 0 ? 0.0 : q > 0 ? a * a * p / q : HUGE_VAL;
    px_delta[size_t(e.pixel)] += with_power - double(e.added_total) * e.added_total;
    // The same with the bvh sampler's probability of the light at the point (at the pixels it checks).
    if (!px_delta_bvh.empty() && e.pixel % bvh_check_stride == 0) {
      bvh_sampler::context b;
      bvh.prepare_at(b, e.context->p, e.context->n);
      double qb = bvh.pmf(b, e.choice.light);
      double with_bvh = a == 0 ? 0.0 : qb > 0 ? a * a * p / qb : HUGE_VAL;
      px_delta_bvh[size_t(e.pixel)] += with_bvh - double(e.added_total) * e.added_total;
    }
    if (e.first_vertex && !px_first.empty()) px_first[size_t(e.pixel)] += with_power;
  }
  const cut_context& ctx = *e.context;
  row.requests.add(ctx);
  int j = e.choice.cluster;  // the member
  if (j < 0 || ctx.pair_count == 1) return;
  double z = e.value;
  if (z > 0) {
    if (params.region_prior) {
      // The albedo-free sample (see bayes_stats) over the point factor the pmf used (its cluster's): z = Y d^2 / cos
      // bound.
      z = z / point_scale(ctx.albedo) / double(ctx.gfac[group_of(ctx, j)]);
    } else if (params.distance_regression) {
      double d = cluster_distance(*tree, ctx.nodes[j], ctx.p);
      z *= d * d;
    }
  }
  // The accumulator of (region, j), in the row state's block of the region: the block is cached in the context while
  // it records into the same row state and region (a hash lookup per change of region).
  if (ctx.rec_owner != &row || ctx.rec_generation != row.generation || ctx.rec_base != ctx.pair_base) {
    ctx.rec_owner = &row;
    ctx.rec_generation = row.generation;
    ctx.rec_base = ctx.pair_base;
    ctx.rec_block = row.block_of(ctx.pair_base, ctx.pair_count);
  }
  row.add_at(row.slot_at(ctx.rec_block, ctx.pair_base, j), z);
}

light_choice bayes_sampler::sample_members(const context& ctx, double u, double u_inner) const {
  if (ctx.count == 0 || !(ctx.cdf[ctx.count] > 0)) return {};
  int j = sample_cdf(ctx.cdf, ctx.count, u);
  double pj = cluster_pmf(ctx, j);
  if (!(pj > 0)) return {};
  int b = ctx.member_begin[j], e = j + 1 < ctx.count ? ctx.member_begin[j + 1] : ctx.pair_count;
  int m = b;
  double p = pj, lo = ctx.cdf[j];  // the member's cell of u: [lo, lo + p)
  if (e - b > 1) {
    // u's place inside the cluster's cell, rescaled to the members' total weight (a cluster chosen has a positive
    // total: its weight is that sum); members of weight 0 are never chosen.
    const float* w = ctx.member_w;
    double floor = member_floor(ctx.group_w[j]), total = ctx.group_total[j];
    double x = (u - ctx.cdf[j]) / pj * total, run = 0, start = 0, wm = 0;
    m = -1;
    for (int k = b; k < e; k++) {
      if (!(w[k] > 0)) continue;
      start = run;
      wm = std::max(double(w[k]), floor);
      run += wm;
      m = k;
      if (x < run) break;
    }
    if (m < 0) return {};
    p = pj * (wm / total);
    lo += start / total * pj;
  }
  int node = ctx.members[m];
  if (node == sun_cluster) return {lights->sun, float(p), m, 1.0f, p};
  // u's place inside the member's cell chooses the light: a stratified u stays stratified down to the light.
  double inner = 1;
  int leaf = sample_by_intensity(*tree, node, place_in_cell(u, lo, p, u_inner), inner);
  return {tree->light[size_t(leaf)], float(p * inner), m, float(inner), p};
}

bool bayes_sampler::cv_covers_light(const context& ctx, int light) const {
  if (!ctx.cv || ctx.count == 0) return false;
  // (The entry holding the light as pmf finds it: the sun is the last cluster and member.)
  if (light == lights->sun)
    return ctx.nodes[ctx.count - 1] == sun_cluster &&
           cv_covers(ctx, ctx.pair_count == ctx.count ? ctx.count - 1 : ctx.pair_count - 1);
  int leaf = tree->leaf_of_light[size_t(light)];
  if (ctx.pair_count == ctx.count)
    return cv_covers(ctx, holding_entry(*tree, leaf, ctx.nodes, ctx.nodes + ctx.tree_count));
  return cv_covers(ctx, holding_entry(*tree, leaf, ctx.members,
                                      ctx.members + ctx.pair_count - (ctx.tree_count < ctx.count ? 1 : 0)));
}

float bayes_sampler::members_pmf(const context& ctx, int light) const {
  if (ctx.count == 0) return 0;
  int m = invalid_id, leaf = invalid_id;
  if (light == lights->sun) {
    if (ctx.nodes[ctx.count - 1] != sun_cluster) return 0;
    m = ctx.pair_count - 1;
  } else {
    leaf = tree->leaf_of_light[size_t(light)];
    m = holding_entry(*tree, leaf, ctx.members, ctx.members + ctx.pair_count - (ctx.tree_count < ctx.count ? 1 : 0));
    if (m < 0) return 0;  // the light's subtree was left out of the cut: it cannot reach this region
  }
  int j = group_of(ctx, m);
  double p = cluster_pmf(ctx, j);
  int b = ctx.member_begin[j], e = j + 1 < ctx.count ? ctx.member_begin[j + 1] : ctx.pair_count;
  if (e - b > 1) {
    const float* w = ctx.member_w;
    double floor = member_floor(ctx.group_w[j]), total = ctx.group_total[j];
    p = total > 0 && w[m] > 0 ? p * (std::max(double(w[m]), floor) / total) : 0.0;
  }
  if (leaf != invalid_id) p *= intensity_descent_pmf(*tree, ctx.members[m], leaf);
  return float(p);
}

void bayes_sampler::refresh_groups(const std::vector<int>* pairs, bool dirty_only) {
  if (!regions.members) return;
  size_t slots = regions.cut_nodes.size();
  stats.gw.resize(slots + 4, 0.0f);
  stats.gw_cv.resize(slots + 4, 0.0f);
  stats.gcv.resize(slots + 4, 0.0f);
  stats.gcol.resize(slots, vec3f{0, 0, 0});
  stats.gtot.resize(slots, 0.0);
  stats.gtot_cv.resize(slots, 0.0);
  stats.gunseen.resize(slots + 16, 0);
  stats.mw.resize(stats.m.size() + 4, 0.0f);
  stats.mw_cv.resize(stats.m.size() + 4, 0.0f);
  const std::vector<int>& slot = regions.pair_slot;
  size_t npairs = slot.size();
  // The sums of the run of pairs of one cluster starting at `first` (a cluster's members are consecutive pairs).
  auto sum_run = [&](size_t first) {
    const int* sl = slot.data();
    const float *w = stats.w.data(), *wcv = stats.w_cv.data(), *cv = stats.cv.data();
    float *mw = stats.mw.data(), *mwcv = stats.mw_cv.data();
    const int g = sl[first];
    size_t end = first + 1;
    while (end < npairs && sl[end] == g) end++;
    // In one sweep: the columns' sums, and members_total's totals of the positive weights as if no floor applied,
    // with the least positive weight: where that is not below the floor (nearly always), the floor changed no term,
    // and the total is members_total's to the bit (the same terms added in the same order).
    // Unseen members of a cluster that also has seen ones (bayes_params::unseen_cap) count for at most its heaviest
    // seen member (w and w_cv apart); elsewhere the caps are infinite, and the sums those of the weights as they are.
    const uint8_t* un = stats.unseen.data();
    bool any_unseen = false, any_seen = false;
    float cap_a = 0, cap_b = 0;
    for (size_t k = first; k < end; k++) {
      if (un[k]) {
        any_unseen = true;
      } else {
        any_seen = true;
        cap_a = std::max(cap_a, w[k]), cap_b = std::max(cap_b, wcv[k]);
      }
    }
    if (!(any_unseen && any_seen)) cap_a = cap_b = HUGE_VALF;
    double a = 0, b = 0, c = 0, r = 0, gr = 0, bl = 0, ta = 0, tb = 0;
    float lo_a = HUGE_VALF, lo_b = HUGE_VALF;
    for (size_t k = first; k < end; k++) {
      const float x = un[k] ? std::min(w[k], cap_a) : w[k], y = un[k] ? std::min(wcv[k], cap_b) : wcv[k], z = cv[k];
      mw[k] = x, mwcv[k] = y;
      a += x, b += y, c += z;
      if (x > 0) ta += double(x), lo_a = std::min(lo_a, x);
      if (y > 0) tb += double(y), lo_b = std::min(lo_b, y);
      // A member without a control variate (most) adds +0 to each colour sum, which starts at +0 and can only stay
      // >= +0 (colours and cv are finite and non-negative): the same bits without reading its node's colour.
      if (z == 0) continue;
      int node = regions.pair_node[k];
      vec3f col = node == sun_cluster ? sun_color : tree->color[size_t(node)];
      r += double(col.x) * z, gr += double(col.y) * z, bl += double(col.z) * z;
    }
    const float fa = float(a), fb = float(b);
    stats.gw[size_t(g)] = fa;
    stats.gw_cv[size_t(g)] = fb;
    stats.gcv[size_t(g)] = float(c);
    stats.gunseen[size_t(g)] = any_unseen && !any_seen;
    stats.gcol[size_t(g)] = {float(r), float(gr), float(bl)};
    const int n = int(end - first);
    const double floor_a = member_floor(fa), floor_b = member_floor(fb);
    stats.gtot[size_t(g)] = double(lo_a) >= floor_a ? ta : members_total(mw + first, n, floor_a);
    stats.gtot_cv[size_t(g)] = double(lo_b) >= floor_b ? tb : members_total(mwcv + first, n, floor_b);
  };
  const std::vector<uint8_t>& dirty = stats.scratch.dirty;
  if (!pairs) {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, regions.key.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i < r.end(); i++) {
        size_t b = size_t(regions.pair_offset[i]), e = b + size_t(regions.pair_count[i]);
        if (!dirty_only) {
          for (size_t k = b; k < e; k++)
            if (k == b || slot[k] != slot[k - 1]) sum_run(k);
          continue;
        }
        // Only the clusters with a flagged member: the others' sums are what they hold (a function of the weights).
        for (size_t k = b; k < e;) {
          size_t first = k;
          bool any = false;
          for (; k < e && slot[k] == slot[first]; k++) any |= dirty[k] != 0;
          if (any) sum_run(first);
        }
      }
    });
    return;
  }
  // Each listed pair was refolded and flagged (stats.scratch.dirty); the first flagged member of a cluster sums it.
  tbb::parallel_for(tbb::blocked_range<size_t>(0, pairs->size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t t = r.begin(); t < r.end(); t++) {
      size_t k = size_t((*pairs)[t]);
      bool first = true;
      while (k > 0 && slot[k - 1] == slot[k] && first) first = !dirty[--k];
      if (first) sum_run(k);
    }
  });
}

void bayes_sampler::sample_done(row_state& row, int pixel, vec3f l) const {
  if (px_var.empty()) return;
  if (pixel != row.check_pixel) {
    if (row.check_pixel >= 0) flush_check(row);
    row.check_pixel = pixel;
    row.check_n = row.check_mean = row.check_m2 = 0;
  }
  double y = luminance(l);
  row.check_n += 1;
  double d = y - row.check_mean;
  row.check_mean += d / row.check_n;
  row.check_m2 += d * (y - row.check_mean);
}

void bayes_sampler::flush_check(const row_state& row) const {
  size_t i = size_t(row.check_pixel);
  if (row.check_n >= 2) {
    px_var[i] = row.check_pending();
    return;
  }
  // One sample in this pass: half the squared difference to the pixel's sample of the pass before (both passes of
  // one spp) is an unbiased estimate of its variance. A pass of one spp after one of more (a --spp total cut short)
  // has no columns: nothing to pair with, and the pass is not counted.
  if (px_cur.size() != px_var.size()) {
    px_var[i] = 0;
    return;
  }
  float y = float(row.check_mean);
  double d = double(y) - px_prev[i];
  px_var[i] = std::isfinite(px_prev[i]) ? 0.5 * d * d : 0.0;
  px_cur[i] = y;
}

void bayes_sampler::restart_check() {
  px_var = px_delta = px_first = px_delta_bvh = {};
  px_prev = px_cur = {};
  fallback_votes = 0;
  check_done = check_pairs = false;
  window_var = window_delta = window_samples = window_first = window_var_bvh = window_delta_bvh = 0;
  bvh_windows = 0;
}

double bayes_sampler::stratified_factor(double power_var, double first) const {
  const double s = params.fallback_stratified;
  if (!params.stratified) return 1.0;
  if (!params.path_traced || !(power_var > 0) || !std::isfinite(power_var) || !(s > 1)) return s;
  const double helped = std::isfinite(first) ? std::min(power_var, std::max(first, 0.0)) : power_var;
  const double left = power_var - (1 - 1 / s) * helped;
  return left > 0 ? std::min(s, power_var / left) : s;
}

void bayes_sampler::check_fallback(const std::vector<row_state>& rows, const std::vector<double>& film, double weight,
                                   int pass_spp, int spp) {
  if (fallback || check_done || frozen || params.oracle_spp > 0 || !(params.fallback_ratio > 0) || !(weight > 0)) return;
  size_t n = film.size() / 3;
  // Checked: passes of two spp or more, and passes of one after one (see flush_check), from 4 spp on.
  bool paired = pass_spp >= 2 || (pass_spp == 1 && px_prev.size() == n && check_pairs);
  if (px_var.size() == n) {
    for (const row_state& r : rows)
      if (r.check_pixel >= 0) flush_check(r);
    // The next pass of one spp has this pass's samples to pair with (every pixel had its one sample).
    check_pairs = pass_spp == 1 && px_cur.size() == n;
    if (check_pairs) px_prev.swap(px_cur);
  }
  if (px_var.size() == n && paired && spp >= 4) {
    // Summed over the pass's samples with relMSE's weights 1 / (m^2 + 0.01), m the pixel's mean luminance with this
    // pass included (a pixel whose earlier samples missed a bright edge would otherwise weigh as black): V, the
    // learned estimator's variance, and V + D, power sampling's (D: the NEE events' second moments, see record).
    double var = 0, delta = 0, first = 0, var_bvh = 0, delta_bvh = 0;
    const bool firsts = px_first.size() == n, bvhs = px_delta_bvh.size() == n;
    for (size_t i = 0; i < n; i++) {  // in pixel order
      vec3f m = {float(film[3 * i] / weight), float(film[3 * i + 1] / weight), float(film[3 * i + 2] / weight)};
      float y = luminance(m);
      double w = 1.0 / (double(y) * y + 0.01);
      var += w * px_var[i];
      delta += w * px_delta[i];
      if (firsts) first += w * px_first[i];
      if (bvhs && i % bvh_check_stride == 0) var_bvh += w * px_var[i], delta_bvh += w * px_delta_bvh[i];
    }
    window_var += var;
    window_delta += delta;
    window_var_bvh += var_bvh;
    window_delta_bvh += delta_bvh;
    window_first += first;
    window_samples += double(n) * pass_spp;
  }
  if (window_samples >= params.fallback_window) {
    // A window is complete: its ratio votes.
    bool valid = window_var > 0 && std::isfinite(window_var) && std::isfinite(window_delta);
    check_ratio = valid ? (window_var + window_delta) / window_var : 0.0;
    const double threshold = params.fallback_ratio * stratified_factor(window_var + window_delta, window_first);
    bool below = valid && window_var + window_delta < threshold * window_var;
    // The bvh sampler (in the first max_bvh_windows windows) against its own threshold, without the stratified factor:
    // it is taken only where it beats learning even per independent sample, whatever stratification would add to
    // that. An infinite estimate (a light bayes drew with a contribution that bvh could never choose) or a NaN one
    // never votes for it.
    const double t_bvh = params.fallback_bvh_ratio;
    const bool bvh_checked = checks_bvh();
    const bool bvh = bvh_checked && window_var_bvh > 0 && std::isfinite(window_var_bvh) && !std::isnan(window_delta_bvh);
    if (bvh) check_ratio_bvh = (window_var_bvh + window_delta_bvh) / window_var_bvh;
    if (bvh_checked) bvh_windows++;
    const bool below_bvh = bvh && check_ratio_bvh < t_bvh;
    fallback_votes = below || below_bvh ? fallback_votes + 1 : 0;
    window_var = window_delta = window_samples = window_first = window_var_bvh = window_delta_bvh = 0;
    fallback = fallback_votes >= 2;
    if (fallback) {
      fallback_spp = spp;
      fallback_bvh = below_bvh && !below;
    }
    check_done = valid && check_ratio >= 2 * threshold && (!bvh_checked || (bvh && !(check_ratio_bvh < 2 * t_bvh)));
    if (fallback || check_done) {
      px_var = {};
      px_delta = {};
      px_delta_bvh = {};
      px_first = {};
      px_prev = {};
      px_cur = {};
      return;
    }
  }
  px_var.assign(n, 0.0);
  px_delta.assign(n, 0.0);
  if (checks_bvh()) {
    px_delta_bvh.assign(n, 0.0);
  } else {
    px_delta_bvh = {};
  }
  if (params.path_traced) px_first.assign(n, 0.0);
  if (pass_spp == 1 && px_prev.size() != n) px_prev.assign(n, NAN);
  if (pass_spp == 1 && px_cur.size() != n) px_cur.assign(n, NAN);
  if (pass_spp > 1) px_prev = {}, px_cur = {};
}

void bayes_sampler::begin_frame(double decay) {
  if (decay >= 1) return;
  decay_stats(stats, decay);
  refresh_all_weights();
}

void bayes_sampler::refresh_all_weights() {
  refresh_weights(stats, params.hierarchy > 0 && params.prior ? &regions.pair_parent : nullptr, params,
                  &regions.pair_node);
  refresh_groups(nullptr);
}

void bayes_sampler::add_pairs(int first_region) {
  resize_stats(stats, regions.pairs, params);
  // Children lists of the coarse pairs (refold reaches a coarse pair's children through them).
  size_t npairs = stats.m.size();
  if (first_region == 0) child_link.clear(), parent_pairs = 0;
  child_link.resize(npairs, invalid_id);
  for (size_t r = size_t(first_region); r < regions.key.size(); r++) {
    size_t b = size_t(regions.pair_offset[r]), e = b + size_t(regions.pair_count[r]);
    for (size_t k = b; k < e; k++) {
      int up = regions.pair_parent[k];
      if (up == invalid_id) continue;
      if (child_link[size_t(up)] == invalid_id) parent_pairs++;
      child_link[k] = child_link[size_t(up)];
      child_link[size_t(up)] = int(k);
    }
  }
  if (!params.region_prior) return;
  // mu0 of each pair: the region bound's distance-free part over the (padded) region box, i.e. a prior mean of
  // z = E d^2 for a receiver facing the cluster (E / d^2 at the box centre without the regression); the sun's is
  // its irradiance. Each region independently (the result does not depend on how the range is split).
  float sun_mu0 = lights->sun != invalid_id ? luminance(lights->sun_irradiance) : 0.0f;
  bool regression = params.distance_regression;
  int end = int(regions.key.size());
  tbb::parallel_for(tbb::blocked_range<int>(first_region, end, 64), [&](const tbb::blocked_range<int>& range) {
    for (int r = range.begin(); r < range.end(); r++) {
      bbox3f box = padded(region_box(regions.grid, regions.key[size_t(r)]));
      vec3f mid = center(box);
      const int* nodes = regions.pair_node.data() + regions.pair_offset[size_t(r)];
      float* out = stats.mu0.data() + regions.pair_offset[size_t(r)];
      for (int j = 0; j < regions.pair_count[size_t(r)]; j++) {
        int node = nodes[j];
        if (node == sun_cluster) {
          out[j] = sun_mu0;
          continue;
        }
        float m = node_region_intensity(*tree, node, box.lo, box.hi);
        if (!regression) {
          float d = cluster_distance(*tree, node, mid);
          m /= d * d;
        }
        out[j] = m;
      }
    }
  });
}

void bayes_sampler::reserve_growth() {
  // Fine pairs stay within the budget, coarse pairs within as many again (region_grid's allowance).
  const size_t now = size_t(regions.pairs), cuts = regions.cut_nodes.size();
  const size_t most = now + 2 * size_t(std::max<int64_t>(regions.params.max_pairs, 0));
  // Room for every pair the budget allows, where that stays within max_reserved_bytes of address space (the default
  // budget: about 350 MB, of which only what the pairs use is ever touched): a column that outgrows its reservation is
  // copied whole into fresh pages, and all of them at once took one pass 0.44 s (the real Cornell box with its light
  // in 128 triangles, 128x96, as its regions reached the budget: half of a 2-second render's learning time). Beyond
  // that, or where the address space is refused, half as much again as now (growth then copies now and then).
  const size_t entries = std::max(cuts, most);
  if (reserve_columns(most, entries, true) <= max_reserved_bytes) {
    try {
      reserve_columns(most, entries);
      return;
    } catch (const std::bad_alloc&) {
      // (strict overcommit: fall through to the smaller reservation)
    }
  }
  reserve_columns(std::min(now + now / 2, most), std::min(cuts + cuts / 2, most));
}

size_t bayes_sampler::reserve_columns(size_t pairs, size_t entries, bool count_only) {
  size_t bytes = 0;
  auto room = [&](auto& column, size_t n) {
    bytes += n * sizeof(column[0]);
    if (!count_only) column.reserve(n);
  };
  for (std::vector<float>* v : {&stats.mu0, &stats.p1_folded, &stats.k_folded}) room(*v, pairs);
  for (std::vector<float>* v : {&stats.w, &stats.w_cv, &stats.cv}) room(*v, pairs + 4);
  room(stats.unseen, pairs + 16);
  room(stats.m, pairs);
  if (!params.region_prior) room(stats.weight, pairs);
  room(stats.scratch.seen, pairs);
  room(stats.scratch.dirty, pairs);
  room(child_link, pairs);
  for (std::vector<int>* v : {&regions.pair_node, &regions.pair_slot, &regions.pair_parent}) room(*v, pairs);
  room(regions.cut_nodes, entries);
  room(regions.member_begin, entries);
  if (!regions.members) return bytes;
  for (std::vector<float>* v : {&stats.gw, &stats.gw_cv, &stats.gcv}) room(*v, entries + 4);
  for (std::vector<float>* v : {&stats.mw, &stats.mw_cv}) room(*v, pairs + 4);
  room(stats.gcol, entries);
  room(stats.gtot, entries);
  room(stats.gtot_cv, entries);
  room(stats.gunseen, entries + 16);
  return bytes;
}

void bayes_sampler::rebuild_posterior() {
  size_t n = stats.m.size();
  stats.weight.resize(params.region_prior ? 0 : n);
  stats.mu0.assign(n, 0.0f);
  stats.w.assign(n + 4, 0.0f);
  add_pairs(0);
  refresh_all_weights();
}

void bayes_sampler::learn(std::vector<row_state>& rows) {
  if (frozen || fallback) return;
  const std::vector<int>* parents = params.hierarchy > 0 ? &regions.pair_parent : nullptr;
  using clock = std::chrono::steady_clock;
  auto secs = [](clock::time_point a, clock::time_point b) { return std::chrono::duration<double>(b - a).count(); };
  size_t old_pairs = stats.m.size();
  auto t0 = clock::now();
  std::vector<int> touched = merge_rows(stats, rows, parents);
  auto t1 = clock::now();
  int before = int(regions.key.size());
  std::vector<const region_requests*> r;
  for (const row_state& row : rows) r.push_back(&row.requests);
  create_requested_regions(regions, *tree, r);
  add_pairs(before);
  auto t2 = clock::now();
  refold(touched, old_pairs);
  auto t3 = clock::now();
  timing.reduce += secs(t0, t1);
  timing.regions += secs(t1, t2);
  timing.refold += secs(t2, t3);
  for (const row_state& row : rows) timing.records += double(row.acc.size());
}

void bayes_sampler::refold(const std::vector<int>& touched, size_t old_pairs) {
  const bool hier = params.hierarchy > 0 && params.prior;
  std::atomic<int64_t> folds{0};  // counted per task (profiles)
  tbb::enumerable_thread_specific<std::vector<int>> children;  // members: refolded children, per thread (any order)
  // Members: a refolded pair is flagged (each pair is folded by one task at a time) for refresh_groups.
  std::vector<uint8_t>& dirty = stats.scratch.dirty;
  if (regions.members) dirty.resize(stats.m.size(), 0);
  auto fold = [&](size_t i) {
    fold_weight(stats, i, hier ? regions.pair_parent[i] : invalid_id, params, regions.pair_node[i] == sun_cluster);
    if (regions.members) dirty[i] = 1;
  };
  // Children of coarse pairs whose p1 moved by more than the tolerance since their children were last examined. A
  // child's p1 = (s p1_parent + n1) / (s + n) moves, relative to itself, by at most the parent's relative move; an
  // examined child is refolded when its own p1 moved by more than the tolerance from the one its weight holds (a
  // child with many samples of its own barely follows its parent). So a child's p1 is never more than about twice
  // the tolerance from its exact value (which it gets whenever it is touched itself). Below p1_floor the tolerance
  // is absolute (tol * p1_floor): a cluster the region nearly never sees keeps a small weight either way. The
  // decisions depend on the statistics only: deterministic. Work: the touched pairs and the moved ones' children.
  // Under the mean hierarchy a coarse pair's children are also refolded when its posterior mean k moved by more than
  // the tolerance (relative) since they were last examined for it; only the children whose own bound lies above the
  // lower of the two means (the others' prior mean is their bound either way).
  const double tol = params.refold_tolerance;
  const bool means = hier && uses_mean_hierarchy(params);
  constexpr double p1_floor = 0.1;
  auto moved_by = [&](double now, double then) { return std::fabs(now - then) > tol * std::max(then, p1_floor); };
  constexpr uint8_t p1_moved = 1, mean_moved = 2;
  std::vector<uint8_t>& moved = stats.scratch.seen;  // all zero between uses; sized for the old pairs
  // Touched pairs (their own statistics changed), flagging the coarse ones that moved.
  tbb::parallel_for(tbb::blocked_range<size_t>(0, touched.size(), 1024), [&](const tbb::blocked_range<size_t>& g) {
    for (size_t t = g.begin(); t < g.end(); t++) {
      // The statistics of the pair `ahead` folds on (scattered where the pass touched few pairs; each fold waits on
      // their load), and its parent's a little later (its index is in cache by then).
      constexpr size_t ahead = 8;
      if (t + ahead < g.end()) {
        _mm_prefetch(reinterpret_cast<const char*>(&stats.m[size_t(touched[t + ahead])]), _MM_HINT_T0);
        _mm_prefetch(reinterpret_cast<const char*>(&regions.pair_parent[size_t(touched[t + ahead])]), _MM_HINT_T0);
      }
      if (hier && t + ahead / 2 < g.end()) {
        int up = regions.pair_parent[size_t(touched[t + ahead / 2])];
        if (up != invalid_id) _mm_prefetch(reinterpret_cast<const char*>(&stats.m[size_t(up)]), _MM_HINT_T0);
      }
      size_t k = size_t(touched[t]);
      fold(k);
      // No children: a fine pair (its link is a sibling), or a coarse one whose fine regions do not exist yet.
      if (!hier || regions.pair_parent[k] != invalid_id || child_link[k] == invalid_id) continue;
      uint8_t flags = 0;
      float now = own_p1(stats, k, params);
      if (moved_by(now, stats.p1_folded[k])) {
        stats.p1_folded[k] = now;
        flags |= p1_moved;
      }
      if (means && std::fabs(own_posterior_mean(stats, k, params) - stats.k_folded[k]) > tol * stats.k_folded[k])
        flags |= mean_moved;
      moved[k] = flags;
    }
    folds.fetch_add(int64_t(g.size()), std::memory_order_relaxed);
  });
  // New pairs (their prior was just set).
  size_t pairs = stats.m.size();
  tbb::parallel_for(tbb::blocked_range<size_t>(old_pairs, pairs, 1024), [&](const tbb::blocked_range<size_t>& g) {
    for (size_t i = g.begin(); i < g.end(); i++) {
      fold(i);
      if (regions.pair_parent[i] == invalid_id) {
        stats.p1_folded[i] = own_p1(stats, i, params);
        stats.k_folded[i] = float(own_posterior_mean(stats, i, params));
      }
    }
    folds.fetch_add(int64_t(g.size()), std::memory_order_relaxed);
  });
  // Children of the moved pairs (each child has one parent: no pair is folded by two tasks). A child is refolded when
  // its parent's mean moved and its bound lies above the lower of the parent's two means (`low`), or when its own
  // p1 moved by more than the tolerance.
  auto child_moved = [&](size_t c, size_t up, uint8_t flags, float low) {
    return ((flags & mean_moved) && stats.mu0[c] > low) ||
           ((flags & p1_moved) && moved_by(pair_p1(stats, c, int(up), params), stats.p1_folded[c]));
  };
  // The parent's `low`, and its mean as its children are examined now.
  auto examine_parent = [&](size_t k, uint8_t flags) {
    float low = 0;
    if (flags & mean_moved) {
      float now = float(own_posterior_mean(stats, k, params));
      low = std::min(now, stats.k_folded[k]);
      stats.k_folded[k] = now;
    }
    return low;
  };
  size_t moved_parents = 0, parents = 0;
  if (hier) {
    for (int k : touched) moved_parents += moved[size_t(k)] != 0;
    parents = parent_pairs;
  }
  // Where many parents moved (the first passes: every coarse pair is learning), nearly every fine pair is examined:
  // one sequential scan of the pairs then beats walking each parent's list of children, which are scattered over
  // the fine regions (a cache miss per child). The same children are refolded either way, with the same inputs.
  const bool scan = hier && moved_parents * 16 > parents;
  if (scan) {
    std::vector<float>& low_of = stats.scratch.low;
    if (low_of.size() < moved.size()) low_of.resize(moved.size());
    for (int k : touched)
      if (moved[size_t(k)]) low_of[size_t(k)] = examine_parent(size_t(k), moved[size_t(k)]);
    const std::vector<int>& parent = regions.pair_parent;
    const size_t flagged = moved.size();  // parents created this pass (not touched) never moved
    tbb::parallel_for(tbb::blocked_range<size_t>(0, pairs, 4096), [&](const tbb::blocked_range<size_t>& g) {
      int64_t count = 0;
      for (size_t c = g.begin(); c < g.end(); c++) {
        int up = parent[c];
        if (up == invalid_id || size_t(up) >= flagged) continue;
        uint8_t flags = moved[size_t(up)];
        if (!flags || !child_moved(c, size_t(up), flags, low_of[size_t(up)])) continue;
        fold(c), count++;  // (members: every cluster is summed again below; no list)
      }
      folds.fetch_add(count, std::memory_order_relaxed);
    });
    for (int k : touched) moved[size_t(k)] = 0;
  } else if (hier) {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, touched.size(), 1024), [&](const tbb::blocked_range<size_t>& g) {
      int64_t count = 0;
      for (size_t t = g.begin(); t < g.end(); t++) {
        int k = touched[t];
        uint8_t flags = moved[size_t(k)];
        if (!flags) continue;
        moved[size_t(k)] = 0;
        float low = examine_parent(size_t(k), flags);
        for (int c = child_link[size_t(k)]; c != invalid_id; c = child_link[size_t(c)])
          if (child_moved(size_t(c), size_t(k), flags, low)) {
            if (regions.members && !dirty[size_t(c)]) children.local().push_back(c);  // not listed yet
            fold(size_t(c)), count++;
          }
      }
      folds.fetch_add(count, std::memory_order_relaxed);
    });
  }
  timing.refolds += double(folds.load());
  if (!regions.members) return;
  if (scan) {
    // Most pairs were refolded: one sweep over the regions instead of a list of the refolded pairs, in which the
    // clusters with a refolded (flagged) member sum their members again.
    refresh_groups(nullptr, true);
    std::fill(dirty.begin(), dirty.end(), uint8_t(0));
    return;
  }
  // The clusters of every refolded pair (listed once each) sum their members' weights again.
  std::vector<int> folded(touched);
  for (size_t i = old_pairs; i < pairs; i++) folded.push_back(int(i));
  for (const std::vector<int>& c : children) folded.insert(folded.end(), c.begin(), c.end());
  refresh_groups(&folded);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, folded.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t t = r.begin(); t < r.end(); t++) dirty[size_t(folded[t])] = 0;
  });
}

}  // namespace bl
