// rng: every random number of a render, keyed by (seed, pixel, sample, path vertex, dimension).
// Invariants: a (pixel, sample) pair owns one PCG32 key; each path vertex draws its own fixed-size block of
// uniforms from a PCG32 generator seeded by a hash of (key, vertex) (vertex_seed), in the fixed order of the
// dimension table below.
// So changing the light sampler (which uses only the light dimensions) leaves camera rays and BSDF samples
// untouched, and no random number depends on thread identity or timing. The camera's jitter and, at the first
// vertex, the light choice, light point and BSDF direction come instead from randomised Sobol' sets over a pixel's
// samples (pixel_jitter, stratify_sample): still functions of (seed, pixel, sample) and where the render's stratified
// light set began.
#pragma once

#include <pcg_random.hpp>

#include <cstdint>

namespace bl {

// The dimension table: slots of one vertex's random block (path vertices 1, 2, ...; the camera's pixel jitter is
// pixel_jitter's, below).
enum rng_dim : int {
  dim_light_select = 0,  // path vertices: which light / cluster
  dim_light_inner = 1,   // the descent inside a cluster whose cell is under 2^-20 of the light choice (place_in_cell);
                         // larger ones descend with the light choice's own number
  dim_light_u = 2,       // point on the chosen light
  dim_light_v = 3,       //
  dim_bsdf_lobe = 4,     // drawn, not read: the lobe is chosen by dim_bsdf_u (sample_bsdf); kept so that the others
                         // draw what they drew
  dim_bsdf_u = 5,        // direction inside the lobe
  dim_bsdf_v = 6,        //
  dim_roulette = 7,      // Russian roulette
  dim_light_select_lo = 8,  // low bits of the two light choices (they use 53-bit uniforms, see u53)
  dim_light_inner_lo = 9,
  dims_per_vertex = 10
};

// One vertex's uniforms in [0, 1) (24-bit floats) and the raw draws behind them.
struct vertex_randoms {
  float u[dims_per_vertex];
  uint32_t raw[dims_per_vertex];
  // A 53-bit uniform in [0, 1) from two draws: discrete choices over many lights (or deep tree descents) need
  // more resolution than 24 bits, or a light with probability below 2^-24 could never be chosen.
  double u53(int hi, int lo) const {
    uint64_t bits = (uint64_t(raw[hi]) << 21) ^ (uint64_t(raw[lo]) >> 11);
    return double(bits & ((uint64_t(1) << 53) - 1)) * 0x1p-53;
  }
};

// 64-bit finaliser (splitmix64): decorrelates nearby keys.
inline uint64_t mix64(uint64_t z) {
  z += 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

// The seed of frame `frame` of an animation rendered with seed `seed` (frame 0: the seed itself, so a one-frame
// render is the still render): every frame draws its own streams.
inline uint64_t frame_seed(uint64_t seed, int frame) {
  return frame == 0 ? seed : mix64(seed ^ (uint64_t(frame) * 0xa0761d6478bd642full));
}

// The PCG32 key of sample `sample` of pixel `pixel` under render seed `seed`.
// (Its per-pixel part, pixel_key_base, is what pixel_streams caches.)
inline uint64_t pixel_key_base(uint64_t seed, uint64_t pixel) { return mix64(mix64(seed) ^ pixel); }
inline uint64_t sample_key_from(uint64_t base, uint64_t sample) { return mix64(base ^ (sample * 0x632be59bd9b4e019ull)); }
inline uint64_t sample_key(uint64_t seed, uint64_t pixel, uint64_t sample) {
  return sample_key_from(pixel_key_base(seed, pixel), sample);
}

// Uniform float in [0, 1) from the top 24 bits of a 32-bit draw (exactly representable).
inline float uint_to_unit(uint32_t v) { return float(v >> 8) * 0x1p-24f; }

// The PCG32 state seed of path vertex `vertex` of the sample with key `key`. Every vertex has its own hashed seed on
// one stream: PCG32 generators that share a seed and differ only in their stream (increment) run through states
// that differ by a key-independent offset at every step, and their outputs are correlated. With the vertex as the
// stream (before 2026-12), Russian roulette with survival 0.9 let a path pass vertices 3..30 with frequency 0.039
// instead of 0.052, and a furnace of albedo 0.9 at depth 50 rendered 9.60 instead of 9.95.
inline uint64_t vertex_seed(uint64_t key, uint32_t vertex) {
  return mix64(key ^ (uint64_t(vertex) * 0xd1b54a32d192ed03ull));
}

// The block of uniforms of path vertex `vertex` (1 = the first hit; the camera's jitter is pixel_jitter's) of the
// sample with key `key`.
inline vertex_randoms draw_vertex(uint64_t key, uint32_t vertex) {
  pcg32 rng(vertex_seed(key, vertex), 0);
  vertex_randoms r;
  for (int i = 0; i < dims_per_vertex; i++) {
    r.raw[i] = rng();
    r.u[i] = uint_to_unit(r.raw[i]);
  }
  return r;
}

// Bits of i in reverse order: the base-2 radical inverse of i (van der Corput) in 0.32 fixed point.
inline uint32_t reverse_bits(uint32_t i) {
  i = __builtin_bswap32(i);
  i = ((i & 0x0f0f0f0fu) << 4) | ((i & 0xf0f0f0f0u) >> 4);
  i = ((i & 0x33333333u) << 2) | ((i & 0xccccccccu) >> 2);
  return ((i & 0x55555555u) << 1) | ((i & 0xaaaaaaaau) >> 1);
}
// The second dimension of the Sobol' sequence at index i in 0.32 fixed point (direction numbers of x + 1), bit by bit.
constexpr uint32_t sobol_second_bits(uint32_t i) {
  uint32_t r = 0;
  for (uint32_t v = 1u << 31; i != 0; i >>= 1, v ^= v >> 1)
    if (i & 1) r ^= v;
  return r;
}
// The same, a byte at a time: the map is linear over GF(2), so it is the XOR of its values on the index's four bytes.
struct sobol_second_table {
  uint32_t t[4][256] = {};
  constexpr sobol_second_table() {
    for (int b = 0; b < 4; b++)
      for (uint32_t v = 0; v < 256; v++) t[b][v] = sobol_second_bits(v << (8 * b));
  }
};
inline constexpr sobol_second_table sobol_second_lut{};
inline uint32_t sobol_second(uint32_t i) {
  const auto& t = sobol_second_lut.t;
  return t[0][i & 0xff] ^ t[1][(i >> 8) & 0xff] ^ t[2][(i >> 16) & 0xff] ^ t[3][i >> 24];
}

// Jitter inside pixel `pixel` of its sample `sample`: point `sample` of the two-dimensional Sobol' sequence (van der
// Corput and Sobol's second dimension), digitally shifted (XOR) by a random pair drawn from the PCG32 stream of the
// pixel's key. Each sample is uniform over the pixel (unbiased), the shift is independent between pixels, and any
// 2^k consecutive samples from a multiple of 2^k are stratified (one per cell of every 2^a x 2^b grid with a + b = k),
// which takes most of the variance off pixels that straddle an edge (a lamp's rim against a dark ceiling).
// (The shift is per pixel: jitter_shift draws it, jitter_at applies it; pixel_streams caches it.)
inline void jitter_shift(uint64_t seed, uint64_t pixel, uint32_t& sx, uint32_t& sy) {
  pcg32 rng(mix64(mix64(seed ^ 0x6a09e667f3bcc909ull) ^ pixel), 0);
  sx = rng();
  sy = rng();
}
inline void jitter_at(uint32_t sx, uint32_t sy, uint64_t sample, float& u, float& v) {
  uint32_t i = uint32_t(sample);
  u = uint_to_unit(reverse_bits(i) ^ sx);
  v = uint_to_unit(sobol_second(i) ^ sy);
}
inline void pixel_jitter(uint64_t seed, uint64_t pixel, uint64_t sample, float& u, float& v) {
  uint32_t sx, sy;
  jitter_shift(seed, pixel, sx, sy);
  jitter_at(sx, sy, sample, u, v);
}

// A nested uniform scramble of x from its low bit up: bit k of the result is bit k of x flipped by a function of
// `seed` and of the bits below k (additions carry upward only; x * c with c even reads only lower bits). So the
// values with the same low bits (an aligned block of 2^k, read in reverse) map onto such a block.
inline uint32_t scramble_low_first(uint32_t x, uint32_t seed) {
  x += seed;
  x ^= x * 0x9e3779b8u;
  x += seed * 0x2545f491u;
  x ^= x * 0xd1b54a32u;
  x += seed ^ 0x68e31da4u;
  x ^= x * 0x5851f42cu;
  x ^= x * 0x14057b7eu;
  return x;
}

// Sample `sample` of a pixel's randomised one-dimensional set with hash h: the van der Corput point of a shuffled
// index (the sample's reversed bits under the nested scramble, so an aligned block of 2^k samples takes an aligned
// block of 2^k indices: one point in each interval of length 2^-k), digitally shifted (XOR), so each sample is
// uniform. Sets of different hashes are independent.
inline uint32_t shuffled_vdc(uint32_t sample, uint64_t h) {
  return scramble_low_first(reverse_bits(sample), uint32_t(h)) ^ uint32_t(h >> 32);
}
// The same for a two-dimensional set: the Sobol' point (van der Corput, Sobol's second dimension) of the shuffled
// index, whose aligned blocks of 2^k form (0, k, 2)-nets (one point in each cell of every 2^a x 2^b grid with
// a + b = k), each coordinate digitally shifted.
inline void sobol_pair(uint32_t sample, uint64_t h, uint32_t& a, uint32_t& b) {
  uint32_t r = scramble_low_first(reverse_bits(sample), uint32_t(h));  // the shuffled index, reversed
  a = r ^ uint32_t(h >> 32);
  b = sobol_second(reverse_bits(r)) ^ uint32_t(mix64(h));
}

// The key of the stratified sets that start at sample `base` of a render with seed `seed`.
inline uint64_t stratum_key_of(uint64_t seed, uint64_t base) {
  return mix64(mix64(seed ^ 0xbb67ae8584caa73bull) ^ (base * 0x9e3779b97f4a7c15ull));
}
// Stratifies over sets of a pixel's samples the first vertex's light choice (1D), point on the light (2D) and, unless
// `last`, BSDF direction (2D), replacing those dimensions of r. Each of the three has its own shuffle and shifts,
// from the hash of its set and pixel (stratum_hashes_of); each sample stays uniform, so any estimator stays
// unbiased, and 2^k consecutive samples of a set from a multiple of 2^k are stratified. The light dimensions take
// `index`, the sample's place in its set; the BSDF direction `bsdf_index`, its place in the BSDF's set (in a render:
// light sets that restart whenever the sampler's model changes, one BSDF set for the whole render; stratify_sample).
// The draws for a light inside a cell too narrow for the choice's number (dim_light_inner), the unread lobe
// number and roulette stay independent.
struct stratum_hashes {
  uint64_t select = 0, point = 0, bsdf = 0;
};
inline stratum_hashes stratum_hashes_of(uint64_t key, uint64_t pixel) {
  uint64_t k = mix64(key ^ pixel);
  return {mix64(k + 1), mix64(k + 2), mix64(k + 3)};
}
// The light dimensions (light choice, point on the light) of stratify_with; alone, for a vertex's further NEE draws.
inline void stratify_light_with(const stratum_hashes& hs, uint32_t index, vertex_randoms& r) {
  r.raw[dim_light_select] = shuffled_vdc(index, hs.select);
  sobol_pair(index, hs.point, r.raw[dim_light_u], r.raw[dim_light_v]);
  r.u[dim_light_select] = uint_to_unit(r.raw[dim_light_select]);
  r.u[dim_light_u] = uint_to_unit(r.raw[dim_light_u]);
  r.u[dim_light_v] = uint_to_unit(r.raw[dim_light_v]);
}
inline void stratify_with(const stratum_hashes& hs, uint32_t index, uint32_t bsdf_index, bool last, vertex_randoms& r) {
  stratify_light_with(hs, index, r);
  if (last) return;
  sobol_pair(bsdf_index, hs.bsdf, r.raw[dim_bsdf_u], r.raw[dim_bsdf_v]);
  r.u[dim_bsdf_u] = uint_to_unit(r.raw[dim_bsdf_u]);
  r.u[dim_bsdf_v] = uint_to_unit(r.raw[dim_bsdf_v]);
}
// All three dimensions from one set (key `key`, place `index`).
inline void stratify_first_vertex(uint64_t key, uint64_t pixel, uint32_t index, bool last, vertex_randoms& r) {
  stratify_with(stratum_hashes_of(key, pixel), index, index, last, r);
}

// What a pixel's samples share, computed once per pixel and pass (the per-pixel parts of sample_key, pixel_jitter
// and the stratified sets), so that a sample draws exactly what those functions give.
struct pixel_streams {
  uint64_t key_base = 0;          // pixel_key_base
  uint32_t shift_x = 0, shift_y = 0;  // jitter_shift
  // select, point: stratum_hashes_of the pass's light set (key stratum_key); bsdf: of the render's first set (key
  // stratum_key_of(seed, 0)), which the BSDF direction keeps for the whole render.
  stratum_hashes strata;
  uint64_t point = 0;  // --light-points auto: the scramble of the pass's light-point set (key point_key)
};
inline pixel_streams pixel_streams_of(uint64_t seed, uint64_t stratum_key, uint64_t pixel, uint64_t point_key = 0) {
  pixel_streams ps;
  ps.key_base = pixel_key_base(seed, pixel);
  jitter_shift(seed, pixel, ps.shift_x, ps.shift_y);
  ps.strata = stratum_hashes_of(stratum_key, pixel);
  ps.strata.bsdf = stratum_hashes_of(stratum_key_of(seed, 0), pixel).bsdf;
  if (point_key != 0) ps.point = stratum_hashes_of(point_key, pixel).point;
  return ps;
}
// The first vertex's stratified dimensions of sample `sample` of a render whose light set began at sample `base`
// (ps: pixel_streams_of that set's key). The light choice and point take the sample's place in the light set, which
// restarts whenever the sampler's model changes, so that no light sample depends on samples its model learned from.
// The BSDF direction takes the sample number in the render's one BSDF set, as the camera jitter does: its sampling
// does not depend on the model. The model it meets may have learned from the same pixel's earlier paths (their deeper
// vertices went where the set's earlier directions sent them), which reaches the estimate only through the MIS weight
// of a light the direction hits: consistent, with a bias that shrinks with the pixel's share of what its region learned
// (none measurable: README, Samplers).
inline void stratify_sample(const pixel_streams& ps, uint64_t sample, uint64_t base, bool last, vertex_randoms& r) {
  stratify_with(ps.strata, uint32_t(sample - base), uint32_t(sample), last, r);
}

}  // namespace bl
