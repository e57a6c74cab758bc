// Analytic scenes with closed-form radiance, rendered through the whole pipeline (scene, Embree, lights,
// samplers, integrator, pass loop) and checked statistically: every pixel is an independent estimate, and
// the mean over pixels must lie within 4.4 standard errors of the exact value (two-sided confidence 99.999%),
// while the standard error itself must be small enough (< 1% of the value) for the test to be decisive.
#include "bvh.h"
#include "lights.h"
#include "render.h"
#include "scene.h"
#include "scene_fixture.h"
#include "test_util.h"
#include "texture.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <functional>

using namespace bl;
using namespace bl::test;

namespace {

constexpr double z_crit = 4.4;

// Renders an in-memory scene (size x size pixels, 2 threads): its film, film weight and path statistics.
render_result render_in_memory(mesh_data mesh, const camera_params& cam, const sun_params& sun, bool two_sided,
                               sampler_kind kind, int max_depth, int spp, int size = 8, uint64_t seed = 1,
                               int light_samples = 1, int light_points = 1,
                               int early_draws = bayes_params{}.early_draws,
                               const std::function<void(render_params&)>& tweak = {}) {
  scene_data scene = build_scene(std::move(mesh), cam, sun, two_sided, 1.0f);
  bvh_data bvh = build_bvh(scene);
  light_data lights = build_lights(scene);
  render_params p;
  p.width = p.height = size;
  p.spp = spp;
  p.max_depth = max_depth;
  p.seed = seed;
  p.threads = 2;
  p.sampler.kind = kind;
  p.light_samples = light_samples;
  p.light_points = light_points;
  p.sampler.bayes.early_draws = early_draws;
  if (tweak) tweak(p);
  return render(scene, bvh, lights, p);
}

// Renders an in-memory scene and returns the per-pixel luminance-free red channel estimates.
std::vector<double> render_pixels(mesh_data mesh, const camera_params& cam, const sun_params& sun, bool two_sided,
                                  sampler_kind kind, int max_depth, int spp, int size = 8, uint64_t seed = 1,
                                  int light_samples = 1, int light_points = 1,
                                  int early_draws = bayes_params{}.early_draws) {
  render_result r = render_in_memory(std::move(mesh), cam, sun, two_sided, kind, max_depth, spp, size, seed,
                                     light_samples, light_points, early_draws);
  std::vector<double> red;  // the film's own mean, in double
  for (int i = 0; i < size * size; i++) red.push_back(r.film[3 * size_t(i)] / r.film_weight);
  return red;
}

// Checks the pixel estimates against the exact value (see the file header for the criterion). `rounding`: a share of
// the value allowed on top for float maths, where the pixels' noise is below it (a small lamp far away: 1e-6).
void check_estimate(const std::vector<double>& px, double exact, double rounding = 0) {
  mean_se m = mean_and_se(px);
  INFO("mean " << m.mean << " +- " << m.se << " exact " << exact);
  CHECK(m.se < 0.01 * exact);
  CHECK(std::fabs(m.mean - exact) < z_crit * m.se + rounding * exact);
}

// A camera at height `h` above `at` (default: the origin) looking straight down at it with a narrow field of view.
camera_params looking_down(float h, vec3f at = {0, 0, 0}) {
  camera_params c;
  c.automatic = false;
  c.eye = at + vec3f{0, h, 0};
  c.target = at;
  c.up = {0, 0, -1};
  c.fov_y_deg = 0.5f;
  return c;
}

// Radiance leaving a Lambertian floor of albedo rho at the point under the centre of a square emitter of side 2a,
// radiance le, at height h facing it: rho E / pi with E = 4 le A / sqrt(1 + A^2) atan(A / sqrt(1 + A^2)), A = a / h.
double under_square_lamp(double a, double h, double le, double rho) {
  double A = a / h, s = A / std::sqrt(1 + A * A);
  return rho / M_PI * 4 * le * s * std::atan(s);
}

// A Lambertian floor of albedo rho, a square emitter of side 2a and radiance le at height h facing it (or facing
// up, away from it), and a small quad of radiance other_le high up facing away (it never lights the floor, but the
// samplers that trust power or bounds still spend draws on it).
mesh_data square_lamp_mesh(float a, float h, float le, float rho, float other_le, bool facing_floor = true) {
  mesh_builder b;
  int floor = b.add_material({rho, rho, rho});
  int lamp = b.add_material({0, 0, 0}, {le, le, le});
  int other = b.add_material({0, 0, 0}, {other_le, other_le, other_le});
  b.add_quad({-20, 0, -20}, {-20, 0, 20}, {20, 0, 20}, {20, 0, -20}, floor);
  if (facing_floor)
    b.add_quad({-a, h, -a}, {a, h, -a}, {a, h, a}, {-a, h, a}, lamp);  // normal -y
  else
    b.add_quad({-a, h, -a}, {-a, h, a}, {a, h, a}, {a, h, -a}, lamp);  // normal +y
  b.add_quad({5, 3, 5}, {5, 3, 6}, {6, 3, 6}, {6, 3, 5}, other);  // faces up: never lights the floor
  return b.mesh;
}

// A Lambertian floor of albedo rho under the sun (direction dir, irradiance e, angular diameter deg), with a quad of
// radiance lamp_le high up facing away from it.
struct sunlit_floor {
  mesh_data mesh;
  sun_params sun;
};
sunlit_floor sunlit_floor_of(float rho, float lamp_le, vec3f dir, float e, float deg) {
  mesh_builder b;
  int floor = b.add_material({rho, rho, rho});
  int lamp = b.add_material({0, 0, 0}, {lamp_le, lamp_le, lamp_le});
  b.add_quad({-20, 0, -20}, {-20, 0, 20}, {20, 0, 20}, {20, 0, -20}, floor);
  b.add_quad({5, 3, 5}, {5, 3, 6}, {6, 3, 6}, {6, 3, 5}, lamp);  // faces up: never lights the floor
  sun_params sun;
  sun.enabled = true;
  sun.direction = dir;
  sun.irradiance = {e, e, e};
  sun.angular_diameter_deg = deg;
  return {b.mesh, sun};
}

const sampler_kind kinds[] = {sampler_kind::uniform, sampler_kind::power,    sampler_kind::bvh,
                              sampler_kind::bound,   sampler_kind::donikian, sampler_kind::bayes};

}  // namespace

