// donikian_sampler: per-pixel / per-block contribution estimates, their blend, and learning between passes.
#include "donikian_sampler.h"

#include "cluster_bounds.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace bl {

// sum += v, at most float's largest value: a sample a hair from a lamp near float's limit (or many of them) would
// make the estimate infinite for good (and the render's checkpoint unreadable); the estimates only steer the pmf.
// (v >= 0: the sum of float additions as before, so images are unchanged below the cap.)
static void add_capped(float& sum, float v) {
  float t = sum + v;
  sum = std::isfinite(t) ? t : std::numeric_limits<float>::max();
}

void donikian_row::clear() {
  requests.clear();
  y = -1;
  std::fill(sum.begin(), sum.end(), 0.0f);
  std::fill(count.begin(), count.end(), 0.0f);
}

void donikian_sampler::prepare(context& ctx, const shade_point& sp) const {
  if (sp.depth > 1) {
    deeper.prepare(ctx, sp);
    ctx.pixel = invalid_id;
    return;
  }
  // First hit: the scene-wide cut, weighted from the pixel's and its block's estimates.
  int k = clusters();
  ctx.p = sp.p;
  ctx.n = sp.n;
  ctx.albedo = sp.albedo;
  ctx.region = invalid_id;
  ctx.fine_key = ~uint64_t(0);  // the context may serve a deeper vertex next: forget the cached region
  ctx.pixel = sp.pixel;
  ctx.nodes = cut.data();
  ctx.count = k;
  ctx.tree_count = tree_count;
  ctx.members = cut.data();  // one member per cluster
  ctx.pair_count = k;
  int x = sp.pixel % width, y = sp.pixel / width;
  int bw = (width + params.block - 1) / params.block;
  size_t b = size_t(y / params.block) * size_t(bw) + size_t(x / params.block);
  double n_pix = pixel_count[size_t(sp.pixel)], n_blk = block_count[b];
  double w[max_cut_entries];
  double total = 0;
  if (n_pix + n_blk > 0) {
    double alpha = n_pix / (n_pix + params.pixel_half);
    const float* ps = &pixel_sum[size_t(sp.pixel) * size_t(k)];
    const float* bs = &block_sum[b * size_t(k)];
    for (int j = 0; j < k; j++) {
      double e_pix = n_pix > 0 ? ps[j] / n_pix : 0.0, e_blk = n_blk > 0 ? bs[j] / n_blk : 0.0;
      w[j] = alpha * e_pix + (1 - alpha) * e_blk;
      total += w[j];
    }
  }
  if (total > 0 && std::isfinite(total)) {
    // Estimates normalised, with the minimum probability spread evenly over every cluster.
    for (int j = 0; j < k; j++) w[j] = (1 - params.min_share) * w[j] / total + params.min_share / k;
  } else {
    // Nothing learned yet for this pixel: the bound at the point.
    float num[max_cut_entries + 3], inv_d2[max_cut_entries + 3];
    if (tree_count > 0) eval_node_bounds(*tree, cut.data(), tree_count, sp.p, sp.n, num, inv_d2);
    for (int j = 0; j < tree_count; j++) w[j] = num[j] * inv_d2[j];
    if (tree_count < k) w[tree_count] = cluster_bound(*tree, *lights, sun_cluster, sp.p, sp.n, sun_sin, sun_cos);
    // Keep every cluster possible (clusters the bound culls may still be learned about).
    double sum = 0;
    for (int j = 0; j < k; j++) sum += w[j];
    for (int j = 0; j < k; j++) w[j] = sum > 0 ? (1 - params.min_share) * w[j] / sum + params.min_share / k : 1.0;
  }
  finish_cdf(ctx, w);
}

void donikian_sampler::record(row_state& row, const nee_event<context>& e) const {
  const cut_context& ctx = *e.context;
  if (ctx.pixel == invalid_id) {
    row.requests.add(ctx);
    return;
  }
  int j = e.choice.cluster;
  if (j < 0) return;
  int k = clusters();
  if (row.sum.empty()) {
    row.sum.assign(size_t(width) * size_t(k), 0.0f);
    row.count.assign(size_t(width), 0.0f);
  }
  int x = ctx.pixel % width;
  row.y = ctx.pixel / width;
  double pj = cluster_pmf(ctx, j);
  if (pj > 0) add_capped(row.sum[size_t(x) * size_t(k) + size_t(j)], float(e.value / pj));
  row.count[size_t(x)] += 1;
}

void donikian_sampler::learn(std::vector<row_state>& rows) {
  std::vector<region_requests> requests;
  requests.reserve(rows.size());
  for (row_state& r : rows) requests.push_back(std::move(r.requests));
  deeper.learn(requests);
  int k = clusters();
  for (const row_state& r : rows) {
    if (r.y < 0 || r.sum.empty()) continue;
    size_t base = size_t(r.y) * size_t(width);
    for (size_t i = 0; i < r.sum.size(); i++) add_capped(pixel_sum[base * size_t(k) + i], r.sum[i]);
    for (int x = 0; x < width; x++) pixel_count[base + size_t(x)] += r.count[size_t(x)];
  }
  // Block estimates: sums over each block's pixels, in a fixed order.
  std::fill(block_sum.begin(), block_sum.end(), 0.0f);
  std::fill(block_count.begin(), block_count.end(), 0.0f);
  int bw = (width + params.block - 1) / params.block;
  for (int y = 0; y < height; y++)
    for (int x = 0; x < width; x++) {
      size_t p = size_t(y) * size_t(width) + size_t(x);
      size_t b = size_t(y / params.block) * size_t(bw) + size_t(x / params.block);
      block_count[b] += pixel_count[p];
      for (int j = 0; j < k; j++)
        add_capped(block_sum[b * size_t(k) + size_t(j)], pixel_sum[p * size_t(k) + size_t(j)]);
    }
}

void donikian_sampler::begin_frame(double decay) {
  if (decay >= 1) return;
  float g = float(decay);
  for (float& v : pixel_sum) v *= g;
  for (float& v : pixel_count) v *= g;
  for (float& v : block_sum) v *= g;
  for (float& v : block_count) v *= g;
}

donikian_sampler make_donikian_sampler(const light_tree_data& tree, const light_data& lights, bound_sampler deeper,
                                       int width, int height, const donikian_params& params,
                                       const region_params& regions, const bbox3f& scene_bounds) {
  donikian_sampler s;
  s.tree = &tree;
  s.lights = &lights;
  s.deeper = std::move(deeper);
  s.params = params;
  s.width = width;
  s.height = height;
  s.sun_sin = s.deeper.sun_sin;
  s.sun_cos = s.deeper.sun_cos;
  vec3f m = extent(scene_bounds) * 1e-3f;
  s.cut = compute_light_cut(tree, {scene_bounds.lo - m, scene_bounds.hi + m}, lights.sun != invalid_id, regions);
  s.tree_count = int(s.cut.size()) - (lights.sun != invalid_id ? 1 : 0);
  int k = s.clusters();
  int bw = (width + params.block - 1) / params.block, bh = (height + params.block - 1) / params.block;
  s.pixel_sum.assign(size_t(width) * size_t(height) * size_t(k), 0.0f);
  s.pixel_count.assign(size_t(width) * size_t(height), 0.0f);
  s.block_sum.assign(size_t(bw) * size_t(bh) * size_t(k), 0.0f);
  s.block_count.assign(size_t(bw) * size_t(bh), 0.0f);
  return s;
}

}  // namespace bl
