// integrator: one path sample — camera ray, emission seen, NEE at every vertex through the light sampler,
// BSDF continuation with MIS (power heuristic), Russian roulette from the third bounce (roulette_scale).
// Invariants: max_depth D counts bounces: NEE runs at vertices 1..D; at vertex D it is unweighted and the
// path ends (D = 1 is pure light sampling, the paper's direct-only mode); emission reached by BSDF sampling
// from vertex k < D is MIS-weighted against NEE at k using the sampler's pmf at k, except a light that a control
// variate covers at k (bayes): NEE takes it alone, unweighted, and its BSDF-sampled hit weighs 0 (both strategies'
// weights still sum to 1 for every light and direction). All randomness comes from draw_vertex(key, vertex) in the
// dimension table of rng.h. Never returns a non-finite value.
#pragma once

#include "bvh.h"
#include "camera.h"
#include "light_sampler_types.h"
#include "light_points.h"
#include "lights.h"
#include "material.h"
#include "profile_timers.h"
#include "rng.h"
#include "sampling.h"
#include "scene.h"

#include <cstdint>
#include <type_traits>

namespace bl {

// Whether a sampler offers control variates (cv_total / cv_cluster on its context).
template <class S, class = void>
struct has_control_variates : std::false_type {};
template <class S>
struct has_control_variates<S, std::void_t<decltype(&S::cv_total)>> : std::true_type {};

// Whether the previous vertex's NEE took `light` unweighted under a control variate (its BSDF-sampled hit then
// weighs 0).
template <class S>
bool covered_by_cv(const S& sampler, const typename S::context& ctx, int light) {
  if constexpr (has_control_variates<S>::value) return sampler.cv_covers_light(ctx, light);
  else return false;
}

// The read-only inputs of path sampling.
struct render_inputs {
  const scene_data* scene = nullptr;
  const bvh_data* bvh = nullptr;
  const light_data* lights = nullptr;
  camera_data camera;
  int max_depth = 5;
  uint64_t seed = 0;
  // The first vertex's light and BSDF dimensions are stratified over sets of a pixel's samples (rng.h,
  // stratify_sample): for the light choice and point, samples from stratum_base on form one set, keyed by
  // stratum_key (stratum_key_of). A sampler without learning has one light set for the whole render; a learning one
  // a new set at every change of its model (every pass while it learns), so that no light sample depends on an
  // earlier sample its model learned from. The BSDF direction has one set for the whole render with every sampler
  // (rng.h, stratify_sample, says what that costs bayes's unbiasedness).
  bool stratify = true;
  uint64_t stratum_base = 0, stratum_key = 0;
  // NEE samples per vertex (light choice, point and shadow ray each; the point's pmf built once): their mean is the
  // vertex's NEE estimate, MIS-weighted as nee_samples draws against one BSDF draw.
  int nee_samples = 1;
  // Light points per NEE draw at the first vertex (light_points.h): K points on the chosen light, each with its
  // shadow ray, averaged. One count for the whole image (light_points), or with point_tiles (--light-points auto)
  // the count of the pixel's tile of point_tile_size^2 pixels, point_tile_cols tiles to a row.
  int light_points = 1;
  const uint8_t* point_tiles = nullptr;
  int point_tile_cols = 0;
  // With point_tiles and stratify: the pass's first sample and the key of its light-point sets, one per pixel
  // (pass_point_uv; stratum_key_of of a seed of their own and point_base).
  uint64_t point_base = 0, point_key = 0;
};

// What one sample reports beside its radiance (the choice of light points, light_points.h).
struct sample_info {
  // Sum over the first vertex's NEE draws of the sample variance of their points' contributions (each taken as if it
  // were the draw's only point): what the variance inside the chosen lights adds to a sample of one point per draw
  // (unbiased for independent points; the lattice's points, spread more evenly, make it an overestimate). 0 with one
  // point.
  double within = 0;
  int points = 1;  // light points per draw at the first vertex
  // Input: the point sets of the lights the pixel drew so far in this run of the pass (light_pass_point_uv); null:
  // the pass's shared point set for every draw.
  light_point_sets* light_sets = nullptr;
};

// Counters of one worker's share of a pass (summed in a fixed order afterwards).
struct path_stats {
  uint64_t camera_rays = 0, shadow_rays = 0, bounce_rays = 0, nee_samples = 0, nee_zero = 0, bad_samples = 0;
  uint64_t first_draws = 0, first_points = 0;  // the first vertex's NEE draws, and the light points they drew
};
inline void add_stats(path_stats& a, const path_stats& b) {
  a.camera_rays += b.camera_rays;
  a.shadow_rays += b.shadow_rays;
  a.bounce_rays += b.bounce_rays;
  a.nee_samples += b.nee_samples;
  a.nee_zero += b.nee_zero;
  a.bad_samples += b.bad_samples;
  a.first_draws += b.first_draws;
  a.first_points += b.first_points;
}

// A sink that drops NEE events (non-learning samplers).
struct null_sink {
  template <class E>
  void record(const E&) {}
};

// The shadow ray of light sample ls at sp: between both points, each moved off its own surface by min_ray_epsilon
// (so neither the receiver nor the emitter itself can block it, even at grazing angles, while a lamp just above a
// floor stays lit and a thin occluder beside the point still casts its shadow); toward the sun, unbounded. tmax = 0
// when both ends coincide (nothing can block the sample). The emitter's end also stays off the emitter by a millionth
// of the ray's length: the ray's direction and length are rounded to float, and Embree's hit distance too, by a few
// ulps of that length, so a lamp whose own coordinates are small (near the origin) lying far from the point was hit by
// its own shadow ray (a review: a 10 cm lamp at y = 0 lit a floor 2 below it to 9 % of the right value, 86 % of its
// samples blocked).
struct shadow_ray {
  vec3f org, dir;
  float tmax = 0;
};
inline shadow_ray shadow_ray_of(const scene_data& scene, const surface_point& sp, const light_sample& ls) {
  vec3f o = offset_along(sp.p, sp.ng, ls.wi, min_ray_epsilon(scene, sp.tri, sp.p));
  if (ls.dist == inf_f) return {o, ls.wi, inf_f};
  vec3f target = offset_along(ls.p, ls.n, -ls.wi, std::max(min_ray_epsilon(scene, ls.tri, ls.p), 1e-6f * ls.dist));
  vec3f d = target - o;
  float t = length(d);
  if (!(t > 0)) return {o, ls.wi, 0.0f};
  return {o, d / t, t};
}
// Whether the light sample is visible from sp.
inline bool unoccluded(const render_inputs& in, const surface_point& sp, const light_sample& ls) {
  shadow_ray r = shadow_ray_of(*in.scene, sp, ls);
  return !(r.tmax > 0) || !occluded(*in.bvh, r.org, r.dir, r.tmax);
}

// The closest hit of a BSDF continuation ray leaving triangle `tri` at its point p (geometric normal ng) in
// direction d. From p itself (an origin moved toward a lamp a few offsets away would see it under a larger solid
// angle, and one moved past it would miss it), counting hits from where the ray is min_ray_epsilon above the
// surface, or at most 2 min_ray_epsilon along it for rays within 30 degrees of the surface (a grazing ray would
// otherwise step over a wall next to the point): far enough for rounding, close enough not to step over a lamp just
// above the surface. A ray leaving a plane cannot hit that plane again, but p lies a few ulps off it, and a grazing
// ray can cross it (the triangle left or a coplanar neighbour, at any distance): a hit on `tri`, or on a triangle
// parallel to it whose plane passes within rounding of p, is traced again from the ray_epsilon offset.
// hit.t is measured from the origin used.
// continuation_tnear: where along the ray hits start to count.
inline float continuation_tnear(const scene_data& scene, int tri, vec3f p, vec3f ng, vec3f d) {
  return min_ray_epsilon(scene, tri, p) / std::max(std::fabs(dot(ng, d)), 0.5f);
}
inline hit_info continuation_hit(const render_inputs& in, int tri, vec3f p, vec3f ng, vec3f d) {
  const scene_data& scene = *in.scene;
  hit_info h = intersect(*in.bvh, p, d, inf_f, continuation_tnear(scene, tri, p, ng, d));
  if (h.tri == invalid_id) return h;
  if (h.tri != tri) {
    // The plane distance in float errs by a few ulps of |p - corner|, which for a large triangle can exceed
    // min_ray_epsilon at p: the tolerance takes 1e-6 of that length on top (about 8 ulps).
    vec3f n = scene.tri_ng[size_t(h.tri)], v = p - scene.tri_p0[size_t(h.tri)];
    bool same_plane = std::fabs(dot(n, ng)) > 0.9999f &&
                      std::fabs(dot(n, v)) <= min_ray_epsilon(scene, tri, p) + 1e-6f * max_abs_component(v);
    if (!same_plane) return h;
  }
  return intersect(*in.bvh, offset_ray_origin(scene, tri, p, ng, d), d);
}

// The closest hit of a camera ray in direction d. An eye on a surface's plane (a hand-written ground at y = 0 and an
// eye at y = 0) would see every ray leaving it hit that surface at t = 0, an image all black or all its back face (a
// review): such a hit is skipped as continuation_hit skips the surface a ray leaves.
inline hit_info camera_hit(const render_inputs& in, vec3f d) {
  const scene_data& scene = *in.scene;
  hit_info h = intersect(*in.bvh, in.camera.eye, d);
  if (!scene.eye_on_a_plane || h.tri == invalid_id || !on_plane_of(scene, h.tri, in.camera.eye)) return h;
  return continuation_hit(in, h.tri, in.camera.eye, scene.tri_ng[size_t(h.tri)], d);
}

// Russian roulette from the third vertex keeps a path with probability min(1, roulette_scale * max(beta)): a path
// whose throughput is at least 1 / roulette_scale always goes on, and a survivor's throughput is raised to that level,
// not to 1. With 1 (pbrt-v4's rule), paths that crossed a dark wall into a room of bright lamps (the plant room's
// storeroom) were cut to a few survivors of large weight: in path-traced renders at 48 spp (seeds 12 / 13), relMSE
// times rays traced fell to 0.85 / 0.85 (bound) and 0.79 / 0.78 (bayes) of scale 1's in the plant room, 0.97 / 0.99 and
// 0.95 / 0.87 in the living room, 0.79 / 0.78 and 0.63 / 0.62 in the hall, 0.79 / 0.80 and 0.81 / 0.81 in the
// Cornell box; scales 2 and 5 scored 0.92-1.14x of 3, no roulette (up to max depth 5) 1.03-1.24x (README, Choosing a
// light sampler).
constexpr float roulette_scale = 3.0f;

// Radiance of sample `sample` of pixel (x, y). `ctxs` are the light-selection contexts of the current and the
// previous vertex (alternating by depth); the caller keeps them across samples of a row, so that samplers can
// reuse per-point work between neighbouring samples (e.g. a region lookup). `tm` times the hot path's stages
// (profile_timers.h; no_timers compiles every timer away).
template <class Sampler, class Sink, class Timers>
vec3f trace_path_timed(const render_inputs& in, const Sampler& sampler, int x, int y, const pixel_streams& ps,
                       uint64_t sample, path_stats& st, Sink& sink, typename Sampler::context (&ctxs)[2], Timers& tm,
                       sample_info* info = nullptr) {
  const scene_data& scene = *in.scene;
  const light_data& lights = *in.lights;
  int pixel = y * in.camera.width + x;
  uint64_t key = sample_key_from(ps.key_base, sample);
  uint64_t t0 = tm.start();
  float jx, jy;
  jitter_at(ps.shift_x, ps.shift_y, sample, jx, jy);
  vec3f org = in.camera.eye;
  vec3f dir = camera_ray_dir(in.camera, float(x) + jx, float(y) + jy);
  st.camera_rays++;

  vec3f radiance = {0, 0, 0}, beta = {1, 1, 1};
  bool prev_mis = false;           // the current ray was BSDF-sampled at a vertex that also ran weighted NEE
  float prev_bsdf_pdf = 0;
  float prev_nee_points = 1;       // ... whose NEE drew this many light points (draws times points per draw)
  const int points1 = in.point_tiles ? int(in.point_tiles[point_tile_of(x, y, in.point_tile_cols)]) : in.light_points;
  if (info) info->within = 0, info->points = points1;
  int from_tri = invalid_id;       // a continuation ray: the triangle it leaves, and its normal (org is its point)
  vec3f from_ng;
  for (int depth = 1;; depth++) {
    if (depth > 1) t0 = tm.start();
    hit_info h = depth == 1 ? camera_hit(in, dir) : continuation_hit(in, from_tri, org, from_ng, dir);
    tm.stop(depth == 1 ? prof_camera : prof_bounce, t0);
    t0 = tm.start();
    if (h.tri == invalid_id) {
      if (in_sun_disk(lights, dir)) {
        float w = 1;
        if (prev_mis && covered_by_cv(sampler, ctxs[(depth - 1) & 1], lights.sun))
          w = 0;
        else if (prev_mis)
          w = power_heuristic(prev_bsdf_pdf, prev_nee_points * sampler.pmf(ctxs[(depth - 1) & 1], lights.sun) *
                                                 cone_pdf(lights.sun_one_minus_cos));
        radiance += beta * lights.sun_radiance * w;
      }
      break;
    }
    surface_point sp = eval_surface(scene, h.tri, h.b1, h.b2, h.p, dir);
    vec3f wo = -dir;
    int hit_light = lights.light_of_tri[h.tri];
    if (hit_light != invalid_id) {
      vec3f le = emitted_radiance(lights, hit_light, sp.front);
      if (!is_black(le)) {
        float w = 1;
        if (prev_mis && covered_by_cv(sampler, ctxs[(depth - 1) & 1], hit_light)) {
          w = 0;
        } else if (prev_mis) {
          float cos_l = std::fabs(dot(scene.tri_ng[h.tri], dir));
          float light_pdf = prev_nee_points * sampler.pmf(ctxs[(depth - 1) & 1], hit_light) *
                            triangle_light_pdf(scene, lights, hit_light, org, h.t, cos_l);
          w = power_heuristic(prev_bsdf_pdf, light_pdf);
        }
        radiance += beta * le * w;
      }
    }
    bsdf_data bsdf = make_bsdf(scene, sp);
    if (is_black_bsdf(bsdf)) {
      tm.stop(prof_shading, t0);
      break;
    }
    vertex_randoms r = draw_vertex(key, uint32_t(depth));
    // (The light point's own numbers, before stratification: --light-points auto's points, below.)
    const float fresh_u = r.u[dim_light_u], fresh_v = r.u[dim_light_v];
    bool last = depth >= in.max_depth;
    if (depth == 1 && in.stratify)
      stratify_sample(ps, sample, in.stratum_base, last, r);
    typename Sampler::context& ctx = ctxs[depth & 1];
    shade_point spt = make_shade_point(sp.p, bsdf, wo, pixel, depth, last);
    if (depth == 1) spt.footprint = pixel_footprint(in.camera, h.t, std::fabs(dot(scene.tri_ng[h.tri], dir)));
    tm.stop(prof_shading, t0);
    if constexpr (Timers::enabled) {
      // Profiles time the region lookup apart; prepare() then finds it cached.
      t0 = tm.start();
      sampler.locate(ctx, spt);
      tm.stop(prof_region, t0);
    }
    t0 = tm.start();
    sampler.prepare(ctx, spt);
    tm.stop(prof_pmf, t0);

    // Next-event estimation: nee_samples draws, each its own light choice and shadow ray, and at the first vertex
    // `points` points on the chosen light (a shifted lattice, light_point_uv), each with its shadow ray.
    // --light-points auto chooses a pixel's count from what earlier samples measured, its own among them; the
    // stratified light point of a sample depends on the set's earlier points, so a count chosen from their outcomes
    // would bias the estimate (as a model learned from them would: the light sets restart when a model changes). So
    // under auto the points come from sets of the pass's own, one per light a pixel's draws chose (light_pass_point_uv;
    // past light_point_sets::max_lights lights in a pixel's pass, one shared by the rest: pass_point_uv), whose
    // counts were chosen before it began (unstratified samples: the sample's own numbers, as a lattice), and MIS
    // weighs them as one point per draw (both sides): given the light chosen, each count then has the same
    // expectation, which no choice of count can tilt. The light choice, the BSDF direction and the camera jitter stay
    // stratified as without auto.
    const int n_nee = in.nee_samples;
    const int points = depth == 1 ? points1 : 1;
    const bool chosen_points = depth == 1 && in.point_tiles != nullptr;
    const float inv_n = 1.0f / float(n_nee), inv_points = 1.0f / float(points);
    const float nee_points = float(n_nee) * float(chosen_points ? 1 : points);
    for (int k = 0; k < n_nee; k++) {
      vertex_randoms rk_own;
      const vertex_randoms* rk = &r;
      float point_u = fresh_u, point_v = fresh_v;
      const bool pass_points = chosen_points && in.stratify;
      const uint64_t point_draw = pass_points ? (sample - in.point_base) * uint64_t(n_nee) + uint64_t(k) : 0;
      if (n_nee > 1) {
        if (k > 0) {
          rk_own = draw_vertex(key, uint32_t(depth) | (uint32_t(k) << 20)), rk = &rk_own;
          point_u = rk_own.u[dim_light_u], point_v = rk_own.u[dim_light_v];
        } else {
          rk_own = r, rk = &rk_own;
        }
        if (depth == 1 && in.stratify)
          stratify_light_with(ps.strata, uint32_t((sample - in.stratum_base) * uint64_t(n_nee) + uint64_t(k)), rk_own);
      }
      t0 = tm.start();
      light_choice choice = sampler.sample(ctx, rk->u53(dim_light_select, dim_light_select_lo),
                                           rk->u53(dim_light_inner, dim_light_inner_lo));
      tm.stop(prof_select, t0);
      if (!(choice.light != invalid_id && choice.prob > 0)) continue;
      bool cv_light = false;
      if constexpr (has_control_variates<Sampler>::value) cv_light = sampler.cv_covers(ctx, choice.cluster);
      st.nee_samples++;
      if (depth == 1) st.first_draws++, st.first_points += uint64_t(points);
      // (Under auto, stratified: the points of this light's own set, light_pass_point_uv; null: the pass's shared set.)
      light_point_set* light_set = pass_points && info && info->light_sets
                                       ? info->light_sets->set_of(choice.light, point_draw, points)
                                       : nullptr;
      const uint32_t light_draw = light_set ? light_set->draws++ : 0;
      float value = 0, added = 0, added_total = 0;
      vec3f unweighted_sum = {0, 0, 0}, add_sum = {0, 0, 0};
      bool seen = false;  // a point was visible
      double c_sum = 0, c_sq = 0;  // the points' contributions, each as a draw's only point (sample_info::within)
      for (int j = 0; j < points; j++) {
        t0 = tm.start();
        float u = chosen_points ? point_u : rk->u[dim_light_u], v = chosen_points ? point_v : rk->u[dim_light_v];
        if (light_set) light_pass_point_uv(*light_set, light_draw, points, j, u, v);
        else if (pass_points) pass_point_uv(ps.point, point_draw, points, j, u, v);
        else if (points > 1) light_point_uv(points, j, u, v);
        light_sample ls = sample_light_point(lights, scene, choice.light, sp.p, u, v);
        vec3f fc = ls.pdf > 0 ? eval_bsdf_cos(bsdf, wo, ls.wi) : vec3f{0, 0, 0};
        tm.stop(prof_point, t0);
        if (!(ls.pdf > 0) || is_black(fc)) continue;
        st.shadow_rays++;
        t0 = tm.start();
        bool visible = unoccluded(in, sp, ls);
        tm.stop(prof_shadow, t0);
        if (!visible) continue;
        seen = true;
        vec3f unweighted = fc * ls.le / ls.pdf;
        // Unweighted at the last vertex, and for a light a control variate covers (its BSDF-sampled hits weigh 0).
        float w = last || cv_light ? 1.0f
                                   : power_heuristic(nee_points * choice.prob * ls.pdf, bsdf_pdf(bsdf, wo, ls.wi));
        vec3f one = beta * unweighted * (w * inv_n / choice.prob);
        unweighted_sum += unweighted;
        add_sum += one;
        if (points > 1) {
          double c = double(luminance(one));
          c_sum += c, c_sq += c * c;
        }
      }
      if (points > 1) {
        unweighted_sum = unweighted_sum * inv_points, add_sum = add_sum * inv_points;
        // Sum of squared deviations from the mean, over points - 1 (clamped: rounding can leave it a hair below 0).
        if (info) info->within += std::max(0.0, (c_sq - c_sum * c_sum / points) / (points - 1));
      }
      if (seen) {
        radiance += add_sum;
        value = luminance(unweighted_sum) / choice.prob_in_cluster;
        added = added_total = luminance(add_sum);
      }
      if constexpr (has_control_variates<Sampler>::value) {
        // Control variate: sum_j c_j + (Y_J - c_J) / P_J, the Y_J / P_J part added above (unweighted where c_J != 0;
        // a cluster without one has c_J = 0 and keeps its MIS weight); c_j in colour is the cluster's learned
        // albedo-free mean times (kd + ks) / pi. (Over nee_samples draws the sum is added once: each draw adds its
        // share.)
        if (ctx.cv) {
          vec3f c = sampler.cv_total(ctx) - sampler.cv_cluster(ctx, choice.cluster) * float(1 / choice.cluster_prob);
          vec3f add = beta * (bsdf.kd + bsdf.ks) * inv_pi_f * c * inv_n;
          radiance += add;
          added_total += luminance(add);
        }
      }
      st.nee_zero += value == 0;
      // An estimate that overflowed (a receiver a hair from a lamp of radiance near float's limit) is dropped from
      // the image with its path (bad_samples, below); a learner must not record it either: an infinite z makes a
      // pair's mean inf and its squared deviations NaN for good.
      if constexpr (Sampler::learns) {
        if (std::isfinite(value) && std::isfinite(added) && std::isfinite(added_total)) {
          t0 = tm.start();
          sink.record(
              nee_event<typename Sampler::context>{&ctx, choice, value, pixel, added, added_total, depth == 1});
          tm.stop(prof_record, t0);
        }
      }
    }
    if (last) break;

    // BSDF continuation.
    t0 = tm.start();
    bsdf_sample bs = sample_bsdf(bsdf, wo, r.u[dim_bsdf_u], r.u[dim_bsdf_v]);
    vec3f fc = bs.pdf > 0 ? eval_bsdf_cos(bsdf, wo, bs.wi) : vec3f{0, 0, 0};
    bool go_on = bs.pdf > 0 && !is_black(fc);
    if (go_on) {
      beta = beta * fc / bs.pdf;
      if (depth >= 3) {
        float q = std::min(1.0f, roulette_scale * max_component(beta));
        go_on = r.u[dim_roulette] < q;
        if (go_on) beta = beta / q;
      }
    }
    tm.stop(prof_continue, t0);
    if (!go_on) break;
    prev_mis = true;
    prev_bsdf_pdf = bs.pdf;
    prev_nee_points = nee_points;
    org = sp.p;  // continuation_hit starts the ray at the point itself
    dir = bs.wi;
    from_tri = h.tri, from_ng = sp.ng;
    st.bounce_rays++;
  }
  if (!is_finite(radiance)) {
    st.bad_samples++;
    return {0, 0, 0};
  }
  return radiance;
}

// trace_path_timed without timers, computing the pixel's streams itself (tests; renders compute them once per pixel).
template <class Sampler, class Sink>
vec3f trace_path(const render_inputs& in, const Sampler& sampler, int x, int y, uint64_t sample, path_stats& st,
                 Sink& sink, typename Sampler::context (&ctxs)[2], sample_info* info = nullptr) {
  no_timers tm;
  pixel_streams ps = pixel_streams_of(in.seed, in.stratum_key, uint64_t(y * in.camera.width + x), in.point_key);
  return trace_path_timed(in, sampler, x, y, ps, sample, st, sink, ctxs, tm, info);
}

}  // namespace bl
