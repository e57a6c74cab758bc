// math: float vectors, bounding boxes and orthonormal frames used by every system.
// Invariants: all rendering maths is float (glibc's float libm is bit-identical across x86-64 CPUs, the
// double one is not); helpers here never call double libm. Compiled with -ffp-contract=off, so a*b+c is
// never fused and results do not depend on the CPU's FMA support.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace bl {

constexpr float pi_f = 3.14159265358979323846f;
constexpr float inv_pi_f = 0.31830988618379067154f;
constexpr float inf_f = std::numeric_limits<float>::infinity();
constexpr int invalid_id = -1;

// 3-component float vector (positions, directions, RGB).
struct vec3f {
  float x = 0, y = 0, z = 0;
  float operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  float& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
};

// 2-component float vector (texture coordinates, random pairs).
struct vec2f {
  float x = 0, y = 0;
};

inline vec3f operator+(vec3f a, vec3f b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline vec3f operator-(vec3f a, vec3f b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline vec3f operator-(vec3f a) { return {-a.x, -a.y, -a.z}; }
inline vec3f operator*(vec3f a, vec3f b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
inline vec3f operator*(vec3f a, float s) { return {a.x * s, a.y * s, a.z * s}; }
inline vec3f operator*(float s, vec3f a) { return {a.x * s, a.y * s, a.z * s}; }
inline vec3f operator/(vec3f a, float s) { return {a.x / s, a.y / s, a.z / s}; }
inline vec3f& operator+=(vec3f& a, vec3f b) { return a = a + b; }
inline vec3f& operator*=(vec3f& a, vec3f b) { return a = a * b; }
inline vec3f& operator*=(vec3f& a, float s) { return a = a * s; }

inline float dot(vec3f a, vec3f b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline vec3f cross(vec3f a, vec3f b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline float length_sq(vec3f a) { return dot(a, a); }
inline float length(vec3f a) { return std::sqrt(dot(a, a)); }
// normalize's rare case, out of line (so that the common case inlines as small as it was): a vector so long or so
// short that its squared length leaves float's normal range is scaled by its largest component first; zero, NaN
// and infinite vectors give zero.
[[gnu::noinline, gnu::cold]] inline vec3f normalize_wide(vec3f a) {
  if (std::isnan(a.x) || std::isnan(a.y) || std::isnan(a.z)) return {0, 0, 0};
  float m = std::max(std::fabs(a.x), std::max(std::fabs(a.y), std::fabs(a.z)));
  if (!(m > 0) || !(m < std::numeric_limits<float>::infinity())) return {0, 0, 0};
  a = a / m;
  return a / length(a);
}
// Unit vector along a; a zero (or NaN) vector gives zero, never NaN; any finite non-zero length works (see
// normalize_wide). The common case is a / |a|.
inline vec3f normalize(vec3f a) {
  float l = length(a);
  if (l > 1e-18f && l < 1e18f) return a / l;
  return normalize_wide(a);
}
inline vec3f vmin(vec3f a, vec3f b) { return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)}; }
inline vec3f vmax(vec3f a, vec3f b) { return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)}; }
inline float max_component(vec3f a) { return std::max(a.x, std::max(a.y, a.z)); }
inline float max_abs_component(vec3f a) {
  return std::max(std::fabs(a.x), std::max(std::fabs(a.y), std::fabs(a.z)));
}
inline bool is_finite(vec3f a) { return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z); }
inline bool is_black(vec3f a) { return a.x == 0 && a.y == 0 && a.z == 0; }
// Rec. 709 luminance of linear RGB.
inline float luminance(vec3f c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }
// The same weights in double (statistics summed over many samples).
inline double luminance(double r, double g, double b) { return 0.2126 * r + 0.7152 * g + 0.0722 * b; }
inline float clampf(float v, float lo, float hi) { return std::min(std::max(v, lo), hi); }
inline float sqr(float v) { return v * v; }
// sqrt that treats tiny negative round-off as zero.
inline float safe_sqrt(float v) { return std::sqrt(std::max(v, 0.0f)); }
// acos that clamps its argument into [-1, 1].
inline float safe_acos(float v) { return std::acos(clampf(v, -1.0f, 1.0f)); }

// Axis-aligned bounding box; an empty box has lo > hi.
struct bbox3f {
  vec3f lo = {inf_f, inf_f, inf_f};
  vec3f hi = {-inf_f, -inf_f, -inf_f};
};
inline bool is_empty(const bbox3f& b) { return b.lo.x > b.hi.x || b.lo.y > b.hi.y || b.lo.z > b.hi.z; }
inline bbox3f merge(bbox3f b, vec3f p) { return {vmin(b.lo, p), vmax(b.hi, p)}; }
inline bbox3f merge(bbox3f a, const bbox3f& b) { return {vmin(a.lo, b.lo), vmax(a.hi, b.hi)}; }
inline vec3f center(const bbox3f& b) { return (b.lo + b.hi) * 0.5f; }
inline vec3f extent(const bbox3f& b) { return b.hi - b.lo; }
inline float diagonal(const bbox3f& b) { return is_empty(b) ? 0.0f : length(b.hi - b.lo); }

// Orthonormal frame (t, b, n), right-handed; built from n without branches on sign (Duff et al. 2017).
struct frame3f {
  vec3f t, b, n;
};
inline frame3f make_frame(vec3f n) {
  float sign = std::copysign(1.0f, n.z);
  float a = -1.0f / (sign + n.z);
  float bb = n.x * n.y * a;
  vec3f t = {1.0f + sign * n.x * n.x * a, sign * bb, -sign * n.x};
  vec3f b = {bb, sign + n.y * n.y * a, -n.y};
  return {t, b, n};
}
inline vec3f to_local(const frame3f& f, vec3f v) { return {dot(v, f.t), dot(v, f.b), dot(v, f.n)}; }
inline vec3f to_world(const frame3f& f, vec3f v) { return f.t * v.x + f.b * v.y + f.n * v.z; }

}  // namespace bl
