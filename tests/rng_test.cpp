// Tests of the random streams: pcg-cpp reference values, key separation, fixed dimension table, the pixel jitter.
#include "math.h"
#include "rng.h"
#include "test_util.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <set>

using namespace bl;

TEST_CASE("pcg32 matches the reference output of pcg-cpp", "[rng]") {
  pcg32 rng(42u, 54u);
  CHECK(rng() == 0xa15c02b7u);
  CHECK(rng() == 0x7b47f409u);
  CHECK(rng() == 0xba1d3330u);
}

TEST_CASE("vertex blocks repeat for the same key and differ between keys and vertices", "[rng]") {
  auto a = draw_vertex(sample_key(0, 10, 3), 2);
  auto b = draw_vertex(sample_key(0, 10, 3), 2);
  for (int i = 0; i < dims_per_vertex; i++) CHECK(a.u[i] == b.u[i]);
  std::set<float> firsts;
  for (uint64_t seed = 0; seed < 4; seed++)
    for (uint64_t px = 0; px < 16; px++)
      for (uint64_t s = 0; s < 16; s++)
        for (uint32_t v = 0; v < 4; v++) firsts.insert(draw_vertex(sample_key(seed, px, s), v).u[0]);
  // 4096 draws of 24-bit uniforms: a collision is possible but more than a handful means keys alias.
  CHECK(firsts.size() > 4080);
}

TEST_CASE("the roulette draws of a path's vertices are independent", "[rng]") {
  // A path survives vertices 3..30 (28 draws below 0.9) with probability 0.9^28 = 0.0523. With the vertex as the
  // PCG32 stream of one shared seed the draws were correlated and 0.039 of 40000 keys survived (z = -12). Binomial
  // standard error sqrt(p (1 - p) / n) = 0.00111; 5 sigma bound. Also each vertex's draw alone (mean 0.5).
  const int n = 40000;
  int survived = 0;
  for (uint64_t k = 0; k < uint64_t(n); k++) {
    uint64_t key = sample_key(3, k, 0);
    bool alive = true;
    for (uint32_t v = 3; v <= 30 && alive; v++) alive = draw_vertex(key, v).u[dim_roulette] < 0.9f;
    survived += alive;
  }
  const double p = std::pow(0.9, 28), se = std::sqrt(p * (1 - p) / n);
  INFO("survived " << survived << " of " << n << ", expected " << p * n);
  CHECK(std::fabs(double(survived) / n - p) < 5 * se);
  // Pairs of neighbouring vertices: the correlation of their roulette draws (standard error 1/sqrt(n) = 0.005).
  double sxy = 0, sx = 0, sy = 0, sxx = 0, syy = 0;
  for (uint64_t k = 0; k < uint64_t(n); k++) {
    uint64_t key = sample_key(5, k, 1);
    double x = draw_vertex(key, 7).u[dim_roulette], y = draw_vertex(key, 8).u[dim_roulette];
    sx += x, sy += y, sxy += x * y, sxx += x * x, syy += y * y;
  }
  double cov = sxy / n - sx / n * sy / n, r = cov / std::sqrt((sxx / n - sx * sx / n / n) * (syy / n - sy * sy / n / n));
  INFO("correlation " << r);
  CHECK(std::fabs(r) < 5 / std::sqrt(double(n)));
}

TEST_CASE("uniforms lie in the unit interval with mean one half", "[rng]") {
  // 80000 uniforms: the mean's standard error is 0.289/sqrt(80000) = 0.00102; 5 sigma bound.
  double sum = 0;
  int n = 0;
  for (uint64_t px = 0; px < 10000; px++) {
    auto r = draw_vertex(sample_key(7, px, 0), 1);
    for (float u : r.u) {
      REQUIRE(u >= 0.0f);
      REQUIRE(u < 1.0f);
      sum += u;
      n++;
    }
  }
  CHECK(std::abs(sum / n - 0.5) < 5 * 0.2887 / std::sqrt(double(n)));
}

