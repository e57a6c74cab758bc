// light_sampler: names of the closed set, construction of each sampler, region discovery.
#include "light_sampler.h"

#include "errors.h"
#include "integrator.h"

#include <algorithm>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace bl {

namespace {

// Fine region keys of the first hits of rays through every pixel centre (sorted, unique), rows traced in parallel
// (the sort makes the result independent of the split).
std::vector<uint64_t> camera_region_keys(const render_inputs& in, const region_grid_data& grid,
                                         const region_params& params) {
  int w = in.camera.width, h = in.camera.height;
  std::vector<std::vector<uint64_t>> rows(size_t(std::max(h, 0)));
  tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& range) {
    for (int y = range.begin(); y < range.end(); y++) {
      std::vector<uint64_t>& row = rows[size_t(y)];
      for (int x = 0; x < w; x++) {
        vec3f dir = camera_ray_dir(in.camera, float(x) + 0.5f, float(y) + 0.5f);
        hit_info hit = camera_hit(in, dir);  // (the render's own first hits)
        if (hit.tri == invalid_id) continue;
        surface_point sp = eval_surface(*in.scene, hit.tri, hit.b1, hit.b2, hit.p, dir);
        uint64_t key = fine_region_key(grid, sp.p);
        // (A hit whose pixel footprint is too large for its fine cell asks for the coarse region, as it samples
        // from that: region_params::min_pixels.)
        float footprint = pixel_footprint(in.camera, hit.t, std::fabs(dot(in.scene->tri_ng[size_t(hit.tri)], dir)));
        if (footprint_too_large(params, grid, footprint)) key = parent_region_key(grid, key, 1);
        if (row.empty() || row.back() != key) row.push_back(key);  // neighbours often share a cell
      }
      std::sort(row.begin(), row.end());
      row.erase(std::unique(row.begin(), row.end()), row.end());
    }
  });
  std::vector<uint64_t> keys;
  for (const auto& row : rows) keys.insert(keys.end(), row.begin(), row.end());
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  return keys;
}

// Regions of a cut-based sampler: the grid, the root, and the regions of directly visible surfaces.
region_state make_regions(const sampler_params& params, const render_inputs& in, const light_tree_data& tree) {
  const region_params rp = effective_region_params(params, in.max_depth, int64_t(in.camera.width) * in.camera.height);
  region_state s = make_region_state(in.scene->bounds, tree, in.lights->sun != invalid_id, rp);
  // The bound sampler reads only cuts: with one cut shared by all regions it needs no region but the root; nor does
  // bayes with one light (bayes_sampler::one_light).
  if (s.shared_cut && (params.kind != sampler_kind::bayes || in.lights->count <= 1)) return s;
  add_regions(s, tree, camera_region_keys(in, s.grid, rp));
  return s;
}

}  // namespace

region_params effective_region_params(const sampler_params& params, int max_depth, int64_t pixels) {
  region_params rp = params.regions;
  rp.max_cut = std::min(std::max(rp.max_cut, 1), max_cut_entries - 1);
  // Statistics per region (bayes) make regions matter even with a shared cut; its members (with the region prior
  // only) are learned refinements of the clusters.
  const bool learned = params.kind == sampler_kind::bayes, members = learned && params.bayes.region_prior;
  // Members by default in direct illumination only: there NEE at the first hit is the whole estimate, while in path
  // tracing most NEE events are at deep vertices and refined learning costs more time than it saves (README).
  if (rp.max_members < 0) rp.max_members = max_depth == 1 ? region_params::auto_members : 0;
  rp.max_members = members ? std::min(rp.max_members, max_cut_entries - 1) : 0;
  // The footprint rule is bayes's (bound reads only cuts, which a finer region only sharpens), from 320x240 pixels up:
  // smaller images have the coarser automatic grid instead, whose cells the rule would send to the coarse regions
  // nearly everywhere (README, Regions).
  if (!learned || pixels < region_params::footprint_pixels) rp.min_pixels = 0;
  if (rp.grid < 0) rp.grid = learned ? region_params::auto_grid(pixels) : region_params::default_grid;
  if (rp.max_pairs < 0)
    rp.max_pairs = learned ? std::max<int64_t>(1, std::min(region_params::default_pairs,
                                                           region_params::auto_pairs_per_pixel * pixels))
                           : region_params::default_pairs;
  return rp;
}

