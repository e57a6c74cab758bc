// Tests of light_points: the lattice of a draw's points on its light, and the choice of their number per tile.
#include "light_points.h"
#include "test_util.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <set>

using namespace bl;

TEST_CASE("a draw's light points take one row and one column each of a K by K grid", "[light_points]") {
  // Whatever the draw's own point, the K points fall in K different columns and K different rows of the K x K grid
  // of the light's (u, v) square (a rank-1 lattice, shifted): K points that repeated a row would sample the light
  // along fewer strips. Each point stays in [0, 1).
  uint64_t state = 7;
  for (int k : {2, 3, 4, 5, 8, 13, 64}) {
    for (int trial = 0; trial < 200; trial++) {
      state = state * 6364136223846793005ull + 1442695040888963407ull;
      float u0 = float(state >> 40) * 0x1p-24f, v0 = float((state >> 16) & 0xffffff) * 0x1p-24f;
      if (trial == 0) u0 = v0 = 0;
      if (trial == 1) u0 = v0 = 0x1.fffffep-1f;  // (the largest float below 1: a shift must wrap, not reach 1)
      std::set<int> cols, rows;
      for (int j = 0; j < k; j++) {
        float u = u0, v = v0;
        light_point_uv(k, j, u, v);
        INFO("K " << k << " point " << j << " of (" << u0 << ", " << v0 << "): (" << u << ", " << v << ")");
        REQUIRE(u >= 0);
        REQUIRE(u < 1);
        REQUIRE(v >= 0);
        REQUIRE(v < 1);
        // The cell relative to the first point's: the lattice moves every point by whole cells.
        cols.insert(int(std::floor((u - u0) * float(k) + 0.5f + float(k))) % k);
        rows.insert(int(std::floor((v - v0) * float(k) + 0.5f + float(k))) % k);
      }
      CHECK(int(cols.size()) == k);
      CHECK(int(rows.size()) == k);
    }
  }
}

namespace {
// One tile's statistics for samples of `points` points whose per-sample variance at one point is rest + within, of
// `vertices` path vertices each (n samples, weight 1).
std::vector<double> tile_stats(double rest, double within, double vertices, int points, double n = 1000) {
  std::vector<double> s(point_stat_fields, 0.0);
  s[ps_samples] = n;
  s[ps_vertices] = n * vertices;
  s[ps_weight] = n;
  s[ps_sq_dev] = n * (rest + within / points);
  s[ps_inv_points] = n / points;
  if (points > 1) s[ps_within] = n * within, s[ps_within_weight] = n;
  return s;
}
int brute_force(double rest, double within, double vertices) {
  int best = 1;
  double best_work = INFINITY;
  for (int k : {1, 2, 3, 5, 8}) {
    double work = (point_cost_per_vertex * vertices + k - 1) * (rest + within / k);
    if (work < best_work) best = k, best_work = work;
  }
  return best;
}
}  // namespace

TEST_CASE("the point count minimises cost times variance from what a tile measured", "[light_points]") {
  // Direct lighting (one vertex) where the variance inside the light is 85 % of a one-point sample's (the plant room's
  // measured share): 5 points. Nothing inside the lights: 1. Nothing but: 8. Path traced (5 vertices), the same
  // split costs relatively less: more points. Every case against the brute-force minimum, from statistics gathered
  // at 2 points (the exploration) and at 5.
  struct variant {
    double rest, within, vertices;
    int expected;
  };
  for (const variant& v : {variant{0.15, 0.85, 1, 5}, variant{1.0, 0.0, 1, 1}, variant{0.0, 1.0, 1, 8},
                           variant{0.9, 0.1, 1, 1}, variant{0.5, 0.5, 1, 2}, variant{0.5, 0.5, 5, 5}}) {
    INFO("rest " << v.rest << " within " << v.within << " vertices " << v.vertices);
    CHECK(brute_force(v.rest, v.within, v.vertices) == v.expected);
    for (int gathered_at : {2, 5})
      CHECK(choose_light_points(tile_stats(v.rest, v.within, v.vertices, gathered_at).data()) == v.expected);
  }
  // Statistics of several passes of different counts add up to the same answer.
  std::vector<double> a = tile_stats(0.15, 0.85, 1, 2), b = tile_stats(0.15, 0.85, 1, 5, 3000),
                      c = tile_stats(0.15, 0.85, 1, 1, 500);
  for (int f = 0; f < point_stat_fields; f++) a[size_t(f)] += b[size_t(f)] + c[size_t(f)];
  CHECK(choose_light_points(a.data()) == 5);
}

TEST_CASE("the point count is one without data, and stays finite-safe", "[light_points]") {
  std::vector<double> none(point_stat_fields, 0.0);
  CHECK(choose_light_points(none.data()) == 1);
  // Samples but never two points (nothing measured inside the lights).
  CHECK(choose_light_points(tile_stats(0.2, 0.8, 1, 1).data()) == 1);
  // Only camera rays that met nothing (no vertex cost is zero): 1.
  std::vector<double> s = tile_stats(0.2, 0.8, 1, 2);
  s[ps_vertices] = 0;
  CHECK(choose_light_points(s.data()) == 1);
  // Non-finite sums (a tile whose statistics overflowed): 1.
  s = tile_stats(0.2, 0.8, 1, 2);
  s[ps_within] = INFINITY;
  CHECK(choose_light_points(s.data()) == 1);
  s = tile_stats(0.2, 0.8, 1, 2);
  s[ps_sq_dev] = NAN;
  CHECK(choose_light_points(s.data()) == 1);
  // A total below the within part (noise): the rest counts as zero, all points.
  s = tile_stats(0.0, 1.0, 1, 2);
  s[ps_sq_dev] *= 0.5;
  CHECK(choose_light_points(s.data()) == 8);
}

TEST_CASE("tiles explore with two points for the first samples, then choose", "[light_points]") {
  std::vector<double> stats = tile_stats(0.15, 0.85, 1, 2);
  std::vector<double> flat = tile_stats(1, 0, 1, 2);
  stats.insert(stats.end(), flat.begin(), flat.end());
  std::vector<uint8_t> points;
  for (int spp = 0; spp < point_explore_spp; spp++) {
    choose_tile_points(stats, spp, points);
    REQUIRE(points.size() == 2);
    CHECK(points[0] == point_explore_points);
    CHECK(points[1] == point_explore_points);
  }
  choose_tile_points(stats, point_explore_spp, points);
  CHECK(points[0] == 5);
  CHECK(points[1] == 1);
}
