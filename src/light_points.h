// light_points: how many points on the chosen light the first vertex's NEE draws (--light-points).
// K points on one chosen light, each with its shadow ray, averaged, cut the variance inside that light (a lamp
// half hidden by leaves, the receiver's cosine across it) K times for the price of K - 1 more points; the choice of
// light and the rest of the path are paid once. `auto` chooses K per tile of point_tile_size^2 pixels, between passes,
// from what the tile's samples measured: the variance inside the lights (from the sample variance of each draw's
// points), what the pixel's mean keeps of a sample's variance (from blocks of its stratified samples), and the
// sample's cost counted in path vertices (deterministic, so the choice never depends on timing or threads).
// Invariants: each point is uniform over the light's (u, v) square (a lattice shifted by the draw's own point), so
// a fixed K gives an unbiased estimate; under auto, whose counts depend on a pixel's own earlier samples, the points
// come from sets of the pass's own, one per light a pixel's draws chose, whose counts were chosen before it began
// (light_pass_point_uv; unstratified samples: the sample's own numbers), and MIS counts one point per draw
// (integrator.h), so that the choice of count cannot tilt the estimate either; the statistics are summed in pixel
// order within a row and in row order within a tile, and are only read between passes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace bl {

constexpr int point_tile_size = 8;     // pixels along a tile's side (--light-points auto)
constexpr int point_explore_spp = 8;   // auto: samples per pixel drawn with explore_points before choosing
constexpr int point_explore_points = 2;
constexpr int max_auto_points = 8;
// auto: blocks of this many consecutive samples of a pass measure what a pixel's stratified mean keeps of a sample's
// variance (measure_tile); a tile's measure takes them once it has point_min_blocks.
constexpr int point_block = 8;
constexpr double point_min_blocks = 16;
constexpr size_t point_reexplore_passes = 8;  // auto: a tile at one point takes two on one pass in this many
// The tiles' statistics are scaled by this at every pass's end before its own are added: the choice follows what the
// latest passes measured (an adaptive sampler's variance falls as it learns).
constexpr double point_stats_decay = 0.5;
// The cost of a path vertex (camera or continuation ray, shading, the light choice, one point and its shadow ray) in
// extra light points (a point, the BSDF at it, a shadow ray). Measured with --profile: an extra point cost about a
// quarter of a direct-lighting sample in the plant room and the living room (bayes and bound).
constexpr double point_cost_per_vertex = 4;

// Point j of K: the draw's own point (u, v) shifted by the j-th point of a K-point rank-1 lattice (a Fibonacci
// lattice where K is a Fibonacci number), wrapped into [0, 1).
void light_point_uv(int points, int j, float& u, float& v);

// --light-points auto, stratified samples: point j of the K points of a pixel's draw number `draw` of a pass (the
// pass's draws numbered from 0 in sample order, nee draws to a sample) is point (draw + 1) K + j of the pixel's
// scrambled 2D Sobol' sequence of that pass (`hash`: its scramble; rng.h, sobol_pair). A draw's K points are then
// consecutive points of one sequence: spread over the light (a block of 2^m from a multiple of 2^m is a net), and
// apart from every other draw's points, while the pass's points of a light spread over it. The set is the pass's
// alone, so the counts, chosen between passes from what earlier samples measured, cannot lean on where its points
// fall. (The sequence starts one draw late: a draw and the next one, whose light choices take the two halves of
// [0, 1) in the light set, would otherwise take the two halves of the light as well, a coupling that cost bayes 10 %
// in the plant room, direct.)
void pass_point_uv(uint64_t hash, uint64_t draw, int points, int j, float& u, float& v);
// The same point's 32-bit coordinates (u and v are their top 24 bits).
void pass_point_bits(uint64_t hash, uint64_t draw, int points, int j, uint32_t& a, uint32_t& b);

// --light-points auto, stratified samples: each light's own point set in a pixel's run of a pass. The c-th draw
// (from 0) of light L in the run takes, for its K points, points cK .. cK + K - 1 of a scrambled 2D Sobol' sequence
// of L's own, digitally shifted (XOR) so that its first point is the shared set's first point of L's first draw in the
// run. So the points that fall on one light are a stratified set of their own however the light choices interleave
// (a digital shift keeps a net a net), and a light drawn once in the run takes the shared set's point, as before:
// many small lights each drawn about once (a lamp of 450 triangles) keep what the shared set's points, spread jointly
// with the stratified light choice, gave them. Each point stays uniform over the light whatever the earlier choices
// were (the shared point is uniform and independent of L's scramble), so the estimate stays unbiased.
struct light_point_set {
  uint64_t hash = 0;                 // the sequence's scramble (pixel, pass, run and light)
  uint32_t shift_a = 0, shift_b = 0; // XORed into its points' 32-bit coordinates
  uint32_t draws = 0;                // the light's draws in the run so far
};
void light_pass_point_uv(const light_point_set& set, uint32_t draw, int points, int j, float& u, float& v);

