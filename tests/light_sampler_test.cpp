// The light-sampler contract (light_sampler_types.h) checked for every available sampler kind, built by
// make_light_sampler on a small scene with a few dozen emitters of very different power (some facing away from
// everything), with and without a sun: at many shading points on the scene's surfaces the pmf sums to 1 (or 0
// when no light can contribute) within 1e-5, sample() returns prob bitwise equal to pmf() (MIS needs it),
// sampled frequencies match the pmf (chi-square, significance 1e-3 per test, 100k samples, fixed seeds), and
// every light that can contribute has pmf > 0, however small its share of the selection weight. The learning
// samplers are checked again after learning from passes of real paths. Exception, stated where it applies: the bvh
// sampler (like pbrt-v4's) may give up in a subtree whose children both prove dark, so its pmf may sum to < 1;
// the missing mass must then be exactly the frequency of "no light" (part of the chi-square test).
#include "bvh.h"
#include "integrator.h"
#include "light_sampler.h"
#include "lights.h"
#include "render.h"
#include "rng.h"
#include "scene.h"
#include "scene_fixture.h"
#include "test_util.h"

#include <catch2/catch.hpp>

#include <optional>

#include <algorithm>
#include <array>
#include <cfloat>
#include <cstring>
#include <memory>
#include <sstream>
#include <type_traits>

using namespace bl;
using namespace bl::test;

