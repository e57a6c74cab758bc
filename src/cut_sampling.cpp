// cut_sampling: region lookup, cdf construction, cluster + intensity-descent sampling and its pmf.
#include "cut_sampling.h"

#include "sampling.h"

#include <algorithm>

namespace bl {

namespace {
// Points the context at a region's cut, pairs and members.
void use_region(cut_context& ctx, const region_state& regions, const region_entry& e) {
  ctx.region = e.id;
  ctx.region_key = e.key;
  ctx.pair_base = e.pair_offset;
  ctx.count = e.cut_size;
  ctx.nodes = regions.cut_nodes.data() + e.cut_offset;
  ctx.tree_count = ctx.count - (regions.has_sun ? 1 : 0);
  ctx.pair_count = e.pair_count;
  ctx.members = regions.pair_node.data() + e.pair_offset;
  ctx.member_begin = regions.member_begin.data() + e.cut_offset;
  ctx.group_base = e.cut_offset;
  ctx.cut_count = ctx.count, ctx.cut_tree_count = ctx.tree_count, ctx.cut_nodes = ctx.nodes;
}
}  // namespace

void locate_region(cut_context& ctx, const region_state& regions, const shade_point& sp, bool cut_only) {
  ctx.p = sp.p;
  ctx.n = sp.n;
  ctx.albedo = sp.albedo;
  // A sampler that reads only the cut, in a scene whose regions all share cut 0: the root's entry serves every point
  // (no cell key, no lookup).
  if (cut_only && regions.shared_cut) {
    constexpr uint64_t shared_key = ~uint64_t(1);  // a marker no lookup sets (cell keys use fewer bits)
    if (ctx.fine_key == shared_key) return;
    ctx.fine_key = shared_key;
    const region_entry* e = find_region_entry(regions, regions.key[size_t(regions.root)]);
    use_region(ctx, regions, *e);
    return;
  }
  uint64_t key = fine_region_key(regions.grid, sp.p);
  // Deep path vertices are few per cell and scattered: they use (and pool their samples in) coarse regions,
  // whose small table stays in cache.
  // A first hit whose pixel covers more than its fine cell can learn from (bayes: region_params::min_pixels) uses the
  // coarse region too.
  bool coarse = sp.depth > regions.params.fine_depth ||
                (!cut_only && footprint_too_large(regions.params, regions.grid, sp.footprint));
  if (coarse) key = parent_region_key(regions.grid, key, 1);
  // Neighbouring samples often fall in the same cell: reuse the last lookup (regions are frozen during a pass).
  if (key != ctx.fine_key) {
    ctx.fine_key = key;
    const region_entry* e = find_region_entry(regions, key);
    if (!e && !coarse) e = find_region_entry(regions, parent_region_key(regions.grid, key, 1));
    if (!e) e = find_region_entry(regions, regions.key[size_t(regions.root)]);
    use_region(ctx, regions, *e);
  }
}

bool finish_cdf(cut_context& ctx, const double* w) { return fill_cdf(w, ctx.count, ctx.cdf); }

light_choice sample_cut(const cut_context& ctx, const light_tree_data& tree, const light_data& lights, double u,
                        double u_inner) {
  if (ctx.count == 0 || !(ctx.cdf[ctx.count] > 0)) return {};
  int j = sample_cdf(ctx.cdf, ctx.count, u);
  double pj = cluster_pmf(ctx, j);
  if (!(pj > 0)) return {};
  int node = ctx.nodes[j];
  if (node == sun_cluster) return {lights.sun, float(pj), j, 1.0f, pj};
  double inner = 1;
  int leaf = sample_by_intensity(tree, node, place_in_cell(u, ctx.cdf[j], pj, u_inner), inner);
  return {tree.light[size_t(leaf)], float(pj * inner), j, float(inner), pj};
}

float cut_pmf(const cut_context& ctx, const light_tree_data& tree, const light_data& lights, int light) {
  if (ctx.count == 0) return 0;
  if (light == lights.sun)
    return ctx.nodes[ctx.count - 1] == sun_cluster ? float(cluster_pmf(ctx, ctx.count - 1)) : 0.0f;
  int leaf = tree.leaf_of_light[size_t(light)];
  int j = holding_entry(tree, leaf, ctx.nodes, ctx.nodes + ctx.tree_count);
  if (j < 0) return 0;  // the light's subtree was left out of the cut: it cannot reach this region
  return float(cluster_pmf(ctx, j) * intensity_descent_pmf(tree, ctx.nodes[j], leaf));
}

int holding_entry(const light_tree_data& tree, int leaf, const int* begin, const int* end) {
  for (int n = leaf; n != invalid_id; n = tree.parent[size_t(n)]) {
    const int* it = std::lower_bound(begin, end, n);
    if (it != end && *it == n) return int(it - begin);
  }
  return -1;
}

int create_requested_regions(region_state& regions, const light_tree_data& tree,
                             const std::vector<const region_requests*>& rows) {
  std::vector<uint64_t> ready;
  for (const region_requests* r : rows)
    for (size_t k = 0; k < r->keys.size(); k++)
      if (add_pending(regions, r->keys[k], r->counts[k])) ready.push_back(r->keys[k]);
  if (ready.empty()) return 0;
  std::sort(ready.begin(), ready.end());
  ready.erase(std::unique(ready.begin(), ready.end()), ready.end());
  for (uint64_t key : ready) remove_pending(regions, key);
  return add_regions(regions, tree, ready);
}

void sun_half_angle(const light_data& lights, float& sin_out, float& cos_out) {
  float omc = lights.sun_one_minus_cos;
  cos_out = 1 - omc;
  sin_out = safe_sqrt(omc * (2 - omc));
}

}  // namespace bl