TEST_CASE("a point under a large emitting square receives the closed form irradiance", "[analytic]") {
  // Square of side 2a at height h, radiance Le, facing down onto a Lambertian floor of albedo rho.
  const float a = 1.0f, h = 0.5f, le = 2.0f, rho = 0.5f;
  for (sampler_kind kind : kinds)
    for (int depth : {1, 2}) {
      double exact = under_square_lamp(a, h, le, rho);
      INFO("sampler " << sampler_name(kind) << " depth " << depth);
      check_estimate(render_pixels(square_lamp_mesh(a, h, le, rho, 0.1f), looking_down(h / 2), {}, false, kind, depth,
                                   1024),
                     exact);
    }
}

TEST_CASE("a lamp of two faces lights the side each face turns to, rays and light samples alike", "[analytic]") {
  // A square lamp written as two reversed faces (one facing down, one up) under a ceiling: the ceiling's point above
  // the lamp's centre gets the up face's closed form. Embree reports either face at the shared distance; it reported
  // the one first in the file, black from its back, so BSDF-sampled rays never saw the second face while light
  // samples did: a bias of -6 % (bvh) to -20 % (uniform) at depth 2 (a review), and with two_sided_emitters the
  // light sampled twice (2x at depth 1). Now a ray meets the face turned toward it, and each face of a sheet emits
  // from its front only, also with two_sided_emitters (a review of that fix: with a black reverse the lamp lit the
  // side the black face covers, and with Ke 1 / 5 per face the file's order chose the radiance).
  const float a = 0.5f, h = 1.0f, rho = 0.5f;
  const vec3f c0{-a, 1, -a}, c1{a, 1, -a}, c2{a, 1, a}, c3{-a, 1, a};
  struct variant {
    bool up_first, two_sided;
    float up_ke, down_ke;
  };
  const variant variants[] = {{false, false, 1, 1}, {true, false, 1, 1}, {false, true, 1, 1},
                              {false, true, 5, 1},  {true, true, 5, 1},   {false, true, 0, 1}};
  for (const variant& v : variants)
    for (sampler_kind kind : kinds)
      for (int depth : {1, 2}) {
        mesh_builder b;
        int ceiling = b.add_material({rho, rho, rho});
        int up_mat = b.add_material({0, 0, 0}, {v.up_ke, v.up_ke, v.up_ke});
        int down_mat = b.add_material({0, 0, 0}, {v.down_ke, v.down_ke, v.down_ke});
        b.add_quad({-20, 1 + h, -20}, {20, 1 + h, -20}, {20, 1 + h, 20}, {-20, 1 + h, 20}, ceiling);  // faces down
        auto down = [&] { b.add_triangle(c0, c1, c2, down_mat), b.add_triangle(c0, c2, c3, down_mat); };
        auto up = [&] { b.add_triangle(c2, c1, c0, up_mat), b.add_triangle(c3, c2, c0, up_mat); };
        if (v.up_first) up(), down();
        else down(), up();
        camera_params cam;
        cam.automatic = false;
        cam.eye = {0, 1 + 0.5f * h, 0};
        cam.target = {0, 1 + h, 0};
        cam.up = {0, 0, -1};
        cam.fov_y_deg = 0.5f;
        INFO("up first " << v.up_first << " two-sided " << v.two_sided << " Ke up " << v.up_ke << " down "
                         << v.down_ke << " sampler " << sampler_name(kind) << " depth " << depth);
        std::vector<double> px = render_pixels(b.mesh, cam, {}, v.two_sided, kind, depth, 1024);
        if (v.up_ke == 0)
          CHECK(*std::max_element(px.begin(), px.end()) == 0);  // the up face is black: nothing reaches the ceiling
        else
          check_estimate(px, under_square_lamp(a, h, v.up_ke, rho));
      }
}