namespace {

constexpr double alpha = 1e-3;     // chi-square significance level of every frequency test here
constexpr double sum_tol = 1e-5;   // tolerance of sum(pmf) = 1 (float cdfs and products of a few factors)
constexpr int chi2_samples = 100000;

bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// A floor, a back wall and an occluding box, lit by 36 small emitters whose radiance spans 1e-3..1e4: most face
// down (randomly tilted), a quarter face up (away from the floor: they light only the ceiling-less void), plus
// optionally a sun. Emitters are partly reflective (shading points on them too).
std::unique_ptr<test_scene> make_test_scene(bool sun, int image = 16) {
  pcg32 rng(2024, 3);
  mesh_builder b;
  int floor = b.add_material({0.5f, 0.5f, 0.5f});
  int wall = b.add_material({0.3f, 0.4f, 0.5f}, {0, 0, 0}, {0.2f, 0.2f, 0.2f}, 20);
  b.add_quad({-10, 0, -10}, {-10, 0, 10}, {10, 0, 10}, {10, 0, -10}, floor);
  b.add_quad({-10, 0, -6}, {10, 0, -6}, {10, 6, -6}, {-10, 6, -6}, wall);
  b.add_box({-1, 0, -1}, {1, 1.5f, 1}, wall);
  for (int i = 0; i < 36; i++) {
    float le = log_uniform(rng, 1e-3f, 1e4f);
    vec3f kd = i % 2 ? vec3f{0.2f, 0.2f, 0.2f} : vec3f{0, 0, 0};
    int m = b.add_material(kd, {le, le * (0.5f + 0.5f * unif(rng)), le * (0.5f + 0.5f * unif(rng))});
    vec3f c = random_in(rng, {-8, 1, -5}, {8, 5, 5});
    float s = log_uniform(rng, 0.05f, 0.5f);
    vec3f p0 = c, p1 = c + vec3f{s, s * (unif(rng) - 0.5f), 0}, p2 = c + vec3f{0, s * (unif(rng) - 0.5f), s};
    if (i % 4 == 3) std::swap(p1, p2);  // faces up
    b.add_triangle(p0, p1, p2, m);
  }
  auto t = build_test_scene(std::move(b.mesh), fixed_camera({0, 6, 14}, {0, 1, 0}, 50),
                             sun ? test_sun({0.3f, 1.0f, 0.2f}, {5, 5, 4}) : sun_params{}, image);
  t->in.max_depth = 3;
  t->in.seed = 5;
  return t;
}

// Shading points on the scene's surfaces: first hits of camera rays and of random rays from random points
// inside the scene's bounds; the normal faces the side the ray came from.
std::vector<shade_point> shading_points(const test_scene& t, int count, uint64_t seed) {
  pcg32 rng(seed, 5);
  std::vector<shade_point> out;
  bbox3f b = t.scene.bounds;
  for (int tries = 0; int(out.size()) < count && tries < 100 * count; tries++) {
    vec3f org, dir;
    if (tries % 3 == 0) {
      org = t.in.camera.eye;
      dir = camera_ray_dir(t.in.camera, unif(rng) * float(t.in.camera.width), unif(rng) * float(t.in.camera.height));
    } else {
      org = random_in(rng, b.lo, b.hi);
      dir = random_unit(rng);
    }
    hit_info h = intersect(t.bvh, org, dir);
    if (h.tri == invalid_id) continue;
    surface_point sp = eval_surface(t.scene, h.tri, h.b1, h.b2, h.p, dir);
    // Pixels cycle through the image (samplers that learn per pixel index their tables with them). The wall's
    // Phong lobe makes some points glossy (bayes weighs their clusters with the lobe, members one by one).
    int pixel = int(out.size()) % (t.in.camera.width * t.in.camera.height);
    out.push_back(make_shade_point(sp.p, make_bsdf(t.scene, sp), -dir, pixel, 1 + tries % 2, false));
  }
  return out;
}

// Whether light l can contribute at (p, n): some point of it faces p from above p's tangent plane (the sun:
// some direction of its disk lies above the plane). Configurations within 1e-5 (cosine) of grazing count as
// "cannot": float rounding in the bounds is of order 1e-7 there and the contribution is at most 1e-5 relative.
bool can_contribute(const test_scene& t, int l, vec3f p, vec3f n) {
  constexpr double margin = 1e-5;
  const light_data& L = t.lights;
  if (l == L.sun) {
    double sin_t = std::sqrt(double(L.sun_one_minus_cos) * (2 - double(L.sun_one_minus_cos)));
    return double(dot(n, L.sun_dir)) > -sin_t + margin;
  }
  int tri = L.tri[size_t(l)];
  vec3f p0 = t.scene.tri_p0[size_t(tri)];
  vec3f v[3] = {p0, p0 + t.scene.tri_e1[size_t(tri)], p0 + t.scene.tri_e2[size_t(tri)]};
  vec3f ng = t.scene.tri_ng[size_t(tri)];
  vec3f c = (v[0] + v[1] + v[2]) * (1.0f / 3);
  double dist = length(p - c);
  double side = double(ng.x) * (p.x - c.x) + double(ng.y) * (p.y - c.y) + double(ng.z) * (p.z - c.z);
  if (L.two_sided) side = std::fabs(side);
  if (!(side > margin * dist)) return false;
  for (vec3f q : v) {
    double d = length(q - p);
    double up = double(n.x) * (q.x - p.x) + double(n.y) * (q.y - p.y) + double(n.z) * (q.z - p.z);
    if (up > margin * d) return true;
  }
  return false;
}

// Share of light l in the summed importance (leaf importances and the sun's) at (p, n), for messages.
double relative_importance(const test_scene& t, int l, vec3f p, vec3f n) {
  float sun_sin = 0, sun_cos = 1;
  if (t.lights.sun != invalid_id) sun_half_angle(t.lights, sun_sin, sun_cos);
  double total = sun_importance(t.lights, n, sun_sin, sun_cos), mine = 0;
  if (l == t.lights.sun) mine = total;
  for (int k = 0; k < t.lights.tri_count; k++) {
    double imp = node_importance(t.tree, t.tree.leaf_of_light[size_t(k)], p, n);
    total += imp;
    if (k == l) mine = imp;
  }
  return total > 0 ? mine / total : 0;
}

// Sink handing NEE events to a learning sampler's row.
template <class S>
struct row_sink {
  const S* sampler;
  typename S::row_state* row;
  template <class E>
  void record(const E& e) {
    sampler->record(*row, e);
  }
};

// Renders `passes` passes of 1 spp with real paths, learning between passes (the render loop, single-threaded).
template <class S>
path_stats learn_passes(const render_inputs& in, S& s, int passes) {
  path_stats st;
  int w = in.camera.width, h = in.camera.height;
  std::vector<typename S::row_state> rows(static_cast<size_t>(h));
  for (int pass = 0; pass < passes; pass++) {
    for (int y = 0; y < h; y++) {
      rows[size_t(y)].clear();
      row_sink<S> sink{&s, &rows[size_t(y)]};
      typename S::context ctxs[2];
      for (int x = 0; x < w; x++) trace_path(in, s, x, y, uint64_t(pass), st, sink, ctxs);
    }
    s.learn(rows);
  }
  return st;
}

// Counters of contract violations over many shading points.
struct contract_report {
  int points = 0, zero_sum = 0, bad_sum = 0, lossy_points = 0, bad_pmf = 0, starved = 0, prob_mismatch = 0, null_with_mass = 0,
      bad_cluster_split = 0, chi2_tests = 0, chi2_failures = 0;
  double worst_sum_error = 0, mean_deficit = 0, worst_deficit = 0;
  std::string notes;  // the first few violations, for the failure message
  void note(const std::string& s) {
    if (std::count(notes.begin(), notes.end(), '\n') < 8) notes += s + "\n";
  }
};

std::string sci(double v) {
  std::ostringstream o;
  o.precision(3);
  o << std::scientific << v;
  return o.str();
}
std::string fmt(vec3f v) {
  std::ostringstream o;
  o.precision(9);
  o << "(" << v.x << " " << v.y << " " << v.z << ")";
  return o.str();
}

// Checks the contract of sampler `s` at the given points; chi-square frequency tests at the first `chi2_points`.
template <class S>
contract_report check_contract(const test_scene& t, const S& s, const std::vector<shade_point>& pts, int chi2_points,
                               uint64_t seed, bool may_lose_mass = false) {
  contract_report rep;
  int nl = t.lights.count;
  pcg32 rng(seed, 9);
  std::vector<float> pmf(static_cast<size_t>(nl));
  auto ctx_ptr = std::make_unique<typename S::context>();  // cut contexts are large: keep them off the stack
  typename S::context& ctx = *ctx_ptr;
  for (size_t k = 0; k < pts.size(); k++) {
    const shade_point& sp = pts[k];
    s.prepare(ctx, sp);
    rep.points++;
    double sum = 0;
    bool any = false;
    for (int l = 0; l < nl; l++) {
      pmf[size_t(l)] = s.pmf(ctx, l);
      if (!(pmf[size_t(l)] >= 0) || !std::isfinite(pmf[size_t(l)]) || pmf[size_t(l)] > 1) rep.bad_pmf++;
      sum += pmf[size_t(l)];
      bool can = can_contribute(t, l, sp.p, sp.n);
      any = any || can;
      if (can && !(pmf[size_t(l)] > 0)) {
        rep.starved++;
        rep.note("starved light " + std::to_string(l) + " at point " + std::to_string(k) + " p " + fmt(sp.p) +
                 " n " + fmt(sp.n) + ", its share of the summed importance " +
                 sci(relative_importance(t, l, sp.p, sp.n)));
      }
    }
    if (sum == 0) {
      rep.zero_sum++;
      if (any) {
        rep.bad_sum++;
        rep.note("pmf sums to 0 at point " + std::to_string(k) + " although some light can contribute");
      }
    } else if (may_lose_mass && sum < 1 - sum_tol) {
      // Selection mass lost in subtrees whose children both turn out to be unable to light the point.
      rep.lossy_points++;
      rep.mean_deficit += 1 - sum;
      rep.worst_deficit = std::max(rep.worst_deficit, 1 - sum);
    } else {
      rep.worst_sum_error = std::max(rep.worst_sum_error, std::fabs(sum - 1));
      if (std::fabs(sum - 1) > sum_tol) {
        rep.bad_sum++;
        rep.note("pmf sums to " + std::to_string(sum) + " at point " + std::to_string(k) + " p " + fmt(sp.p) +
                 " n " + fmt(sp.n));
      }
    }
    // sample() against pmf(): bitwise equal probabilities; no failed sample while the pmf has full mass.
    bool do_chi2 = int(k) < chi2_points;
    int n_samples = do_chi2 ? chi2_samples : 200;
    std::vector<double> obs(size_t(nl) + 1, 0.0);
    for (int i = 0; i < n_samples; i++) {
      double u1 = unif53(rng), u2 = unif53(rng);
      light_choice c = s.sample(ctx, u1, u2);
      if (c.light == invalid_id) {
        obs[size_t(nl)] += 1;
        if (std::fabs(sum - 1) <= sum_tol) rep.null_with_mass++;
        continue;
      }
      obs[size_t(c.light)] += 1;
      if (!same_bits(c.prob, pmf[size_t(c.light)]) || !(c.prob > 0)) {
        rep.note("sample prob " + std::to_string(c.prob) + " pmf " + std::to_string(pmf[size_t(c.light)]) +
                 " light " + std::to_string(c.light));
        rep.prob_mismatch++;
      }
      if constexpr (std::is_same_v<typename S::context, cut_context>) {
        // prob = P(cluster) * P(light | cluster), the split the learner's observations rely on (both factors are
        // rounded from double separately, so the product agrees to float resolution, not bit for bit).
        bool valid = c.cluster >= 0 && c.cluster < ctx.pair_count && c.cluster_prob > 0 && c.cluster_prob <= 1;
        double split = valid ? c.cluster_prob * double(c.prob_in_cluster) : 0.0;
        if (!valid || std::fabs(double(c.prob) - split) > 2e-7 * split)
          rep.bad_cluster_split++;
      }
    }
    if (do_chi2) {
      std::vector<double> exp(size_t(nl) + 1, 0.0);
      for (int l = 0; l < nl; l++) exp[size_t(l)] = n_samples * double(pmf[size_t(l)]);
      exp[size_t(nl)] = n_samples * std::max(0.0, 1 - sum);
      if (sum == 0) exp[size_t(nl)] = n_samples;
      double pv = chi2_pvalue(obs, exp);
      rep.chi2_tests++;
      if (!(pv > alpha)) {
        rep.chi2_failures++;
        rep.note("chi-square p-value " + std::to_string(pv) + " at point " + std::to_string(k));
      }
    }
  }
  if (rep.lossy_points > 0) rep.mean_deficit /= rep.lossy_points;
  return rep;
}

void require_contract(const contract_report& r) {
  INFO("points " << r.points << " (pmf sum 0 at " << r.zero_sum << "), worst |sum - 1| " << r.worst_sum_error
                 << ", chi-square tests " << r.chi2_tests << ", points losing selection mass " << r.lossy_points
                 << " (mean loss " << r.mean_deficit << ", worst " << r.worst_deficit << ")\n" << r.notes);
  CHECK(r.points > 0);
  CHECK(r.bad_pmf == 0);
  CHECK(r.bad_sum == 0);
  CHECK(r.starved == 0);
  CHECK(r.prob_mismatch == 0);
  CHECK(r.null_with_mass == 0);
  CHECK(r.bad_cluster_split == 0);
  CHECK(r.chi2_failures == 0);
}

const sampler_kind all_kinds[] = {sampler_kind::uniform, sampler_kind::power, sampler_kind::bvh, sampler_kind::bound,
                                  sampler_kind::donikian, sampler_kind::bayes};

// Region options of the cut-based samplers: the defaults, small cuts on a coarse grid without members (clusters of
// many lights, so the intensity descent inside clusters is exercised), and those small cuts with members (bayes:
// clusters of several members, each chosen inside its cluster by its learned weight, then descended; the other
// samplers ignore members), and (bayes) those with members whose unseen clusters and members are capped after a
// single sample (bayes_params::unseen_cap 1: caps at many points, inside clusters too).
constexpr int param_variants = 4;
sampler_params params_variant(sampler_kind kind, int variant) {
  sampler_params p;
  p.kind = kind;
  if (variant >= 1) {
    p.regions.max_cut = 4;
    p.regions.grid = 4;
  }
  if (variant >= 1) p.regions.max_members = variant >= 2 ? 16 : 0;
  if (variant == 3) p.bayes.unseen_cap = 1;
  return p;
}

}  // namespace