TEST_CASE("the Sobol' points behind the pixel jitter have their textbook values", "[rng]") {
  // Van der Corput: 0, 1/2, 1/4, 3/4, 1/8, ...; Sobol's second dimension in natural order: 0, 1/2, 3/4, 1/4, 5/8, 1/8,
  // 3/8, 7/8 (direction numbers 1/2, 3/4, 5/8, 15/16, ...).
  const double vdc[] = {0, 0.5, 0.25, 0.75, 0.125, 0.625, 0.375, 0.875};
  const double sob[] = {0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875};
  for (uint32_t i = 0; i < 8; i++) {
    CHECK(reverse_bits(i) * 0x1p-32 == vdc[i]);
    CHECK(sobol_second(i) * 0x1p-32 == sob[i]);
  }
  CHECK(sobol_second(8) * 0x1p-32 == 15.0 / 16);
  CHECK(reverse_bits(0x80000000u) == 1u);
}

TEST_CASE("pixel jitter is uniform per sample and stratified over a pixel's samples", "[rng]") {
  // Stratified: samples [16 k, 16 k + 16) of a pixel fall one per cell of every 2^a x 2^b grid with a + b = 4.
  for (uint64_t px : {0u, 7u, 12345u})
    for (uint64_t k : {0u, 1u, 5u})
      for (int a = 0; a <= 4; a++) {
        std::set<int> cells;
        for (uint64_t s = 16 * k; s < 16 * k + 16; s++) {
          float u, v;
          pixel_jitter(3, px, s, u, v);
          REQUIRE(u >= 0.0f);
          REQUIRE(u < 1.0f);
          REQUIRE(v >= 0.0f);
          REQUIRE(v < 1.0f);
          cells.insert(int(u * float(1 << a)) * 16 + int(v * float(1 << (4 - a))));
        }
        CHECK(cells.size() == 16);
      }
  // Uniform: one sample of each of 40000 pixels (their shifts are independent), chi-square over a 10 x 10 grid
  // (99 degrees of freedom; p > 1e-4 fails one run in 10^4), for a first and a later sample index.
  for (uint64_t s : {0u, 37u}) {
    std::vector<double> observed(100, 0.0), expected(100, 400.0);
    for (uint64_t px = 0; px < 40000; px++) {
      float u, v;
      pixel_jitter(11, px, s, u, v);
      observed[size_t(int(u * 10) * 10 + int(v * 10))] += 1;
    }
    CHECK(bl::test::chi2_pvalue(observed, expected) > 1e-4);
  }
  // Determinism and separation: the same (seed, pixel, sample) repeats, another seed or pixel moves the point.
  float u0, v0, u1, v1, u2, v2, u3, v3;
  pixel_jitter(1, 2, 3, u0, v0);
  pixel_jitter(1, 2, 3, u1, v1);
  pixel_jitter(2, 2, 3, u2, v2);
  pixel_jitter(1, 3, 3, u3, v3);
  CHECK(u0 == u1);
  CHECK(v0 == v1);
  CHECK((u0 != u2 || v0 != v2));
  CHECK((u0 != u3 || v0 != v3));
}

// The first vertex's randoms of sample `index` of a stratified set with key `key`, pixel `px`.
static vertex_randoms first_vertex(uint64_t key, uint64_t px, uint32_t index, bool last = false) {
  vertex_randoms r = draw_vertex(sample_key(9, px, index), 1);
  stratify_first_vertex(key, px, index, last, r);
  return r;
}

