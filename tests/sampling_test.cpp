// Tests of sampling warps against their pdfs (chi-square of histograms against the pdf integrated per
// cell, nori style) and of discrete distributions. Every test is seeded; significance 1e-3 per test.
#include "lights.h"
#include "material.h"
#include "rng.h"
#include "sampling.h"
#include "test_util.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <vector>

using namespace bl;
using namespace bl::test;

namespace {

constexpr double alpha = 1e-3;  // chi-square significance level of every test here

// Chi-square test of a direction warp: histogram over (cos theta, phi) cells against the pdf integrated
// over each cell by a midpoint rule (pdf is solid angle; d omega = d cos_theta d phi).
double direction_pvalue(const std::function<vec3f(vec2f)>& warp, const std::function<float(vec3f)>& pdf,
                        float cos_lo, int n_theta, int n_phi, int samples, uint64_t seed) {
  std::vector<double> obs(size_t(n_theta) * n_phi, 0.0), exp(obs.size(), 0.0);
  for (int i = 0; i < samples; i++) {
    vec3f d = warp(uniform_pair(seed, uint64_t(i)));
    float c = d.z;
    if (c < cos_lo) {
      obs[0] += 1e9;  // outside the support: guaranteed failure
      continue;
    }
    int it = std::min(n_theta - 1, int((c - cos_lo) / (1 - cos_lo) * n_theta));
    float phi = std::atan2(d.y, d.x);
    if (phi < 0) phi += 2 * pi_f;
    int ip = std::min(n_phi - 1, int(phi / (2 * pi_f) * n_phi));
    obs[size_t(it) * n_phi + ip] += 1;
  }
  const int sub = 16;
  double dc = (1.0 - cos_lo) / n_theta, dp = 2 * M_PI / n_phi;
  for (int it = 0; it < n_theta; it++)
    for (int ip = 0; ip < n_phi; ip++) {
      double acc = 0;
      for (int a = 0; a < sub; a++)
        for (int b = 0; b < sub; b++) {
          double c = cos_lo + (it + (a + 0.5) / sub) * dc;
          double phi = (ip + (b + 0.5) / sub) * dp;
          double s = std::sqrt(std::max(0.0, 1 - c * c));
          acc += pdf(vec3f{float(s * std::cos(phi)), float(s * std::sin(phi)), float(c)});
        }
      exp[size_t(it) * n_phi + ip] = acc / (sub * sub) * dc * dp * samples;
    }
  return chi2_pvalue(obs, exp);
}

}  // namespace

TEST_CASE("normalize gives the unit vector at any finite scale and zero for zero, NaN or infinite input", "[sampling]") {
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  vec3f unit = normalize(vec3f{3, 4, 12});  // 13 long
  CHECK(unit.x == 3.0f / 13.0f);
  for (float scale : {1e-30f, 1e-20f, 1e20f, 1e30f}) {
    INFO("scale " << scale);
    vec3f v = normalize(vec3f{3, 4, 12} * scale);  // squared length out of float's normal range
    CHECK(v.x == Approx(3.0 / 13).epsilon(1e-6));
    CHECK(v.z == Approx(12.0 / 13).epsilon(1e-6));
    CHECK(length(v) == Approx(1.0).epsilon(1e-6));
  }
  for (vec3f bad : {vec3f{0, 0, 0}, vec3f{nan, 1, 0}, vec3f{1, nan, 0}, vec3f{1, 0, nan}, vec3f{inf, 1, 0},
                    vec3f{1, -inf, 0}}) {
    vec3f v = normalize(bad);
    INFO(bad.x << " " << bad.y << " " << bad.z);
    CHECK(v.x == 0);
    CHECK(v.y == 0);
    CHECK(v.z == 0);
  }
}

TEST_CASE("cosine hemisphere samples follow cos over pi", "[sampling]") {
  double p = direction_pvalue([](vec2f u) { return sample_cosine_hemisphere(u.x, u.y); },
                              [](vec3f d) { return cosine_hemisphere_pdf(d.z); }, 0, 10, 20, 200000, 1);
  CHECK(p > alpha);
}