TEST_CASE("every light sampler satisfies the sampling contract", "[samplers]") {
  for (bool sun : {true, false}) {
    auto t = make_test_scene(sun);
    std::vector<shade_point> pts = shading_points(*t, 300, sun ? 1 : 2);
    REQUIRE(pts.size() == 300);
    CHECK(std::count_if(pts.begin(), pts.end(), [](const shade_point& p) { return p.gloss_peak > 0; }) >= 30);
    for (sampler_kind kind : all_kinds) {
      if (!sampler_available(kind)) continue;
      for (int variant = 0; variant < param_variants; variant++) {
        if (variant >= 1 && (kind == sampler_kind::uniform || kind == sampler_kind::power || kind == sampler_kind::bvh))
          continue;
        if (variant >= 2 && kind != sampler_kind::bayes) continue;  // members are the bayes sampler's only
        INFO("sampler " << sampler_name(kind) << " sun " << sun << " variant " << variant);
        light_sampler ls = make_light_sampler(params_variant(kind, variant), t->in, t->tree);
        // The bvh sampler, like pbrt-v4's, gives up when both children of a node it descended into turn out to
        // have zero importance: its pmf may sum to less than 1 (the rest is "no light", checked by chi-square).
        bool lossy = kind == sampler_kind::bvh;
        std::visit([&](const auto& s) { require_contract(check_contract(*t, s, pts, 8, 100 + variant, lossy)); }, ls);
      }
    }
  }
}

TEST_CASE("evenly spaced selection numbers choose every light in proportion, inside clusters too", "[samplers]") {
  // Stratified sampling hands a sampler u's spread evenly over [0, 1). A sampler that inverts one u down to the
  // light (the cluster's cell, then u's place inside it for the member and the descent by intensity) gives each
  // light an interval of u of its probability's length: M evenly spaced u's choose it M * pmf times, less than one
  // off. A descent that drew its own number (u_inner, held fixed here) would send every u of a cluster to one light.
  auto t = make_test_scene(false);
  std::vector<shade_point> pts = shading_points(*t, 40, 5);
  const int nl = t->lights.count, count = 4096;
  for (sampler_kind kind : {sampler_kind::power, sampler_kind::bvh, sampler_kind::bound, sampler_kind::donikian,
                            sampler_kind::bayes}) {
    if (!sampler_available(kind)) continue;
    for (int variant = 0; variant < param_variants; variant++) {
      if (variant >= 1 && (kind == sampler_kind::power || kind == sampler_kind::bvh)) continue;
      if (variant >= 2 && kind != sampler_kind::bayes) continue;
      INFO("sampler " << sampler_name(kind) << " variant " << variant);
      light_sampler ls = make_light_sampler(params_variant(kind, variant), t->in, t->tree);
      std::visit(
          [&](auto& s) {
            using S = std::decay_t<decltype(s)>;
            if constexpr (S::learns) learn_passes(t->in, s, 3);  // (bayes: members of unequal learned weights)
            auto ctx = std::make_unique<typename S::context>();
            std::vector<int> hits(static_cast<size_t>(nl));
            int several = 0;  // points where some chosen cluster holds more than one light
            double worst = 0;
            for (const shade_point& sp : pts) {
              s.prepare(*ctx, sp);
              std::fill(hits.begin(), hits.end(), 0);
              std::vector<int> light_of_cluster;
              bool shared = false;
              for (int i = 0; i < count; i++) {
                light_choice c = s.sample(*ctx, (i + 0.5) / count, 0.5);
                if (c.light == invalid_id) continue;
                hits[size_t(c.light)]++;
                if (c.cluster >= 0) {
                  if (light_of_cluster.size() <= size_t(c.cluster)) light_of_cluster.resize(size_t(c.cluster) + 1, -1);
                  int& l = light_of_cluster[size_t(c.cluster)];
                  shared = shared || (l >= 0 && l != c.light);
                  l = c.light;
                }
              }
              several += shared;
              for (int l = 0; l < nl; l++)
                worst = std::max(worst, std::fabs(hits[size_t(l)] - count * double(s.pmf(*ctx, l))));
            }
            CHECK(worst < 1.01);
            if (kind != sampler_kind::power && kind != sampler_kind::bvh) CHECK(several > 0);
          },
          ls);
    }
  }
}

TEST_CASE("learning samplers satisfy the sampling contract after learning", "[samplers]") {
  for (bool sun : {true, false}) {
    auto t = make_test_scene(sun);
    std::vector<shade_point> pts = shading_points(*t, 300, sun ? 3 : 4);
    for (sampler_kind kind : {sampler_kind::bound, sampler_kind::bayes}) {
      for (int variant = 0; variant < param_variants; variant++) {
        if (variant >= 2 && kind != sampler_kind::bayes) continue;
        INFO("sampler " << sampler_name(kind) << " sun " << sun << " variant " << variant);
        light_sampler ls = make_light_sampler(params_variant(kind, variant), t->in, t->tree);
        std::visit(
            [&](auto& s) {
              using S = std::decay_t<decltype(s)>;
              if constexpr (S::learns) {
                path_stats st = learn_passes(t->in, s, 6);
                CHECK(st.bad_samples == 0);
                CHECK(st.nee_samples > 0);
                require_contract(check_contract(*t, s, pts, 8, 200 + variant));
              }
            },
            ls);
        if (auto* b = std::get_if<bayes_sampler>(&ls)) {
          // The statistics did learn something (and stayed finite).
          double n = 0;
          bool finite = true;
          for (size_t i = 0; i < b->stats.m.size(); i++) {
            n += b->stats.m[i].n0 + b->stats.m[i].n1;
            finite = finite && std::isfinite(b->stats.m[i].mean) && std::isfinite(b->stats.m[i].m2) &&
                     pair_state_finite(b->stats, i);
          }
          CHECK(n > 0);
          CHECK(finite);
          if (variant == 3) {  // (the caps did apply: unseen pairs, and clusters holding seen and unseen members)
            size_t unseen = 0, capped = 0;
            for (uint8_t u : b->stats.unseen) unseen += u;
            for (size_t i = 0; i < b->stats.m.size(); i++) capped += b->stats.mw[i] < b->stats.w[i];
            CHECK(unseen > 0);
            CHECK(capped > 0);
          }
        }
      }
    }
  }
}