TEST_CASE("a ray meets the face of a sheet turned toward it only where that face is not a hole", "[analytic]") {
  // The down face of a sheet emits and has a cut-out whose half x < 0 is a hole; its reverse, the up face, is black
  // and whole. A camera below looking up through the hole sees nothing (the filter passes the ray through the down
  // face to the up face's back; the switch to the face turned toward the ray took the hole: 1.0, a review).
  const float a = 1.0f, h = 1.0f;
  for (sampler_kind kind : {sampler_kind::uniform, sampler_kind::bayes}) {
    mesh_builder b;
    int lamp = b.add_material({0, 0, 0}, {1, 1, 1});
    int black = b.add_material({0, 0, 0});
    const vec3f c0{-a, h, -a}, c1{a, h, -a}, c2{a, h, a}, c3{-a, h, a};
    size_t first = b.mesh.tri_positions.size();
    b.add_triangle(c0, c1, c2, lamp), b.add_triangle(c0, c2, c3, lamp);  // faces down
    for (size_t k = first; k < b.mesh.tri_positions.size(); k++) {
      vec3f p = b.mesh.positions[size_t(b.mesh.tri_positions[k])];
      b.mesh.tri_texcoords[k] = int(b.mesh.texcoords.size());
      b.mesh.texcoords.push_back({(p.x + a) / (2 * a), (p.z + a) / (2 * a)});
    }
    b.mesh.textures.push_back(texture_from_texels8("mask", 2, 1, 2, {255, 0, 255, 255}));  // x < 0: a hole
    b.mesh.materials[size_t(lamp)].alpha_texture = 0;
    b.add_triangle(c2, c1, c0, black), b.add_triangle(c3, c2, c0, black);  // faces up, whole
    camera_params cam;
    cam.automatic = false;
    cam.eye = {-0.5f, 0, 0};
    cam.target = {-0.5f, h, 0};
    cam.up = {0, 0, -1};
    cam.fov_y_deg = 5;
    std::vector<double> px = render_pixels(b.mesh, cam, {}, false, kind, 1, 4);
    INFO("sampler " << sampler_name(kind));
    CHECK(*std::max_element(px.begin(), px.end()) == 0);
    cam.eye.x = cam.target.x = 0.5f;  // the opaque half: the lamp's radiance, 1
    px = render_pixels(b.mesh, cam, {}, false, kind, 1, 4);
    CHECK(*std::min_element(px.begin(), px.end()) == 1);
  }
}

TEST_CASE("a tilted tile through the origin under a low sun does not shadow itself", "[analytic]") {
  // The least ray offset near the origin was 0.4 float steps of the tile's corners (1e-6 x 0.05 x its largest
  // coordinate), less than the rounding of a point interpolated from them: with the sun 10 degrees above the tile,
  // 2002 of 4800 pixels lost up to 25 % (a review). Exact: rho / pi x E x sin 10 degrees.
  mesh_builder b;
  int floor = b.add_material({0.5f, 0.5f, 0.5f});
  b.add_triangle({-1, -1, -1}, {1, 1, 1}, {1, -0.25f, -1}, floor);
  b.add_triangle({-1, -1, -1}, {-1, 0.25f, 1}, {1, 1, 1}, floor);
  camera_params cam;
  cam.automatic = false;
  cam.eye = {-0.060609f, 0.161624f, -0.101015f};
  cam.target = {0, 0, 0};
  cam.up = {0, 0, -1};
  cam.fov_y_deg = 50;
  sun_params sun;
  sun.enabled = true;
  sun.direction = normalize(vec3f{0.8694809f, 0.486118f, -0.0877056f});
  sun.irradiance = {1, 1, 1};
  std::vector<double> px = render_pixels(b.mesh, cam, sun, false, sampler_kind::power, 1, 16, 48, 3);
  const double exact = 0.5 / M_PI * std::sin(10 * M_PI / 180);
  int off = 0;
  for (double v : px) off += std::fabs(v - exact) > 0.01 * exact;
  CHECK(off == 0);
}

TEST_CASE("the holes of an emitter's own map_d emit nothing", "[analytic]") {
  // The square lamp above with a two-texel cut-out: its half x < 0 opaque, its half x > 0 a hole. The point under
  // the centre, on the line between the halves, receives half the whole square's irradiance by symmetry.
  const float a = 1.0f, h = 0.5f, le = 2.0f, rho = 0.5f;
  for (sampler_kind kind : kinds)
    for (int depth : {1, 2}) {
      mesh_builder b;
      int floor = b.add_material({rho, rho, rho});
      int lamp = b.add_material({0, 0, 0}, {le, le, le});
      b.add_quad({-20, 0, -20}, {-20, 0, 20}, {20, 0, 20}, {20, 0, -20}, floor);
      size_t first = b.mesh.tri_positions.size();
      b.add_quad({-a, h, -a}, {a, h, -a}, {a, h, a}, {-a, h, a}, lamp);
      for (size_t k = first; k < b.mesh.tri_positions.size(); k++) {
        vec3f p = b.mesh.positions[size_t(b.mesh.tri_positions[k])];
        b.mesh.tri_texcoords[k] = int(b.mesh.texcoords.size());
        b.mesh.texcoords.push_back({(p.x + a) / (2 * a), (p.z + a) / (2 * a)});
      }
      // Two texels of grey + alpha: white, opaque then a hole.
      b.mesh.textures.push_back(texture_from_texels8("mask", 2, 1, 2, {255, 255, 255, 0}));
      b.mesh.materials[size_t(lamp)].alpha_texture = 0;
      double exact = 0.5 * under_square_lamp(a, h, le, rho);
      INFO("sampler " << sampler_name(kind) << " depth " << depth);
      check_estimate(render_pixels(b.mesh, looking_down(h / 2), {}, false, kind, depth, 1024), exact);
    }
}