std::string coarse_grid_warning(const sampler_params& params, int max_depth, int64_t pixels, const bbox3f& bounds,
                                const light_data& lights, bool given_grid) {
  const sampler_kind k = params.kind;
  const region_params rp = effective_region_params(params, max_depth, pixels);
  const bool shared = shares_one_cut(int(lights.tri.size()), lights.sun != invalid_id, rp);
  // (donikian's regions serve the vertices past the first; bound's only cuts, which a shared cut makes one)
  const bool reads = (k == sampler_kind::bayes && lights.count > 1) || (k == sampler_kind::bound && !shared) ||
                     (k == sampler_kind::donikian && !shared && max_depth > 1);
  if (!reads) return "";
  float shortest = 0;
  const float cell = fine_cell_side(bounds, rp.grid, &shortest);
  const double asked = double(shortest) / std::max(1, rp.grid);
  if (!(double(cell) > 1.01 * asked)) return "";
  const bbox3f b = grid_bounds(bounds);
  const float longest = max_component(extent(b)), coords = std::max(max_abs_component(b.lo), max_abs_component(b.hi));
  char why[160], buf[768];
  if (double(cell) > double(longest) / ((1 << 20) - 1) * 1.0001)
    std::snprintf(why, sizeof why, "cells are no smaller than a few float ulps of coordinates %.3g from the origin",
                  double(coords));
  else
    std::snprintf(why, sizeof why, "at most 2^20 cells fit along its longest side, %.3g", double(longest));
  const std::string asker = given_grid ? "--grid " + std::to_string(rp.grid) : "the default grid";
  std::snprintf(buf, sizeof buf,
                "%s's regions are cells of side %.3g, %.3g times coarser than %s asks for (%d cells along the scene's "
                "shortest side, %.3g): %s. Regions that coarse learn little of what each part of the scene sees; a "
                "ground or backdrop far larger than the rest usually does it: leave it out, or cut it to the part in "
                "view",
                sampler_name(k), double(cell), double(cell) / asked, asker.c_str(), rp.grid, double(shortest), why);
  return buf;
}

const char* sampler_name(sampler_kind kind) {
  switch (kind) {
    case sampler_kind::uniform: return "uniform";
    case sampler_kind::power: return "power";
    case sampler_kind::bvh: return "bvh";
    case sampler_kind::bound: return "bound";
    case sampler_kind::donikian: return "donikian";
    case sampler_kind::bayes: return "bayes";
  }
  return "?";
}

bool parse_sampler_kind(const std::string& name, sampler_kind& kind) {
  for (sampler_kind k : all_sampler_kinds)
    if (name == sampler_name(k)) {
      kind = k;
      return true;
    }
  return false;
}

std::string sampler_names() {
  std::string s;
  for (sampler_kind k : all_sampler_kinds) s += std::string(s.empty() ? "" : " | ") + sampler_name(k);
  return s;
}

bool sampler_available(sampler_kind) { return true; }

bool needs_light_tree(sampler_kind kind) {
  return kind == sampler_kind::bvh || kind == sampler_kind::bound || kind == sampler_kind::bayes ||
         kind == sampler_kind::donikian;
}