TEST_CASE("lazily refolded bayes weights stay within the refold tolerance of an exact refold", "[samplers][bayes]") {
  auto t = make_test_scene(false);
  for (bool means : {false, true})
  for (double tol : {0.0, 0.05, 0.2}) {
    sampler_params sp;
    sp.kind = sampler_kind::bayes;
    sp.bayes.refold_tolerance = tol;
    sp.bayes.mean_hierarchy = means;
    light_sampler ls = make_light_sampler(sp, t->in, t->tree);
    auto& s = std::get<bayes_sampler>(ls);
    learn_passes(t->in, s, 12);
    bayes_stats exact = s.stats;
    refresh_weights(exact, &s.regions.pair_parent, s.params, &s.regions.pair_node);
    int checked = 0, differ = 0;
    double worst = 0;
    for (size_t i = 0; i < s.stats.m.size(); i++) {
      int up = s.regions.pair_parent[i];
      if (up == invalid_id) {
        CHECK(s.stats.w[i] == exact.w[i]);  // no parent: always folded exactly
        continue;
      }
      if (pair_p1(exact, i, up, s.params) < 0.1 || !(exact.w[i] > 0)) continue;
      checked++;
      differ += s.stats.w[i] != exact.w[i];
      worst = std::max(worst, std::fabs(double(s.stats.w[i]) / double(exact.w[i]) - 1));
    }
    INFO("mean hierarchy " << means << ", tolerance " << tol << ": " << checked << " fine pairs, " << differ
                           << " lazily stale, worst " << worst);
    CHECK(checked > 100);
    if (tol == 0) CHECK(differ == 0);
    // W is proportional to sqrt(p1), and a child's p1 is at most 2 tol (relative) from its exact value. Under the mean
    // hierarchy W = sqrt(p1 Q(mu)) also depends on the prior mean mu, with Q at most about quadratic in mu: W moves by
    // about the mean's relative change at most. A child holds the parent's mean of when it was last folded, and both
    // that and the parent's mean now lie within tol of the parent's reference (k_folded): 2 tol apart at most (the
    // bound was 1 + tol here until a review found 11.7 % on the hall's pairs at tol 0.05).
    CHECK(worst <= (means ? 1 + 2 * tol : 1.0) * std::sqrt(1 + 2 * tol) - 1 + 1e-5);
    if (tol >= 0.2) CHECK(differ > 0);  // the laziness is real: some weights were not refolded
  }
}

TEST_CASE("without the hierarchy, folding every weight afresh reproduces the learned ones", "[samplers][bayes]") {
  // Animations (begin_frame) fold every pair afresh; passes refold the changed ones. Without the hierarchy both must
  // leave a fine pair alone with its coarse parent: a refresh that passed the parents capped the control variate of
  // a fine pair without samples by its parent's sample mean, which no pass did. A Beta prior of p0 that makes such
  // pairs nearly always visible (b0 100) gives them control variates.
  auto t = make_test_scene(false);
  for (bool naive : {false, true}) {
    sampler_params sp;
    sp.kind = sampler_kind::bayes;
    sp.bayes.hierarchy = 0;
    sp.bayes.b0 = 100;
    sp.bayes.prior = !naive;
    light_sampler ls = make_light_sampler(sp, t->in, t->tree);
    auto& s = std::get<bayes_sampler>(ls);
    learn_passes(t->in, s, 12);
    bayes_stats learned = s.stats;
    s.refresh_all_weights();
    size_t differ = 0, with_cv = 0, orphans = 0;
    for (size_t i = 0; i < s.stats.m.size(); i++) {
      differ += s.stats.w[i] != learned.w[i] || s.stats.w_cv[i] != learned.w_cv[i] || s.stats.cv[i] != learned.cv[i];
      with_cv += learned.cv[i] != 0;
      int up = s.regions.pair_parent[i];
      orphans += up != invalid_id && s.stats.m[i].n1 == 0 && s.stats.m[size_t(up)].n1 > 0;
    }
    INFO("naive " << naive << ": " << s.stats.m.size() << " pairs, " << with_cv << " with a control variate, "
                  << orphans << " fine ones without samples under a parent with some");
    CHECK(orphans > 0);  // (the case the refresh must not treat apart)
    CHECK(differ == 0);
  }
}

TEST_CASE("the automatic region budget is 32 pairs per pixel for bayes, within the default", "[samplers][bayes]") {
  for (int image : {16, 512}) {
    auto t = make_test_scene(false, image);
    t->in.max_depth = 1;  // direct: fine regions are refined into members (many pairs each)
    sampler_params sp;
    sp.regions.max_pairs = -1;
    sp.kind = sampler_kind::bayes;
    light_sampler lb = make_light_sampler(sp, t->in, t->tree);
    const region_state& r = std::get<bayes_sampler>(lb).regions;
    const int64_t want = std::min<int64_t>(region_params::default_pairs, 32 * int64_t(image) * image);
    CHECK(r.params.max_pairs == want);
    CHECK(r.pairs <= 2 * want + r.pair_count[size_t(r.root)]);  // fine pairs, coarse ones as many again, the root
    sp.kind = sampler_kind::bound;
    light_sampler lo = make_light_sampler(sp, t->in, t->tree);
    CHECK(std::get<bound_sampler>(lo).regions.params.max_pairs == region_params::default_pairs);
  }
}

TEST_CASE("bayes's automatic grid scales with the image below 320x240, the others keep 64, and --grid wins",
          "[samplers][regions]") {
  // 64 * sqrt(pixels / 76800), rounded, within [16, 64] (README).
  CHECK(region_params::auto_grid(320 * 240) == 64);
  CHECK(region_params::auto_grid(640 * 480) == 64);
  CHECK(region_params::auto_grid(160 * 120) == 32);
  CHECK(region_params::auto_grid(128 * 96) == 26);
  CHECK(region_params::auto_grid(80 * 60) == 16);
  CHECK(region_params::auto_grid(40 * 30) == 16);
  CHECK(region_params::auto_grid(1) == 16);
  CHECK(region_params::auto_grid(0) == 16);
  CHECK(region_params::auto_grid(319 * 240) == 64);  // 63.9 rounds up
  CHECK(region_params::auto_grid(300 * 225) == 60);
  sampler_params sp;
  sp.regions.grid = -1;  // the command line's default
  sp.kind = sampler_kind::bayes;
  CHECK(effective_region_params(sp, 1, 160 * 120).grid == 32);
  CHECK(effective_region_params(sp, 5, 1920 * 1080).grid == 64);
  for (sampler_kind k : {sampler_kind::bound, sampler_kind::bvh, sampler_kind::donikian}) {
    sp.kind = k;
    CHECK(effective_region_params(sp, 1, 160 * 120).grid == region_params::default_grid);
  }
  sp.kind = sampler_kind::bayes;
  sp.regions.grid = 48;  // --grid 48
  CHECK(effective_region_params(sp, 1, 160 * 120).grid == 48);
}