TEST_CASE("a lamp just above a floor far from the origin gives the closed form irradiance", "[analytic]") {
  // The square lamp of the test above at 1/50 of its size, 0.01 above the floor, everything moved to (1000, 1000,
  // 1000): the gap is half the default ray offset there (2e-5 x 1000), which neither a shadow ray nor (path traced,
  // under MIS) a BSDF continuation ray may step over, and which a continuation ray must see from the point itself.
  const vec3f c = {1000, 1000, 1000};
  const float a = 0.02f, h = 0.01f, le = 2.0f, rho = 0.5f;
  for (sampler_kind kind : {sampler_kind::uniform, sampler_kind::bound, sampler_kind::bayes})
    for (int depth : {1, 2}) {
    mesh_builder b;
    int floor = b.add_material({rho, rho, rho});
    int lamp = b.add_material({0, 0, 0}, {le, le, le});
    b.add_quad(c + vec3f{-20, 0, -20}, c + vec3f{-20, 0, 20}, c + vec3f{20, 0, 20}, c + vec3f{20, 0, -20}, floor);
    b.add_quad(c + vec3f{-a, h, -a}, c + vec3f{a, h, -a}, c + vec3f{a, h, a}, c + vec3f{-a, h, a}, lamp);
    // The closed form for the geometry as stored (float coordinates near 1000 are 6e-5 apart).
    double hs = double(c.y + h) - double(c.y), as = double(c.x + a) - double(c.x);
    double exact = under_square_lamp(as, hs, le, rho);
    INFO("sampler " << sampler_name(kind) << " depth " << depth);
    check_estimate(render_pixels(b.mesh, looking_down(0.005f, c), {}, false, kind, depth, 1024), exact);
  }
}

TEST_CASE("a small lamp at the origin lights a floor far below it with the closed form irradiance", "[analytic]") {
  // A 10 cm lamp at y = 0 (its coordinates, and so its own ray offset, tiny) over a floor 2 and 50 below: the shadow
  // ray's end, rounded by a few ulps of its length, fell behind the lamp's plane and the lamp blocked its own samples
  // (a review: 9 % of the closed form, every sampler). The end now stays off the lamp by a millionth of the length.
  const float a = 0.05f, le = 2.0f, rho = 0.5f;
  for (float h : {2.0f, 50.0f})
    for (sampler_kind kind : kinds)
      for (int depth : {1, 2}) {
        mesh_builder b;
        int floor = b.add_material({rho, rho, rho});
        int lamp = b.add_material({0, 0, 0}, {le, le, le});
        b.add_quad({-200, -h, -200}, {-200, -h, 200}, {200, -h, 200}, {200, -h, -200}, floor);
        b.add_quad({-a, 0, -a}, {a, 0, -a}, {a, 0, a}, {-a, 0, a}, lamp);  // normal -y: faces the floor
        double exact = under_square_lamp(a, h, le, rho);
        INFO("height " << h << " sampler " << sampler_name(kind) << " depth " << depth);
        // (The pixels' noise is about 1e-6 of the value, below float's rounding of the estimate: 6e-6 off.)
        check_estimate(render_pixels(b.mesh, looking_down(h / 2, {0, -h, 0}), {}, false, kind, depth, 1024), exact,
                       1e-4);
      }
}

