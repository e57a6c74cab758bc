// micro_bench: microbenchmarks of light selection's building blocks — region lookup, per-point pmf build and
// sampling over cuts of 8..512 clusters (bound and bayes samplers), posterior weight evaluation and coefficient
// updates, the per-pass observation reduction (row accumulation, merge, weight refresh), light tree builds of
// 10^3..10^6 emitters, and points on a triangle light (by area or by solid angle). Inputs are deterministic (PCG32,
// fixed seeds); setup stays outside the timed loops.
// Per-item costs are counters of the form ns_per_X (seconds per X, printed with an SI prefix: "2.5n" = 2.5 ns).
#include "bayes_sampler.h"
#include "bayes_stats.h"
#include "bound_sampler.h"
#include "bvh.h"
#include "cluster_bounds.h"
#include "camera.h"
#include "cut_sampling.h"
#include "integrator.h"
#include "light_sampler.h"
#include "light_tree.h"
#include "lights.h"
#include "region_grid.h"
#include "rng.h"
#include "scene.h"
#include "scene_desc.h"

// test_util.h names the renderer binary in a helper these benchmarks never call.
#ifndef BAYESLIGHT_BINARY
#define BAYESLIGHT_BINARY "bayeslight"
#endif
#include "../tests/test_util.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

namespace {

using namespace bl;

// Uniform float in [0, 1) (24 bits).
float unit(pcg32& r) { return uint_to_unit(r()); }
// Uniform double in [0, 1) (53 bits).
double unit53(pcg32& r) {
  uint64_t hi = r(), lo = r();
  return double(((hi << 21) ^ (lo >> 11)) & ((uint64_t(1) << 53) - 1)) * 0x1p-53;
}

// Per-item cost counter: seconds per item (with kInvert the rate becomes a time), items = count per iteration.
benchmark::Counter per_item(const benchmark::State& state, double items_per_iteration) {
  return benchmark::Counter(double(state.iterations()) * items_per_iteration,
                            benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// ---------------------------------------------------------------------------------------------------------
// 1. Region lookup on data/hall/direct.json, regions discovered by make_light_sampler at 160x120.

constexpr int lookup_points = 1 << 16;

// The hall scene with a bound sampler's regions and two point sets: camera first hits through random points of
// random pixels (visible surfaces, as a render queries them) and points uniform by area over every triangle.
struct hall_fixture {
  scene_data scene;
  std::unique_ptr<bvh_data> bvh;
  light_data lights;
  light_tree_data tree;
  region_state regions;
  std::vector<vec3f> visible, anywhere;
};

hall_fixture& hall() {
  static hall_fixture* f = [] {
    auto* h = new hall_fixture;
    scene_desc desc = load_scene_desc(std::string(BAYESLIGHT_SOURCE_DIR) + "/data/hall/direct.json");
    int w = 160, ht = 120;
    h->scene = build_scene(desc, float(w) / float(ht));
    h->bvh = std::make_unique<bvh_data>(build_bvh(h->scene));
    h->lights = build_lights(h->scene);
    h->tree = build_light_tree(h->lights, h->scene);
    render_inputs in;
    in.scene = &h->scene;
    in.bvh = h->bvh.get();
    in.lights = &h->lights;
    in.camera = make_camera(h->scene.camera, w, ht);
    sampler_params sp;
    sp.kind = sampler_kind::bound;
    light_sampler ls = make_light_sampler(sp, in, h->tree);
    h->regions = std::get<bound_sampler>(ls).regions;
    pcg32 rng(101, 1);
    while (int(h->visible.size()) < lookup_points) {
      vec3f dir = camera_ray_dir(in.camera, unit(rng) * float(w), unit(rng) * float(ht));
      hit_info hit = intersect(*h->bvh, in.camera.eye, dir);
      if (hit.tri == invalid_id) continue;
      h->visible.push_back(eval_surface(h->scene, hit.tri, hit.b1, hit.b2, dir).p);
    }
    std::vector<double> area_cdf(h->scene.tri_area.size());
    double acc = 0;
    for (size_t t = 0; t < area_cdf.size(); t++) area_cdf[t] = acc += h->scene.tri_area[t];
    for (int i = 0; i < lookup_points; i++) {
      double u = unit53(rng) * acc;
      size_t t = size_t(std::upper_bound(area_cdf.begin(), area_cdf.end(), u) - area_cdf.begin());
      t = std::min(t, area_cdf.size() - 1);
      float b1 = unit(rng), b2 = unit(rng);
      if (b1 + b2 > 1) b1 = 1 - b1, b2 = 1 - b2;
      h->anywhere.push_back(h->scene.tri_p0[t] + h->scene.tri_e1[t] * b1 + h->scene.tri_e2[t] * b2);
    }
    return h;
  }();
  return *f;
}

// Region lookup find_region(fine_region_key(p)) at random points, in random order (no reuse between
// neighbours); ns per lookup. Arg 0: visible points (camera first hits), 1: uniform over all surfaces.
void BM_region_lookup(benchmark::State& state) {
  hall_fixture& h = hall();
  const std::vector<vec3f>& pts = state.range(0) == 0 ? h.visible : h.anywhere;
  int fine = 0;
  for (vec3f p : pts) {
    uint64_t key = fine_region_key(h.regions.grid, p);
    fine += h.regions.key[size_t(find_region(h.regions, key))] == key;
  }
  size_t i = 0;
  for (auto _ : state) {
    int r = find_region(h.regions, fine_region_key(h.regions.grid, pts[i]));
    benchmark::DoNotOptimize(r);
    i = (i + 1) & (lookup_points - 1);
  }
  state.SetLabel(state.range(0) == 0 ? "visible" : "any_surface");
  state.counters["regions"] = double(h.regions.key.size());
  state.counters["table_KiB"] = double(h.regions.table.size() * sizeof(region_entry)) / 1024;
  state.counters["fine_hit"] = double(fine) / double(pts.size());
}
BENCHMARK(BM_region_lookup)->Arg(0)->Arg(1);

// ---------------------------------------------------------------------------------------------------------
// 2. PMF build and sampling over cuts of N clusters: 2048 small emitters on a ceiling above a floor.

constexpr int ceiling_lights = 2048;
constexpr int cut_regions = 16;      // fine regions on the floor
constexpr int points_per_region = 16;

// The many-lights scene (scene, lights and tree; no Embree: light selection never traces rays).
struct ceiling_scene {
  scene_data scene;
  light_data lights;
  light_tree_data tree;
};

ceiling_scene& ceiling() {
  static ceiling_scene* s = [] {
    test::mesh_builder b;
    int floor = b.add_material({0.5f, 0.5f, 0.5f});
    b.add_quad({-10, 0, -10}, {-10, 0, 10}, {10, 0, 10}, {10, 0, -10}, floor);
    // 16 emission levels over two decades; each light picks one, with a jittered position and size.
    int levels[16];
    for (int l = 0; l < 16; l++) {
      float le = std::pow(10.0f, float(l) / 7.5f);
      levels[l] = b.add_material({0, 0, 0}, {le, 0.9f * le, 0.8f * le});
    }
    pcg32 rng(202, 1);
    for (int i = 0; i < ceiling_lights; i++) {
      float x = -8 + 16 * (float(i % 64) + 0.5f * unit(rng)) / 64, z = -8 + 16 * (float(i / 64) + 0.5f * unit(rng)) / 32;
      float y = 4 - 0.2f * unit(rng), s = 0.05f + 0.1f * unit(rng);
      // Facing down: cross(e1, e2) = (s, 0, 0) x (0, 0, s) = (0, -s^2, 0).
      b.add_triangle({x, y, z}, {x + s, y, z}, {x, y, z + s}, levels[rng() % 16]);
    }
    auto* c = new ceiling_scene;
    camera_params cam;
    cam.automatic = false;
    cam.eye = {0, 2, 12};
    c->scene = build_scene(std::move(b.mesh), cam, sun_params{}, false, 1.0f);
    c->lights = build_lights(c->scene);
    c->tree = build_light_tree(c->lights, c->scene);
    return c;
  }();
  return *s;
}

// Both samplers over the same regions (max_cut = N, coherence 0, threshold 0: every fine cut has N clusters),
// the bayes one with learned statistics, and shading points inside the fine regions, grouped by region.
struct cut_fixture {
  bound_sampler bound;
  bayes_sampler bayes;
  std::vector<shade_point> points;
};

std::unique_ptr<cut_fixture> make_cut_fixture(int max_cut) {
  ceiling_scene& c = ceiling();
  auto f = std::make_unique<cut_fixture>();
  region_params rp;
  rp.max_cut = max_cut;
  rp.coherence = 0;
  rp.cut_threshold = 0;
  region_state regions = make_region_state(c.scene.bounds, c.tree, false, rp);
  pcg32 rng(303, uint64_t(max_cut));
  std::vector<uint64_t> keys;
  while (int(keys.size()) < cut_regions) {
    vec3f p = {-9 + 18 * unit(rng), 0, -9 + 18 * unit(rng)};
    uint64_t k = fine_region_key(regions.grid, p);
    if (std::find(keys.begin(), keys.end(), k) == keys.end()) keys.push_back(k);
  }
  std::vector<uint64_t> sorted = keys;
  std::sort(sorted.begin(), sorted.end());
  add_regions(regions, c.tree, sorted);
  for (uint64_t k : keys) {
    bbox3f box = region_box(regions.grid, k);
    for (int i = 0; i < points_per_region; i++) {
      vec3f p = {box.lo.x + (box.hi.x - box.lo.x) * unit(rng), 0, box.lo.z + (box.hi.z - box.lo.z) * unit(rng)};
      f->points.push_back(shade_point{p, {0, 1, 0}, 0.5f, 0, 1});
    }
  }
  f->bound.tree = f->bayes.tree = &c.tree;
  f->bound.lights = f->bayes.lights = &c.lights;
  f->bound.regions = regions;
  f->bayes.regions = regions;
  resize_stats(f->bayes.stats, regions.pairs, f->bayes.params);
  // Learned statistics: 480 rows of NEE observations (30% zeros, the rest spread over three decades) on
  // random pairs of the fine regions, folded in as between passes.
  std::vector<bayes_row> rows(480);
  std::vector<int> fine_regions;
  for (uint64_t k : keys) fine_regions.push_back(find_region_key(regions, k));
  for (bayes_row& row : rows)
    for (int e = 0; e < 256; e++) {
      size_t r = size_t(fine_regions[rng() % cut_regions]);
      int pair = regions.pair_offset[r] + int(rng() % uint32_t(regions.cut_size[r]));
      row.add(pair, unit(rng) < 0.3f ? 0.0 : std::pow(10.0, 3 * double(unit(rng)) - 1));
    }
  f->bayes.learn(rows);
  return f;
}

// Cached per cut size (every benchmark of one N shares it).
cut_fixture& cuts(int max_cut) {
  static int cached = -1;
  static std::unique_ptr<cut_fixture> f;
  if (cached != max_cut) f = make_cut_fixture(max_cut), cached = max_cut;
  return *f;
}

// Records the cut size actually reached (and, for work linear in it, the cost per cluster).
void cut_counters(benchmark::State& state, const cut_fixture& f, bool per_cluster) {
  cut_context ctx;
  f.bound.locate(ctx, f.points[0]);
  state.counters["clusters"] = ctx.count;
  if (per_cluster) state.counters["ns_per_cluster"] = per_item(state, ctx.count);
}

// bound_sampler::prepare (region lookup, mostly reused; SSE bounds of N clusters; cdf) per shading point;
// ns per point, ns_per_cluster.
void BM_bound_prepare(benchmark::State& state) {
  cut_fixture& f = cuts(int(state.range(0)));
  cut_context ctx;
  size_t i = 0, n = f.points.size();
  for (auto _ : state) {
    f.bound.prepare(ctx, f.points[i]);
    benchmark::DoNotOptimize(ctx.cdf[ctx.count]);
    if (++i == n) i = 0;
  }
  cut_counters(state, f, true);
}
BENCHMARK(BM_bound_prepare)->Arg(8)->Arg(32)->Arg(128)->Arg(512);

// bayes_sampler::prepare (bounds, posterior weights from learned statistics, cdf) per shading point;
// ns per point, ns_per_cluster.
void BM_bayes_prepare(benchmark::State& state) {
  cut_fixture& f = cuts(int(state.range(0)));
  cut_context ctx;
  size_t i = 0, n = f.points.size();
  for (auto _ : state) {
    f.bayes.prepare(ctx, f.points[i]);
    benchmark::DoNotOptimize(ctx.cdf[ctx.count]);
    if (++i == n) i = 0;
  }
  cut_counters(state, f, true);
}
BENCHMARK(BM_bayes_prepare)->Arg(8)->Arg(32)->Arg(128)->Arg(512);

// The two stages of prepare apart — eval_node_bounds (SSE importance of the cut's nodes) per shading point;
// ns per point, ns_per_cluster.
void BM_eval_node_bounds(benchmark::State& state) {
  cut_fixture& f = cuts(int(state.range(0)));
  ceiling_scene& c = ceiling();
  cut_context ctx;
  f.bound.locate(ctx, f.points[0]);
  alignas(16) float num[max_cut_entries + 3], inv_d2[max_cut_entries + 3];
  size_t i = 0;
  for (auto _ : state) {
    eval_node_bounds(c.tree, ctx.nodes, ctx.tree_count, f.points[i].p, f.points[i].n, num, inv_d2);
    benchmark::DoNotOptimize(num[0]);
    benchmark::ClobberMemory();
    if (++i == points_per_region) i = 0;  // points of the first region (its cut is ctx's)
  }
  cut_counters(state, f, true);
}
BENCHMARK(BM_eval_node_bounds)->Arg(8)->Arg(32)->Arg(128)->Arg(512);

// ... and finish_cdf (floored, normalised double cdf of N weights) per shading point; ns per point, ns_per_cluster.
void BM_finish_cdf(benchmark::State& state) {
  cut_fixture& f = cuts(int(state.range(0)));
  cut_context ctx;
  f.bound.locate(ctx, f.points[0]);
  std::vector<double> w(size_t(ctx.count));
  pcg32 rng(505, 2);
  for (double& x : w) x = std::pow(10.0, 4 * double(unit(rng)) - 2);
  for (auto _ : state) {
    bool ok = finish_cdf(ctx, w.data());
    benchmark::DoNotOptimize(ok);
    benchmark::ClobberMemory();
  }
  cut_counters(state, f, true);
}
BENCHMARK(BM_finish_cdf)->Arg(8)->Arg(32)->Arg(128)->Arg(512);

// Prepared bayes contexts of one point per region, and random uniforms with their sampled lights.
struct sample_inputs {
  std::vector<cut_context> ctx;
  std::vector<double> u, u_inner;
  std::vector<int> light;  // what sample_cut picks for (ctx[i % regions], u[i], u_inner[i])
};
constexpr int sample_count = 4096;

sample_inputs make_sample_inputs(const cut_fixture& f) {
  sample_inputs s;
  s.ctx.resize(cut_regions);
  for (int r = 0; r < cut_regions; r++) f.bayes.prepare(s.ctx[size_t(r)], f.points[size_t(r * points_per_region)]);
  pcg32 rng(404, 1);
  for (int i = 0; i < sample_count; i++) {
    s.u.push_back(unit53(rng));
    s.u_inner.push_back(unit53(rng));
    s.light.push_back(f.bayes.sample(s.ctx[size_t(i % cut_regions)], s.u.back(), s.u_inner.back()).light);
  }
  return s;
}

// sample_cut (binary search of the cdf, then intensity descent to a leaf) per sample; ns per sample.
void BM_sample_cut(benchmark::State& state) {
  cut_fixture& f = cuts(int(state.range(0)));
  sample_inputs s = make_sample_inputs(f);
  ceiling_scene& c = ceiling();
  size_t i = 0;
  for (auto _ : state) {
    light_choice lc = sample_cut(s.ctx[i % cut_regions], c.tree, c.lights, s.u[i], s.u_inner[i]);
    benchmark::DoNotOptimize(lc);
    i = (i + 1) & (sample_count - 1);
  }
  cut_counters(state, f, false);
}
BENCHMARK(BM_sample_cut)->Arg(8)->Arg(32)->Arg(128)->Arg(512);

// cut_pmf of a sampled light (walk up from its leaf to the cut, binary search per level, descent pmf) per
// query; ns per query.
void BM_cut_pmf(benchmark::State& state) {
  cut_fixture& f = cuts(int(state.range(0)));
  sample_inputs s = make_sample_inputs(f);
  ceiling_scene& c = ceiling();
  size_t i = 0;
  for (auto _ : state) {
    float pmf = cut_pmf(s.ctx[i % cut_regions], c.tree, c.lights, s.light[i]);
    benchmark::DoNotOptimize(pmf);
    i = (i + 1) & (sample_count - 1);
  }
  cut_counters(state, f, false);
}
BENCHMARK(BM_cut_pmf)->Arg(8)->Arg(32)->Arg(128)->Arg(512);

// ---------------------------------------------------------------------------------------------------------
// 3. Posterior evaluation.

constexpr int posterior_pairs = 4096;

// eval_weight (double precision, the scalar path) over 4096 pairs with random coefficients; ns per pair.
void BM_eval_weight(benchmark::State& state) {
  pcg32 rng(505, 1);
  std::vector<pair_weight> w(posterior_pairs);
  std::vector<double> v(posterior_pairs), g(posterior_pairs);
  for (int i = 0; i < posterior_pairs; i++) {
    w[size_t(i)] = {unit(rng), unit(rng) - 0.5f, unit(rng), 0.1f * unit(rng)};
    v[size_t(i)] = std::pow(10.0, 4 * double(unit(rng)) - 2);
    g[size_t(i)] = 1 / (0.1 + 10 * double(unit(rng)));
  }
  bayes_params p;
  for (auto _ : state) {
    double sum = 0;
    for (int i = 0; i < posterior_pairs; i++) sum += eval_weight(w[size_t(i)], p, v[size_t(i)], g[size_t(i)]);
    benchmark::DoNotOptimize(sum);
  }
  state.counters["ns_per_pair"] = per_item(state, posterior_pairs);
}
BENCHMARK(BM_eval_weight);

// Random statistics of `pairs` pairs: 30% of them empty, the others with up to 200 samples.
bayes_stats random_stats(size_t pairs, uint64_t seed) {
  bayes_params p;
  bayes_stats s;
  resize_stats(s, int64_t(pairs), p);
  pcg32 rng(seed, 1);
  for (size_t i = 0; i < pairs; i++) {
    if (unit(rng) < 0.3f) continue;
    s.m[i].n0 = double(rng() % 100);
    s.m[i].n1 = double(1 + rng() % 100);
    s.m[i].mean = std::pow(10.0, 3 * double(unit(rng)) - 1);
    s.m[i].m2 = s.m[i].n1 * s.m[i].mean * s.m[i].mean * double(unit(rng));
  }
  return s;
}

// pair_coefficients (posterior coefficients from one pair's statistics) over 65536 pairs; ns per pair.
void BM_pair_coefficients(benchmark::State& state) {
  constexpr size_t pairs = 1 << 16;
  bayes_stats s = random_stats(pairs, 606);
  bayes_params p;
  for (auto _ : state) {
    float sum = 0;
    for (size_t i = 0; i < pairs; i++) sum += pair_coefficients(s.m[i], p).q2;
    benchmark::DoNotOptimize(sum);
  }
  state.counters["ns_per_pair"] = per_item(state, pairs);
}
BENCHMARK(BM_pair_coefficients);

// ---------------------------------------------------------------------------------------------------------
// 4. Observation reduction per pass: 480 rows over 2^20 pairs in regions of 64 clusters (the first 256 regions
// coarse, the others fine with a coarse parent region).

constexpr int reduction_rows = 480;
constexpr size_t reduction_pairs = size_t(1) << 20;
constexpr int pairs_per_region = 64;
constexpr int coarse_regions = 256;

std::vector<int> reduction_parents() {
  std::vector<int> parents(reduction_pairs, invalid_id);
  pcg32 rng(707, 1);
  for (size_t r = coarse_regions; r < reduction_pairs / pairs_per_region; r++) {
    int up = int(rng() % coarse_regions);
    for (int j = 0; j < pairs_per_region; j++)
      parents[r * pairs_per_region + size_t(j)] = up * pairs_per_region + j;
  }
  return parents;
}

// One row's events: `distinct` pairs from a run of neighbouring fine regions (a row of pixels crosses a band of
// cells), each touched once, then random ones of them up to `events`; z zero 30% of the time.
struct row_events {
  std::vector<int> pair;
  std::vector<double> z;
};
std::vector<row_events> make_row_events(int distinct, int events) {
  std::vector<row_events> rows(reduction_rows);
  pcg32 rng(808, uint64_t(distinct));
  size_t fine_regions = reduction_pairs / pairs_per_region - coarse_regions;
  for (row_events& r : rows) {
    size_t first = coarse_regions + rng() % (fine_regions - size_t(distinct) / pairs_per_region - 1);
    std::vector<int> pool;
    for (int k = 0; k < distinct; k++) pool.push_back(int(first * pairs_per_region) + k);
    for (int e = 0; e < events; e++) {
      r.pair.push_back(e < distinct ? pool[size_t(e)] : pool[rng() % uint32_t(distinct)]);
      r.z.push_back(unit(rng) < 0.3f ? 0.0 : std::pow(10.0, 3 * double(unit(rng)) - 1));
    }
  }
  return rows;
}

// bayes_row::clear + bayes_row::add of every event of 480 rows (the record side of a pass, rows reused as between
// passes); ms per pass, ns per event.
void BM_row_add(benchmark::State& state) {
  int distinct = int(state.range(0)), events = int(state.range(1));
  std::vector<row_events> ev = make_row_events(distinct, events);
  std::vector<bayes_row> rows(reduction_rows);
  auto pass = [&] {
    for (int r = 0; r < reduction_rows; r++) {
      bayes_row& row = rows[size_t(r)];
      row.clear();
      const row_events& e = ev[size_t(r)];
      for (int k = 0; k < events; k++) row.add(e.pair[size_t(k)], e.z[size_t(k)]);
    }
    benchmark::ClobberMemory();
  };
  pass();  // untimed: rows reach their steady-state capacity, as after the first pass of a render
  for (auto _ : state) pass();
  state.counters["ns_per_event"] = per_item(state, double(reduction_rows) * events);
}
BENCHMARK(BM_row_add)->Args({200, 640})->Args({2000, 4000})->Unit(benchmark::kMillisecond);

// merge_rows of 480 prepared rows into 2^20 pairs with parents (fold in row order + parallel coefficient
// updates of the touched pairs); ms per pass, ns per event and per distinct pair. Real time (TBB inside).
void BM_merge_rows(benchmark::State& state) {
  int distinct = int(state.range(0)), events = int(state.range(1));
  std::vector<row_events> ev = make_row_events(distinct, events);
  std::vector<bayes_row> rows(reduction_rows);
  for (int r = 0; r < reduction_rows; r++)
    for (int k = 0; k < events; k++) rows[size_t(r)].add(ev[size_t(r)].pair[size_t(k)], ev[size_t(r)].z[size_t(k)]);
  std::vector<int> parents = reduction_parents();
  bayes_params p;
  bayes_stats s = random_stats(reduction_pairs, 909);
  for (auto _ : state) {
    merge_rows(s, rows, &parents);
    benchmark::ClobberMemory();
  }
  state.counters["ns_per_event"] = per_item(state, double(reduction_rows) * events);
  state.counters["ns_per_row_pair"] = per_item(state, double(reduction_rows) * distinct);
}
BENCHMARK(BM_merge_rows)->Args({200, 640})->Args({2000, 4000})->Unit(benchmark::kMillisecond)->UseRealTime();

// refresh_weights over 2^20 pairs with parents (folding p1 into every sampling weight; TBB parallel_for);
// ms per pass, ns per pair. Real time.
void BM_refresh_weights(benchmark::State& state) {
  std::vector<int> parents = reduction_parents();
  bayes_params p;
  bayes_stats s = random_stats(reduction_pairs, 1010);
  for (auto _ : state) {
    refresh_weights(s, &parents, p, nullptr);  // (no sun)
    benchmark::ClobberMemory();
  }
  state.counters["ns_per_pair"] = per_item(state, double(reduction_pairs));
}
BENCHMARK(BM_refresh_weights)->Unit(benchmark::kMillisecond)->UseRealTime();

// ---------------------------------------------------------------------------------------------------------
// 5. Light tree build.

// N small emissive triangles (edges 0.01..0.11 in random directions, so random orientations) in a 100^3 box,
// radiance from 64 levels over three decades (powers vary with level and area).
struct random_lights {
  scene_data scene;
  light_data lights;
};

std::unique_ptr<random_lights> make_random_lights(int n) {
  test::mesh_builder b;
  int levels[64];
  for (int l = 0; l < 64; l++) {
    float le = std::pow(10.0f, 3 * float(l) / 63);
    levels[l] = b.add_material({0, 0, 0}, {le, le, le});
  }
  pcg32 rng(1111, uint64_t(n));
  auto dir = [&] {
    vec3f d;
    do d = {2 * unit(rng) - 1, 2 * unit(rng) - 1, 2 * unit(rng) - 1};
    while (!(length_sq(d) > 1e-4f && length_sq(d) <= 1));
    return normalize(d);
  };
  b.mesh.positions.reserve(size_t(3 * n));
  for (int i = 0; i < n; i++) {
    vec3f a = {100 * unit(rng), 100 * unit(rng), 100 * unit(rng)};
    vec3f e1 = dir() * (0.01f + 0.1f * unit(rng)), e2 = dir() * (0.01f + 0.1f * unit(rng));
    b.add_triangle(a, a + e1, a + e2, levels[rng() % 64]);
  }
  auto r = std::make_unique<random_lights>();
  r->scene = build_scene(std::move(b.mesh), camera_params{}, sun_params{}, false, 1.0f);
  r->lights = build_lights(r->scene);
  return r;
}

// build_light_tree over N random emitters; ms per build (setup cached per N, outside the timing).
void BM_light_tree_build(benchmark::State& state) {
  static int cached = -1;
  static std::unique_ptr<random_lights> lights;
  int n = int(state.range(0));
  if (cached != n) lights.reset(), lights = make_random_lights(n), cached = n;
  int depth = 0;
  for (auto _ : state) {
    light_tree_data t = build_light_tree(lights->lights, lights->scene);
    depth = t.depth;
    benchmark::DoNotOptimize(t.packed.data());
  }
  state.counters["emitters"] = double(lights->lights.tri_count);
  state.counters["depth"] = depth;
  state.counters["ns_per_emitter"] = per_item(state, n);
}
BENCHMARK(BM_light_tree_build)->Arg(1000)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_light_tree_build)->Arg(1000000)->Iterations(1)->Unit(benchmark::kMillisecond);

// ---------------------------------------------------------------------------------------------------------
// 6. A point on a triangle light: 4096 shading points under a 1 m triangle lamp at distances that make it subtend
// about 0.015 sr (arg 0: the ball bound turns solid-angle sampling down), about 0.06 sr (arg 1: the exact solid angle
// is computed, then area sampling) and 0.5-5 sr (arg 2: solid-angle sampling); ns per sample.
void BM_light_point(benchmark::State& state) {
  test::mesh_builder b;
  int lamp = b.add_material({0, 0, 0}, {1, 1, 1});
  b.add_triangle({-0.6f, 0, -0.4f}, {0.7f, 0, -0.3f}, {0.1f, 0, 0.8f}, lamp);  // faces down
  scene_data scene = build_scene(std::move(b.mesh), camera_params{}, sun_params{}, false, 1.0f);
  light_data lights = build_lights(scene);
  const float heights[] = {7.0f, 3.4f, 0.1f}, spreads[] = {0.4f, 0.1f, 0.4f};
  const float h = heights[state.range(0)], spread = spreads[state.range(0)];
  constexpr int points = 4096;
  std::vector<vec3f> x(points);
  std::vector<vec2f> u(points);
  pcg32 rng(808, 1);
  int solid = 0;
  for (int i = 0; i < points; i++) {
    float y = -h * (1 - 0.5f * spread + spread * unit(rng));
    x[size_t(i)] = {0.3f * (unit(rng) - 0.5f), y, 0.3f * (unit(rng) - 0.5f)};
    u[size_t(i)] = {unit(rng), unit(rng)};
    solid += spherical_solid_angle(scene, 0, x[size_t(i)]) > 0;
  }
  for (auto _ : state) {
    float sum = 0;
    for (int i = 0; i < points; i++)
      sum += sample_light_point(lights, scene, 0, x[size_t(i)], u[size_t(i)].x, u[size_t(i)].y).pdf;
    benchmark::DoNotOptimize(sum);
  }
  state.counters["by_solid_angle"] = double(solid) / points;
  state.counters["ns_per_sample"] = per_item(state, points);
}
BENCHMARK(BM_light_point)->Arg(0)->Arg(1)->Arg(2);

}  // namespace