TEST_CASE("bayes statistics columns are not reallocated while passes add regions", "[samplers][bayes]") {
  // Regions for every cell a sample asks for (min_samples 1) and paths of 3 segments (deep vertices ask for coarse
  // cells): the pairs grow far past the set-up's, and no column may move (a move copies it whole: a pause of tenths of
  // a second per million pairs, and both copies at once in the peak memory).
  auto t = make_test_scene(false);
  sampler_params sp;
  sp.kind = sampler_kind::bayes;
  sp.regions.min_samples = 1;
  light_sampler ls = make_light_sampler(sp, t->in, t->tree);
  auto& s = std::get<bayes_sampler>(ls);
  const size_t pairs0 = s.stats.m.size(), entries0 = s.regions.cut_nodes.size();
  auto columns = [&s] {
    return std::array<const void*, 9>{s.stats.m.data(),          s.stats.mu0.data(),        s.stats.w.data(),
                                      s.stats.w_cv.data(),       s.stats.cv.data(),         s.stats.p1_folded.data(),
                                      s.regions.pair_node.data(), s.regions.pair_parent.data(),
                                      s.regions.cut_nodes.data()};
  };
  const auto before = columns();
  learn_passes(t->in, s, 6);
  INFO("pairs " << pairs0 << " -> " << s.stats.m.size() << ", cut entries " << entries0 << " -> "
                << s.regions.cut_nodes.size());
  REQUIRE(s.stats.m.size() > 2 * pairs0);  // far past half as many again (the reservation before)
  REQUIRE(s.regions.cut_nodes.size() > 2 * entries0);
  const auto after = columns();
  for (size_t i = 0; i < before.size(); i++) {
    INFO("column " << i);
    CHECK(after[i] == before[i]);
  }
}

TEST_CASE("a bayes cluster of several members weighs the sum of its members' weights after learning", "[samplers][bayes]") {
  // Small cuts with members: clusters of several members whose weights learn apart. After every pass the cluster
  // columns must hold exactly the in-order sums of their members' current weights (refold refreshes only the clusters
  // of refolded pairs), and a member's probability must be its cluster's times its share of the cluster's weight.
  // Where a cluster holds unseen members (bayes_params::unseen_cap) beside seen ones, an unseen member's weight counts
  // for at most the heaviest seen member's (w and w_cv apart).
  auto t = make_test_scene(true);
  light_sampler ls = make_light_sampler(params_variant(sampler_kind::bayes, 2), t->in, t->tree);
  auto& s = std::get<bayes_sampler>(ls);
  REQUIRE(s.regions.members);
  int grouped = 0, learned = 0, mixed = 0;
  for (int round = 0; round < 4; round++) {
    learn_passes(t->in, s, 2);
    const region_state& r = s.regions;
    for (size_t g = 0; g < r.key.size(); g++) {
      int b = r.pair_offset[g], n = r.pair_count[g], c = r.cut_size[g], o = r.cut_offset[g];
      for (int j = 0; j < c; j++) {
        int e = j + 1 < c ? r.member_begin[size_t(o + j + 1)] : n;
        float cap = 0, cap_cv = 0;
        int unseen = 0, seen = 0;
        for (int k = r.member_begin[size_t(o + j)]; k < e; k++) {
          size_t i = size_t(b + k);
          if (s.stats.unseen[i]) {
            unseen++;
          } else {
            seen++;
            cap = std::max(cap, s.stats.w[i]), cap_cv = std::max(cap_cv, s.stats.w_cv[i]);
          }
        }
        if (unseen == 0 || seen == 0) cap = cap_cv = HUGE_VALF;
        double w = 0, w_cv = 0, cv = 0;
        for (int k = r.member_begin[size_t(o + j)]; k < e; k++) {
          size_t i = size_t(b + k);
          REQUIRE(r.pair_slot[i] == o + j);
          const bool u = s.stats.unseen[i];
          const float mw = u ? std::min(s.stats.w[i], cap) : s.stats.w[i];
          const float mw_cv = u ? std::min(s.stats.w_cv[i], cap_cv) : s.stats.w_cv[i];
          CHECK(s.stats.mw[i] == mw);
          CHECK(s.stats.mw_cv[i] == mw_cv);
          w += mw, w_cv += mw_cv;
          cv += s.stats.cv[i];
          learned += s.stats.m[i].n0 + s.stats.m[i].n1 > 0;
        }
        grouped += e - r.member_begin[size_t(o + j)] > 1;
        mixed += unseen > 0 && seen > 0;
        INFO("region " << g << " cluster " << j);
        CHECK(s.stats.gunseen[size_t(o + j)] == (seen == 0 && unseen > 0));
        CHECK(s.stats.gw[size_t(o + j)] == float(w));
        CHECK(s.stats.gw_cv[size_t(o + j)] == float(w_cv));
        CHECK(s.stats.gcv[size_t(o + j)] == float(cv));
      }
    }
  }
  CHECK(grouped > 10);
  CHECK(learned > 100);
  CHECK(mixed > 0);
  // A member's probability at a point: its cluster's times its weight over the cluster's (no weight here is so small
  // that the floor applies).
  std::vector<shade_point> pts = shading_points(*t, 50, 7);
  auto ctx = std::make_unique<cut_context>();
  int checked = 0;
  for (const shade_point& sp : pts) {
    s.prepare(*ctx, sp);
    for (int i = 0; i < 200; i++) {
      light_choice c = s.sample(*ctx, (i + 0.5) / 200, 0.5);
      if (c.light == invalid_id || ctx->pair_count == ctx->count) continue;
      int j = s.group_of(*ctx, c.cluster);
      int e = j + 1 < ctx->count ? ctx->member_begin[j + 1] : ctx->pair_count;
      double total = 0;  // (the members' weights as capped inside the cluster)
      for (int k = ctx->member_begin[j]; k < e; k++) total += ctx->member_w[k];
      REQUIRE(ctx->member_w == (ctx->cv ? s.stats.mw_cv.data() : s.stats.mw.data()) + ctx->pair_base);
      CHECK(c.cluster_prob == Approx(cluster_pmf(*ctx, j) * ctx->member_w[c.cluster] / total).epsilon(1e-12));
      checked++;
    }
  }
  CHECK(checked > 1000);
}

// Regions of the budget tests: a 16-cell grid, clusters refined into at most 8 members.
static region_params small_region_params() {
  region_params rp;
  rp.grid = 16;
  rp.max_members = 8;
  return rp;
}

// The fine keys, sorted and distinct, of 400 shading points of t (seed 21).
static std::vector<uint64_t> reached_fine_keys(const test_scene& t, const region_grid_data& grid) {
  std::vector<uint64_t> keys;
  for (const shade_point& sp : shading_points(t, 400, 21)) keys.push_back(fine_region_key(grid, sp.p));
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  return keys;
}

// The test scene, small region parameters, a region state with no region yet and the fine keys its points reach.
struct budget_case {
  std::unique_ptr<test_scene> t = make_test_scene(false);
  region_params rp = small_region_params();
  region_state probe = make_region_state(t->scene.bounds, t->tree, false, rp);
  std::vector<uint64_t> keys = reached_fine_keys(*t, probe.grid);
  budget_case() { REQUIRE(keys.size() > 20); }
};