TEST_CASE("the first vertex's light and BSDF samples are stratified over a set, uniform and independent", "[rng]") {
  const uint64_t key = stratum_key_of(5, 0);
  // Stratified: any aligned block of 16 samples puts one light choice in each 1/16 of [0, 1), and one light point
  // and one BSDF direction in each cell of every 2^a x 2^(4-a) grid.
  for (uint64_t px = 0; px < 50; px++)
    for (uint32_t block : {0u, 3u}) {
      std::set<int> select;
      std::set<int> light[5], bsdf[5];
      for (uint32_t i = 16 * block; i < 16 * block + 16; i++) {
        vertex_randoms r = first_vertex(key, px, i);
        select.insert(int(r.u53(dim_light_select, dim_light_select_lo) * 16));
        for (int a = 0; a <= 4; a++) {
          light[a].insert(int(r.u[dim_light_u] * float(1 << a)) * 16 + int(r.u[dim_light_v] * float(1 << (4 - a))));
          bsdf[a].insert(int(r.u[dim_bsdf_u] * float(1 << a)) * 16 + int(r.u[dim_bsdf_v] * float(1 << (4 - a))));
        }
      }
      CHECK(select.size() == 16);
      for (int a = 0; a <= 4; a++) {
        CHECK(light[a].size() == 16);
        CHECK(bsdf[a].size() == 16);
      }
    }
  // Uniform per sample: sample 0 and sample 37 of 40000 pixels (independent shuffles and shifts), chi-square over
  // 100 cells (99 degrees of freedom; p > 1e-4 fails one run in 10^4 per check).
  for (uint32_t i : {0u, 37u}) {
    std::vector<double> sel(100, 0.0), light(100, 0.0), bsdf(100, 0.0), expected(100, 400.0);
    for (uint64_t px = 0; px < 40000; px++) {
      vertex_randoms r = first_vertex(key, px, i);
      sel[size_t(r.u53(dim_light_select, dim_light_select_lo) * 100)] += 1;
      light[size_t(int(r.u[dim_light_u] * 10) * 10 + int(r.u[dim_light_v] * 10))] += 1;
      bsdf[size_t(int(r.u[dim_bsdf_u] * 10) * 10 + int(r.u[dim_bsdf_v] * 10))] += 1;
    }
    CHECK(bl::test::chi2_pvalue(sel, expected) > 1e-4);
    CHECK(bl::test::chi2_pvalue(light, expected) > 1e-4);
    CHECK(bl::test::chi2_pvalue(bsdf, expected) > 1e-4);
  }
  // Independent between dimensions: over the 256 samples of each of 100 pixels, the pairs (choice, light u),
  // (light u, BSDF u), (light v, BSDF v) and (jitter u, light u) fill a 10 x 10 grid evenly (sets that shared one
  // shuffle would tie one coordinate to the other through their shifts and leave most cells empty).
  std::vector<double> h[4];
  for (auto& x : h) x.assign(100, 0.0);
  std::vector<double> expected(100, 256.0);
  auto cell = [](float a, float b) { return size_t(int(a * 10) * 10 + int(b * 10)); };
  for (uint64_t px = 0; px < 100; px++)
    for (uint32_t i = 0; i < 256; i++) {
      vertex_randoms r = first_vertex(key, px, i);
      float ju, jv;
      pixel_jitter(5, px, i, ju, jv);
      h[0][cell(r.u[dim_light_select], r.u[dim_light_u])] += 1;
      h[1][cell(r.u[dim_light_u], r.u[dim_bsdf_u])] += 1;
      h[2][cell(r.u[dim_light_v], r.u[dim_bsdf_v])] += 1;
      h[3][cell(ju, r.u[dim_light_u])] += 1;
    }
  for (int k = 0; k < 4; k++) {
    INFO("pair " << k);
    CHECK(bl::test::chi2_pvalue(h[k], expected) > 1e-4);
  }
  // The last vertex keeps its BSDF draws; the other dimensions are the independent draws of draw_vertex.
  vertex_randoms plain = draw_vertex(sample_key(9, 7, 3), 1);
  vertex_randoms last = first_vertex(key, 7, 3, true);
  for (int d : {int(dim_light_inner), int(dim_bsdf_lobe), int(dim_roulette), int(dim_light_select_lo),
                int(dim_light_inner_lo), int(dim_bsdf_u), int(dim_bsdf_v)})
    CHECK(last.raw[d] == plain.raw[d]);
  // Sets of other keys (another pass, another seed) are other sets.
  CHECK(first_vertex(key, 7, 3).raw[dim_light_u] == first_vertex(key, 7, 3).raw[dim_light_u]);
  CHECK(first_vertex(stratum_key_of(5, 8), 7, 3).raw[dim_light_u] != first_vertex(key, 7, 3).raw[dim_light_u]);
  CHECK(first_vertex(stratum_key_of(6, 0), 7, 3).raw[dim_light_u] != first_vertex(key, 7, 3).raw[dim_light_u]);
}

