// Tests of light_points: the lattice of a draw's points on its light, and the choice of their number per tile.
#include "light_points.h"
#include "rng.h"
#include "test_util.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <set>
#include <vector>

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

TEST_CASE("a pass's light points: each draw's spread over the light, none repeated, none coupled to the next draw's",
          "[light_points]") {
  // --light-points auto draws a pass's points from a set of its own (pass_point_uv). A lattice shifted by each
  // draw's point of the stratified set (as fixed counts do) repeats, for every even K, the points of the draw paired
  // with it in the set, whose point lies (1/2, 1/2) away; and consecutive points of the set taking the two halves of
  // the light beside the two halves of the light choice cost bayes 10 % in the plant room (direct). Over many pixel
  // scrambles: the K = 4 points of a draw take the four quadrants of the (u, v) square; 64 draws of 2 points give 128
  // different points; and draws 2i and 2i + 1 of one point each are (1/2, 1/2) apart in only some pixels.
  uint64_t state = 11;
  int paired = 0, pairs = 0;
  for (int trial = 0; trial < 200; trial++) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    const uint64_t hash = state ^ (state >> 29);
    for (uint64_t draw = 0; draw < 16; draw++) {
      std::set<int> quadrants;
      for (int j = 0; j < 4; j++) {
        float u, v;
        pass_point_uv(hash, draw, 4, j, u, v);
        REQUIRE(u >= 0);
        REQUIRE(u < 1);
        REQUIRE(v >= 0);
        REQUIRE(v < 1);
        quadrants.insert(int(u * 2) * 2 + int(v * 2));
      }
      CHECK(quadrants.size() == 4);
    }
    std::set<std::pair<float, float>> seen;
    for (uint64_t draw = 0; draw < 64; draw++)
      for (int j = 0; j < 2; j++) {
        float u, v;
        pass_point_uv(hash, draw, 2, j, u, v);
        seen.insert({u, v});
      }
    CHECK(seen.size() == 128);
    for (uint64_t draw = 0; draw < 64; draw += 2) {
      float u0, v0, u1, v1;
      pass_point_uv(hash, draw, 1, 0, u0, v0);
      pass_point_uv(hash, draw + 1, 1, 0, u1, v1);
      paired += std::fabs(std::fabs(u1 - u0) - 0.5f) < 1e-6f && std::fabs(std::fabs(v1 - v0) - 0.5f) < 1e-6f;
      pairs++;
    }
  }
  INFO(paired << " of " << pairs << " draw pairs (1/2, 1/2) apart");
  CHECK(paired < pairs * 3 / 4);
}

TEST_CASE("a run of a pass keeps a point set for each light it draws, up to its capacity of lights", "[light_points]") {
  light_point_sets c;
  c.reset(12345, 0);
  light_point_set* a = c.set_of(5, 0, 2);
  REQUIRE(a != nullptr);
  CHECK(a->draws == 0);
  a->draws++;
  light_point_set* b = c.set_of(7, 1, 2);
  REQUIRE(b != nullptr);
  CHECK(b != a);
  CHECK(b->hash != a->hash);
  CHECK(c.set_of(5, 2, 2) == a);
  CHECK(a->draws == 1);
  CHECK(c.set_of(1 << 30, 3, 2) != nullptr);  // (large ids: the hall's tens of thousands of emitters and more)
  // A full table: every light it holds keeps its set; a new one takes the pass's shared set (null).
  c.reset(12345, 0);
  std::vector<light_point_set*> sets;
  for (int l = 0; l < light_point_sets::max_lights; l++) sets.push_back(c.set_of(l * 1000 + 3, uint64_t(l), 1));
  for (int l = 0; l < light_point_sets::max_lights; l++) {
    REQUIRE(sets[size_t(l)] != nullptr);
    CHECK(c.set_of(l * 1000 + 3, 999, 1) == sets[size_t(l)]);
  }
  CHECK(c.set_of(999999, 999, 1) == nullptr);
  // A reset starts new sets (the next pixel, or a later run of the pass: another scramble).
  const uint64_t first_hash = sets[0]->hash;
  c.reset(12345, 8);
  light_point_set* again = c.set_of(3, 0, 1);
  REQUIRE(again != nullptr);
  CHECK(again->draws == 0);
  CHECK(again->hash != first_hash);
  CHECK(c.set_of(999999, 1, 1) != nullptr);
}