light_sampler make_light_sampler(const sampler_params& params, const render_inputs& in, const light_tree_data& tree) {
  const light_data& lights = *in.lights;
  float sun_sin = 0, sun_cos = 1;
  if (lights.sun != invalid_id) sun_half_angle(lights, sun_sin, sun_cos);
  switch (params.kind) {
    case sampler_kind::uniform: return uniform_sampler{lights.count};
    case sampler_kind::power: return power_sampler{make_discrete(lights.power.data(), lights.count)};
    case sampler_kind::bvh: return bvh_sampler{&tree, &lights, sun_sin, sun_cos};
    case sampler_kind::bound: {
      bound_sampler s;
      s.tree = &tree;
      s.lights = &lights;
      s.sun_sin = sun_sin;
      s.sun_cos = sun_cos;
      s.regions = make_regions(params, in, tree);
      return s;
    }
    case sampler_kind::donikian: {
      bound_sampler b;
      b.tree = &tree;
      b.lights = &lights;
      b.sun_sin = sun_sin;
      b.sun_cos = sun_cos;
      b.regions = make_regions(params, in, tree);
      const region_params rp = b.regions.params;
      return make_donikian_sampler(tree, lights, std::move(b), in.camera.width, in.camera.height, params.donikian, rp,
                                   in.scene->bounds);
    }
    case sampler_kind::bayes: {
      if (tree.color.size() != tree.light.size())
        throw std::logic_error("the bayes sampler needs the light tree's colours (build_light_tree with colors)");
      bayes_sampler s;
      s.tree = &tree;
      s.lights = &lights;
      s.sun_sin = sun_sin;
      s.sun_cos = sun_cos;
      s.params = params.bayes;
      s.params.stratified = in.stratify;
      s.params.path_traced = in.max_depth > 1;
      s.power = power_sampler{make_discrete(lights.power.data(), lights.count)};
      s.bvh.tree = &tree, s.bvh.lights = &lights, s.bvh.sun_sin = sun_sin, s.bvh.sun_cos = sun_cos;
      if (lights.sun != invalid_id && luminance(lights.sun_irradiance) > 0)
        s.sun_color = lights.sun_irradiance / luminance(lights.sun_irradiance);
      s.one_light = lights.count <= 1;
      s.fallback = s.one_light;
      s.regions = make_regions(params, in, tree);
      s.reserve_growth();
      s.add_pairs(0);
      s.refresh_all_weights();
      return s;
    }
    default: break;
  }
  throw usage_error(std::string("sampler \"") + sampler_name(params.kind) + "\" is not available in this build");
}

template <typename T>
static size_t bytes_of(const std::vector<T>& v) {
  return v.size() * sizeof(T);
}

size_t sampler_memory_bytes(const light_sampler& s) {
  if (auto* b = std::get_if<bound_sampler>(&s)) return region_memory_bytes(b->regions);
  if (auto* b = std::get_if<bayes_sampler>(&s)) {
    // Every column the sampler keeps per pair (and the fallback check's per pixel), as allocated.
    const bayes_stats& st = b->stats;
    return region_memory_bytes(b->regions) + bytes_of(st.m) + bytes_of(st.weight) +
           bytes_of(st.mu0) + bytes_of(st.w) + bytes_of(st.w_cv) + bytes_of(st.cv) + bytes_of(st.p1_folded) +
           bytes_of(st.k_folded) + bytes_of(st.gw) + bytes_of(st.gw_cv) + bytes_of(st.gcv) + bytes_of(st.gcol) +
           bytes_of(st.gtot) + bytes_of(st.gtot_cv) + bytes_of(st.unseen) + bytes_of(st.gunseen) + bytes_of(st.mw) +
           bytes_of(st.mw_cv) + bytes_of(b->child_link) +
           bytes_of(b->px_var) + bytes_of(b->px_delta) + bytes_of(b->px_delta_bvh) + bytes_of(b->px_first) +
           bytes_of(b->px_prev) + bytes_of(b->px_cur);
  }
  if (auto* d = std::get_if<donikian_sampler>(&s))
    return region_memory_bytes(d->deeper.regions) +
           (d->pixel_sum.size() + d->pixel_count.size() + d->block_sum.size() + d->block_count.size()) * sizeof(float);
  return 0;
}

}  // namespace bl
