// Tests of the random streams: pcg-cpp reference values, key separation, fixed dimension table.
#include "math.h"
#include "rng.h"

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

TEST_CASE("a partial vertex block holds the whole block's first dimensions", "[rng]") {
  for (uint64_t px = 0; px < 64; px++)
    for (uint32_t v = 0; v < 3; v++)
      for (int count = 0; count <= dims_per_vertex; count++) {
        auto whole = draw_vertex(sample_key(5, px, 2), v);
        auto part = draw_vertex(sample_key(5, px, 2), v, count);
        for (int i = 0; i < count; i++) {
          REQUIRE(part.raw[i] == whole.raw[i]);
          REQUIRE(part.u[i] == whole.u[i]);
        }
      }
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
