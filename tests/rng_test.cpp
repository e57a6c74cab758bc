// Tests of the random streams: pcg-cpp reference values, key separation, fixed dimension table, the pixel jitter.
#include "math.h"
#include "rng.h"
#include "test_util.h"

#include <catch2/catch.hpp>

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
