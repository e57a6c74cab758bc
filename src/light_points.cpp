// light_points: the lattice of a draw's points on its light, and the per-tile choice of their number.
#include "light_points.h"

#include "rng.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace bl {

namespace {
// The lattice's generator: K / golden ratio^2 rounded, moved up to the next number coprime with K (so that the K
// points take K different rows as well as K different columns).
int lattice_generator(int k) {
  int g = std::max(1, int(std::lround(double(k) * 0.3819660112501051)));
  while (std::gcd(g, k) != 1) g++;
  return g;
}
float wrap01(float t) { return t >= 1.0f ? t - 1.0f : t; }
}  // namespace

void light_point_uv(int points, int j, float& u, float& v) {
  if (j == 0) return;
  const int g = lattice_generator(points);
  u = wrap01(u + float(j) / float(points));
  v = wrap01(v + float(int((int64_t(j) * g) % points)) / float(points));
}

void pass_point_bits(uint64_t hash, uint64_t draw, int points, int j, uint32_t& a, uint32_t& b) {
  sobol_pair(uint32_t((draw + 1) * uint64_t(points) + uint64_t(j)), hash, a, b);
}

void pass_point_uv(uint64_t hash, uint64_t draw, int points, int j, float& u, float& v) {
  uint32_t a, b;
  pass_point_bits(hash, draw, points, j, a, b);
  u = uint_to_unit(a), v = uint_to_unit(b);
}

void light_pass_point_uv(const light_point_set& set, uint32_t draw, int points, int j, float& u, float& v) {
  uint32_t a, b;
  sobol_pair(draw * uint32_t(points) + uint32_t(j), set.hash, a, b);
  u = uint_to_unit(a ^ set.shift_a), v = uint_to_unit(b ^ set.shift_b);
}

light_point_sets::light_point_sets() { std::fill(light_, light_ + slots, -1); }

void light_point_sets::reset(uint64_t pass_hash, uint64_t run_start) {
  for (int i = 0; i < used_; i++) light_[used_at_[i]] = -1;
  used_ = 0;
  pass_hash_ = pass_hash;
  run_hash_ = mix64(pass_hash ^ mix64(run_start ^ 0xa54ff53a5f1d36f1ull));
}

light_point_set* light_point_sets::set_of(int light, uint64_t draw, int points) {
  uint32_t i = (uint32_t(light) * 0x9e3779b1u) >> 24;  // (slots = 2^8)
  for (;; i = (i + 1) & (slots - 1)) {
    if (light_[i] == light) return &set_[i];
    if (light_[i] < 0) break;
  }
  if (used_ == max_lights) return nullptr;
  light_[i] = light, used_at_[used_++] = uint16_t(i);
  light_point_set& s = set_[i];
  s.hash = mix64(run_hash_ ^ (uint64_t(uint32_t(light)) * 0xd6e8feb86659fd93ull));
  s.draws = 0;
  // The shift that puts the sequence's point 0 on the shared set's first point of this draw.
  uint32_t shared_a, shared_b, own_a, own_b;
  pass_point_bits(pass_hash_, draw, points, 0, shared_a, shared_b);
  sobol_pair(0, s.hash, own_a, own_b);
  s.shift_a = shared_a ^ own_a, s.shift_b = shared_b ^ own_b;
  return &s;
}