TEST_CASE("fine cells follow the shortest extent of a thin scene, and a thousandth of the longest only when flat",
          "[samplers][regions]") {
  // A room 3 high on a ground reaching 1e5 took a thousandth of the ground's side as its shortest extent: cells of
  // 1.56, a 4 x 4 room in a few of them, where bayes then had 2.4 times the relMSE of the same room on a ground of 1e3
  // (a review). Now its own height (3 / 64), within the cap of 2^20 cells along an axis.
  light_tree_data tree;
  region_params rp;
  region_state thin = make_region_state({{-5e4f, 0, -5e4f}, {5e4f, 3, 5e4f}}, tree, false, rp);
  CHECK(thin.grid.cell[0] == Approx(1e5 / double((1 << 20) - 1)).epsilon(1e-4));  // 3 / 64 capped by 2^20 cells
  region_state small = make_region_state({{-500, 0, -500}, {500, 3, 500}}, tree, false, rp);
  CHECK(small.grid.cell[0] == Approx(3.0 / 64).epsilon(1e-5));
  region_state flat = make_region_state({{-5e4f, 0, -5e4f}, {5e4f, 0, 5e4f}}, tree, false, rp);
  CHECK(flat.grid.cell[0] == Approx(1e5 * 1e-3 / 64).epsilon(1e-5));
  // A plane at y = 1000 whose corners' y differ by an ulp (6e-5) is flat too, not a scene 6e-5 thick.
  region_state jitter = make_region_state({{0, 1000, 0}, {10, 1000.00006f, 10}}, tree, false, rp);
  // (its thousandth, 1.6e-4, is below 4 ulps of 1000: cells are at least that, see the next test)
  CHECK(jitter.grid.cell[0] == Approx(4 * FLT_EPSILON * 1000.00006).epsilon(1e-4));
  region_state jitter_near = make_region_state({{0, 10, 0}, {10, 10.000001f, 10}}, tree, false, rp);
  CHECK(jitter_near.grid.cell[0] == Approx(10 * 1e-3 / 64).epsilon(1e-4));
}

TEST_CASE("region cells far from the origin span a few ulps at least, and their padded boxes hold their points",
          "[samplers][regions]") {
  // A scene 1 cm thick and 10 wide at x = 1e4 had cells of 1.6e-4, below an ulp of 1e4 (9.8e-4): boxes of zero size,
  // whose cluster bounds are infinite, and points outside their own box (a review).
  light_tree_data tree;
  region_params rp;
  const bbox3f bounds = {{1e4f, 0, 0}, {1e4f + 10, 0.01f, 10}};
  region_state s = make_region_state(bounds, tree, false, rp);
  CHECK(s.grid.cell[0] >= 4 * FLT_EPSILON * 1e4f);
  pcg32 rng(7, 1);
  int outside = 0, empty = 0;
  for (int k = 0; k < 10000; k++) {
    vec3f p = {1e4f + 10 * unif(rng), 0.01f * unif(rng), 10 * unif(rng)};
    bbox3f box = region_box(s.grid, fine_region_key(s.grid, p));
    empty += !(box.hi.x > box.lo.x && box.hi.y > box.lo.y && box.hi.z > box.lo.z);
    bbox3f b = padded(box);
    outside += !(p.x >= b.lo.x && p.x <= b.hi.x && p.y >= b.lo.y && p.y <= b.hi.y && p.z >= b.lo.z && p.z <= b.hi.z);
  }
  CHECK(empty == 0);
  CHECK(outside == 0);
  // Bounds whose extent overflows float (the loader refuses such meshes; in-memory ones must not convert NaN to int).
  region_state huge = make_region_state({{-3e38f, 0, 0}, {3e38f, 1, 1}}, tree, false, rp);
  for (int l = 0; l < 2; l++)
    for (int a = 0; a < 3; a++) CHECK((huge.grid.dims[l][a] >= 1 && huge.grid.dims[l][a] <= (1 << 20)));
}

TEST_CASE("fine regions over the pair budget are not created, and their keys are not tried again", "[samplers][regions]") {
  // The fine cells that shading points reach, requested at once under a pair budget that holds about half of what
  // they ask for: the regions that fit are created (coarse ones within their own allowance), the others are not, and
  // their keys stay out for good: their pairs are a function of the key and the pair count only grows, so a key
  // once over the budget would only have its cut computed again at every pass, to be turned down again.
  budget_case c;
  auto& [t, rp, probe, keys] = c;
  const int64_t base = probe.pairs;  // the root's
  add_regions(probe, t->tree, keys);
  int64_t wanted = probe.pairs - base;
  REQUIRE(probe.members);
  rp.max_pairs = base + wanted / 2;
  region_state s = make_region_state(t->scene.bounds, t->tree, false, rp);
  for (uint64_t key : keys) {
    REQUIRE(add_pending(s, key, uint32_t(rp.min_samples)));
    remove_pending(s, key);
  }
  int added = add_regions(s, t->tree, keys);
  int64_t fine_pairs = 0;
  for (size_t r = 0; r < s.key.size(); r++)
    if (r != size_t(s.root) && !is_coarse_key(s.key[r])) fine_pairs += s.pair_count[r];
  CHECK(fine_pairs <= rp.max_pairs);
  std::vector<uint64_t> refused;
  for (uint64_t key : keys)
    if (find_region_key(s, key) == invalid_id) refused.push_back(key);
  INFO(keys.size() << " fine keys, " << added << " regions added, " << refused.size() << " refused");
  REQUIRE(!refused.empty());
  REQUIRE(refused.size() < keys.size());
  for (uint64_t key : refused) {
    int r = find_region(s, key);
    CHECK(is_coarse_key(s.key[size_t(r)]));           // its coarse region serves it
    CHECK_FALSE(add_pending(s, key, 1u << 20));       // however many samples ask for it again
  }
  // Asked for anyway, they still create nothing (and no cut is computed for them); a key never refused is still
  // counted as before.
  int64_t cuts_before = s.cuts_computed;
  CHECK(add_regions(s, t->tree, refused) == 0);
  CHECK(s.cuts_computed == cuts_before);
  CHECK_FALSE(add_pending(s, ~uint64_t(0) >> 3, uint32_t(rp.min_samples - 1)));
  CHECK(add_pending(s, ~uint64_t(0) >> 3, 1));
}

TEST_CASE("once the pair budget is spent no cut is computed for the keys it turns down", "[samplers][regions]") {
  // A fine grid with --region-min-samples 1 asks for a new cell at nearly every NEE sample: every one had its cut and
  // members computed (and held, 1-12 KB each) before the budget was looked at: 2.8 GB and 285 s for a 64 x 48 image.
  budget_case c;
  auto& [t, rp, probe, keys] = c;
  std::vector<uint64_t> first(keys.begin(), keys.begin() + keys.size() / 2), rest(keys.begin() + keys.size() / 2,
                                                                                   keys.end());
  add_regions(probe, t->tree, first);
  // The budget: exactly what the first half took (their coarse regions stay within their own allowance).
  rp.max_pairs = probe.pairs;
  region_state s = make_region_state(t->scene.bounds, t->tree, false, rp);
  add_regions(s, t->tree, first);
  REQUIRE(s.pairs == rp.max_pairs);
  int64_t cuts_before = s.cuts_computed;
  std::vector<uint64_t> fine_new;  // keys of the second half whose coarse region exists already: fine cuts only
  for (uint64_t k : rest)
    if (find_region_key(s, parent_region_key(s.grid, k, 1)) != invalid_id && find_region_key(s, k) == invalid_id)
      fine_new.push_back(k);
  REQUIRE(!fine_new.empty());
  CHECK(add_regions(s, t->tree, fine_new) == 0);
  CHECK(s.cuts_computed == cuts_before);
  for (uint64_t k : fine_new) CHECK(find_region(s, k) == find_region_key(s, parent_region_key(s.grid, k, 1)));
}