TEST_CASE("a wall thinner than the default ray offset still shadows a point beside it far from the origin", "[analytic]") {
  // At (1000, 1000, 1000) the default ray offset is 0.02. A wall 0.01 high stands 0.005 beside the viewed point; a
  // lamp (or the sun) low behind it is hidden from the point: every shadow ray passes the wall at a height under
  // 0.002 above the floor. A shadow ray started 0.02 above the floor would pass over the wall and light the point;
  // path traced (depth 2), a BSDF ray toward the lamp that skipped its first 0.005 would pass through the wall.
  const vec3f c = {1000, 1000, 1000};
  for (bool sun_light : {false, true})
    for (sampler_kind kind : kinds)
      for (int depth : {1, 2}) {
      mesh_builder b;
      int floor = b.add_material({0.5f, 0.5f, 0.5f});
      int lamp = b.add_material({0, 0, 0}, {2, 2, 2});
      b.add_quad(c + vec3f{-20, 0, -20}, c + vec3f{-20, 0, 20}, c + vec3f{20, 0, 20}, c + vec3f{20, 0, -20}, floor);
      b.add_quad(c + vec3f{0.005f, 0, -5}, c + vec3f{0.005f, 0.01f, -5}, c + vec3f{0.005f, 0.01f, 5},
                 c + vec3f{0.005f, 0, 5}, floor);
      sun_params sun;
      if (sun_light) {
        sun.enabled = true;
        sun.direction = normalize(vec3f{1, 0.1f, 0});
        sun.irradiance = {3, 3, 3};
      } else {
        // Facing -x, toward the point, 1 away and 0.05 to 0.15 up: elevations under 9 degrees.
        b.add_quad(c + vec3f{1, 0.05f, -0.05f}, c + vec3f{1, 0.05f, 0.05f}, c + vec3f{1, 0.15f, 0.05f},
                   c + vec3f{1, 0.15f, -0.05f}, lamp);
      }
      INFO("sampler " << sampler_name(kind) << (sun_light ? " sun" : " lamp") << " depth " << depth);
      std::vector<double> px = render_pixels(b.mesh, looking_down(0.005f, c), sun, false, kind, depth, 64);
      CHECK(*std::max_element(px.begin(), px.end()) == 0.0);
    }
}

namespace {
// A closed sphere of 32 x 32 faces, each emitting Le = 1 (two-sided) with albedo rho, seen from its centre: the
// radiance is sum_{k=0..depth} rho^k (see the test below for why a sphere).
// A closed sphere of radius 1 whose grey walls (albedo rho) emit 1, seen from its centre.
struct furnace_scene {
  mesh_data mesh;
  camera_params cam;
};
furnace_scene furnace_of(float rho) {
  mesh_builder b;
  int wall = b.add_material({rho, rho, rho}, {1, 1, 1});
  b.add_sphere({0, 0, 0}, 1, 32, wall);
  furnace_scene f{b.mesh, {}};
  f.cam.automatic = false;
  f.cam.eye = {0, 0, 0};
  f.cam.target = {0, 0, 1};
  f.cam.fov_y_deg = 12;
  return f;
}

void check_furnace(float rho, sampler_kind kind, int depth, int spp, int size) {
  furnace_scene f = furnace_of(rho);
  double exact = 0;
  for (int k = 0; k <= depth; k++) exact += std::pow(rho, k);
  check_estimate(render_pixels(f.mesh, f.cam, {}, true, kind, depth, spp, size), exact);
}
}  // namespace

TEST_CASE("a furnace sphere of emitting grey walls sums its bounces", "[analytic]") {
  // Closed surface, every triangle emits Le (two-sided) with albedo rho: radiance Le * sum_{k=0..D} rho^k.
  // A tessellated sphere, not a box: in a box, the NEE of a vertex near an edge samples the adjacent wall with an
  // integrand ~ 1/d^2, and over vertices near edges its variance is infinite (value tail ~ y^-3/2), so a
  // standard error measured from pixels says nothing and the z test below would pass or fail by luck. Between
  // the sphere's faces (about 6 degrees apart) the same term carries a factor sin^2 of that angle.
  for (sampler_kind kind : kinds)
    for (int depth : {1, 3, 5}) {
      INFO("sampler " << sampler_name(kind) << " depth " << depth);
      check_furnace(0.5f, kind, depth, 512, 8);
    }
}

TEST_CASE("bayes's control variates at every path vertex keep the furnace's sum", "[analytic]") {
  // Every wall emits, so every vertex's NEE has lamps with learned means: with control variates at every vertex a
  // covered light is sampled by NEE alone, unweighted, and a BSDF-sampled hit on it weighs 0. Learning is forced on
  // (no fallback: a furnace has nothing to learn, and bayes would turn into the power sampler after 12 spp). Weighing
  // such a hit by MIS as before (NEE then counting its light twice) rendered 2.12 +- 0.003 for the exact 1.75 at
  // depth 2; without the control variates the same image is also exact (--bayes-cv-last-only).
  for (int depth : {2, 3}) {
    double exact = 0;
    for (int k = 0; k <= depth; k++) exact += std::pow(0.5, k);
    std::vector<double> images[2];
    for (bool every : {true, false}) {
      INFO("depth " << depth << (every ? ", control variates at every vertex" : ", at the last only"));
      furnace_scene f = furnace_of(0.5f);
      render_result r = render_in_memory(f.mesh, f.cam, {}, true, sampler_kind::bayes, depth, 512, 8, 1, 1, 1,
                                         bayes_params{}.early_draws, [&](render_params& p) {
                                           p.sampler.bayes.fallback_ratio = 0;
                                           p.sampler.bayes.cv_every_vertex = every;
                                         });
      REQUIRE(r.fallback_spp == 0);
      std::vector<double> red;
      for (size_t i = 0; i < 64; i++) red.push_back(r.film[3 * i] / r.film_weight);
      check_estimate(red, exact);
      images[every] = red;
    }
    CHECK(images[0] != images[1]);  // (the switch takes effect)
  }
}

