// light_points: how many points on the chosen light the first vertex's NEE draws (--light-points).
// K points on one chosen light, each with its shadow ray, averaged, cut the variance inside that light (a lamp
// half hidden by leaves, the receiver's cosine across it) K times for the price of K - 1 more points; the choice of
// light and the rest of the path are paid once. `auto` chooses K per tile of point_tile_size^2 pixels, between passes,
// from what the tile's samples measured: the variance inside the lights (from the sample variance of each draw's
// points), the sample's whole variance, and the sample's cost counted in path vertices (deterministic, so the choice
// never depends on timing or threads).
// Invariants: each point is uniform over the light's (u, v) square (a lattice shifted by the draw's own point), so
// every K gives an unbiased estimate; the statistics are summed in pixel order within a row and in row order within
// a tile, and are only read between passes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace bl {

constexpr int point_tile_size = 8;     // pixels along a tile's side (--light-points auto)
constexpr int point_explore_spp = 8;   // auto: samples per pixel drawn with explore_points before choosing
constexpr int point_explore_points = 2;
constexpr int max_auto_points = 8;
// The cost of a path vertex (camera or continuation ray, shading, the light choice, one point and its shadow ray) in
// extra light points (a point, the BSDF at it, a shadow ray). Measured with --profile: an extra point cost about a
// quarter of a direct-lighting sample in the plant room and the living room (bayes and bound).
constexpr double point_cost_per_vertex = 4;

// Point j of K: the draw's own point (u, v) shifted by the j-th point of a K-point rank-1 lattice (a Fibonacci
// lattice where K is a Fibonacci number), wrapped into [0, 1).
void light_point_uv(int points, int j, float& u, float& v);

// Per-tile statistics, point_stat_fields doubles per tile. Samples are weighted by g = 1 / (m^2 + 0.01), m the
// pixel's luminance mean before the pass (relMSE's weight, SPEC.md §6), and counted only once the pixel has a mean.
enum point_stat_field {
  ps_samples,     // samples (unweighted)
  ps_vertices,    // path vertices of those samples (camera and continuation rays)
  ps_weight,      // sum of g
  ps_sq_dev,      // sum of g (y - m)^2, y the sample's luminance
  ps_inv_points,  // sum of g / K
  ps_within,      // sum of g * sample_info::within, over samples of K >= 2
  ps_within_weight,  // sum of g over those samples
  point_stat_fields
};

// The number of points (1, 2, 3, 5 or 8) that minimises cost times variance per sample, where a sample of K points
// costs c + K - 1 (c: its vertices times point_cost_per_vertex) and has variance v_rest + v_within / K; 1 without
// data. `s` holds one tile's point_stat_fields.
int choose_light_points(const double* s);

// The tile counts of an image.
inline int point_tile_cols(int width) { return (width + point_tile_size - 1) / point_tile_size; }
inline int point_tile_rows(int height) { return (height + point_tile_size - 1) / point_tile_size; }

// Every tile's count for the next pass, given `spp` samples per pixel done: point_explore_points before
// point_explore_spp, then choose_light_points.
void choose_tile_points(const std::vector<double>& stats, int spp, std::vector<uint8_t>& points);

}  // namespace bl