TEST_CASE("coarse regions keep within the pair budget of their own, and the pending table within its limit",
          "[samplers][regions]") {
  // A fine grid's fine regions turned down by the budget each still brought a coarse region, with no limit (7.6 times
  // the budget at --grid 1024), and every cell a sample touched stayed in the pending table for good (35-40 bytes per
  // NEE sample at --grid 100000).
  auto t = make_test_scene(false);
  region_params rp = small_region_params();
  region_state probe = make_region_state(t->scene.bounds, t->tree, false, rp);
  std::vector<uint64_t> keys = reached_fine_keys(*t, probe.grid);
  const int64_t base = probe.pairs;  // the root's
  add_regions(probe, t->tree, keys);
  int64_t coarse_wanted = 0, coarse_regions = 0;
  for (size_t r = 0; r < probe.key.size(); r++)
    if (is_coarse_key(probe.key[r])) coarse_wanted += probe.pair_count[r], coarse_regions++;
  REQUIRE(coarse_regions >= 3);
  // A budget that holds no fine region beside the root, and about half the coarse ones' pairs.
  rp.max_pairs = base + coarse_wanted / 2;
  region_state s = make_region_state(t->scene.bounds, t->tree, false, rp);
  add_regions(s, t->tree, keys);
  int64_t coarse_pairs = 0;
  for (size_t r = 0; r < s.key.size(); r++)
    if (is_coarse_key(s.key[r])) coarse_pairs += s.pair_count[r];
  CHECK(coarse_pairs > 0);
  CHECK(coarse_pairs <= rp.max_pairs);
  std::vector<uint64_t> rooted;  // fine keys whose coarse region was turned down: the root serves them, for good
  for (uint64_t key : keys)
    if (find_region(s, key) == s.root) rooted.push_back(key);
  REQUIRE(!rooted.empty());
  for (uint64_t key : rooted) CHECK_FALSE(add_pending(s, key, 1u << 20));
  // Cells that never gather min_samples requests: the table forgets their counts at its limit (2^20 keys here),
  // keeping the marks of keys over the budget.
  for (uint64_t i = 0; i < 1'300'000; i++) add_pending(s, (uint64_t(1) << 40) + i * 7919, 1);
  CHECK(s.pending_count <= size_t(1) << 20);
  CHECK(s.pending.size() <= size_t(1) << 21);
  for (uint64_t key : rooted) CHECK_FALSE(add_pending(s, key, 1u << 20));
}

TEST_CASE("under a cut shared by every region the bound sampler keeps the root alone and chooses as before",
          "[samplers][regions]") {
  // A handful of lights (here up to 64 by option): every region's cut is cut 0, so regions cannot change what the
  // bound sampler (which reads only cuts) chooses. It used to create a region for every cell its points reached and
  // look the cell up at every vertex (20249 regions, 4.4 MB in the Cornell box at 640 x 480) for nothing.
  auto t = make_test_scene(true);
  sampler_params sp;
  sp.kind = sampler_kind::bound;
  sp.regions.shared_cut_lights = 64;
  light_sampler ls = make_light_sampler(sp, t->in, t->tree);
  bound_sampler& b = std::get<bound_sampler>(ls);
  REQUIRE(b.regions.shared_cut);
  CHECK(b.regions.key.size() == 1);
  // Recording and learning create nothing.
  std::vector<shade_point> pts = shading_points(*t, 200, 5);
  std::vector<bound_sampler::row_state> rows(1);
  auto ctx = std::make_unique<cut_context>();
  for (const shade_point& p : pts) {
    b.prepare(*ctx, p);
    light_choice c = b.sample(*ctx, 0.5, 0.5);
    b.record(rows[0], nee_event<cut_context>{ctx.get(), c, 1.0f, 0, 1.0f, 1.0f});
  }
  b.learn(rows);
  CHECK(b.regions.key.size() == 1);
  // The regions it no longer creates held the same cut: a point finds the same clusters through them (so the images
  // are the same: the goldens of bound and donikian in the Cornell box, 8 lights, a shared cut, did not change).
  region_state seeded = b.regions;
  add_regions(seeded, t->tree, reached_fine_keys(*t, seeded.grid));
  REQUIRE(seeded.key.size() > 20);
  auto via_cell = std::make_unique<cut_context>();
  int differ = 0;
  for (const shade_point& p : pts) {
    locate_region(*ctx, b.regions, p, true);
    locate_region(*via_cell, seeded, p, false);
    if (ctx->count != via_cell->count || !std::equal(ctx->nodes, ctx->nodes + ctx->count, via_cell->nodes)) differ++;
  }
  CHECK(differ == 0);
}

TEST_CASE("a point whose fine cell has no region uses its coarse cell's region, else the root", "[samplers][regions]") {
  // The fallback only costs variance when wrong (a mutation sending such points to the root passed every test but the
  // goldens): checked on the region a point locates.
  auto t = make_test_scene(true);
  sampler_params sp;
  sp.kind = sampler_kind::bound;
  sp.regions.shared_cut_lights = 0;
  light_sampler ls = make_light_sampler(sp, t->in, t->tree);
  region_state s = std::get<bound_sampler>(ls).regions;
  REQUIRE_FALSE(s.shared_cut);
  const std::vector<shade_point> pts = shading_points(*t, 400, 5);
  const shade_point& p = pts[0];
  const uint64_t k = fine_region_key(s.grid, p.p), coarse = parent_region_key(s.grid, k, 1);
  REQUIRE(add_regions(s, t->tree, {k}) == 2);  // its coarse parent, then itself
  // A point one fine cell away inside the same coarse cell, and a point of another coarse cell.
  std::optional<shade_point> same_coarse, other_coarse;
  const float c = s.grid.cell[0];
  for (vec3f step : {vec3f{c, 0, 0}, vec3f{-c, 0, 0}, vec3f{0, 0, c}, vec3f{0, 0, -c}, vec3f{0, c, 0}, vec3f{0, -c, 0}}) {
    shade_point q = p;
    q.p = p.p + step;
    uint64_t qk = fine_region_key(s.grid, q.p);
    if (qk != k && parent_region_key(s.grid, qk, 1) == coarse && !same_coarse) same_coarse = q;
  }
  for (const shade_point& q : pts)
    if (parent_region_key(s.grid, fine_region_key(s.grid, q.p), 1) != coarse && !other_coarse) other_coarse = q;
  REQUIRE(same_coarse);
  REQUIRE(other_coarse);
  const uint64_t root = s.key[size_t(s.root)];
  REQUIRE(coarse != root);
  auto at = [&](shade_point q, int depth) {
    auto ctx = std::make_unique<cut_context>();
    q.depth = depth;
    locate_region(*ctx, s, q, false);
    return ctx->region_key;
  };
  for (int depth : {1, s.params.fine_depth + 1}) {
    INFO("depth " << depth);
    const bool fine = depth <= s.params.fine_depth;
    CHECK(at(p, depth) == (fine ? k : coarse));
    CHECK(at(*same_coarse, depth) == coarse);
    CHECK(at(*other_coarse, depth) == root);
  }
}

