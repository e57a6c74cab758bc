// bvh_sampler: importance-driven tree descent and its exact pmf.
#include "bvh_sampler.h"

namespace bl {

float sun_importance(const light_data& lights, vec3f n, float sun_sin, float sun_cos) {
  if (lights.sun == invalid_id) return 0;
  return luminance(lights.sun_irradiance) * receiver_cos_bound(n, lights.sun_dir, sun_sin, sun_cos);
}

void bvh_sampler::prepare_at(context& ctx, vec3f p, vec3f n) const {
  ctx.p = p;
  ctx.n = n;
  float is = sun_importance(*lights, n, sun_sin, sun_cos);
  float it = node_count(*tree) > 0 ? node_importance(*tree, 0, p, n) : 0.0f;
  ctx.p_sun = is > 0 ? left_share(is, it) : 0.0;
  ctx.p_tree = it > 0 ? 1 - ctx.p_sun : 0.0;
}

light_choice bvh_sampler::sample(const context& ctx, double u, double) const {
  if (ctx.p_sun > 0 && u < ctx.p_sun) return {lights->sun, float(ctx.p_sun)};
  if (!(ctx.p_tree > 0)) return {};
  u = std::min((u - ctx.p_sun) / ctx.p_tree, 0x1.fffffffffffffp-1);
  double prob = ctx.p_tree;
  int node = 0;
  while (!is_leaf(*tree, node)) {
    int l = tree->left[size_t(node)], r = tree->right[size_t(node)];
    float il = node_importance(*tree, l, ctx.p, ctx.n), ir = node_importance(*tree, r, ctx.p, ctx.n);
    // Both children unable to reach the point: this sample is lost (as in pbrt-v4); pmf() accounts for it.
    if (!(il + ir > 0)) return {};
    double pl = left_share(il, ir);
    if (u < pl) {
      u = std::min(u / pl, 0x1.fffffffffffffp-1);
      prob *= pl;
      node = l;
    } else {
      u = std::min((u - pl) / (1 - pl), 0x1.fffffffffffffp-1);
      prob *= 1 - pl;
      node = r;
    }
  }
  if (!(prob > 0)) return {};
  return {tree->light[size_t(node)], float(prob)};
}

float bvh_sampler::pmf(const context& ctx, int light) const {
  if (light == lights->sun) return float(ctx.p_sun);
  if (!(ctx.p_tree > 0)) return 0;
  int path[max_tree_depth + 1];
  int len = 0;
  for (int n = tree->leaf_of_light[size_t(light)]; n != 0; n = tree->parent[size_t(n)]) path[len++] = n;
  double prob = ctx.p_tree;
  for (int k = len - 1; k >= 0; k--) {
    int child = path[k], parent = tree->parent[size_t(child)];
    int l = tree->left[size_t(parent)], r = tree->right[size_t(parent)];
    float il = node_importance(*tree, l, ctx.p, ctx.n), ir = node_importance(*tree, r, ctx.p, ctx.n);
    if (!(il + ir > 0)) return 0;
    double pl = left_share(il, ir);
    prob *= child == l ? pl : 1 - pl;
  }
  return float(prob);
}

}  // namespace bl
