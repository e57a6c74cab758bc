// lights: emitter collection, power, and point sampling (on triangles uniform by area or, seen under a large solid
// angle, by solid angle; uniform in the sun's cone).
#include "lights.h"

#include "sampling.h"

namespace bl {

light_data build_lights(const scene_data& scene) {
  light_data l;
  const mesh_data& m = scene.mesh;
  int n = triangle_count(m);
  l.two_sided = scene.two_sided_emitters;
  l.light_of_tri.assign(n, invalid_id);
  for (int t = 0; t < n; t++) {
    if (!scene.material_emissive[m.tri_materials[t]]) continue;
    // A face with a reversed twin is one side of a sheet: it emits from its front only, also with two_sided (the
    // other side is its twin's, which a ray from there meets).
    bool sheets = l.two_sided && !scene.tri_twin.empty();
    bool front_only = sheets && scene.tri_twin[size_t(t)] != invalid_id;
    if (sheets) l.front_only.push_back(front_only);
    l.light_of_tri[t] = int(l.tri.size());
    l.tri.push_back(t);
    vec3f le = m.materials[m.tri_materials[t]].ke;
    l.radiance.push_back(le);
    l.power.push_back(luminance(le) * scene.tri_area[t] * pi_f * (l.two_sided && !front_only ? 2.0f : 1.0f));
  }
  l.tri_count = int(l.tri.size());
  l.count = l.tri_count;
  if (scene.sun.enabled && max_component(scene.sun.irradiance) > 0) {
    l.sun = l.count++;
    l.sun_dir = normalize(scene.sun.direction);
    l.sun_frame = make_frame(l.sun_dir);
    l.sun_one_minus_cos = sun_one_minus_cos(scene.sun.angular_diameter_deg);
    float sin2 = l.sun_one_minus_cos * (2 - l.sun_one_minus_cos);
    l.sun_irradiance = scene.sun.irradiance;
    l.sun_radiance = scene.sun.irradiance / (pi_f * sin2);
    // Power of a distant light: its irradiance over the disk that bounds the scene (as pbrt does).
    float r = 0.5f * diagonal(scene.bounds);
    // (At most 1e30, the emitters' limit (obj_io.cpp): an infinite power would leave nothing else sampled.)
    l.power.push_back(std::min(luminance(scene.sun.irradiance) * pi_f * r * r, 1e30f));
  }
  return l;
}

void set_sun_direction(light_data& l, vec3f direction) {
  if (l.sun == invalid_id) return;
  l.sun_dir = normalize(normalize(direction));  // scene_desc's normalisation, then build_lights'
  l.sun_frame = make_frame(l.sun_dir);
}

namespace {

// Solid-angle sampling computes in double: where the shading point lies near the line through two corners (a lamp
// standing on the floor it lights, the diagonal of a quad lamp just above a point), those corners' directions are
// nearly opposite, and float's cross products and Arvo's formula lost so much there that the warp put samples 1 rad
// off their place (a review: irradiance 0.02 mm from a 1 m panel at half its value). Double's +, -, *, / and sqrt are
// correctly rounded, so the result is the same on every machine; the two transcendental calls stay in float
// (glibc's double sin/atan2 differ in the last bit between CPUs with and without FMA; STACK.md).
struct dvec3 {
  double x = 0, y = 0, z = 0;
};
dvec3 to_double(vec3f v) { return {v.x, v.y, v.z}; }
dvec3 operator+(dvec3 a, dvec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
dvec3 operator-(dvec3 a, dvec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
dvec3 operator*(dvec3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
double dot(dvec3 a, dvec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
dvec3 cross(dvec3 a, dvec3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
double length(dvec3 a) { return std::sqrt(dot(a, a)); }
// a / |a|, or zero for a zero vector.
dvec3 unit(dvec3 a) {
  double l = length(a);
  return l > 0 ? a * (1 / l) : dvec3{};
}

// Triangle t as seen from x, in units of |p0 - x| (so that no product of lengths leaves double's range at any
// scene scale): its corners' offsets from x (p0 - x and the edges e1, e2 as stored), and the same triangle with its
// corners renamed cyclically for the warp (a: corner A's offset, ab = B - A, ac = C - A) so that the two whose
// directions from x are the most nearly opposite are A and C, the pair Arvo's construction handles best (B and C'
// then never meet head-on, and A B is never the long arc its formula divides by): with A and B opposite, in double,
// 1e-4 below a quad's diagonal, the estimate was still 0.6 % high.
constexpr double spherical_max_second_opposite = 0.999;
struct triangle_view {
  dvec3 p0, e1, e2;  // as stored: corner 0's offset, edges
  dvec3 a, ab, ac;   // renamed for the warp: A's offset, B - A, C - A
  double triple = 0;  // a . (e1 x e2) (any naming): its sign tells the side x is on (negative: the front)
  float omega = 0;    // solid angle; 0 = sample by area
};

// The solid angle from the corners' offsets a, b = a + e1, c = a + e2: tan(omega / 2) = |a . (b x c)| /
// (|a||b||c| + (a.b)|c| + (b.c)|a| + (c.a)|b|) (Van Oosterom and Strackee 1983), the triple product taken from the
// edges (a . (e1 x e2): no cancellation between nearly parallel corners).
triangle_view view_of(const scene_data& scene, int t, vec3f x) {
  triangle_view w;
  vec3f e1 = scene.tri_e1[size_t(t)], e2 = scene.tri_e2[size_t(t)], p0 = scene.tri_p0[size_t(t)];
  // Cheap rejections, in float with a margin for rounding (a triangle they turn away is sampled by area, which is
  // always valid). The triangle lies in the ball about its centroid through its farthest corner (radius r, centre at
  // distance d), which from outside subtends 2 pi (1 - cos) with sin^2 = r^2 / d^2: below the threshold's sin^2 the
  // triangle cannot reach it. Closer, every point of the triangle is at least m = max(d - r, |h|) from x (h: x's
  // distance to the plane), and omega = integral of |h| / dist^3 over the area is at most area |h| / m^3.
  constexpr float s_min = spherical_min_solid_angle * inv_pi_f -
                          spherical_min_solid_angle * spherical_min_solid_angle * (0.25f * inv_pi_f * inv_pi_f);
  constexpr float margin = 0.999f;
  vec3f g = (e1 + e2) * (1.0f / 3.0f);
  float r2 = std::max(length_sq(g), std::max(length_sq(g - e1), length_sq(g - e2)));
  float d2 = length_sq(p0 + g - x);
  if (r2 < margin * s_min * d2) return w;
  float h = std::fabs(dot(scene.tri_ng[size_t(t)], x - p0));
  float m = std::max(std::sqrt(d2) - std::sqrt(r2), h);
  if (scene.tri_area[size_t(t)] * h < margin * spherical_min_solid_angle * (m * m * m)) return w;
  dvec3 a = to_double(p0) - to_double(x);
  double k = 1 / length(a);
  if (!std::isfinite(k)) return w;
  w.p0 = a * k, w.e1 = to_double(e1) * k, w.e2 = to_double(e2) * k;
  dvec3 c[3] = {w.p0, w.p0 + w.e1, w.p0 + w.e2};
  double l[3] = {length(c[0]), length(c[1]), length(c[2])};
  w.triple = dot(w.p0, cross(w.e1, w.e2));
  double den = l[0] * l[1] * l[2] + dot(c[0], c[1]) * l[2] + dot(c[1], c[2]) * l[0] + dot(c[2], c[0]) * l[1];
  if (!(l[1] > 0 && l[2] > 0) || !std::isfinite(den) || !std::isfinite(w.triple)) return w;
  // omega = 2 atan2(|triple|, den), compared with the thresholds through their half-angle tangents first (the
  // arctangent only where solid-angle sampling is taken): omega >= min where den <= 0 (omega >= pi) or
  // |triple| >= den tan(min / 2); omega <= max where den >= 0 or |triple| >= -den tan(gap / 2) (gap = 2 pi - max).
  double y = std::fabs(w.triple);
  bool above_min = den <= 0 || y >= den * double(spherical_min_tan_half);
  bool below_max = den >= 0 || y >= -den * double(spherical_max_cot_half);
  if (!(above_min && below_max)) return w;
  // B: the corner outside the most nearly opposite pair (the lowest cosine between two corners' directions). Where a
  // second pair is nearly opposite too (x within a sliver's width of two of its edge lines: B then lies next to A,
  // and the arc from B to C' turns on rounding as C' nears C), area sampling.
  double cos01 = dot(c[0], c[1]) / (l[0] * l[1]), cos12 = dot(c[1], c[2]) / (l[1] * l[2]),
         cos20 = dot(c[2], c[0]) / (l[2] * l[0]);
  int b = cos01 <= cos12 && cos01 <= cos20 ? 2 : cos12 <= cos20 ? 0 : 1;
  double second = b == 2 ? std::min(cos12, cos20) : b == 0 ? std::min(cos01, cos20) : std::min(cos01, cos12);
  if (second < -spherical_max_second_opposite) return w;
  // The arctangent of the ratio's float rounding: a relative error of 1e-7 at most, from any ratio.
  double scale = std::max(y, std::fabs(den));
  w.omega = 2 * std::atan2(float(y / scale), float(den / scale));
  w.a = c[(b + 2) % 3];
  w.ab = c[b] - w.a;
  w.ac = c[(b + 1) % 3] - w.a;
  return w;
}

// Arvo's warp (Arvo 1995, "Stratified sampling of spherical triangles"): u picks the sub-triangle A B C' of area
// u omega with C' on the arc from A to C, v the point on the arc from B to C' (uniform in solid angle over the
// whole). The angle at A and the great circles' directions come from cross products with the edges (a x ab is
// a x b, a x ac is a x c). Returns the unit direction, or zero where no valid one is left.
dvec3 spherical_direction(const triangle_view& w, float u, float v) {
  dvec3 b = w.a + w.ab;
  double la = length(w.a);
  dvec3 A = w.a * (1 / la), B = unit(b);  // A as unit() gives it, |a| kept for the angle below
  dvec3 n_ab = cross(w.a, w.ab), n_ac = cross(w.a, w.ac);
  // The angle at A: between the planes through A and B and through A and C; |n_ab x n_ac| = |a| |a . (ab x ac)|.
  double sin_part = la * std::fabs(w.triple), cos_part = dot(n_ab, n_ac);
  double h = std::sqrt(sin_part * sin_part + cos_part * cos_part);
  if (!(h > 0)) return {};
  double sin_alpha = sin_part / h, cos_alpha = cos_part / h;
  double cos_c = dot(A, B);
  float area = u * w.omega;
  double sin_area = std::sin(area), cos_area = std::cos(area);
  // s, t: sine and cosine of (area - alpha).
  double s = sin_area * cos_alpha - cos_area * sin_alpha, t = cos_area * cos_alpha + sin_area * sin_alpha;
  double p = t - cos_alpha, q = s + sin_alpha * cos_c;
  double cos_b = ((q * t - p * s) * cos_alpha - q) / ((q * s + p * t) * sin_alpha);  // cosine of the arc A C'
  if (!std::isfinite(cos_b)) return {};
  // C' stays on the arc from A to C: the float sine and cosine of the area leave cos_b a little below cos(A C) as u
  // nears 1, and with A and C nearly opposite a C' past C lies beyond the triangle's plane (a review: 0.8 % of the
  // solid angle lost 0.1 mm beside a sliver's edge line).
  cos_b = std::min(std::max(cos_b, dot(A, unit(w.a + w.ac))), 1.0);
  dvec3 toward_c = unit(cross(n_ac, w.a));  // perpendicular to A, in the plane of A and C, toward C
  dvec3 c_prime = A * cos_b + toward_c * std::sqrt(1 - cos_b * cos_b);
  double z = 1 - v * (1 - dot(c_prime, B));
  dvec3 perp = unit(c_prime - B * dot(c_prime, B));
  return B * z + perp * std::sqrt(std::max(1 - z * z, 0.0));
}

// The light sample of a triangle sampled by solid angle (w.omega > 0): the direction from Arvo's warp, the point
// where it meets the triangle's plane (as barycentrics clamped onto the triangle against rounding, so the point lies
// on it as an area sample's does), pdf 1 / omega.
light_sample sample_by_solid_angle(const light_data& l, const scene_data& scene, int light, vec3f x,
                                   const triangle_view& w, float u, float v, light_sample s) {
  int t = s.tri;
  bool front = w.triple < 0;
  if (w.triple == 0 || (!front && !emits_both_sides(l, light))) return s;
  dvec3 n = cross(w.e1, w.e2);  // in the view's units
  dvec3 dir = spherical_direction(w, u, v);
  double along = dot(n, w.p0) / dot(n, dir);
  if (!(along > 0) || !std::isfinite(along)) return s;
  dvec3 rel = dir * along - w.p0;  // the plane point relative to corner 0
  double d00 = dot(w.e1, w.e1), d01 = dot(w.e1, w.e2), d11 = dot(w.e2, w.e2), d20 = dot(rel, w.e1),
         d21 = dot(rel, w.e2);
  double den = dot(n, n);
  double b1 = std::max((d11 * d20 - d01 * d21) / den, 0.0), b2 = std::max((d00 * d21 - d01 * d20) / den, 0.0);
  if (!(b1 + b2 <= 1)) {
    double sum = b1 + b2;
    if (!std::isfinite(sum)) return s;
    b1 /= sum, b2 /= sum;
  }
  float fb1 = float(b1), fb2 = float(b2);
  if (scene.has_alpha && alpha_hole(scene, t, fb1, fb2)) return s;
  s.p = scene.tri_p0[size_t(t)] + scene.tri_e1[size_t(t)] * fb1 + scene.tri_e2[size_t(t)] * fb2;
  vec3f d = s.p - x;
  float dist2 = length_sq(d);
  if (!(dist2 > 0)) return s;
  s.dist = std::sqrt(dist2);
  s.wi = d / s.dist;
  if (!(std::fabs(dot(s.n, s.wi)) > 0)) return s;
  s.le = l.radiance[light];
  s.pdf = 1 / w.omega;
  return s;
}

}  // namespace

float spherical_solid_angle(const scene_data& scene, int t, vec3f x) { return view_of(scene, t, x).omega; }

light_sample sample_light_point(const light_data& l, const scene_data& scene, int light, vec3f x, float u,
                                float v) {
  light_sample s;
  if (light == l.sun) {
    s.wi = normalize(to_world(l.sun_frame, sample_cone(u, v, l.sun_one_minus_cos)));
    s.dist = inf_f;
    s.le = l.sun_radiance;
    s.pdf = cone_pdf(l.sun_one_minus_cos);
    return s;
  }
  int t = l.tri[light];
  s.tri = t;
  s.n = scene.tri_ng[t];
  triangle_view w = view_of(scene, t, x);
  if (w.omega > 0) return sample_by_solid_angle(l, scene, light, x, w, u, v, s);
  vec2f b = sample_triangle(u, v);
  s.p = scene.tri_p0[t] + scene.tri_e1[t] * b.x + scene.tri_e2[t] * b.y;
  // A hole of the emitter's own cut-out emits nothing (rays pass through it; pdf 0: no contribution).
  if (scene.has_alpha && alpha_hole(scene, t, b.x, b.y)) return s;
  vec3f d = s.p - x;
  float dist2 = length_sq(d);
  if (!(dist2 > 0)) return s;
  s.dist = std::sqrt(dist2);
  s.wi = d / s.dist;
  float cos_l = -dot(s.n, s.wi);
  if (cos_l < 0 && emits_both_sides(l, light)) cos_l = -cos_l;
  if (!(cos_l > 0)) return s;
  s.le = l.radiance[light];
  s.pdf = triangle_area_pdf(scene.tri_area[t], s.dist, cos_l);
  return s;
}

}  // namespace bl