TEST_CASE("cone samples are uniform in the cone", "[sampling]") {
  float half = 25 * pi_f / 180;
  float omc = 1 - std::cos(half);
  double p = direction_pvalue([omc](vec2f u) { return sample_cone(u.x, u.y, omc); },
                              [omc](vec3f d) { return 1 - d.z <= omc ? cone_pdf(omc) : 0.0f; },
                              std::cos(half), 8, 16, 100000, 2);
  CHECK(p > alpha);
}

TEST_CASE("sun sized cones stay inside their half angle with a normalised pdf", "[sampling]") {
  // 0.53 degree disk: 1 - cos is 1.07e-5, so precision matters; all samples inside, pdf * solid angle = 1.
  float half = 0.5f * 0.53f * pi_f / 180;
  float s = std::sin(0.5f * half);
  float omc = 2 * s * s;
  for (int i = 0; i < 10000; i++) {
    vec2f u = uniform_pair(3, uint64_t(i));
    vec3f d = sample_cone(u.x, u.y, omc);
    REQUIRE(std::fabs(length(d) - 1) < 1e-5f);
    REQUIRE(1 - d.z <= omc * 1.001f);
  }
  double solid_angle = 2 * M_PI * (1 - std::cos(double(half)));
  CHECK(double(cone_pdf(omc)) * solid_angle == Approx(1.0).epsilon(1e-4));
}

TEST_CASE("phong lobe samples follow their pdf", "[sampling]") {
  for (float n : {1.0f, 10.0f, 80.0f}) {
    double p = direction_pvalue([n](vec2f u) { return sample_phong_lobe(u.x, u.y, n); },
                                [n](vec3f d) { return phong_lobe_pdf(d.z, n); }, 0, 12, 12, 150000,
                                uint64_t(4 + n));
    CHECK(p > alpha);
  }
}

TEST_CASE("triangle samples are uniform over the triangle", "[sampling]") {
  // Cells of an n x n grid over (b1, b2): inside cells get 2/n^2 of the samples, diagonal ones half that.
  const int n = 16, samples = 200000;
  std::vector<double> obs(n * n, 0.0), exp(n * n, 0.0);
  for (int i = 0; i < samples; i++) {
    vec2f u = uniform_pair(5, uint64_t(i));
    vec2f b = sample_triangle(u.x, u.y);
    REQUIRE(b.x >= 0);
    REQUIRE(b.y >= 0);
    REQUIRE(b.x + b.y <= 1.0f);
    int ix = std::min(n - 1, int(b.x * n)), iy = std::min(n - 1, int(b.y * n));
    obs[size_t(iy) * n + ix] += 1;
  }
  for (int iy = 0; iy < n; iy++)
    for (int ix = 0; ix < n; ix++) {
      double frac = ix + iy < n - 1 ? 1.0 : (ix + iy == n - 1 ? 0.5 : 0.0);
      exp[size_t(iy) * n + ix] = samples * frac * 2.0 / (n * n);
    }
  CHECK(chi2_pvalue(obs, exp) > alpha);
}

TEST_CASE("discrete distributions sample their pmf and never pick zero weights", "[sampling]") {
  std::vector<float> w = {0, 3, 0.5f, 0, 10, 1e-3f, 2, 0};
  discrete_data d = make_discrete(w.data(), int(w.size()));
  double total = 0;
  for (size_t i = 0; i < w.size(); i++) total += discrete_pmf(d, int(i));
  CHECK(total == Approx(1.0).epsilon(1e-6));
  for (size_t i = 0; i < w.size(); i++) {
    if (w[i] == 0) CHECK(discrete_pmf(d, int(i)) == 0);
    else CHECK(std::fabs(discrete_pmf(d, int(i)) - w[i] / 15.501) < 2.5e-7);  // float cdf resolution near 1
  }
  const int samples = 300000;
  std::vector<double> obs(w.size(), 0.0), exp(w.size(), 0.0);
  for (int i = 0; i < samples; i++) {
    int k = sample_discrete(d, uniform_pair(6, uint64_t(i)).x);
    REQUIRE(k >= 0);
    REQUIRE(w[size_t(k)] > 0);
    obs[size_t(k)] += 1;
  }
  for (size_t i = 0; i < w.size(); i++) exp[i] = samples * double(discrete_pmf(d, int(i)));
  CHECK(chi2_pvalue(obs, exp) > alpha);
  // The extreme ends of [0, 1) map onto positive-weight items.
  CHECK(w[size_t(sample_discrete(d, 0.0f))] > 0);
  CHECK(w[size_t(sample_discrete(d, 0x1.fffffep-1f))] > 0);
}

