// Tests of point sampling on triangle lights: the solid-angle warp (Arvo) against solid angles computed in double
// (chi-square of the samples over sub-triangles, significance 1e-4 per configuration), the pdf a BSDF hit evaluates
// for MIS against the sample's own, the rule that picks the warp, and the irradiance estimate against Lambert's
// closed form for a polygon (4.4 standard errors, two-sided 99.999 %). Every test is seeded.
#include "lights.h"
#include "rng.h"
#include "sampling.h"
#include "scene.h"
#include "test_util.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace bl;
using namespace bl::test;

namespace {

struct dvec {
  double x, y, z;
};
dvec to_d(vec3f v) { return {v.x, v.y, v.z}; }
dvec sub(dvec a, dvec b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
double ddot(dvec a, dvec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
dvec dcross(dvec a, dvec b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
double dlen(dvec a) { return std::sqrt(ddot(a, a)); }
dvec dlerp3(dvec p0, dvec p1, dvec p2, double b1, double b2) {
  return {p0.x + (p1.x - p0.x) * b1 + (p2.x - p0.x) * b2, p0.y + (p1.y - p0.y) * b1 + (p2.y - p0.y) * b2,
          p0.z + (p1.z - p0.z) * b1 + (p2.z - p0.z) * b2};
}

// Solid angle of triangle p0 p1 p2 seen from x, in double (Van Oosterom and Strackee).
double solid_angle(dvec x, dvec p0, dvec p1, dvec p2) {
  dvec a = sub(p0, x), b = sub(p1, x), c = sub(p2, x);
  double la = dlen(a), lb = dlen(b), lc = dlen(c);
  double num = std::fabs(ddot(a, dcross(b, c)));
  double den = la * lb * lc + ddot(a, b) * lc + ddot(b, c) * la + ddot(c, a) * lb;
  return 2 * std::atan2(num, den);
}

// Irradiance at x (unit normal n) from a triangle of uniform radiance le wholly above x's horizon (Lambert):
// E = le / 2 sum over edges of the angle the edge subtends times n . (the unit normal of the plane through x and it).
double lambert_irradiance(dvec x, dvec n, dvec p0, dvec p1, dvec p2, double le) {
  dvec v[3] = {sub(p0, x), sub(p1, x), sub(p2, x)};
  double sum = 0;
  for (int i = 0; i < 3; i++) {
    dvec a = v[i], b = v[(i + 1) % 3];
    dvec g = dcross(a, b);
    double theta = std::atan2(dlen(g), ddot(a, b));
    sum += theta * ddot(n, g) / dlen(g);
  }
  return 0.5 * le * std::fabs(sum);
}

// A scene of one emitting triangle (radiance le; two-sided or not) and nothing else.
struct one_triangle {
  scene_data scene;
  light_data lights;
  one_triangle(vec3f p0, vec3f p1, vec3f p2, bool two_sided = false, float le = 1) {
    mesh_builder b;
    int lamp = b.add_material({0, 0, 0}, {le, le, le});
    b.add_triangle(p0, p1, p2, lamp);
    scene = build_scene(std::move(b.mesh), camera_params{}, sun_params{}, two_sided, 1.0f);
    lights = build_lights(scene);
  }
  dvec corner(int i) const {
    vec3f p = scene.tri_p0[0];
    return to_d(i == 0 ? p : i == 1 ? p + scene.tri_e1[0] : p + scene.tri_e2[0]);
  }
};

// Barycentrics (b1, b2) of a point of the triangle, in double.
void barycentrics(const one_triangle& t, vec3f p, double& b1, double& b2) {
  dvec e1 = to_d(t.scene.tri_e1[0]), e2 = to_d(t.scene.tri_e2[0]), r = sub(to_d(p), to_d(t.scene.tri_p0[0]));
  double d00 = ddot(e1, e1), d01 = ddot(e1, e2), d11 = ddot(e2, e2), d20 = ddot(r, e1), d21 = ddot(r, e2);
  double den = d00 * d11 - d01 * d01;
  b1 = (d11 * d20 - d01 * d21) / den;
  b2 = (d00 * d21 - d01 * d20) / den;
}

// Chi-square p-value of `samples` light samples from x over the n^2 sub-triangles of an n-fold split of the
// triangle, each expected in proportion to its solid angle; also checks every sample's pdf against the solid angle
// and against the pdf a BSDF hit would evaluate there.
double warp_pvalue(const one_triangle& t, vec3f x, int n, int samples, uint64_t seed) {
  dvec xd = to_d(x), c0 = t.corner(0), c1 = t.corner(1), c2 = t.corner(2);
  double omega = solid_angle(xd, c0, c1, c2);
  // Cell (i, j) of the split, upright (corners (i, j), (i + 1, j), (i, j + 1), over n) or inverted: index
  // 2 (j n + i) + (inverted); the inverted ones exist for i + j < n - 1.
  std::vector<double> obs(size_t(2 * n * n), 0.0), exp(size_t(2 * n * n), 0.0);
  auto cell_of = [n](double b1, double b2) {
    double fx = b1 * n, fy = b2 * n;
    int i = std::min(n - 1, std::max(0, int(fx))), j = std::min(n - 1, std::max(0, int(fy)));
    if (i + j > n - 1) i = n - 1 - j;  // rounding just outside the long edge
    bool inverted = (fx - i) + (fy - j) > 1 && i + j < n - 1;
    return 2 * (j * n + i) + (inverted ? 1 : 0);
  };
  for (int j = 0; j < n; j++)
    for (int i = 0; i + j < n; i++) {
      auto at = [&](double bi, double bj) { return dlerp3(c0, c1, c2, bi / n, bj / n); };
      exp[size_t(2 * (j * n + i))] = samples * solid_angle(xd, at(i, j), at(i + 1, j), at(i, j + 1)) / omega;
      if (i + j < n - 1)
        exp[size_t(2 * (j * n + i) + 1)] =
            samples * solid_angle(xd, at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)) / omega;
    }
  float omega_f = spherical_solid_angle(t.scene, 0, x);
  REQUIRE(omega_f > 0);
  REQUIRE(std::fabs(omega_f - omega) < 2e-5 * omega);
  for (int s = 0; s < samples; s++) {
    vec2f u = uniform_pair(seed, uint64_t(s));
    light_sample ls = sample_light_point(t.lights, t.scene, 0, x, u.x, u.y);
    REQUIRE(ls.pdf == 1 / omega_f);
    REQUIRE(std::fabs(length(ls.wi) - 1) < 1e-5f);
    float cos_l = std::fabs(dot(ls.n, ls.wi));
    REQUIRE(triangle_light_pdf(t.scene, t.lights, 0, x, ls.dist, cos_l) == ls.pdf);
    double b1, b2;
    barycentrics(t, ls.p, b1, b2);
    REQUIRE(b1 >= -1e-5);
    REQUIRE(b2 >= -1e-5);
    REQUIRE(b1 + b2 <= 1 + 1e-5);
    obs[size_t(cell_of(b1, b2))] += 1;
  }
  return chi2_pvalue(obs, exp);
}

// Mean and standard error of the irradiance estimate le cos / pdf at x (receiver normal n) from `samples` light
// samples of one triangle.
mean_se irradiance_estimate(const one_triangle& t, vec3f x, vec3f n, int samples, uint64_t seed) {
  std::vector<double> e;
  for (int s = 0; s < samples; s++) {
    vec2f u = uniform_pair(seed, uint64_t(s));
    light_sample ls = sample_light_point(t.lights, t.scene, 0, x, u.x, u.y);
    e.push_back(ls.pdf > 0 ? double(ls.le.x) * std::max(0.0f, dot(n, ls.wi)) / ls.pdf : 0.0);
  }
  return mean_and_se(e);
}

}  // namespace

TEST_CASE("solid-angle samples of a triangle light are uniform in its solid angle", "[lights]") {
  // A triangle of about 1 m seen from points below it at heights from 1 m to 2 mm (solid angle 0.4 to 6.2 sr), from
  // beside it at grazing angles, and a sliver 1000:1 close by.
  const vec3f p0 = {-0.6f, 1, -0.4f}, p1 = {0.7f, 1, -0.3f}, p2 = {0.1f, 1, 0.8f};
  one_triangle tri(p0, p1, p2);  // faces down (e1 x e2 along -y)
  int configs = 0;
  for (float h : {1.0f, 0.3f, 0.05f, 0.01f, 0.002f})
    for (vec3f at : {vec3f{0.05f, 0, 0.02f}, vec3f{0.5f, 0, -0.25f}}) {
      vec3f x = at + vec3f{0, 1 - h, 0};
      double omega = solid_angle(to_d(x), tri.corner(0), tri.corner(1), tri.corner(2));
      if (omega < spherical_min_solid_angle * 1.01 || omega > spherical_max_solid_angle * 0.999) continue;
      INFO("height " << h << " at " << at.x << " " << at.z << " solid angle " << omega);
      CHECK(warp_pvalue(tri, x, 6, 60000, uint64_t(100 + configs)) > 1e-4);
      configs++;
    }
  CHECK(configs >= 8);
  // Beside it: 5 cm below its plane, 15 cm outside its nearest edge.
  {
    vec3f x = {0.05f, 0.95f, -0.5f};
    INFO("beside");
    CHECK(warp_pvalue(tri, x, 6, 60000, 7) > 1e-4);
  }
  // The same view at scales of 1e-9 and 1e9 (products of three lengths would leave float's range there).
  for (float scale : {1e-9f, 1e9f}) {
    one_triangle scaled(p0 * scale, p1 * scale, p2 * scale);
    vec3f x = vec3f{0.05f, 0.95f, 0.02f} * scale;
    INFO("scale " << scale);
    CHECK(warp_pvalue(scaled, x, 6, 60000, 9) > 1e-4);
  }
  // A sliver 50:1 (1 m by 2 cm) 5 cm above, with its sharp corner first, second and third: the tip and the far
  // corners lie in nearly opposite directions (cosines -0.98).
  for (int k = 0; k < 3; k++) {
    const vec3f tip = {0, 1, 0}, s1 = {1, 1, 0.01f}, s2 = {1, 1, -0.01f};
    one_triangle sliver(k == 0 ? tip : k == 1 ? s2 : s1, k == 0 ? s1 : k == 1 ? tip : s2,
                        k == 0 ? s2 : k == 1 ? s1 : tip, true);
    INFO("sliver, its tip corner " << k);
    CHECK(warp_pvalue(sliver, {0.5f, 0.95f, 0}, 4, 60000, uint64_t(8 + k)) > 1e-4);
  }
  // 1000:1 (2 mm wide) from 1 mm under it: the tip lies within 0.3 degree of opposite both far corners, where the
  // warp's arc from B to C' turns on rounding (samples 0.4 rad off its place): area sampling there.
  for (int k = 0; k < 3; k++) {
    const vec3f tip = {0, 1, 0}, s1 = {1, 1, 0.001f}, s2 = {1, 1, -0.001f};
    one_triangle thin(k == 0 ? tip : k == 1 ? s2 : s1, k == 0 ? s1 : k == 1 ? tip : s2, k == 0 ? s2 : k == 1 ? s1 : tip,
                      true);
    const vec3f x = {0.5f, 0.999f, 0};
    INFO("thin sliver, its tip corner " << k);
    CHECK(solid_angle(to_d(x), thin.corner(0), thin.corner(1), thin.corner(2)) > 1);
    CHECK(spherical_solid_angle(thin.scene, 0, x) == 0);
  }
}

TEST_CASE("the warp stays uniform over random triangles seen under any solid angle it takes", "[lights]") {
  pcg32 rng(99, 1);
  auto unit = [&] { return float(rng() >> 8) * (1.0f / 16777216.0f); };
  int tested = 0;
  for (int k = 0; k < 400 && tested < 24; k++) {
    vec3f p[3];
    for (vec3f& c : p) c = {4 * unit() - 2, 4 * unit() - 2, 4 * unit() - 2};
    vec3f x = {unit() - 0.5f, unit() - 0.5f, unit() - 0.5f};
    one_triangle t(p[0], p[1], p[2], true);
    if (!(t.scene.tri_area[0] > 0)) continue;
    double omega = solid_angle(to_d(x), t.corner(0), t.corner(1), t.corner(2));
    if (omega < spherical_min_solid_angle * 1.01 || omega > spherical_max_solid_angle * 0.999) continue;
    INFO("random triangle " << k << " solid angle " << omega);
    CHECK(warp_pvalue(t, x, 4, 20000, uint64_t(1000 + k)) > 1e-4);
    tested++;
  }
  CHECK(tested == 24);
}

TEST_CASE("solid-angle sampling takes the triangles a point sees large, and only those", "[lights]") {
  // The rule is the exact solid angle against the thresholds: a point far away, or seeing the triangle edge-on, or
  // a hair above its inside, samples by area (pdf d^2 / (cos area)), and its BSDF hits evaluate the same pdf.
  const vec3f p0 = {-1, 0, -1}, p1 = {1, 0, -1}, p2 = {0, 0, 1};
  one_triangle tri(p0, p2, p1, true);  // in the plane y = 0
  pcg32 rng(5, 3);
  auto unit = [&] { return float(rng() >> 8) * (1.0f / 16777216.0f); };
  int solid = 0, area = 0;
  for (int k = 0; k < 20000; k++) {
    // Points at distances from 1e-4 to 100 in every direction.
    vec3f dir = normalize(vec3f{2 * unit() - 1, 2 * unit() - 1, 2 * unit() - 1});
    float r = std::pow(10.0f, 6 * unit() - 4);
    vec3f x = dir * r;
    double omega = solid_angle(to_d(x), tri.corner(0), tri.corner(1), tri.corner(2));
    float got = spherical_solid_angle(tri.scene, 0, x);
    INFO("point " << x.x << " " << x.y << " " << x.z << " solid angle " << omega << " rule " << got);
    if (omega > spherical_min_solid_angle * 1.0001 && omega < spherical_max_solid_angle * 0.9999) {
      CHECK(got > 0);
      solid++;
    } else if (omega < spherical_min_solid_angle * 0.9999 || omega > spherical_max_solid_angle * 1.0001) {
      CHECK(got == 0);
      area++;
    }
    if (got > 0) continue;
    light_sample ls = sample_light_point(tri.lights, tri.scene, 0, x, unit(), unit());
    if (!(ls.pdf > 0)) continue;
    float cos_l = std::fabs(dot(ls.n, ls.wi));
    CHECK(ls.pdf == ls.dist * ls.dist / (cos_l * tri.scene.tri_area[0]));
    CHECK(triangle_light_pdf(tri.scene, tri.lights, 0, x, ls.dist, cos_l) == ls.pdf);
  }
  CHECK(solid > 1000);
  CHECK(area > 1000);
  // The tangents the rule compares belong to the thresholds.
  CHECK(std::tan(0.5 * double(spherical_min_solid_angle)) == Approx(spherical_min_tan_half).epsilon(1e-6));
  CHECK(std::tan(0.5 * double(spherical_max_gap)) == Approx(spherical_max_cot_half).epsilon(1e-6));
}

TEST_CASE("a one-sided triangle sampled by solid angle gives nothing behind it", "[lights]") {
  one_triangle front({-1, 0, -1}, {0, 0, 1}, {1, 0, -1});  // normal +y
  one_triangle both({-1, 0, -1}, {0, 0, 1}, {1, 0, -1}, true);
  for (float y : {0.1f, -0.1f})
    for (int i = 0; i < 100; i++) {
      vec2f u = uniform_pair(11, uint64_t(i));
      vec3f x = {0.1f, y, 0};
      REQUIRE(spherical_solid_angle(front.scene, 0, x) > 0);
      light_sample a = sample_light_point(front.lights, front.scene, 0, x, u.x, u.y);
      light_sample b = sample_light_point(both.lights, both.scene, 0, x, u.x, u.y);
      CHECK((a.pdf > 0) == (y > 0));
      CHECK(b.pdf > 0);
      if (y > 0) CHECK(a.p.x == b.p.x);
    }
}

TEST_CASE("irradiance near a large triangle: solid-angle samples match Lambert's formula with far less noise",
          "[lights]") {
  // A floor point 2 cm under a 1.6 m triangle lamp, one beside it and one 0.2 mm under it (6.28 sr, near the upper
  // threshold): the mean of le cos / pdf over samples must match the closed form, sampling by solid angle and (at
  // the first two) by area alike, and by solid angle with a standard error a tenth of the area sampler's.
  const vec3f p0 = {-0.8f, 0.02f, -0.6f}, p1 = {0.9f, 0.02f, -0.5f}, p2 = {0.0f, 0.02f, 0.9f};
  one_triangle tri(p0, p1, p2, false, 3.0f);  // faces down
  const int samples = 40000;
  for (vec3f x : {vec3f{0, 0, 0}, vec3f{0.5f, 0, 0.2f}, vec3f{0.1f, 0.0198f, 0.1f}}) {
    dvec n = {0, 1, 0};
    double exact = lambert_irradiance(to_d(x), n, tri.corner(0), tri.corner(1), tri.corner(2), 3.0);
    INFO("point " << x.x << " " << x.z << " solid angle "
                  << solid_angle(to_d(x), tri.corner(0), tri.corner(1), tri.corner(2)));
    REQUIRE(spherical_solid_angle(tri.scene, 0, x) > 0);
    std::vector<double> sa, area;
    for (int s = 0; s < samples; s++) {
      vec2f u = uniform_pair(21, uint64_t(s));
      light_sample ls = sample_light_point(tri.lights, tri.scene, 0, x, u.x, u.y);
      sa.push_back(ls.pdf > 0 ? double(ls.le.x) * std::max(0.0f, ls.wi.y) / ls.pdf : 0.0);
      // Area sampling of the same triangle: a uniform point, pdf d^2 / (cos_l area).
      vec2f b = sample_triangle(u.x, u.y);
      vec3f p = tri.scene.tri_p0[0] + tri.scene.tri_e1[0] * b.x + tri.scene.tri_e2[0] * b.y;
      vec3f d = p - x;
      float dist = length(d);
      vec3f wi = d / dist;
      float cos_l = -dot(tri.scene.tri_ng[0], wi);
      area.push_back(cos_l > 0 ? 3.0 * std::max(0.0f, wi.y) * cos_l * tri.scene.tri_area[0] / (dist * dist) : 0.0);
    }
    mean_se m = mean_and_se(sa), ma = mean_and_se(area);
    INFO("point " << x.x << " " << x.z << " exact " << exact << " solid angle " << m.mean << " +- " << m.se
                  << " area " << ma.mean << " +- " << ma.se);
    CHECK(m.se < 0.01 * exact);
    CHECK(std::fabs(m.mean - exact) < 4.4 * m.se);
    if (x.y > 0) continue;  // 0.2 mm under it, 40000 area samples have not met their heavy tail (mean 0.075 of 9.4)
    CHECK(std::fabs(ma.mean - exact) < 4.4 * ma.se);
    CHECK(m.se < 0.1 * ma.se);
  }
}

TEST_CASE("points on the line through two corners of a lamp get its irradiance, every corner order", "[lights]") {
  // Seen from a point near the line through two corners, between them, those corners lie in nearly opposite
  // directions: in float, Arvo's construction lost its precision there (a review: 0.02 mm from the foot of a 1 m
  // panel standing on a floor, half the irradiance; 0.1 mm under a quad lamp's diagonal, 22 % low or 52 % high by
  // corner order). Each case: every cyclic order of the corners, against Lambert's formula (4.4 standard errors).
  struct lamp_case {
    const char* name;
    vec3f c0, c1, c2, x, n;
  };
  const lamp_case cases[] = {
      // Half of a 1 m quad lamp facing down, 0.1 mm and 1 mm under its diagonal (x near the line c0 c1).
      {"0.1 mm under a quad's diagonal", {0, 1, 0}, {1, 1, 1}, {1, 1, 0}, {0.5f, 0.9999f, 0.5f}, {0, 1, 0}},
      {"1 mm under a quad's diagonal, off centre", {0, 1, 0}, {1, 1, 1}, {1, 1, 0}, {0.2f, 0.999f, 0.2f}, {0, 1, 0}},
      // The half with the foot of a 1 m panel standing upright on a floor: floor points 0.02 and 0.2 mm in front of it.
      {"0.02 mm from a panel's foot", {-0.5f, 0, 0}, {0.5f, 0, 0}, {0.5f, 1, 0}, {0.1f, 0, 2e-5f}, {0, 1, 0}},
      {"0.2 mm from a panel's foot", {-0.5f, 0, 0}, {0.5f, 0, 0}, {0.5f, 1, 0}, {-0.3f, 0, 2e-4f}, {0, 1, 0}},
      // A flat triangle 2 m by 2 mm, 1 mm and 0.2 mm under it, between its two far corners.
      {"1 mm under a flat triangle", {-1, 1, 0}, {0, 1, 0.002f}, {1, 1, 0}, {0, 0.999f, 0.001f}, {0, 1, 0}},
      {"0.2 mm under a flat triangle", {-1, 1, 0}, {0, 1, 0.002f}, {1, 1, 0}, {0, 0.9998f, 0.001f}, {0, 1, 0}},
  };
  for (const lamp_case& c : cases)
    for (int k = 0; k < 3; k++) {
      vec3f p[3] = {c.c0, c.c1, c.c2};
      one_triangle t(p[k], p[(k + 1) % 3], p[(k + 2) % 3], true);
      double exact = lambert_irradiance(to_d(c.x), to_d(c.n), t.corner(0), t.corner(1), t.corner(2), 1.0);
      INFO(c.name << ", corners from " << k << ": exact " << exact);
      REQUIRE(spherical_solid_angle(t.scene, 0, c.x) > 0);
      mean_se m = irradiance_estimate(t, c.x, c.n, 200000, uint64_t(31 + k));
      INFO("estimate " << m.mean << " +- " << m.se);
      CHECK(m.se < 0.01 * exact);
      CHECK(std::fabs(m.mean - exact) < 4.4 * m.se);
    }
}

TEST_CASE("no solid-angle sample is lost beside a lamp's edge line", "[lights]") {
  // Points a little outside the line through two corners, between them, at 0.1-0.3 of that offset above the plane:
  // C' ran past C as u neared 1 (the float sine and cosine of the area), beyond the plane (pdf 0, lost) or off the
  // triangle (a review: a sliver lost 0.8 % of its solid angle and 1.5 % of its irradiance; a right triangle 1e-4).
  struct lamp_case {
    const char* name;
    vec3f c0, c1, c2, x;
  };
  const float a = 0.03f;
  const lamp_case cases[] = {
      {"beside a sliver's edge", {0, 0, 0}, {1, 0, 0}, {std::cos(a), std::sin(a), 0}, {0.35f, -1e-4f, 8.8e-6f}},
      {"beside a right triangle's edge", {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.35f, -1e-6f, 1e-7f}},
  };
  const vec3f n = {0, 1, 0};
  for (const lamp_case& c : cases)
    for (int k = 0; k < 3; k++) {
      vec3f p[3] = {c.c0, c.c1, c.c2};
      one_triangle t(p[k], p[(k + 1) % 3], p[(k + 2) % 3], true);
      double exact = lambert_irradiance(to_d(c.x), to_d(n), t.corner(0), t.corner(1), t.corner(2), 1.0);
      INFO(c.name << ", corners from " << k << ": exact " << exact);
      REQUIRE(spherical_solid_angle(t.scene, 0, c.x) > 0);
      int lost = 0;
      std::vector<double> e;
      for (int s = 0; s < 400000; s++) {
        vec2f u = uniform_pair(uint64_t(41 + k), uint64_t(s));
        light_sample ls = sample_light_point(t.lights, t.scene, 0, c.x, u.x, u.y);
        lost += !(ls.pdf > 0);
        e.push_back(ls.pdf > 0 ? double(ls.le.x) * std::max(0.0f, dot(n, ls.wi)) / ls.pdf : 0.0);
      }
      mean_se m = mean_and_se(e);
      INFO("estimate " << m.mean << " +- " << m.se << ", lost " << lost);
      CHECK(lost == 0);
      CHECK(std::fabs(m.mean - exact) < 4.4 * m.se);
    }
}

TEST_CASE("an emitter's power counts the faces it emits from", "[lights]") {
  // Power (power sampling, the light tree's intensity behind it) is luminance(Le) * area * pi per emitting face: twice
  // that for a two-sided emitter, once for each face of a sheet (a face and its reverse, each emitting from its
  // front only).
  const vec3f p0{0, 0, 0}, p1{2, 0, 0}, p2{0, 0, 3};  // area 3
  const double one_face = 2.0 * 3.0 * M_PI;
  one_triangle one_sided(p0, p1, p2, false, 2), two_sided(p0, p1, p2, true, 2);
  CHECK(one_sided.lights.power[0] == Approx(one_face).epsilon(1e-6));
  CHECK(two_sided.lights.power[0] == Approx(2 * one_face).epsilon(1e-6));
  mesh_builder b;
  int lamp = b.add_material({0, 0, 0}, {2, 2, 2});
  b.add_triangle(p0, p1, p2, lamp);
  b.add_triangle(p2, p1, p0, lamp);
  scene_data sheet = build_scene(std::move(b.mesh), camera_params{}, sun_params{}, true, 1.0f);
  light_data sheet_lights = build_lights(sheet);
  REQUIRE(sheet_lights.power.size() == 2);
  for (float pw : sheet_lights.power) CHECK(pw == Approx(one_face).epsilon(1e-6));
}