TEST_CASE("a furnace of albedo 0.9 sums fifty bounces", "[analytic]") {
  // Deep paths: Russian roulette draws at every vertex from the third. Correlated draws between vertices (each
  // vertex's PCG32 stream number on one shared seed, before 2026-12) rendered 9.60 for the exact 9.954 (-17 sigma).
  check_furnace(0.9f, sampler_kind::uniform, 50, 512, 16);
}

TEST_CASE("Russian roulette spares paths of throughput at least a third", "[analytic]") {
  // roulette_scale 3 (integrator.h): from the third vertex a path goes on with probability min(1, 3 max(beta)). Inside
  // a closed sphere of albedo rho every continuation hits a wall, so the bounce rays per path have exact expectations
  // (beta is rho^k after the k-th bounce, the roulette drawn after the third): rho 0.8 keeps every path to max depth 5
  // (beta 0.51, then 0.41): 4 bounce rays; rho 0.5 keeps 3/8 at vertex 3 (beta 1/8, raised to 1/3) and 1/2 of those at
  // vertex 4: 2 + 3/8 + 3/16 = 2.5625 (with the scale 1 before: 2.1875; without roulette: 4). 32768 paths: the
  // standard error of the mean is about 0.004.
  for (float rho : {0.8f, 0.5f}) {
    furnace_scene f = furnace_of(rho);
    render_result r = render_in_memory(f.mesh, f.cam, {}, true, sampler_kind::uniform, 5, 512, 8, 7);
    REQUIRE(r.stats.camera_rays == 8 * 8 * 512);
    const double per_path = double(r.stats.bounce_rays) / double(r.stats.camera_rays);
    INFO("rho " << rho << ": " << per_path << " bounce rays per path");
    if (rho > 0.7f) CHECK(r.stats.bounce_rays == 4 * r.stats.camera_rays);
    else CHECK(std::fabs(per_path - 2.5625) < 0.03);
  }
}

TEST_CASE("the sun lights a floor with its irradiance times the cosine", "[analytic]") {
  // A uniform disk's cosine-weighted solid angle is cos(theta_s) pi sin^2(theta_max): E = E_sun cos(theta_s).
  const float rho = 0.6f, e_sun = 3.0f;
  vec3f dir = normalize(vec3f{0.3f, 1.0f, 0.2f});
  for (sampler_kind kind : kinds)
    for (int depth : {1, 2}) {
      // A lamp facing up (no contribution) with about the sun's power, so that light selection matters and
      // the wasted samples are frequent enough for the pixel variance to show them.
      sunlit_floor f = sunlit_floor_of(rho, 3000, dir, e_sun, 0.53f);
      double exact = rho / M_PI * e_sun * dir.y;
      INFO("sampler " << sampler_name(kind) << " depth " << depth);
      check_estimate(render_pixels(f.mesh, looking_down(1), f.sun, false, kind, depth, 512), exact);
    }
}

TEST_CASE("several light samples per vertex average to the closed form, MIS weighted as that many draws", "[analytic]") {
  // --light-samples K: K NEE draws at every vertex, averaged. Path traced, the BSDF ray that meets a light is weighted
  // against K draws of the light (K p_light), and each draw against the BSDF the same way: a factor K missing on either
  // side leaves the weights summing to other than one. A large square lamp close to the floor and a sun 40 degrees
  // wide make the two densities comparable where it matters.
  const float a = 1.0f, h = 0.5f, le = 2.0f, rho = 0.5f;
  for (sampler_kind kind : kinds)
    for (int depth : {1, 2}) {
      INFO("square lamp, sampler " << sampler_name(kind) << " depth " << depth);
      check_estimate(render_pixels(square_lamp_mesh(a, h, le, rho, 0.1f), looking_down(h / 2), {}, false, kind, depth,
                                   384, 8, 1, 3),
                     under_square_lamp(a, h, le, rho));
    }
  const float e_sun = 3.0f;
  const vec3f dir = normalize(vec3f{0.3f, 1.0f, 0.2f});
  for (sampler_kind kind : kinds)
    for (int depth : {1, 2}) {
      sunlit_floor f = sunlit_floor_of(rho, 0.2f, dir, e_sun, 40);  // 40 degrees, all above the horizon: E_sun cos
      INFO("sun, sampler " << sampler_name(kind) << " depth " << depth);
      check_estimate(render_pixels(f.mesh, looking_down(1), f.sun, false, kind, depth, 384, 8, 1, 3),
                     rho / M_PI * e_sun * dir.y);
    }
}