namespace {
// Draws a run of a pass from its sample `run_start` (its draws numbered from there): `lights` lights chosen in random
// order (`state`), `points` points a draw, until each has `per_light` points; returns each light's points in order,
// and in `first` the shared set's first point of each light's first draw.
std::vector<std::vector<std::pair<float, float>>> draw_run(uint64_t pass_hash, uint64_t run_start, int lights,
                                                           int points, size_t per_light, uint64_t& state,
                                                           std::vector<std::pair<float, float>>& first) {
  light_point_sets c;
  c.reset(pass_hash, run_start);
  auto pts = std::vector<std::vector<std::pair<float, float>>>(size_t(lights));
  first.assign(size_t(lights), {-1.0f, -1.0f});
  for (uint64_t draw = run_start;; draw++) {
    bool done = true;
    for (const auto& p : pts) done = done && p.size() >= per_light;
    if (done) return pts;
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    const int light = int((state >> 33) % uint64_t(lights));
    light_point_set* set = c.set_of(light * 17 + 2, draw, points);
    REQUIRE(set != nullptr);
    const uint32_t d = set->draws++;
    if (d == 0) pass_point_uv(pass_hash, draw, points, 0, first[size_t(light)].first, first[size_t(light)].second);
    for (int j = 0; j < points; j++) {
      float u, v;
      light_pass_point_uv(*set, d, points, j, u, v);
      REQUIRE(u >= 0);
      REQUIRE(u < 1);
      REQUIRE(v >= 0);
      REQUIRE(v < 1);
      pts[size_t(light)].push_back({u, v});
    }
  }
}
}  // namespace

TEST_CASE("each light's points in a run of a pass are a stratified set of its own, from the shared set's point",
          "[light_points]") {
  // --light-points auto (light_pass_point_uv): three lights chosen in random order, two points a draw. The first 8
  // points of each light are a (0, 3, 2)-net: one point in each cell of the 8 x 1, 4 x 2, 2 x 4 and 1 x 8 grids of
  // the light's (u, v) square, however the choices interleave (the pass's shared set, which the draws of all lights
  // take in turn, gives one light a random subset of its points). Each light's first point is the shared set's
  // point of its first draw (a light drawn once keeps it). A later run of the pass (its draws numbered on) draws
  // other points.
  uint64_t state = 23;
  for (int trial = 0; trial < 100; trial++) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    const uint64_t pass_hash = state ^ (state >> 29);
    std::vector<std::pair<float, float>> first;
    const auto pts = draw_run(pass_hash, 0, 3, 2, 8, state, first);
    for (int light = 0; light < 3; light++) {
      CHECK(pts[size_t(light)][0] == first[size_t(light)]);
      for (int a = 0; a <= 3; a++) {
        std::set<int> cells;
        for (size_t i = 0; i < 8; i++) {
          const auto& p = pts[size_t(light)][i];
          cells.insert(int(p.first * float(1 << a)) * 8 + int(p.second * float(1 << (3 - a))));
        }
        INFO("trial " << trial << ", light " << light << ", grid " << (1 << a) << " x " << (1 << (3 - a)));
        CHECK(cells.size() == 8);
      }
    }
    CHECK(pts[0][1] != pts[1][1]);
    uint64_t state2 = state;
    std::vector<std::pair<float, float>> first_later;
    const auto later = draw_run(pass_hash, 100, 3, 2, 8, state2, first_later);
    CHECK(later[0][0] == first_later[0]);
    CHECK(later[0][0] != pts[0][0]);
    CHECK(later[0][2] != pts[0][2]);
  }
}

TEST_CASE("a light's point in a run of a pass is uniform over its square", "[light_points]") {
  // Unbiasedness: the c-th draw's point of a light's set, over pixels' scrambles, is uniform, whatever c. Chi-squared
  // over the 4 x 4 cells of 32000 points (15 degrees of freedom; 37.7 is the 0.1 % quantile), for draws 0, 1, 5 and
  // 77 of three points (the second point of each).
  for (uint32_t draw : {0u, 1u, 5u, 77u}) {
    int counts[16] = {};
    const int n = 32000;
    light_point_sets c;
    for (int i = 0; i < n; i++) {
      c.reset(mix64(uint64_t(i) + 99), uint64_t(i % 7));
      light_point_set* set = c.set_of(4, uint64_t(i % 5), 3);
      REQUIRE(set != nullptr);
      float u, v;
      light_pass_point_uv(*set, draw, 3, 1, u, v);
      counts[int(u * 4) * 4 + int(v * 4)]++;
    }
    double chi2 = 0, expected = n / 16.0;
    for (int k = 0; k < 16; k++) chi2 += (counts[k] - expected) * (counts[k] - expected) / expected;
    INFO("draw " << draw << ": chi2 " << chi2);
    CHECK(chi2 < 37.7);
  }
}