// The point sets of the lights one pixel's run of a pass drew (light_pass_point_uv), for up to max_lights lights;
// the draws of further lights take the pass's shared set (pass_point_uv). Open addressing; reset clears only the
// slots a run used.
class light_point_sets {
 public:
  static constexpr int slots = 256;             // a power of two
  static constexpr int max_lights = slots / 2;  // (the table at most half full)
  light_point_sets();
  // A new run (the next pixel, or a later piece of a pass, which draws new sets): `pass_hash` the pixel's pass set's
  // scramble (pixel_streams::point), `run_start` the run's first sample.
  void reset(uint64_t pass_hash, uint64_t run_start);
  // The set of `light`, made at its first draw, `draw` (the pass's draw number) of `points` points; null where the
  // table holds max_lights others.
  light_point_set* set_of(int light, uint64_t draw, int points);

 private:
  uint64_t pass_hash_ = 0, run_hash_ = 0;
  int32_t light_[slots];
  light_point_set set_[slots];
  uint16_t used_at_[max_lights];
  int used_ = 0;
};

// Per-tile statistics, point_stat_fields doubles per tile. Samples are weighted by g = 1 / (m^2 + 0.01), m the
// pixel's luminance mean before the pass (relMSE's weight, SPEC.md §6), and counted only once the pixel has a mean.
enum point_stat_field {
  ps_samples,         // samples (all)
  ps_vertices,        // path vertices of those samples (camera and continuation rays)
  ps_mean_samples,    // samples of pixels with a mean
  ps_sq_dev,          // sum of g (y - m)^2 n / (n + 1) over those, y the sample's luminance, n the mean's samples
  ps_inv_points,      // sum of 1 / K over those
  ps_within,          // sum of g * sample_info::within over those of K >= 2
  ps_within_samples,  // how many those are
  ps_block_dev,       // blocks of point_block consecutive samples of a pass (from a multiple of point_block counted
                      // from the light set's start, render_inputs::stratum_base): the sum of g (y - m)^2 over them
  ps_block_ss,        // the sum of g times each block's squared deviations from its own mean
  ps_blocks,          // how many blocks
  point_stat_fields
};

// What a tile measured, per sample (relMSE-weighted variances): the variance inside the chosen lights at one point,
// the rest that the pixel's mean keeps (its stratified set's blocks, measure_tile), and the cost in extra points
// (path vertices times point_cost_per_vertex). ok = false without data (or with non-finite sums): such a tile keeps
// one point.
struct tile_measure {
  double within = 0, rest = 0, cost = 0, samples = 0;
  bool ok = false;
};
tile_measure measure_tile(const double* s);
// Adds to a tile's statistics `s` a block of one pixel's samples (their luminances y[0..point_block), samples
// k point_block to (k + 1) point_block - 1 of a pass), m the pixel's mean before the pass and g its weight.
void add_point_block(double* s, const double* y, double m, double g);

// The count (1, 2, 3, 5 or 8) that minimises rest + within / K + lambda (K - 1): a tile's share of the image's error
// plus lambda times its share of the render's time. lambda is the image's error per unit of time, so the choice
// minimises error times time for the whole image, whose tiles share one sample count (a tile whose own samples are
// cheap to improve but add little error gets fewer points than its own efficiency would ask).
int best_points(double within, double rest, double lambda);

// The tile counts of an image.
inline int point_tile_cols(int width) { return (width + point_tile_size - 1) / point_tile_size; }
inline int point_tile_rows(int height) { return (height + point_tile_size - 1) / point_tile_size; }
// The tile of pixel (x, y) in an image of `cols` tiles to a row, and the length of an image's statistics.
inline size_t point_tile_of(int x, int y, int cols) {
  return size_t(y / point_tile_size) * size_t(cols) + size_t(x / point_tile_size);
}
inline size_t point_stats_size(int width, int height) {
  return size_t(point_tile_cols(width)) * size_t(point_tile_rows(height)) * point_stat_fields;
}

// Every tile's count for the next pass (pass `pass`, `spp` samples per pixel done, `draws` NEE draws per first vertex,
// each paying K - 1 extra points): point_explore_points before
// point_explore_spp; then best_points for the lambda (of a geometric range) whose counts give the image the least
// error times cost. A tile at one point takes two on one pass in point_reexplore_passes (by tile and pass), so that
// what it measures inside its lights stays current.
void choose_tile_points(const std::vector<double>& stats, int spp, int pass, int draws, std::vector<uint8_t>& points);

}  // namespace bl