TEST_CASE("several light points per draw average to the closed form, MIS weighted as that many", "[analytic]") {
  // --light-points K (and auto): K points on the first vertex's chosen light. Path traced, the BSDF ray from the first
  // vertex that meets a light is weighted against K points (K p_light), each point against the BSDF the same way.
  // With two draws as well (--light-samples 2): 2K. The lattice's points must each be uniform for this to hold.
  const float a = 1.0f, h = 0.5f, le = 2.0f, rho = 0.5f;
  const float e_sun = 3.0f;
  const vec3f dir = normalize(vec3f{0.3f, 1.0f, 0.2f});
  for (sampler_kind kind : kinds)
    for (int depth : {1, 2})
      for (int points : {3, 0}) {
        const int draws = points == 0 ? 2 : 1;
        INFO("square lamp, sampler " << sampler_name(kind) << " depth " << depth << " points " << points);
        check_estimate(render_pixels(square_lamp_mesh(a, h, le, rho, 0.1f), looking_down(h / 2), {}, false, kind,
                                     depth, 384, 8, 1, draws, points),
                       under_square_lamp(a, h, le, rho));
        sunlit_floor f = sunlit_floor_of(rho, 0.2f, dir, e_sun, 40);
        INFO("sun");
        check_estimate(render_pixels(f.mesh, looking_down(1), f.sun, false, kind, depth, 384, 8, 1, draws, points),
                       rho / M_PI * e_sun * dir.y);
      }
}