namespace {
// One tile's statistics for n samples of `points` points, each of weight g = 1, whose variance at one point is
// rest + within, of `vertices` path vertices each.
std::vector<double> tile_stats(double rest, double within, double vertices, int points, double n = 1000) {
  std::vector<double> s(point_stat_fields, 0.0);
  s[ps_samples] = n;
  s[ps_vertices] = n * vertices;
  s[ps_mean_samples] = n;
  s[ps_sq_dev] = n * (rest + within / points);
  s[ps_inv_points] = n / points;
  if (points > 1) s[ps_within] = n * within, s[ps_within_samples] = n;
  return s;
}
void add_to(std::vector<double>& a, const std::vector<double>& b) {
  for (size_t f = 0; f < a.size(); f++) a[f] += b[f];
}
}  // namespace

TEST_CASE("a tile's measures come back from its sums, whatever mix of point counts made them", "[light_points]") {
  // Passes at 2, 5 and 1 points: the part inside the lights is measured at 2 and 5 only, and the rest is what the
  // total leaves at each pass's count.
  std::vector<double> s = tile_stats(0.15, 0.85, 3, 2);
  add_to(s, tile_stats(0.15, 0.85, 3, 5, 3000));
  add_to(s, tile_stats(0.15, 0.85, 3, 1, 500));
  tile_measure m = measure_tile(s.data());
  REQUIRE(m.ok);
  CHECK(m.within == Approx(0.85));
  CHECK(m.rest == Approx(0.15));
  CHECK(m.cost == Approx(3 * point_cost_per_vertex));
  CHECK(m.samples == 4500);
}

TEST_CASE("blocks of a pixel's samples measure what its stratified mean keeps of their variance", "[light_points]") {
  // y = u on [0, 1) (mean 1/2, variance 1/12): blocks of point_block samples, one in each of point_block equal strata
  // (what a block of a pixel's stratified set does to a smooth integrand), keep point_block Var(ybar) = 1 /
  // (12 point_block^2) per sample; independent ones keep all of 1/12. 20000 blocks of each, seeded: the estimate's
  // relative standard error is under 2 % in both cases, the bounds 4 %.
  pcg32 rng(12345u, 7u);
  auto unit = [&] { return double(rng() >> 8) * 0x1p-24; };
  const int blocks = 20000;
  const double b = point_block;
  for (bool strata : {true, false}) {
    std::vector<double> s(point_stat_fields, 0.0);
    double y[point_block];
    for (int k = 0; k < blocks; k++) {
      for (int i = 0; i < point_block; i++) y[i] = strata ? (i + unit()) / b : unit();
      add_point_block(s.data(), y, 0.5, 2.0);  // (weight 2: the sums carry it, the estimate divides it out below)
    }
    CHECK(s[ps_blocks] == blocks);
    const double kept = (s[ps_block_dev] - s[ps_block_ss]) / s[ps_blocks] / 2.0;
    const double expect = strata ? 1 / (12 * b * b) : 1.0 / 12;
    INFO((strata ? "stratified" : "independent") << ": kept " << kept << ", expected " << expect);
    CHECK(kept == Approx(expect).epsilon(0.04));
  }
}

TEST_CASE("a tile's rest is what its blocks keep, once it has enough of them", "[light_points]") {
  // A whole variance of 1 per sample (rest 0.15 + within 0.85 at one point), of which the blocks say the mean keeps
  // 0.5: with two points the within part is 0.425, so the rest is 0.075.
  std::vector<double> s = tile_stats(0.15, 0.85, 3, 2);
  s[ps_block_dev] = point_min_blocks * 8.0, s[ps_block_ss] = point_min_blocks * 7.5, s[ps_blocks] = point_min_blocks;
  tile_measure m = measure_tile(s.data());
  REQUIRE(m.ok);
  CHECK(m.within == Approx(0.85));
  CHECK(m.rest == Approx(0.5 - 0.85 / 2));
  // Fewer blocks: the sample's own variance, as before.
  s[ps_blocks] = point_min_blocks - 1;
  CHECK(measure_tile(s.data()).rest == Approx(0.15));
  // Blocks that keep less than the within part (noise): no rest.
  s[ps_blocks] = point_min_blocks, s[ps_block_ss] = point_min_blocks * 7.9;
  CHECK(measure_tile(s.data()).rest == 0);
  // Non-finite block sums: no measure.
  s[ps_block_dev] = INFINITY;
  CHECK(!measure_tile(s.data()).ok);
}