TEST_CASE("a render's first-vertex BSDF directions form one set while its light sets restart with the model", "[rng]") {
  // A learning render's light sets restart at every change of its model (here at samples 8, 10, 12, 16, 32 and 48);
  // its BSDF directions stay one set, as a fixed sampler's: over samples 0-63 of a pixel, one in each cell of every
  // 2^a x 2^(6-a) grid.
  const uint64_t seed = 5;
  const uint64_t bases[] = {0, 8, 10, 12, 16, 32, 48};
  auto base_of = [&](uint64_t s) {
    uint64_t b = 0;
    for (uint64_t x : bases)
      if (x <= s) b = x;
    return b;
  };
  for (uint64_t px = 0; px < 40; px++) {
    std::set<int> bsdf[7];
    std::set<int> select;
    for (uint64_t s = 0; s < 64; s++) {
      const uint64_t base = base_of(s);
      vertex_randoms r = draw_vertex(sample_key(seed, px, s), 1);
      stratify_sample(pixel_streams_of(seed, stratum_key_of(seed, base), px), s, base, false, r);
      for (int a = 0; a <= 6; a++)
        bsdf[a].insert(int(r.u[dim_bsdf_u] * float(1 << a)) * 64 + int(r.u[dim_bsdf_v] * float(1 << (6 - a))));
      // The same direction as in a render whose set never restarts.
      vertex_randoms fixed = draw_vertex(sample_key(seed, px, s), 1);
      stratify_sample(pixel_streams_of(seed, stratum_key_of(seed, 0), px), s, 0, false, fixed);
      CHECK(r.raw[dim_bsdf_u] == fixed.raw[dim_bsdf_u]);
      CHECK(r.raw[dim_bsdf_v] == fixed.raw[dim_bsdf_v]);
      // The light dimensions are those of the sample's place in its own set.
      vertex_randoms own = draw_vertex(sample_key(seed, px, s), 1);
      stratify_first_vertex(stratum_key_of(seed, base), px, uint32_t(s - base), false, own);
      CHECK(r.raw[dim_light_select] == own.raw[dim_light_select]);
      CHECK(r.raw[dim_light_u] == own.raw[dim_light_u]);
      CHECK(r.raw[dim_light_v] == own.raw[dim_light_v]);
      if (base == 32) select.insert(int(r.u53(dim_light_select, dim_light_select_lo) * 16));
    }
    for (int a = 0; a <= 6; a++) {
      INFO("pixel " << px << ", grid 2^" << a << " x 2^" << 6 - a);
      CHECK(bsdf[a].size() == 64);
    }
    CHECK(select.size() == 16);  // (the set of samples 32-47: one light choice in each 1/16)
  }
}

TEST_CASE("make_frame is orthonormal for any unit normal", "[math]") {
  for (int i = 0; i < 1000; i++) {
    auto r = draw_vertex(sample_key(1, i, 0), 0);
    float z = 2 * r.u[0] - 1, phi = 2 * pi_f * r.u[1];
    float s = safe_sqrt(1 - z * z);
    vec3f n = {s * std::cos(phi), s * std::sin(phi), z};
    if (i == 0) n = {0, 0, -1};
    auto f = make_frame(n);
    CHECK(std::abs(dot(f.t, f.b)) < 1e-5f);
    CHECK(std::abs(dot(f.t, f.n)) < 1e-5f);
    CHECK(std::abs(length(f.t) - 1) < 1e-5f);
    CHECK(std::abs(length(f.b) - 1) < 1e-5f);
    vec3f c = cross(f.t, f.b);
    CHECK(length(c - f.n) < 1e-4f);
  }
}