TEST_CASE("light point counts chosen from a pixel's own samples leave its estimate unbiased", "[analytic]") {
  // --light-points auto chooses a tile's count from what its samples measured. Had the points started from the
  // stratified light set, whose later points depend on its earlier ones, and had MIS counted the points, the count
  // would lean on where later samples land: a 1x1 image (one pixel, its own tile), glossy floor under a lamp half
  // hidden by two strips, a brighter lamp and an 8-degree sun, depth 2, two draws per vertex, power sampling, 16 spp,
  // read -1.16 % +- 0.05 % against 8 fixed points over 300000 seeds (a review). Paired seeds, auto against 8 points:
  // the mean difference within z_crit standard errors, the standard error under a quarter of that bias.
  mesh_builder b;
  const int floor = b.add_material({0.5f, 0.5f, 0.5f}, {0, 0, 0}, {0.3f, 0.3f, 0.3f}, 20);
  const int lamp = b.add_material({0, 0, 0}, {2, 2, 2}), lamp2 = b.add_material({0, 0, 0}, {30, 30, 30});
  const int occ = b.add_material({0.5f, 0.5f, 0.5f});
  b.add_quad({-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, floor);
  b.add_quad({-0.5f, 1, -0.5f}, {0.5f, 1, -0.5f}, {0.5f, 1, 0.5f}, {-0.5f, 1, 0.5f}, lamp);
  b.add_quad({1.25f, 1, -0.25f}, {1.75f, 1, -0.25f}, {1.75f, 1, 0.25f}, {1.25f, 1, 0.25f}, lamp2);
  b.add_quad({-0.05f, 0.6f, -2}, {-0.05f, 0.6f, 2}, {0.2f, 0.6f, 2}, {0.2f, 0.6f, -2}, occ);
  b.add_quad({-2, 0.7f, 0.1f}, {-2, 0.7f, 0.25f}, {2, 0.7f, 0.25f}, {2, 0.7f, 0.1f}, occ);
  camera_params cam = looking_down(0.3f);
  cam.fov_y_deg = 30;
  sun_params sun;
  sun.enabled = true;
  sun.direction = normalize(vec3f{0.05f, 1, 0.3f});
  sun.irradiance = {3, 3, 3};
  sun.angular_diameter_deg = 8;
  scene_data scene = build_scene(b.mesh, cam, sun, false, 1.0f);
  bvh_data bvh = build_bvh(scene);
  light_data lights = build_lights(scene);
  render_params p;
  p.width = p.height = 1;
  p.spp = 16;
  p.max_depth = 2;
  p.threads = 1;
  p.sampler.kind = sampler_kind::power;
  p.light_samples = 2;
  auto pixel = [&](int points, uint64_t seed) {
    p.light_points = points;
    p.seed = seed;
    render_result r = render(scene, bvh, lights, p);
    return luminance(vec3f{float(r.film[0]), float(r.film[1]), float(r.film[2])}) / r.film_weight;
  };
  std::vector<double> diff;
  double level = 0;
  const int seeds = 30000;
  for (int s = 0; s < seeds; s++) {
    const double fixed = pixel(8, uint64_t(s));
    diff.push_back(pixel(0, uint64_t(s)) - fixed);
    level += fixed / seeds;
  }
  mean_se d = mean_and_se(diff);
  INFO("auto - 8 points: " << d.mean << " +- " << d.se << " at " << level);
  CHECK(d.se < 0.0029 * level);
  CHECK(std::fabs(d.mean) < z_crit * d.se);
}

TEST_CASE("light points are spread over the light: five cut the spread inside a near lamp", "[analytic]") {
  // Five points on one light that repeated a point (or fell on a line across it) would not cut the noise of a large
  // lamp close to the floor, whose solid-angle samples differ by the floor's cosine. One light (no choice to make):
  // the pixels' standard deviation with five points against one, at the same spp.
  const float a = 1.0f, h = 0.5f, le = 2.0f, rho = 0.5f;
  const mesh_data mesh = square_lamp_mesh(a, h, le, rho, 0);
  for (sampler_kind kind : {sampler_kind::uniform, sampler_kind::bayes}) {
    mean_se one = mean_and_se(render_pixels(mesh, looking_down(h / 2), {}, false, kind, 1, 16, 8, 3, 1, 1));
    mean_se five = mean_and_se(render_pixels(mesh, looking_down(h / 2), {}, false, kind, 1, 16, 8, 3, 1, 5));
    INFO("sampler " << sampler_name(kind) << " se with 1: " << one.se << " with 5: " << five.se);
    CHECK(one.se > 0);
    CHECK(five.se < 0.6 * one.se);
  }
}

TEST_CASE("light samples per vertex are drawn apart: four cut the pixels' spread about in half", "[analytic]") {
  // K draws that repeated one light choice or point would average to the same estimate with the same noise. Direct
  // illumination under a square lamp, with a lamp facing away that the fixed samplers waste draws on: the pixels'
  // standard deviation with four draws against one, at the same spp. Independent draws give 1/2 (stratified, less);
  // the bound 0.7 leaves the spread's own sampling error (64 pixels: about 9 % each) more than 3 sigma. (bayes without
  // its early draws, which would give both renders four.)
  const float a = 1.0f, h = 0.5f, le = 2.0f, rho = 0.5f;
  const mesh_data mesh = square_lamp_mesh(a, h, le, rho, 50);
  for (sampler_kind kind : kinds) {
    mean_se one = mean_and_se(render_pixels(mesh, looking_down(h / 2), {}, false, kind, 1, 16, 8, 3, 1, 1, 1));
    mean_se four = mean_and_se(render_pixels(mesh, looking_down(h / 2), {}, false, kind, 1, 16, 8, 3, 4, 1, 1));
    INFO("sampler " << sampler_name(kind) << " se with 1: " << one.se << " with 4: " << four.se);
    CHECK(one.se > 0);
    CHECK(four.se < 0.7 * one.se);
  }
}

TEST_CASE("bayes draws its early NEE samples in a direct render's first passes only, and not once it fell back",
          "[analytic]") {
  // --bayes-early-draws 4 (the default) in the passes that start before --bayes-early-spp 16: here the first 18 spp
  // (passes of 1 spp to 8, then 8-10, 10-12, 12-15, 15-18). Every camera ray meets the floor, so a render of 20 spp
  // takes 4 draws per pixel in each of its first 18 spp and 1 in the last 2. A path-traced render takes one draw
  // throughout, and so does a render after its fallback to power sampling (forced here at 5 spp).
  const float a = 1.0f, h = 0.5f, le = 2.0f, rho = 0.5f;
  const auto t = build_test_scene(square_lamp_mesh(a, h, le, rho, 50), looking_down(h / 2));
  render_params p;
  p.width = p.height = 4;
  p.spp = 20;
  p.max_depth = 1;
  p.seed = 5;
  p.threads = 2;
  p.sampler.kind = sampler_kind::bayes;
  const uint64_t pixels = 16;
  int early = 0;  // the spp of the passes that start before early_spp
  for (int pass = 0, done = 0; done < p.sampler.bayes.early_spp; pass++) {
    done += pass_size(pass, done, int64_t(pixels));
    early = done;
  }
  REQUIRE(early == 18);
  auto draws = [&](int early_draws, int max_depth, double fallback_ratio) {
    render_params q = p;
    q.sampler.bayes.early_draws = early_draws;
    q.max_depth = max_depth;
    if (fallback_ratio > 0) q.sampler.bayes.fallback_ratio = fallback_ratio, q.sampler.bayes.fallback_window = 1;
    render_result r = render(t->scene, t->bvh, t->lights, q);
    INFO("early draws " << early_draws << " max depth " << max_depth << " fallback after " << r.fallback_spp);
    CHECK(r.stats.camera_rays == pixels * 20);
    if (fallback_ratio > 0) CHECK(r.fallback_spp == 5);
    return r;
  };
  CHECK(draws(1, 1, 0).stats.nee_samples == pixels * 20);
  CHECK(draws(4, 1, 0).stats.nee_samples == pixels * (4 * uint64_t(early) + 20 - uint64_t(early)));
  CHECK(draws(4, 1, 1e9).stats.nee_samples == pixels * (4 * 5 + 15));
  // Path traced: the same image with or without them.
  render_result one = draws(1, 2, 0), four = draws(4, 2, 0);
  CHECK(four.stats.nee_samples == one.stats.nee_samples);
  CHECK(four.film == one.film);
}

TEST_CASE("a two-sided lamp lights the floor its back faces, with every sampler", "[analytic]") {
  // two_sided_emitters: a single sheet emits from both faces. A square lamp facing up, away from the floor, lights it
  // with its back: the light tree's normal cones, the bounds and the samplers' pmfs must all count that side.
  const float a = 1.0f, h = 0.5f, le = 2.0f, rho = 0.5f;
  // (The small quad emits nothing here: two-sided, it would light the floor too.)
  const mesh_data mesh = square_lamp_mesh(a, h, le, rho, 0, false);
  for (sampler_kind kind : kinds)
    for (int depth : {1, 2}) {
      INFO("sampler " << sampler_name(kind) << " depth " << depth);
      check_estimate(render_pixels(mesh, looking_down(h / 2), {}, true, kind, depth, 512),
                     under_square_lamp(a, h, le, rho));
    }
}