TEST_CASE("the guide table finds the item the cdf search finds", "[sampling]") {
  // Distributions of 17 to 2000 items (zeros in runs, tiny and huge weights, equal weights): for u at every guide
  // cell's start, just below and above it, at the cdf's own steps and at random, sample_discrete picks the item
  // sample_cdf picks (the inversion, which keeps stratified u stratified), never one of weight zero.
  pcg32 rng(91, 4);
  int mismatches = 0, zero_picks = 0, checked = 0;
  for (int c = 0; c < 60; c++) {
    int n = 17 + int(rng() % (c < 50 ? 200 : 2000));
    std::vector<float> w(static_cast<size_t>(n));
    for (int i = 0; i < n; i++) {
      float r = uint_to_unit(rng());
      w[size_t(i)] = c % 5 == 0 ? 1.0f : (r < 0.3f ? 0.0f : std::exp(30 * uint_to_unit(rng()) - 15));
    }
    if (c % 3 == 0)
      for (int i = 0; i < n / 3; i++) w[size_t(i)] = 0;  // a run of zeros
    discrete_data d = make_discrete(w.data(), n);
    if (d.cdf.empty()) continue;
    REQUIRE(d.guide.size() == size_t(n));
    std::vector<double> us = {0.0, 0x1.fffffffffffffp-1};
    for (int k = 0; k <= n; k++) {
      double x = double(k) / n;
      us.insert(us.end(), {x, std::nextafter(x, 0.0), std::nextafter(x, 1.0), d.cdf[size_t(k)],
                           std::nextafter(d.cdf[size_t(k)], 0.0)});
    }
    for (int k = 0; k < 2000; k++) us.push_back(double(uniform_pair(13, uint64_t(k)).x));
    for (double u : us) {
      if (!(u >= 0 && u < 1)) continue;
      int a = sample_discrete(d, u), b = sample_cdf(d.cdf.data(), n, u);
      checked++;
      mismatches += a != b;
      zero_picks += w[size_t(a)] == 0;
    }
  }
  INFO(checked << " samples checked");
  CHECK(checked > 100000);
  CHECK(mismatches == 0);
  CHECK(zero_picks == 0);
}

TEST_CASE("an all zero distribution is empty", "[sampling]") {
  std::vector<float> w = {0, 0, 0};
  discrete_data d = make_discrete(w.data(), 3);
  CHECK(sample_discrete(d, 0.5f) == -1);
  CHECK(discrete_pmf(d, 1) == 0);
}

TEST_CASE("the power heuristic is a partition of unity", "[sampling]") {
  CHECK(power_heuristic(1, 1) == Approx(0.5));
  CHECK(power_heuristic(3, 1) + power_heuristic(1, 3) == Approx(1.0));
  CHECK(power_heuristic(0, 1) == 0);
  CHECK(power_heuristic(inf_f, 1) == 1);
}

TEST_CASE("directions fall in the sun's disk with its solid angle, for disks down to 0.001 degrees", "[sampling]") {
  // Directions uniform in the cone of 4x the disk's half-angle about the sun's direction land in the disk with
  // probability (1 - cos t) / (1 - cos 4t) (about 1/16). 1 - dot(dir, sun) in float took every direction within
  // 2.4e-4 rad for a disk of 0.01 degrees. Binomial, 4.4 sigma.
  for (float diameter_deg : {0.53f, 0.1f, 0.03f, 0.01f, 0.001f}) {
    light_data l;
    l.sun = 0;
    l.sun_dir = normalize(vec3f{0.3f, 0.8f, -0.5f});
    double half = 0.5 * double(diameter_deg) * M_PI / 180;
    l.sun_one_minus_cos = float(2 * std::pow(std::sin(half / 2), 2));
    double wide = 2 * std::pow(std::sin(2 * half), 2);  // 1 - cos(4 half)
    double p = double(l.sun_one_minus_cos) / wide;
    frame3f f = make_frame(l.sun_dir);
    const int n = 200000;
    int inside = 0;
    for (int i = 0; i < n; i++) {
      vec2f u = uniform_pair(41, uint64_t(i));
      inside += in_sun_disk(l, normalize(to_world(f, sample_cone(u.x, u.y, float(wide)))));
    }
    double se = std::sqrt(p * (1 - p) / n);
    INFO("diameter " << diameter_deg << " degrees: " << inside << " of " << n << " inside, expected " << p * n);
    CHECK(std::fabs(double(inside) / n - p) < 4.4 * se);
  }
}

