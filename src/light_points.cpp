// light_points: the lattice of a draw's points on its light, and the per-tile choice of their number.
#include "light_points.h"

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

int choose_light_points(const double* s) {
  if (!(s[ps_samples] > 0 && s[ps_weight] > 0 && s[ps_within_weight] > 0)) return 1;
  const double within = s[ps_within] / s[ps_within_weight];
  const double total = s[ps_sq_dev] / s[ps_weight];
  // What the rest of the sample adds (camera jitter, the light choice, the path past the first vertex); the samples'
  // mix of point counts weighs the within part they had. Noise can take the difference below zero.
  const double cost = point_cost_per_vertex * s[ps_vertices] / s[ps_samples];
  if (!(within > 0) || !(cost > 0) || !std::isfinite(within + total + cost + s[ps_inv_points])) return 1;
  const double rest = std::max(0.0, total - within * s[ps_inv_points] / s[ps_weight]);
  static const int candidates[] = {1, 2, 3, 5, 8};
  int best = 1;
  double best_work = (cost) * (rest + within);
  for (int k : candidates) {
    if (k > max_auto_points) break;
    const double work = (cost + double(k - 1)) * (rest + within / double(k));
    if (work < best_work) best = k, best_work = work;
  }
  return best;
}

void choose_tile_points(const std::vector<double>& stats, int spp, std::vector<uint8_t>& points) {
  const size_t tiles = stats.size() / point_stat_fields;
  points.resize(tiles);
  for (size_t t = 0; t < tiles; t++)
    points[t] = uint8_t(spp < point_explore_spp ? point_explore_points : choose_light_points(&stats[t * point_stat_fields]));
}

}  // namespace bl
