// sampling: warps from uniforms to directions and points, each next to its pdf, and a discrete
// distribution whose pmf is exactly the probability its sampling realises (cdf differences).
// Invariants: float maths only; pdfs are w.r.t. solid angle for directions and area for points.
#pragma once

#include "math.h"

#include <vector>

namespace bl {

// Cosine-weighted direction about +z; pdf = cos / pi.
inline vec3f sample_cosine_hemisphere(float u, float v) {
  float r = std::sqrt(u), phi = 2 * pi_f * v;
  return {r * std::cos(phi), r * std::sin(phi), safe_sqrt(1 - u)};
}
inline float cosine_hemisphere_pdf(float cos_theta) { return cos_theta > 0 ? cos_theta * inv_pi_f : 0; }

// Uniform point on a triangle as barycentrics (b1, b2) of corners 1 and 2; pdf = 1 / area.
inline vec2f sample_triangle(float u, float v) {
  float su = std::sqrt(u);
  return {v * su, 1 - su};
}

// Uniform direction in the cone about +z of half-angle theta_max, given one_minus_cos = 1 - cos(theta_max)
// (kept separately: for the 0.53 degree sun, cos(theta_max) itself has almost no float precision left).
inline vec3f sample_cone(float u, float v, float one_minus_cos) {
  float omc = u * one_minus_cos;                // 1 - cos(theta)
  float sin_theta = safe_sqrt(omc * (2 - omc));
  float phi = 2 * pi_f * v;
  return {sin_theta * std::cos(phi), sin_theta * std::sin(phi), 1 - omc};
}
inline float cone_pdf(float one_minus_cos) { return 1 / (2 * pi_f * one_minus_cos); }

// Phong lobe cos^n(alpha) about +z; pdf = (n + 1) / (2 pi) cos^n(alpha).
inline vec3f sample_phong_lobe(float u, float v, float n) {
  float cos_a = std::pow(u, 1 / (n + 1));
  float sin_a = safe_sqrt(1 - cos_a * cos_a);
  float phi = 2 * pi_f * v;
  return {sin_a * std::cos(phi), sin_a * std::sin(phi), cos_a};
}
inline float phong_lobe_pdf(float cos_a, float n) {
  return cos_a > 0 ? (n + 1) * (0.5f * inv_pi_f) * std::pow(cos_a, n) : 0;
}

// Power heuristic (beta = 2) weight of strategy a against b.
inline float power_heuristic(float pdf_a, float pdf_b) {
  float a = pdf_a * pdf_a, b = pdf_b * pdf_b;
  if (!(a > 0)) return 0;
  if (!std::isfinite(a)) return 1;
  return a / (a + b);
}

// Smallest probability of an item with positive weight, relative to the total: far below anything that changes
// an estimate's variance, far above the resolution of a 53-bit uniform (2^-53), so every such item can be chosen.
constexpr double min_positive_share = 0x1p-40;

// A discrete distribution over n items built from non-negative weights.
struct discrete_data {
  std::vector<double> cdf;  // n + 1 entries, cdf[0] = 0, cdf[n] = 1 (empty when all weights are zero)
  std::vector<int> guide;   // n > 16: guide[k] is the item at u = k / n, where sample_discrete starts its walk
};

// Builds the cdf (accumulated in double, in index order; positive weights floored at min_positive_share).
discrete_data make_discrete(const float* weights, int n);
// Fills cdf[0..n] from non-negative weights as make_discrete does; false (cdf all zero) when none is positive.
bool fill_cdf(const double* weights, int n, double* cdf);
// Index i with cdf[i] <= u < cdf[i+1] in cdf[0..n]; never an item of probability zero.
int sample_cdf(const double* cdf, int n, double u);
// Index sampled from d with u; -1 when the distribution is empty. The same item as sample_cdf (the cdf is inverted,
// so stratified u stay stratified over the items), found from the guide table in O(1) expected steps.
int sample_discrete(const discrete_data& d, double u);
// Probability of item i (exactly what sample_discrete realises).
inline double discrete_pmf(const discrete_data& d, int i) {
  return d.cdf.empty() ? 0.0 : d.cdf[size_t(i) + 1] - d.cdf[size_t(i)];
}

}  // namespace bl