TEST_CASE("a first hit whose pixel footprint outgrows its fine cell uses the coarse region, under bayes only",
          "[samplers][regions]") {
  auto t = make_test_scene(true, 320);  // (from 320 x 240 pixels up: region_params::footprint_pixels)
  sampler_params sp;
  sp.kind = sampler_kind::bound;
  sp.regions.shared_cut_lights = 0;
  light_sampler ls = make_light_sampler(sp, t->in, t->tree);
  region_state s = std::get<bound_sampler>(ls).regions;
  CHECK(s.params.min_pixels == 0);  // bound: finer regions only sharpen its cuts
  const shade_point p = shading_points(*t, 1, 5)[0];
  const uint64_t k = fine_region_key(s.grid, p.p), coarse = parent_region_key(s.grid, k, 1);
  add_regions(s, t->tree, {k});
  REQUIRE(find_region_key(s, k) != invalid_id);
  REQUIRE(find_region_key(s, coarse) != invalid_id);
  s.params.min_pixels = 0.125f;
  // The threshold: a cell side^2 of min_pixels footprints^2.
  const float edge = s.grid.cell[0] / std::sqrt(s.params.min_pixels);
  auto at = [&](float footprint, bool cut_only, int depth = 1) {
    auto ctx = std::make_unique<cut_context>();
    shade_point q = p;
    q.footprint = footprint;
    q.depth = depth;
    locate_region(*ctx, s, q, cut_only);
    return ctx->region_key;
  };
  CHECK(at(0, false) == k);
  CHECK(at(0.98f * edge, false) == k);
  CHECK(at(1.02f * edge, false) == coarse);
  CHECK(at(1.02f * edge, true) == k);  // a sampler that reads only cuts keeps the fine cell
  s.params.min_pixels = 0;
  CHECK(at(1e6f * edge, false) == k);  // off
  CHECK(footprint_too_large(region_params{}, s.grid, 1.02f * edge));
  CHECK_FALSE(footprint_too_large(region_params{}, s.grid, 0.98f * edge));

  // The footprint: distance x the pixel's angle (2 tan(fov/2) / height) over sqrt(cos).
  const camera_data& cam = t->in.camera;
  const float pixel = 2 * std::tan(0.5f * 50 * pi_f / 180) / float(cam.height);
  CHECK(pixel_footprint(cam, 3, 1) == Approx(3 * pixel).epsilon(1e-5));
  CHECK(pixel_footprint(cam, 3, 0.25f) == Approx(6 * pixel).epsilon(1e-5));
  CHECK(std::isfinite(pixel_footprint(cam, 3, 0)));  // grazing: cos clamped

  // bayes's regions before the first pass: the cells camera rays reach, fine ones only where the footprint allows.
  auto fine_regions = [&](float min_pixels) {
    sampler_params b;
    b.kind = sampler_kind::bayes;
    b.regions.min_pixels = min_pixels;
    light_sampler lb = make_light_sampler(b, t->in, t->tree);
    const region_state& r = std::get<bayes_sampler>(lb).regions;
    CHECK(r.params.min_pixels == min_pixels);
    int fine = 0;
    for (size_t i = 0; i < r.key.size(); i++) fine += int(i) != r.root && !is_coarse_key(r.key[i]);
    return fine;
  };
  CHECK(fine_regions(0) > 0);
  CHECK(fine_regions(1e6f) == 0);
  // Below 320 x 240 pixels the automatic grid sizes the cells to the image instead: the rule is off.
  sampler_params small;
  small.kind = sampler_kind::bayes;
  CHECK(effective_region_params(small, 1, 320 * 240).min_pixels == region_params{}.min_pixels);
  CHECK(effective_region_params(small, 1, 320 * 240 - 1).min_pixels == 0);
}

TEST_CASE("a scene without any light gives empty light selections", "[samplers]") {
  mesh_builder b;
  int floor = b.add_material({0.5f, 0.5f, 0.5f});
  b.add_quad({-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, floor);
  camera_params cam;
  cam.automatic = false;
  cam.eye = {0, 2, 2};
  cam.target = {0, 0, 0};
  scene_data scene = build_scene(std::move(b.mesh), cam, sun_params{}, false, 1.0f);
  bvh_data bvh = build_bvh(scene);
  light_data lights = build_lights(scene);
  light_tree_data tree = build_light_tree(lights, scene);
  render_inputs in;
  in.scene = &scene;
  in.bvh = &bvh;
  in.lights = &lights;
  in.camera = make_camera(scene.camera, 4, 4);
  for (sampler_kind kind : all_kinds) {
    if (!sampler_available(kind)) continue;
    INFO("sampler " << sampler_name(kind));
    sampler_params p;
    p.kind = kind;
    light_sampler ls = make_light_sampler(p, in, tree);
    std::visit(
        [&](const auto& s) {
          auto ctx = std::make_unique<typename std::decay_t<decltype(s)>::context>();
          s.prepare(*ctx, shade_point{{0, 0, 0}, {0, 1, 0}, 0.5f, 0, 1});
          light_choice c = s.sample(*ctx, 0.5f, 0.5f);
          CHECK(c.light == invalid_id);
          CHECK(c.prob == 0);
        },
        ls);
  }
}


TEST_CASE("a light with a tiny share of the selection weight keeps a non zero pmf", "[samplers]") {
  // Two bright lamps and five dim ones (radiance ratio 1e8), all facing the same floor point from similar
  // distances. Every lamp can contribute, so every sampler must give every lamp pmf > 0 (unbiasedness), however
  // small its share: a share below the float resolution of a cdf or of 1 - p must not round to exactly 0.
  mesh_builder b;
  int floor = b.add_material({0.5f, 0.5f, 0.5f});
  int bright = b.add_material({0, 0, 0}, {1e7f, 1e7f, 1e7f});
  int dim = b.add_material({0, 0, 0}, {0.1f, 0.1f, 0.1f});
  b.add_quad({-10, 0, -10}, {-10, 0, 10}, {10, 0, 10}, {10, 0, -10}, floor);
  auto lamp = [&](float x, float z, int m) {  // a 0.2 x 0.2 quad at height 2 facing down
    b.add_quad({x, 2, z}, {x + 0.2f, 2, z}, {x + 0.2f, 2, z + 0.2f}, {x, 2, z + 0.2f}, m);
  };
  lamp(-3, 0, dim);
  lamp(-1.5f, 0, dim);
  lamp(0, 0, bright);
  lamp(1.5f, 0, dim);
  lamp(3, 0, dim);
  lamp(0, 1.5f, dim);
  lamp(0, -1.5f, bright);
  auto t = build_test_scene(std::move(b.mesh), fixed_camera({0, 5, 5}, {0, 0, 0}));
  std::vector<shade_point> pts;
  for (float x : {-1.0f, 0.0f, 0.7f})
    for (float z : {-0.5f, 0.3f}) pts.push_back(shade_point{{x, 0, z}, {0, 1, 0}, 0.5f, 0, 1});
  for (sampler_kind kind : all_kinds) {
    if (!sampler_available(kind)) continue;
    INFO("sampler " << sampler_name(kind));
    sampler_params p;
    p.kind = kind;
    light_sampler ls = make_light_sampler(p, t->in, t->tree);
    std::visit(
        [&](const auto& s) {
          auto ctx = std::make_unique<typename std::decay_t<decltype(s)>::context>();
          int starved = 0;
          std::string which;
          for (const shade_point& sp : pts) {
            s.prepare(*ctx, sp);
            for (int l = 0; l < t->lights.count; l++) {
              REQUIRE(can_contribute(*t, l, sp.p, sp.n));
              if (!(s.pmf(*ctx, l) > 0)) {
                starved++;
                which += " " + std::to_string(l);
              }
            }
          }
          INFO("lights with pmf 0 (over " << pts.size() << " points):" << which);
          CHECK(starved == 0);
        },
        ls);
  }
}