tile_measure measure_tile(const double* s) {
  tile_measure m;
  if (!(s[ps_samples] > 0 && s[ps_mean_samples] > 0 && s[ps_within_samples] > 0)) return m;
  m.within = s[ps_within] / s[ps_within_samples];
  const double total = s[ps_sq_dev] / s[ps_mean_samples];
  m.cost = point_cost_per_vertex * s[ps_vertices] / s[ps_samples];
  m.samples = s[ps_mean_samples];
  if (!(m.within >= 0) || !(m.cost > 0) ||
      !std::isfinite(m.within + total + m.cost + s[ps_inv_points] + s[ps_block_dev] + s[ps_block_ss]))
    return m;
  // What the pixel's mean keeps of a sample's variance: its samples are a stratified set (the light choice, the camera
  // jitter), which removes much of (y - m)^2 from the mean. Over blocks of point_block consecutive samples from a
  // multiple of point_block counted from the light set's start (each a block of that set; blocks counted from sample 0
  // split the sets of an adaptive sampler, which restart with its model, and so measured more than they keep: HISTORY,
  // stop 65), sum (y - m)^2 - sum (y - ybar)^2 = b (ybar - m)^2 estimates b
  // Var(ybar) (plus b (m - mu)^2, the earlier mean's own error, small against it): the variance per sample of the
  // blocks' means, whatever the samples' correlation. The Cornell box, direct, measured 0.0032 against (y - m)^2's
  // 0.016 (HISTORY, stop 63). Without enough blocks (a tile of short passes), the sample's own variance.
  const double kept = s[ps_blocks] >= point_min_blocks
                          ? std::max(0.0, (s[ps_block_dev] - s[ps_block_ss]) / s[ps_blocks])
                          : total;
  // The rest (camera jitter, the light choice, the path past the first vertex): the samples' mix of point counts
  // weighs the within part they had. Noise can take the difference below zero.
  m.rest = std::max(0.0, kept - m.within * s[ps_inv_points] / s[ps_mean_samples]);
  m.ok = true;
  return m;
}

void add_point_block(double* s, const double* y, double m, double g) {
  double mean = 0, dev = 0, ss = 0;
  for (int i = 0; i < point_block; i++) mean += y[i];
  mean /= point_block;
  for (int i = 0; i < point_block; i++) dev += (y[i] - m) * (y[i] - m), ss += (y[i] - mean) * (y[i] - mean);
  s[ps_block_dev] += g * dev, s[ps_block_ss] += g * ss, s[ps_blocks] += 1;
}

int best_points(double within, double rest, double lambda) {
  static const int candidates[] = {2, 3, 5, 8};
  int best = 1;
  double best_value = rest + within;
  for (int k : candidates) {
    if (k > max_auto_points) break;
    const double value = rest + within / double(k) + lambda * double(k - 1);
    if (value < best_value) best = k, best_value = value;
  }
  return best;
}

void choose_tile_points(const std::vector<double>& stats, int spp, int pass, int draws, std::vector<uint8_t>& points) {
  const size_t tiles = stats.size() / point_stat_fields;
  points.assign(tiles, uint8_t(spp < point_explore_spp ? point_explore_points : 1));
  if (spp < point_explore_spp) return;
  std::vector<tile_measure> m(tiles);
  for (size_t t = 0; t < tiles; t++) m[t] = measure_tile(&stats[t * point_stat_fields]);
  // The image's error and cost per sample at the counts best_points gives for lambda (sums in tile order).
  std::vector<uint8_t> trial(tiles, 1);
  auto allocate = [&](double lambda, double& error, double& cost) {
    error = cost = 0;
    for (size_t t = 0; t < tiles; t++)
      if (m[t].ok) {
        trial[t] = uint8_t(best_points(m[t].within, m[t].rest, lambda * draws));
        error += m[t].samples * (m[t].rest + m[t].within / trial[t]);
        cost += m[t].samples * (m[t].cost + draws * (trial[t] - 1));
      }
  };
  // lambda over a geometric range around the error per cost at one point everywhere (from about 1/1000 of it up to
  // 8 times): the counts of the lambda whose error times cost is least.
  double error = 0, cost = 0;
  allocate(INFINITY, error, cost);  // (one point everywhere: best_points compares no value above rest + within)
  if (!(cost > 0 && error > 0) || !std::isfinite(error * cost)) return;
  const double lambda1 = error / cost;
  double best = error * cost;
  for (int j = -20; j <= 6; j++) {
    allocate(lambda1 * std::exp2(0.5 * j), error, cost);
    if (error * cost < best) best = error * cost, points = trial;
  }
  for (size_t t = 0; t < tiles; t++)
    if (points[t] == 1 && (t + size_t(pass)) % point_reexplore_passes == 0) points[t] = 2;
}

}  // namespace bl