namespace {
// The directional albedo at normal incidence (wo along the normal) of b, by midpoint quadrature over the polar angle
// (the lobe is symmetric about the normal there): 2 pi * integral of f cos(theta) sin(theta) dtheta.
double albedo_at_normal_incidence(const bsdf_data& b) {
  const int steps = 200000;
  const double dt = 0.5 * M_PI / steps;
  double sum = 0;
  for (int i = 0; i < steps; i++) {
    double t = (i + 0.5) * dt;
    vec3f wi = {float(std::sin(t)), 0, float(std::cos(t))};
    sum += double(eval_bsdf_cos(b, {0, 0, 1}, wi).x) * std::sin(t) * dt;  // (eval_bsdf_cos includes the cosine)
  }
  return 2 * M_PI * sum;
}
bsdf_data facing_up(vec3f kd, vec3f ks, float ns) {
  bsdf_data b;
  b.kd = kd, b.ks = ks, b.ns = ns;
  b.spec_prob = luminance(ks) > 0 ? luminance(ks) / (luminance(kd) + luminance(ks)) : 0;
  b.frame = make_frame({0, 0, 1});
  b.ng = {0, 0, 1};
  return b;
}
}  // namespace

TEST_CASE("the normalized Phong lobe reflects ks at normal incidence, and Lambert kd", "[sampling]") {
  // f = ks (n + 2) / (2 pi) cos^n(alpha): at normal incidence the mirror direction is the normal and the integral of
  // f cos over the hemisphere is ks exactly, for every exponent.
  for (float n : {0.0f, 1.0f, 10.0f, 100.0f, 1000.0f}) {
    INFO("exponent " << n);
    CHECK(albedo_at_normal_incidence(facing_up({0, 0, 0}, {0.7f, 0.7f, 0.7f}, n)) == Approx(0.7).epsilon(2e-4));
  }
  CHECK(albedo_at_normal_incidence(facing_up({0.6f, 0.6f, 0.6f}, {0, 0, 0}, 1)) == Approx(0.6).epsilon(2e-4));
}

TEST_CASE("sampled BSDF directions follow bsdf_pdf, the glossy and diffuse lobes mixed", "[sampling]") {
  // Directions binned by cos(theta) and phi about the normal (dw = dcos dphi), expected from a midpoint quadrature
  // of bsdf_pdf over each bin; samples that fail (the glossy lobe below the surface) against the pdf's missing mass.
  // Chi-square over 65 cells, seeded (p > 1e-4).
  bsdf_data b = facing_up({0.5f, 0.5f, 0.5f}, {0.3f, 0.3f, 0.3f}, 20);
  const float t = 0.7f;  // wo 40 degrees from the normal
  const vec3f wo = {std::sin(t), 0, std::cos(t)};
  const int nz = 8, nphi = 8, sub = 48, n = 400000;
  auto cell = [&](vec3f w) {
    int iz = std::min(nz - 1, int(w.z * nz));
    double phi = std::atan2(double(w.y), double(w.x)) + M_PI;
    int ip = std::min(nphi - 1, int(phi / (2 * M_PI) * nphi));
    return iz * nphi + ip;
  };
  std::vector<double> expected(size_t(nz * nphi + 1), 0.0), observed(expected.size(), 0.0);
  double total = 0;
  for (int i = 0; i < nz * sub; i++)
    for (int j = 0; j < nphi * sub; j++) {
      double z = (i + 0.5) / (nz * sub), phi = (j + 0.5) / (nphi * sub) * 2 * M_PI - M_PI;
      double s = std::sqrt(1 - z * z);
      vec3f w = {float(s * std::cos(phi)), float(s * std::sin(phi)), float(z)};
      double p = double(bsdf_pdf(b, wo, w)) / (nz * sub) * (2 * M_PI / (nphi * sub));
      expected[size_t(cell(w))] += p * n;
      total += p;
    }
  expected.back() = std::max(0.0, 1 - total) * n;
  CHECK(total < 1.0);  // part of the glossy lobe lies below the surface at this angle
  CHECK(total > 0.9);
  int pdf_mismatch = 0;  // a sample's pdf must be bsdf_pdf of its direction (MIS weighs with both)
  for (int i = 0; i < n; i++) {
    vec2f u = uniform_pair(61, uint64_t(i));
    bsdf_sample bs = sample_bsdf(b, wo, u.x, u.y);
    if (bs.pdf > 0) {
      observed[size_t(cell(bs.wi))] += 1;
      pdf_mismatch += bs.pdf != bsdf_pdf(b, wo, bs.wi);
    } else {
      observed.back() += 1;
    }
  }
  CHECK(pdf_mismatch == 0);
  CHECK(bl::test::chi2_pvalue(observed, expected) > 1e-4);
}

