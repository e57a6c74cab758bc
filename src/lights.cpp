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

// Triangle t as seen from x, in units of |p0 - x| (so that neither the products of three lengths below nor the warp
// leave float's range at any scene scale): corner 0's offset a = (p0 - x) / |p0 - x|, the edges in those units.
struct triangle_view {
  vec3f a, e1, e2;
  float la = 0;      // |a| (1 up to rounding)
  float triple = 0;  // a . (e1 x e2): its sign tells the side x is on (negative: the front)
  float omega = 0;   // solid angle; 0 = sample by area
};

// The solid angle from the corners' offsets a, b = a + e1, c = a + e2, in forms that keep float precision for a
// small or distant triangle: tan(omega / 2) = |a . (b x c)| / (|a||b||c| + (a.b)|c| + (b.c)|a| + (c.a)|b|)
// (Van Oosterom and Strackee 1983), with the triple product taken from the edges (a . (e1 x e2): no cancellation
// between nearly parallel corners).
triangle_view view_of(const scene_data& scene, int t, vec3f x) {
  triangle_view w;
  vec3f e1 = scene.tri_e1[size_t(t)], e2 = scene.tri_e2[size_t(t)], p0 = scene.tri_p0[size_t(t)];
  // Cheap rejection: the triangle lies in the ball about its centroid through its farthest corner, and from outside a
  // ball of radius r at distance d the ball subtends 2 pi (1 - cos) with sin^2 = r^2 / d^2; below the threshold's
  // sin^2 the triangle cannot reach it.
  constexpr float s_min = spherical_min_solid_angle * inv_pi_f -
                          spherical_min_solid_angle * spherical_min_solid_angle * (0.25f * inv_pi_f * inv_pi_f);
  vec3f g = (e1 + e2) * (1.0f / 3.0f);
  float r2 = std::max(length_sq(g), std::max(length_sq(g - e1), length_sq(g - e2)));
  float d2 = length_sq(p0 + g - x);
  if (r2 < s_min * d2) return w;
  vec3f a = p0 - x;
  float k = 1 / length(a);
  if (!std::isfinite(k)) return w;
  w.a = a * k, w.e1 = e1 * k, w.e2 = e2 * k;
  vec3f b = w.a + w.e1, c = w.a + w.e2;
  w.la = length(w.a);
  float lb = length(b), lc = length(c);
  w.triple = dot(w.a, cross(w.e1, w.e2));
  float den = w.la * lb * lc + dot(w.a, b) * lc + dot(b, c) * w.la + dot(c, w.a) * lb;
  if (!(lb > 0 && lc > 0) || !std::isfinite(den) || !std::isfinite(w.triple)) return w;
  float omega = 2 * std::atan2(std::fabs(w.triple), den);
  if (omega >= spherical_min_solid_angle && omega <= spherical_max_solid_angle) w.omega = omega;
  return w;
}

// Arvo's warp (Arvo 1995, "Stratified sampling of spherical triangles"): u picks the sub-triangle A B C' of area
// u omega with C' on the arc from A to C, v the point on the arc from B to C' (uniform in solid angle over the
// whole). The angle at A and the great circles' directions come from cross products with the edges (a x e1 is
// a x b, a x e2 is a x c), which keep their precision where the corners' directions nearly coincide. Returns the
// unit direction, or zero where rounding leaves no valid one.
vec3f spherical_direction(const triangle_view& w, float u, float v) {
  vec3f b = w.a + w.e1;
  vec3f A = w.a / w.la, B = b / length(b);
  vec3f n_ab = cross(w.a, w.e1), n_ac = cross(w.a, w.e2);
  // The angle at A: between the planes through A and B and through A and C; |n_ab x n_ac| = |a| |a . (e1 x e2)|.
  float sin_part = w.la * std::fabs(w.triple), cos_part = dot(n_ab, n_ac);
  float h = std::sqrt(sin_part * sin_part + cos_part * cos_part);
  if (!(h > 0)) return {0, 0, 0};
  float sin_alpha = sin_part / h, cos_alpha = cos_part / h;
  float cos_c = dot(A, B);
  float area = u * w.omega;
  float sin_area = std::sin(area), cos_area = std::cos(area);
  // s, t: sine and cosine of (area - alpha).
  float s = sin_area * cos_alpha - cos_area * sin_alpha, t = cos_area * cos_alpha + sin_area * sin_alpha;
  float p = t - cos_alpha, q = s + sin_alpha * cos_c;
  float cos_b = ((q * t - p * s) * cos_alpha - q) / ((q * s + p * t) * sin_alpha);  // cosine of the arc A C'
  if (!std::isfinite(cos_b)) return {0, 0, 0};
  cos_b = clampf(cos_b, -1.0f, 1.0f);
  vec3f toward_c = normalize(cross(n_ac, w.a));  // unit, perpendicular to A, in the plane of A and C, toward C
  vec3f c_prime = A * cos_b + toward_c * safe_sqrt(1 - cos_b * cos_b);
  float z = 1 - v * (1 - dot(c_prime, B));
  vec3f perp = normalize(c_prime - B * dot(c_prime, B));
  return B * z + perp * safe_sqrt(1 - z * z);
}

// The light sample of a triangle sampled by solid angle (w.omega > 0): the direction from Arvo's warp, the point
// where it meets the triangle's plane (as barycentrics clamped onto the triangle, so the point lies on it as an area
// sample's does), pdf 1 / omega.
light_sample sample_by_solid_angle(const light_data& l, const scene_data& scene, int light, vec3f x,
                                   const triangle_view& w, float u, float v, light_sample s) {
  int t = s.tri;
  bool front = w.triple < 0;
  if (w.triple == 0 || (!front && !emits_both_sides(l, light))) return s;
  vec3f e1 = w.e1, e2 = w.e2, n = cross(e1, e2);  // in the view's units
  vec3f dir = spherical_direction(w, u, v);
  float along = dot(n, w.a) / dot(n, dir);
  if (!(along > 0) || !std::isfinite(along)) return s;
  vec3f rel = dir * along - w.a;  // the plane point relative to corner 0
  float d00 = dot(e1, e1), d01 = dot(e1, e2), d11 = dot(e2, e2), d20 = dot(rel, e1), d21 = dot(rel, e2);
  float den = length_sq(n);
  float b1 = std::max((d11 * d20 - d01 * d21) / den, 0.0f), b2 = std::max((d00 * d21 - d01 * d20) / den, 0.0f);
  if (!(b1 + b2 <= 1)) {
    float sum = b1 + b2;
    if (!std::isfinite(sum)) return s;
    b1 /= sum, b2 /= sum;
  }
  if (scene.has_alpha && alpha_hole(scene, t, b1, b2)) return s;
  s.p = scene.tri_p0[size_t(t)] + scene.tri_e1[size_t(t)] * b1 + scene.tri_e2[size_t(t)] * b2;
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
  float a = scene.tri_area[t];
  s.pdf = a > 0 ? s.dist * s.dist / (cos_l * a) : 0;
  return s;
}

}  // namespace bl
