// bvh_sampler: light selection by stochastic descent of the light tree (Conty Estevez & Kulla 2018, the
// approach of pbrt-v4's BVH light sampler): at every interior node a child is chosen proportionally to its
// importance for the shading point; the sun competes with the tree's root at the top.
// Invariants: pmf(ctx, light) recomputes exactly the products sample() forms (same order, same floats);
// lights that provably cannot reach the point get probability 0, all others > 0.
#pragma once

#include "light_sampler_types.h"
#include "light_tree.h"

namespace bl {

// The bvh sampler over a light tree it does not own.
struct bvh_sampler {
  static constexpr bool learns = false;
  // Per shading point: the point and the top-level split between the sun and the tree.
  struct context {
    vec3f p, n;
    double p_sun = 0;    // probability of the sun
    double p_tree = 0;   // probability of the tree (1 - p_sun, or 0)
  };
  const light_tree_data* tree = nullptr;
  const light_data* lights = nullptr;
  float sun_sin = 0, sun_cos = 1;  // sun disk half-angle

  void locate(context&, const shade_point&) const {}
  void prepare(context& ctx, const shade_point& sp) const { prepare_at(ctx, sp.p, sp.n); }
  void prepare_at(context& ctx, vec3f p, vec3f n) const;
  light_choice sample(const context& ctx, double u, double) const;
  float pmf(const context& ctx, int light) const;
  void end_pass() {}
  void begin_frame(double) {}
};

// Importance of the sun for a receiver normal n: luminance(E) * cos bound over the disk.
float sun_importance(const light_data& lights, vec3f n, float sun_sin, float sun_cos);

}  // namespace bl