TEST_CASE("a tile without data or with non-finite sums keeps one point", "[light_points]") {
  CHECK(!measure_tile(std::vector<double>(point_stat_fields, 0.0).data()).ok);
  // Samples but never two points (nothing measured inside the lights).
  CHECK(!measure_tile(tile_stats(0.2, 0.8, 1, 1).data()).ok);
  // Only camera rays that met nothing: no vertex, no cost.
  std::vector<double> s = tile_stats(0.2, 0.8, 1, 2);
  s[ps_vertices] = 0;
  CHECK(!measure_tile(s.data()).ok);
  for (point_stat_field f : {ps_within, ps_sq_dev, ps_inv_points, ps_vertices})
    for (double bad : {double(INFINITY), double(NAN)}) {
      s = tile_stats(0.2, 0.8, 1, 2);
      s[f] = bad;
      INFO("field " << int(f) << " = " << bad);
      CHECK(!measure_tile(s.data()).ok);
    }
  // A total below the within part (noise): the rest counts as zero.
  s = tile_stats(0.0, 1.0, 1, 2);
  s[ps_sq_dev] *= 0.5;
  CHECK(measure_tile(s.data()).ok);
  CHECK(measure_tile(s.data()).rest == 0);
  // The choice over the whole image gives such tiles one point (their tiles' data are left out of lambda).
  std::vector<double> stats = tile_stats(0.2, 0.8, 1, 1);
  std::vector<uint8_t> points;
  choose_tile_points(stats, 100, 1, 1, points);
  CHECK(int(points[0]) == 1);
}

TEST_CASE("the point count minimises error plus lambda times cost", "[light_points]") {
  // Against the brute-force minimum of rest + within / K + lambda (K - 1) over 1, 2, 3, 5, 8.
  for (double within : {0.0, 0.01, 0.1, 0.5, 0.85, 1.0, 10.0})
    for (double rest : {0.0, 0.15, 1.0})
      for (double lambda : {0.0, 0.001, 0.02, 0.1, 1.0}) {
        int best = 1;
        double best_value = rest + within;
        for (int k : {2, 3, 5, 8})
          if (rest + within / k + lambda * (k - 1) < best_value) best = k, best_value = rest + within / k + lambda * (k - 1);
        INFO("within " << within << " rest " << rest << " lambda " << lambda);
        CHECK(best_points(within, rest, lambda) == best);
      }
  CHECK(best_points(1, 0, 0) == 8);   // free points: all of them
  CHECK(best_points(0, 1, 0) == 1);   // nothing inside the lights to average
  CHECK(best_points(0.85, 0.15, 1) == 1);  // points dear against the image's error
}

TEST_CASE("tiles share one sample count: points go where the image's error is", "[light_points]") {
  // Two tiles of the same share inside the lights (85 %), one with 100 times the other's error: one sample count for
  // both, so the points go to the first; at that spp the second's error hardly counts. (Each tile alone, by its own
  // error times cost, would take 5 points.) Before point_explore_spp, every tile takes point_explore_points.
  std::vector<double> stats = tile_stats(15, 85, 1, 2);
  const std::vector<double> quiet = tile_stats(0.15, 0.85, 1, 2);
  stats.insert(stats.end(), quiet.begin(), quiet.end());
  std::vector<uint8_t> points;
  for (int spp = 0; spp < point_explore_spp; spp++) {
    choose_tile_points(stats, spp, spp, 1, points);
    REQUIRE(points.size() == 2);
    CHECK(int(points[0]) == point_explore_points);
    CHECK(int(points[1]) == point_explore_points);
  }
  // (Passes 9 and 10: tile 1 is not the tile of a re-exploring pass in either.)
  for (int pass : {9, 10}) {
    choose_tile_points(stats, 100, pass, 1, points);
    INFO("pass " << pass);
    CHECK(int(points[0]) >= 5);
    CHECK(int(points[1]) == 1);
  }
  // A tile at one point takes two on one pass in point_reexplore_passes, by tile and pass.
  choose_tile_points(stats, 100, int(point_reexplore_passes) - 1, 1, points);
  CHECK(int(points[1]) == 2);
  // Alike tiles of equal error and share: both 5 (alone or together).
  std::vector<double> twins = quiet;
  twins.insert(twins.end(), quiet.begin(), quiet.end());
  choose_tile_points(twins, 100, 10, 1, points);
  CHECK(int(points[0]) == 5);
  CHECK(int(points[1]) == 5);
  // With 4 draws per vertex each extra point is paid 4 times: (4 + 4 (K - 1)) (0.15 + 0.85 / K) is least at K = 1.
  choose_tile_points(twins, 100, 10, 4, points);
  CHECK(int(points[0]) == 1);
  CHECK(int(points[1]) == 1);
}
