// Scale and long-run health: a scene with 10^5 emissive triangles loads, builds its light tree and renders with
// every tree-based sampler within a stated memory per light; and a long render (65536 spp) of an analytic
// scene stays accurate (film sums and learned statistics do not lose late contributions).
#include "bvh.h"
#include "light_sampler.h"
#include "light_tree.h"
#include "lights.h"
#include "render.h"
#include "rng.h"
#include "scene.h"
#include "scene_fixture.h"
#include "test_util.h"

#include <catch2/catch.hpp>
#include <tbb/parallel_for.h>
#include <pmmintrin.h>

#include <atomic>

using namespace bl;
using namespace bl::test;

namespace {

// Bytes held by the lights and the light tree.
size_t light_bytes(const light_data& l, const light_tree_data& t) {
  size_t b = l.tri.size() * sizeof(int) + l.radiance.size() * sizeof(vec3f) + l.power.size() * sizeof(float) +
             l.light_of_tri.size() * sizeof(int);
  size_t nodes = size_t(node_count(t));
  b += nodes * (2 * sizeof(vec3f) + sizeof(vec3f) + sizeof(float) + sizeof(vec3f) + 3 * sizeof(float) +
                4 * sizeof(int) + sizeof(node_pack) + sizeof(double) + sizeof(vec3f));
  return b + t.leaf_of_light.size() * sizeof(int);
}

}  // namespace

TEST_CASE("a scene with 100000 emissive triangles renders with every sampler", "[scale]") {
  mesh_builder b;
  int floor = b.add_material({0.5f, 0.5f, 0.5f});
  b.add_quad({-50, 0, -50}, {-50, 0, 50}, {50, 0, 50}, {50, 0, -50}, floor);
  // 10^5 small lamps facing down on a 100 m x 100 m ceiling, radiance varying over 3 decades.
  const int n = 100000;
  for (int i = 0; i < n; i++) {
    auto r = draw_vertex(sample_key(3, uint64_t(i), 0), 0);
    float x = -49 + 98 * r.u[0], z = -49 + 98 * r.u[1], s = 0.05f;
    float le = std::pow(10.0f, 3 * r.u[2]);
    int m = b.add_material({0, 0, 0}, {le, le, le});
    b.add_triangle({x, 4, z}, {x + s, 4, z}, {x, 4, z + s}, m);  // normal -y
  }
  camera_params cam;
  cam.automatic = false;
  cam.eye = {0, 2, 20};
  cam.target = {0, 0.5f, 0};
  scene_data scene = build_scene(std::move(b.mesh), cam, {}, false, 4.0f / 3.0f);
  bvh_data bvh = build_bvh(scene);
  light_data lights = build_lights(scene);
  REQUIRE(lights.count == n);
  light_tree_data tree = build_light_tree(lights, scene);
  CHECK(tree.depth <= max_tree_depth);
  double per_light = double(light_bytes(lights, tree)) / n;
  INFO("bytes per light (lights + tree): " << per_light);
  CHECK(per_light < 400);
  // Depth 2, and direct illumination (where bayes refines its clusters into members by default).
  for (int depth : {2, 1})
  for (sampler_kind kind : {sampler_kind::bvh, sampler_kind::bound, sampler_kind::bayes}) {
    render_params p;
    p.width = 32;
    p.height = 24;
    p.spp = 2;
    p.max_depth = depth;
    p.threads = 2;
    p.sampler.kind = kind;
    render_result r = render(scene, bvh, lights, p);
    INFO(sampler_name(kind) << " depth " << depth << ": sampler state " << r.sampler_bytes << " bytes, " << r.regions
                            << " regions, " << r.pairs << " pairs");
    CHECK(r.spp == 2);
    CHECK(r.stats.bad_samples == 0);
    double sum = 0;
    for (double v : r.film) {
      REQUIRE(std::isfinite(v));
      sum += v;
    }
    CHECK(sum > 0);
  }
}

TEST_CASE("a long render stays accurate", "[scale]") {
  // The point under a large emitting square of analytic_test: 65536 spp on an 8x8 image with bayes, so late
  // samples add 1/65536 of the film each. The 64 pixels are independent estimates: their mean must lie within
  // 4.4 standard errors (99.999%) of the closed form, and the standard error must be below 0.2% of it.
  const float a = 1.0f, h = 0.5f, le = 2.0f, rho = 0.5f;
  mesh_builder b;
  int floor = b.add_material({rho, rho, rho});
  int lamp = b.add_material({0, 0, 0}, {le, le, le});
  b.add_quad({-20, 0, -20}, {-20, 0, 20}, {20, 0, 20}, {20, 0, -20}, floor);
  b.add_quad({-a, h, -a}, {a, h, -a}, {a, h, a}, {-a, h, a}, lamp);
  camera_params cam;
  cam.automatic = false;
  cam.eye = {0, h / 2, 0};
  cam.target = {0, 0, 0};
  cam.up = {0, 0, -1};
  cam.fov_y_deg = 0.5f;
  scene_data scene = build_scene(std::move(b.mesh), cam, {}, false, 1.0f);
  bvh_data bvh = build_bvh(scene);
  light_data lights = build_lights(scene);
  render_params p;
  p.width = p.height = 8;
  p.spp = 65536;
  p.max_depth = 1;
  p.threads = 2;
  p.sampler.kind = sampler_kind::bayes;
  render_result r = render(scene, bvh, lights, p);
  REQUIRE(r.spp == 65536);
  double A = a / h, s = A / std::sqrt(1 + A * A);
  double exact = rho / M_PI * 4 * le * s * std::atan(s);
  std::vector<double> px;
  for (int i = 0; i < 64; i++) px.push_back(r.film[3 * size_t(i)] / r.film_weight);
  mean_se m = mean_and_se(px);
  INFO("mean " << m.mean << " +- " << m.se << " exact " << exact);
  CHECK(m.se < 0.002 * exact);
  CHECK(std::fabs(m.mean - exact) < 4.4 * m.se);
}

TEST_CASE("TBB work after the BVH's build keeps denormals (no flush-to-zero)", "[scale]") {
  // Embree's commit turns on flush-to-zero and denormals-are-zero while it builds; when it was the thread's first use
  // of TBB, TBB's implicit arena kept them for every later parallel_for outside an explicit arena (bayes' learning,
  // the regions' set-up), unlike the passes (their own arena): prior means below FLT_MIN became 0 there (a lamp of
  // radiance 1e-37 rendered 1.3 % dark with bayes). Run as its own process (ctest), the BVH is its first use of TBB.
  mesh_builder b;
  b.add_quad({-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, b.add_material({0.5f, 0.5f, 0.5f}));
  auto t = build_test_scene(std::move(b.mesh), fixed_camera({0, 1, 3}, {0, 0, 0}));
  std::atomic<unsigned> modes{0};
  tbb::parallel_for(0, 64, [&](int) { modes.fetch_or(_mm_getcsr() & (_MM_FLUSH_ZERO_MASK | _MM_DENORMALS_ZERO_MASK)); });
  CHECK(modes.load() == 0u);
}