TEST_CASE("evenly spaced BSDF numbers choose the glossy lobe in proportion and stay even inside the diffuse one",
          "[sampling]") {
  // The first vertex stratifies (u, v) over a pixel's samples. The lobe comes from u (glossy below spec_prob) and u's
  // place inside the lobe's share picks the direction: M evenly spaced u's give the glossy lobe M * spec_prob of them,
  // less than one off, and the diffuse ones' 1 - cos^2(theta) (their rescaled u) stay evenly spaced, no gap wider than
  // 1.5 of the even spacing. A lobe of its own random number (the code before) gives a binomial count and gaps of
  // several spacings. An exponent of 1e6 keeps every glossy direction within 0.005 rad of the normal, where no
  // diffuse one of these lands.
  bsdf_data b = facing_up({0.5f, 0.5f, 0.5f}, {0.3f, 0.3f, 0.3f}, 1e6f);
  const int m = 4096;
  int glossy = 0, failed = 0;
  std::vector<double> diffuse;
  for (int i = 0; i < m; i++) {
    double u = (i + 0.5) / m, v = std::fmod(i * 0.6180339887498949, 1.0);
    bsdf_sample bs = sample_bsdf(b, {0, 0, 1}, float(u), float(v));
    if (!(bs.pdf > 0)) {
      failed++;
    } else if (bs.wi.z > std::cos(0.005f)) {
      glossy++;
    } else {
      diffuse.push_back(1 - double(bs.wi.z) * double(bs.wi.z));
    }
  }
  INFO("glossy " << glossy << " of " << m << ", spec_prob " << b.spec_prob);
  CHECK(failed == 0);  // (wo along the normal: no direction falls below the surface)
  CHECK(std::fabs(glossy - m * double(b.spec_prob)) < 1.01);
  std::sort(diffuse.begin(), diffuse.end());
  double gap = diffuse.front();
  for (size_t i = 1; i < diffuse.size(); i++) gap = std::max(gap, diffuse[i] - diffuse[i - 1]);
  gap = std::max(gap, 1 - diffuse.back());
  INFO("widest gap " << gap << " against the even spacing " << 1.0 / double(diffuse.size()));
  CHECK(gap < 1.5 / double(diffuse.size()));
}

TEST_CASE("a material whose Kd + Ks exceed one is scaled to reflect at most all light", "[sampling]") {
  // Kd 0.8 + Ks 0.6 (the loader warns): both scaled by 1 / 1.4, so the albedo at normal incidence is 1, not 1.4.
  mesh_builder mb;
  int m = mb.add_material({0.8f, 0.8f, 0.8f}, {0, 0, 0}, {0.6f, 0.6f, 0.6f}, 20);
  mb.add_triangle({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, m);  // normal +z
  scene_data scene = build_scene(std::move(mb.mesh), camera_params{}, sun_params{}, false, 1.0f);
  bsdf_data b = make_bsdf(scene, eval_surface(scene, 0, 0.25f, 0.25f, {0, 0, -1}));
  CHECK(b.kd.x == Approx(0.8 / 1.4).epsilon(1e-6));
  CHECK(b.ks.x == Approx(0.6 / 1.4).epsilon(1e-6));
  CHECK(albedo_at_normal_incidence(b) == Approx(1.0).epsilon(2e-4));
}
