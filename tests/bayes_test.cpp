// Tests of the Bayesian statistics and sampler (METHOD.md sections 3-5): the reference posterior against the
// conjugate Normal-inverse-gamma / Beta update written out independently here, the fast coefficient form against
// the reference, prior-only weights proportional to the bound, order-independent merging (Chan vs one pass),
// convergence of a learned PMF to sqrt((1 - p0)(k^2 + h)) / d^2 with a tolerance derived from the estimator's
// standard deviation, and the ablations (mean only, no prior, no distance regression).
#include <catch2/catch.hpp>

#include <cstring>
#include <memory>
#include <optional>

#include "bayes_sampler.h"
#include "bayes_stats.h"
#include "bound_sampler.h"
#include "bvh.h"
#include "integrator.h"
#include "light_sampler.h"
#include "rng.h"
#include "scene.h"
#include "scene_fixture.h"
#include "test_util.h"

using namespace bl;
using namespace bl::test;

namespace {

// A parentless pair's coefficients with its p1 folded in: what a point-prior shading point evaluates (region-prior
// mode, the default, folds them further into `w` and keeps no such column).
pair_weight weight_of(const bayes_stats& s, size_t i, const bayes_params& p) {
  return folded_coeffs(s, i, own_p1(s, i, p), p);
}

// Uniform in [0, 1) with 53 random bits, and log-uniform in [lo, hi), in double precision.
double unif64(pcg32& r) {
  return (double(r() >> 5) * 67108864.0 + double(r() >> 6)) * (1.0 / 9007199254740992.0);
}
double log_uniform64(pcg32& r, double lo, double hi) {
  return lo * std::pow(hi / lo, unif64(r));
}
// Standard normal (Box-Muller).
double normal(pcg32& r) {
  double u1 = 1 - unif64(r), u2 = unif64(r);
  return std::sqrt(-2 * std::log(u1)) * std::cos(2 * M_PI * u2);
}

// Counts of zero and non-zero samples y, and the sums of z = y d^2 and z^2 over the non-zero ones (long double).
struct sums {
  long double n0 = 0, n1 = 0, s1 = 0, s2 = 0;
};
sums raw_sums(const std::vector<double>& y, long double d2) {
  sums r;
  for (double v : y) {
    if (v == 0) {
      r.n0 += 1;
      continue;
    }
    long double z = v * d2;
    r.n1 += 1;
    r.s1 += z;
    r.s2 += z * z;
  }
  return r;
}

// The conjugate posterior written out from METHOD.md section 4 with raw sums (long double), independent of
// bayes_stats.cpp: returns sqrt((1 - p0)(k^2 + h)) / d^2 with point estimates k = mu_n, h = beta_n / (alpha_n - 1),
// 1 - p0 the posterior mean of the non-zero probability; or the mean-only ablation (1 - p0) mu_n / d^2.
long double hand_posterior(const bayes_params& p, double bound, double scale, double d, const std::vector<double>& y,
                           bool second_moment = true) {
  long double d2 = (long double)d * d;
  long double mu0 = (long double)scale * bound * d2;
  auto [n0, n1, s1, s2] = raw_sums(y, d2);
  long double one_minus_p0 = (p.b0 + n1) / (p.a0 + p.b0 + n0 + n1);  // Beta(a0 + n0, b0 + n1): mean of 1 - p0
  long double kn = p.kappa0 + n1;
  long double mun = (p.kappa0 * mu0 + s1) / kn;
  if (!second_moment) return one_minus_p0 * mun / d2;
  long double an = p.alpha0 + n1 / 2;
  long double beta0 = p.c * mu0 * mu0 * (p.alpha0 - 1);
  long double bn = beta0 + 0.5L * (s2 + p.kappa0 * mu0 * mu0 - kn * mun * mun);
  long double h = bn / (an - 1);
  return std::sqrt(one_minus_p0 * (mun * mun + h)) / d2;
}

// The naive plug-in ablation written out: p0 = n0 / n, k = mean z, h = population variance of z; no samples:
// the bound itself.
long double hand_naive(double bound, double scale, double d, const std::vector<double>& y, bool second_moment) {
  long double d2 = (long double)d * d;
  auto [n0, n1, s1, s2] = raw_sums(y, d2);
  if (n0 + n1 == 0) return (long double)scale * bound;
  long double p1 = n1 / (n0 + n1);
  if (n1 == 0) return 0;
  long double k = s1 / n1, h = s2 / n1 - k * k;
  if (!second_moment) return p1 * k / d2;
  return std::sqrt(p1 * (k * k + h)) / d2;
}

// Count, mean and sum of squared deviations of the non-zero z = y d^2 (two-pass, long double).
struct moments {
  double n0 = 0, n1 = 0, mean = 0, m2 = 0;
};
moments exact_moments(const std::vector<double>& z) {
  moments m;
  long double s = 0;
  for (double v : z) {
    if (v == 0)
      m.n0 += 1;
    else
      m.n1 += 1, s += v;
  }
  long double mean = m.n1 > 0 ? s / m.n1 : 0, ss = 0;
  for (double v : z)
    if (v != 0) ss += (v - mean) * (v - mean);
  m.mean = double(mean);
  m.m2 = double(ss);
  return m;
}

double rel_err(double a, double b) {
  return std::fabs(a - b) / std::max(std::fabs(b), 1e-300);
}

// Parameter sets: the defaults, and a different prior.
std::vector<bayes_params> param_sets() {
  bayes_params a;
  bayes_params b;
  b.a0 = 2;
  b.b0 = 2;
  b.kappa0 = 3;
  b.alpha0 = 1.5;
  b.c = 0.5;
  return {a, b};
}

// Synthetic observations Y: zeros with probability p0, else |N(k, h)| / d^2 (non-negative, as real samples are).
std::vector<double> synthetic(pcg32& r, int n, double p0, double k, double h, double d) {
  std::vector<double> y;
  for (int i = 0; i < n; i++) {
    if (unif64(r) < p0)
      y.push_back(0);
    else
      y.push_back(std::fabs(k + std::sqrt(h) * normal(r)) / (d * d));
  }
  return y;
}

// A floor lit by `lamps` small lamps of different radiance and height (plus a sun), and everything a sampler needs.
std::unique_ptr<test_scene> make_scene(int lamps, bool sun) {
  mesh_builder b;
  int floor = b.add_material({0.5f, 0.5f, 0.5f});
  b.add_quad({-10, 0, -10}, {-10, 0, 10}, {10, 0, 10}, {10, 0, -10}, floor);
  for (int i = 0; i < lamps; i++) {
    float le = std::pow(10.0f, float(i % 5) - 2);
    int m = b.add_material({0, 0, 0}, {le, le, le});
    float x = -6 + 12 * float(i) / float(std::max(1, lamps - 1)), y = 1 + float(i % 3), z = float(i % 4) - 1.5f;
    b.add_quad({x, y, z}, {x + 0.3f, y, z}, {x + 0.3f, y, z + 0.3f}, {x, y, z + 0.3f}, m);
  }
  auto t = build_test_scene(std::move(b.mesh), fixed_camera({0, 8, 8}, {0, 0, 0}, 60),
                             sun ? test_sun({-0.4f, 1, 0.3f}, {2, 2, 2}) : sun_params{});
  t->in.max_depth = 1;
  return t;
}

// First hit of the centre ray of pixel (x, y): a point whose fine region exists from the start.
shade_point pixel_point(const test_scene& t, int x, int y) {
  vec3f dir = camera_ray_dir(t.in.camera, float(x) + 0.5f, float(y) + 0.5f);
  hit_info h = intersect(t.bvh, t.in.camera.eye, dir);
  REQUIRE(h.tri != invalid_id);
  surface_point sp = eval_surface(t.scene, h.tri, h.b1, h.b2, h.p, dir);
  return shade_point{sp.p, sp.ng, 0.5f, y * t.in.camera.width + x, 1};
}

// A bayes sampler over make_scene(3, sun) whose cuts are the 3 lamps (3 clusters, not a shared cut of 6 leaves,
// and not refined into members: each cluster is one pair, whose posterior the tests below follow), then the sun if
// `sun`, with bayes parameters `bp`, and a context prepared at pixel (4, 4) whose cut is those clusters. The point is a
// path's first vertex, not its last: its NEE is MIS-weighted and, unless bp.cv_every_vertex (the default rule; the
// control-variate tests set it), has no control variates, so that the learning tests check the plain pmf.
struct three_lamps {
  std::unique_ptr<test_scene> t;
  std::optional<light_sampler> ls;
  shade_point pt;
  std::unique_ptr<cut_context> ctx;
  bayes_sampler& sampler() { return std::get<bayes_sampler>(*ls); }
};
three_lamps make_three_lamps(const bayes_params& bp, bool sun = false, bool cv_every_vertex = false) {
  three_lamps f;
  f.t = make_scene(3, sun);
  sampler_params sp;
  sp.kind = sampler_kind::bayes;
  sp.regions.shared_cut_lights = 0;
  sp.regions.max_members = 0;
  sp.bayes = bp;
  sp.bayes.cv_every_vertex = cv_every_vertex;
  f.ls.emplace(make_light_sampler(sp, f.t->in, f.t->tree));
  f.pt = pixel_point(*f.t, 4, 4);
  f.ctx = std::make_unique<cut_context>();
  f.sampler().prepare(*f.ctx, f.pt);
  REQUIRE(f.ctx->count == (sun ? 4 : 3));
  if (sun) REQUIRE(f.ctx->nodes[3] == sun_cluster);
  return f;
}

// The prior of cluster j of a prepared context at pt in the sampler's mode, as the arguments of posterior_weight:
// the weight is posterior_weight(p, bound, scale, d, ...) with mu0 = scale * bound * d^2 the prior mean of z. Point
// prior: the bound at the point and scale = albedo / pi (z = Y d^2). Region prior: bound = mu0_j g_j of the pair and
// scale = 1 (z = (Y / (albedo / pi)) d^2). `prior_weight` is the prior-only weight the sampler mixes and falls back
// to (the bound, or mu0 g), and `y_per_z` turns a z into the sample Y that records it.
// The receiver orientation factor of cluster `node` at (p, n) in the region-prior mode (1 when the orientation
// switch is off): (r - n.(p - c)) / |p - c| clamped to [1e-3, 1] for a tree node, the receiver cosine bound
// toward the sun disk for the sun, computed here in double.
double orientation_of(const test_scene& t, const bayes_sampler& s, int node, vec3f p, vec3f n) {
  if (!s.params.region_prior || !s.params.orientation) return 1;
  double o;
  if (node == sun_cluster) {
    o = receiver_cos_bound(n, t.lights.sun_dir, s.sun_sin, s.sun_cos);
  } else {
    vec3f c = node_center(t.tree, node);
    double r = node_radius(t.tree, node);
    double dn = double(n.x) * (p.x - c.x) + double(n.y) * (p.y - c.y) + double(n.z) * (p.z - c.z);
    o = (r - dn) / std::sqrt(double(length_sq(p - c)));
  }
  return std::min(1.0, std::max(o, 1e-3));
}

// o: the orientation factor; the sample Y records z = Y d^2 / o (z = Y / o without the regression).
struct prior_args {
  double bound, scale, d, prior_weight, y_per_z, o;
};
prior_args prior_of(const test_scene& t, const bayes_sampler& s, const cut_context& ctx, int j, const shade_point& pt) {
  prior_args a;
  double point_scale = pt.albedo * inv_pi_f;
  a.d = cluster_distance(t.tree, ctx.nodes[j], pt.p);
  a.o = orientation_of(t, s, ctx.nodes[j], pt.p, pt.n);
  if (s.params.region_prior) {
    // Without the regression the sampler's weight is W o (no g), and mu0 is a mean of Y / (albedo / pi) / o.
    double g = 1 / (a.d * a.d);
    a.bound = double(s.stats.mu0[size_t(ctx.pair_base + j)]) * (s.params.distance_regression ? g : 1.0) * a.o;
    a.scale = 1;
    a.prior_weight = a.bound;
    a.y_per_z = point_scale * g * a.o;
  } else {
    float inv_d2;
    float num = cluster_bound_parts(t.tree, t.lights, ctx.nodes[j], pt.p, pt.n, 0, 1, inv_d2);
    a.bound = double(num) * inv_d2;
    a.scale = point_scale;
    a.prior_weight = a.bound;
    a.y_per_z = 1 / (a.d * a.d);
  }
  return a;
}

}  // namespace

TEST_CASE("the reference posterior weight is the conjugate Normal inverse gamma and Beta posterior", "[bayes]") {
  pcg32 rng(31, 1);
  struct data_case {
    int n;
    double p0, k, h, d;
  };
  const data_case cases[] = {{0, 0, 1, 1, 1},        {5, 1.0, 1, 1, 2},      {1, 0, 3, 1, 0.5},
                             {7, 0.3, 0.5, 0.1, 2},  {200, 0.5, 10, 4, 0.1}, {1000, 0.05, 2e-4, 1e-9, 30},
                             {50, 0.9, 5e5, 1e10, 1}};
  for (const bayes_params& p : param_sets())
    for (const data_case& dc : cases) {
      std::vector<double> y = synthetic(rng, dc.n, dc.p0, dc.k, dc.h, dc.d);
      std::vector<double> z;
      for (double v : y) z.push_back(v * dc.d * dc.d);
      moments m = exact_moments(z);
      for (double bound : {1e-3, 0.7, 40.0}) {
        double scale = 0.15;
        INFO("n " << dc.n << " p0 " << dc.p0 << " d " << dc.d << " bound " << bound << " alpha0 " << p.alpha0);
        double w = posterior_weight(p, bound, scale, dc.d, m.n0, m.n1, m.mean, m.m2);
        long double ref = hand_posterior(p, bound, scale, dc.d, y);
        CHECK(rel_err(w, double(ref)) < 1e-9);
        bayes_params mo = p;
        mo.second_moment = false;
        CHECK(rel_err(posterior_weight(mo, bound, scale, dc.d, m.n0, m.n1, m.mean, m.m2),
                      double(hand_posterior(p, bound, scale, dc.d, y, false))) < 1e-9);
        // No prior: the naive plug-in moments.
        bayes_params np = p;
        np.prior = false;
        double naive = posterior_weight(np, bound, scale, dc.d, m.n0, m.n1, m.mean, m.m2);
        long double naive_ref = hand_naive(bound, scale, dc.d, y, true);
        if (naive_ref == 0)
          CHECK(naive == 0);
        else
          CHECK(rel_err(naive, double(naive_ref)) < 1e-9);
        np.second_moment = false;
        double naive_mean = posterior_weight(np, bound, scale, dc.d, m.n0, m.n1, m.mean, m.m2);
        long double naive_mean_ref = hand_naive(bound, scale, dc.d, y, false);
        if (naive_mean_ref == 0)
          CHECK(naive_mean == 0);
        else
          CHECK(rel_err(naive_mean, double(naive_mean_ref)) < 1e-9);
        // With the prior, every cluster with a non-zero bound keeps a finite positive weight.
        CHECK(std::isfinite(w));
        CHECK(w > 0);
      }
      CHECK(posterior_weight(p, 0.0, 0.15, dc.d, m.n0, m.n1, m.mean, m.m2) == 0);
    }
}

TEST_CASE("a pair's control-variate posterior is the Normal inverse gamma update of its samples", "[bayes]") {
  // pair_posterior's k (posterior mean of z) and h (posterior expected variance, beta_n / (alpha_n - 1)) feed the
  // control variates; the test of those takes them from pair_posterior itself, so they are checked here against the
  // conjugate update computed from the raw samples (a mutation alpha_n = alpha0 + n1 went unnoticed but for goldens).
  bayes_params p;
  p.kappa0 = 1, p.alpha0 = 2, p.c = 0.3;
  bayes_stats s;
  resize_stats(s, 1, p);
  s.m[0] = {0, 4, 2, 3};  // four non-zero samples of mean 2 and squared deviations summing to 3
  double k = 0, h = 0;
  REQUIRE(pair_posterior(s, 0, p, 1.0, k, h));
  // kappa_n = 5, k = (1 + 8) / 5; alpha_n = 2 + 2; beta_n = 0.3 (2 - 1) + (3 + 4 (2 - 1)^2 / 5) / 2 = 2.2.
  CHECK(k == Approx(1.8).epsilon(1e-12));
  CHECK(h == Approx(2.2 / 3).epsilon(1e-12));
  bayes_params naive = p;
  naive.prior = false;
  REQUIRE(pair_posterior(s, 0, naive, 1.0, k, h));
  CHECK(k == 2);
  CHECK(h == Approx(0.75).epsilon(1e-12));
  // Random samples, other priors: from the samples themselves, in long double.
  pcg32 rng(41, 3);
  for (int trial = 0; trial < 50; trial++) {
    bayes_params q;
    q.kappa0 = 0.1 + 4 * unif64(rng), q.alpha0 = 1.5 + 3 * unif64(rng);
    q.c = 0.05 + unif64(rng);
    const int n = 1 + int(40 * unif64(rng));
    const double mu0 = 0.01 + 10 * unif64(rng);
    std::vector<double> z;
    for (int i = 0; i < n; i++) z.push_back(mu0 * (0.2 + 3 * unif64(rng)));
    moments m = exact_moments(z);
    s.m[0] = {0, m.n1, m.mean, m.m2};
    REQUIRE(pair_posterior(s, 0, q, mu0, k, h));
    long double sum = 0, kn = q.kappa0 + n;
    for (double v : z) sum += v;
    long double mean = sum / n, ss = 0;
    for (double v : z) ss += (v - mean) * (v - mean);
    long double beta = q.c * mu0 * mu0 * (q.alpha0 - 1) + ss / 2 + q.kappa0 * n * (mean - mu0) * (mean - mu0) / (2 * kn);
    INFO("trial " << trial << " n " << n);
    CHECK(rel_err(k, double((q.kappa0 * mu0 + sum) / kn)) < 1e-12);
    CHECK(rel_err(h, double(beta / (q.alpha0 + n / 2.0L - 1))) < 1e-12);
  }
}

TEST_CASE("fast coefficient weights agree with the reference posterior", "[bayes]") {
  // Random statistics over many orders of magnitude, merged through rows; eval_weight (float coefficients)
  // must agree with posterior_weight (double) to 1e-5 relative for random v = scale * bound and g = 1 / d^2.
  pcg32 rng(37, 2);
  std::vector<bayes_params> sets = param_sets();
  bayes_params mo;
  mo.second_moment = false;
  bayes_params np;
  np.prior = false;
  bayes_params npm = np;
  npm.second_moment = false;
  sets.push_back(mo);
  sets.push_back(np);
  sets.push_back(npm);
  for (const bayes_params& p : sets) {
    const int pairs = 300;
    bayes_stats s;
    resize_stats(s, pairs, p);
    std::vector<bayes_row> rows(3);
    for (int i = 0; i < pairs; i++) {
      int n = i % 10 == 0 ? 0 : int(log_uniform64(rng, 1, 3000));
      double p0 = unif64(rng), zs = log_uniform64(rng, 1e-12, 1e12), cv = log_uniform64(rng, 1e-3, 3);
      for (int k = 0; k < n; k++) {
        double z = unif64(rng) < p0 ? 0.0 : zs * std::fabs(1 + cv * normal(rng));
        rows[size_t(rng(3))].add(i, z);
      }
    }
    merge_rows(s, rows, nullptr);
    // Clusters a region nearly never sees lit (p0 -> 1): E[1 - p0] of 1e-15 and less, which 1 - p0 formed from p0
    // would cancel (the reference did, 2x off at n0 = 1e15).
    for (int i = 5; i < pairs; i += 25) s.m[size_t(i)].n0 = i % 2 ? 1e15 : 1e13;
    refresh_weights(s, nullptr, p, nullptr);
    int worst_pair = -1;
    double worst = 0;
    for (int i = 0; i < pairs; i++)
      for (int k = 0; k < 20; k++) {
        double bound = log_uniform64(rng, 1e-8, 1e8), scale = log_uniform64(rng, 0.01, 1), d = log_uniform64(rng, 1e-3, 1e3);
        double v = scale * bound, g = 1 / (d * d);
        double fast = eval_weight(weight_of(s, size_t(i), p), p, v, g);
        double ref =
            posterior_weight(p, bound, scale, d, s.m[size_t(i)].n0, s.m[size_t(i)].n1, s.m[size_t(i)].mean, s.m[size_t(i)].m2);
        double e = ref == 0 ? std::fabs(fast) : rel_err(fast, ref);
        if (e > worst) worst = e, worst_pair = i;
      }
    INFO("prior " << p.prior << " second moment " << p.second_moment << " alpha0 " << p.alpha0 << ": worst pair "
                  << worst_pair << " n0 " << s.m[size_t(worst_pair)].n0 << " n1 " << s.m[size_t(worst_pair)].n1 << " mean "
                  << s.m[size_t(worst_pair)].mean << " m2 " << s.m[size_t(worst_pair)].m2);
    CHECK(worst < 1e-5);
  }
}

TEST_CASE("prior only weights are proportional to the bound", "[bayes]") {
  for (const bayes_params& p : param_sets()) {
    bayes_stats s;
    resize_stats(s, 5, p);
    pcg32 rng(41, 3);
    double ratio = eval_weight(weight_of(s, 0, p), p, 1.0, 1.0);
    CHECK(ratio > 0);
    for (int k = 0; k < 200; k++) {
      double v = log_uniform64(rng, 1e-10, 1e10), g = log_uniform64(rng, 1e-6, 1e6);
      CHECK(rel_err(eval_weight(weight_of(s, size_t(k % 5), p), p, v, g), ratio * v) < 1e-12);
      double d = 1 / std::sqrt(g);
      CHECK(rel_err(posterior_weight(p, v, 1.0, d, 0, 0, 0, 0), ratio * v) < 1e-6);  // float coefficient
    }
    CHECK(eval_weight(weight_of(s, 0, p), p, 0.0, 1.0) == 0);
  }
}

TEST_CASE("a bayes sampler without data picks clusters like the bound sampler", "[bayes]") {
  // Same regions and cuts; the prior-only weights are a constant times the bounds, so cluster probabilities agree
  // to float precision (bounds are products in float in one and in double in the other, cdfs are float).
  for (bool sun : {true, false}) {
    auto t = make_scene(12, sun);
    sampler_params pb;
    pb.kind = sampler_kind::bound;
    pb.regions.max_cut = 5;
    sampler_params py = pb;
    py.kind = sampler_kind::bayes;
    py.bayes.region_prior = false;  // the per-point prior (region_prior: see the test below)
    light_sampler lb = make_light_sampler(pb, t->in, t->tree), ly = make_light_sampler(py, t->in, t->tree);
    const bound_sampler& sb = std::get<bound_sampler>(lb);
    const bayes_sampler& sy = std::get<bayes_sampler>(ly);
    auto cb = std::make_unique<cut_context>(), cy = std::make_unique<cut_context>();
    pcg32 rng(43, 4);
    int compared = 0;
    double worst = 0;
    for (int k = 0; k < 400; k++) {
      vec3f p = {float(-9 + 18 * unif64(rng)), 0, float(-9 + 18 * unif64(rng))};
      shade_point sp{p, {0, 1, 0}, float(0.1 + 0.8 * unif64(rng)), 0, 1};
      sb.prepare(*cb, sp);
      sy.prepare(*cy, sp);
      REQUIRE(cb->count == cy->count);
      for (int l = 0; l < t->lights.count; l++) {
        double a = sb.pmf(*cb, l), b = sy.pmf(*cy, l);
        worst = std::max(worst, std::fabs(a - b) / (1e-5 * a + 3e-7));
        compared++;
      }
    }
    INFO("sun " << sun << ": " << compared << " light pmfs compared, worst |diff| / (1e-5 pmf + 3e-7) " << worst);
    CHECK(worst <= 1);
  }
}

TEST_CASE("with the region prior a bayes sampler without data weighs clusters by mu0 over d^2", "[bayes]") {
  // Prior only: w_j = const * mu0_j g_j o_j (o_j the orientation factor, orientation_of), with mu0_j the distance-free region bound of the cluster over the padded
  // region box (the sun: its irradiance), g_j = 1 / max(|p - c_j|^2, r_j^2), and w_j = 0 exactly when the cluster's
  // bounding sphere lies behind the point's surface.
  for (bool sun : {true, false}) {
    auto t = make_scene(12, sun);
    sampler_params py;
    py.kind = sampler_kind::bayes;
    py.regions.max_cut = 5;
    REQUIRE(py.bayes.region_prior);
    light_sampler ly = make_light_sampler(py, t->in, t->tree);
    const bayes_sampler& sy = std::get<bayes_sampler>(ly);
    auto cy = std::make_unique<cut_context>();
    pcg32 rng(59, 7);
    int compared = 0, behind = 0, in_front = 0;
    double worst = 0;
    for (int k = 0; k < 400; k++) {
      vec3f p = {float(-9 + 18 * unif64(rng)), float(4 * unif64(rng)), float(-9 + 18 * unif64(rng))};
      // Random normals, many of them facing away from some lamps.
      vec3f n = normalize(vec3f{float(normal(rng)), float(normal(rng)), float(normal(rng))});
      shade_point sp{p, n, float(0.1 + 0.8 * unif64(rng)), 0, 1};
      *cy = cut_context{};
      sy.prepare(*cy, sp);
      if (cy->count < 2) continue;
      bbox3f box = padded(region_box(sy.regions.grid, cy->region_key));
      double w[max_cut_entries], total = 0;
      for (int j = 0; j < cy->count; j++) {
        int node = cy->nodes[j];
        double mu0, g = 1;
        bool front;
        if (node == sun_cluster) {
          mu0 = luminance(t->lights.sun_irradiance);
          front = dot(n, t->lights.sun_dir) > -sy.sun_sin;
        } else {
          mu0 = node_region_intensity(t->tree, node, box.lo, box.hi);
          vec3f c = node_center(t->tree, node);
          double r = node_radius(t->tree, node);
          g = 1 / std::max(double(length_sq(p - c)), r * r);
          front = dot(n, c - p) > -r;
        }
        CHECK(double(sy.stats.mu0[size_t(cy->pair_base + j)]) == mu0);
        w[j] = front ? mu0 * g * orientation_of(*t, sy, node, p, n) : 0;
        // The point factor the sampler records with (z = Y / factor): g o in front, 0 behind.
        double factor = front ? g * orientation_of(*t, sy, node, p, n) : 0;
        CHECK(std::fabs(double(cy->gfac[j]) - factor) <= 1e-5 * factor);
        (front ? in_front : behind)++;
        total += w[j];
      }
      for (int j = 0; j < cy->count; j++) {
        double want = total > 0 ? w[j] / total : 0, got = cluster_pmf(*cy, j);
        worst = std::max(worst, std::fabs(got - want) / (1e-5 * want + 3e-7));
        if (want == 0) CHECK(got == 0);
        compared++;
      }
    }
    INFO("sun " << sun << ": " << compared << " cluster pmfs compared (" << in_front << " in front, " << behind
                << " behind), worst |diff| / (1e-5 pmf + 3e-7) " << worst);
    CHECK(worst <= 1);
    CHECK(behind > 100);
    CHECK(in_front > 100);
  }
}

TEST_CASE("merging rows in any grouping gives the one pass statistics", "[bayes]") {
  pcg32 rng(47, 5);
  bayes_params p;
  const int pairs = 40;
  // Observations per pair: zeros and log-normal values around different scales.
  std::vector<std::vector<double>> obs(pairs);
  std::vector<std::pair<int, double>> stream;
  for (int i = 0; i < pairs; i++) {
    double scale = log_uniform64(rng, 1e-3, 1e3);
    int n = 1 + int(rng(400));
    for (int k = 0; k < n; k++) {
      double z = unif64(rng) < 0.3 ? 0.0 : scale * std::exp(0.5 * normal(rng));
      obs[size_t(i)].push_back(z);
    }
  }
  // Interleave the pairs' observations in a random order (as NEE events of many pixels would).
  std::vector<size_t> next(pairs, 0);
  for (bool left = true; left;) {
    left = false;
    for (int i = 0; i < pairs; i++) {
      int burst = int(rng(4));
      for (int b = 0; b < burst && next[size_t(i)] < obs[size_t(i)].size(); b++)
        stream.push_back({i, obs[size_t(i)][next[size_t(i)]++]});
      left = left || next[size_t(i)] < obs[size_t(i)].size();
    }
  }
  // Reference: one-pass Welford in the stream order, and a two-pass long double computation.
  std::vector<moments> welford(pairs);
  for (auto [i, z] : stream) {
    moments& m = welford[size_t(i)];
    if (z == 0) {
      m.n0 += 1;
      continue;
    }
    m.n1 += 1;
    double delta = z - m.mean;
    m.mean += delta / m.n1;
    m.m2 += delta * (z - m.mean);
  }
  // Groupings: everything in one row; one row per observation; random chunks merged over several passes.
  for (int grouping = 0; grouping < 3; grouping++) {
    bayes_stats s;
    resize_stats(s, pairs, p);
    if (grouping == 0) {
      std::vector<bayes_row> rows(1);
      for (auto [i, z] : stream) rows[0].add(i, z);
      merge_rows(s, rows, nullptr);
      refresh_weights(s, nullptr, p, nullptr);
    } else if (grouping == 1) {
      std::vector<bayes_row> rows(stream.size());
      for (size_t k = 0; k < stream.size(); k++) rows[k].add(stream[k].first, stream[k].second);
      merge_rows(s, rows, nullptr);
      refresh_weights(s, nullptr, p, nullptr);
    } else {
      size_t k = 0;
      for (int pass = 0; pass < 4; pass++) {
        std::vector<bayes_row> rows(7);
        size_t end = pass == 3 ? stream.size() : stream.size() * size_t(pass + 1) / 4;
        for (; k < end; k++) rows[size_t(rng(7))].add(stream[k].first, stream[k].second);
        for (bayes_row& r : rows) {
          // Reused rows must start empty after clear().
          bayes_row copy = r;
          copy.clear();
          CHECK(copy.acc.empty());
        }
        merge_rows(s, rows, nullptr);
        refresh_weights(s, nullptr, p, nullptr);
      }
    }
    for (int i = 0; i < pairs; i++) {
      INFO("grouping " << grouping << " pair " << i);
      moments ex = exact_moments(obs[size_t(i)]);
      CHECK(s.m[size_t(i)].n0 == ex.n0);
      CHECK(s.m[size_t(i)].n1 == ex.n1);
      CHECK(rel_err(s.m[size_t(i)].mean, welford[size_t(i)].mean) <= 1e-12);
      CHECK(rel_err(s.m[size_t(i)].m2, welford[size_t(i)].m2) <= 1e-12);
      CHECK(rel_err(s.m[size_t(i)].mean, ex.mean) <= 1e-12);
      CHECK(rel_err(s.m[size_t(i)].m2, ex.m2) <= 1e-12);
      // The coefficients were refreshed from the merged statistics.
      double ref =
          posterior_weight(p, 2.0, 0.3, 1.5, s.m[size_t(i)].n0, s.m[size_t(i)].n1, s.m[size_t(i)].mean, s.m[size_t(i)].m2);
      CHECK(rel_err(eval_weight(weight_of(s, size_t(i), p), p, 0.6, 1 / 2.25), ref) < 1e-5);
    }
  }
}

TEST_CASE("merging rows folds them in row order, bit for bit", "[bayes]") {
  // The statistics must not depend on how rows were grouped into calls (passes, thread counts): merging rows 0..3 in
  // one call gives the bits of merging them one call each, in row order. The values make the rounding depend on the
  // order (checked: the rows reversed give other bits), so a fold in another order fails here; the grouping test
  // above compares to 1e-12 only (a mutation review: a reversed fold passed it and every golden).
  const std::vector<std::vector<std::pair<int, double>>> data = {
      {{0, 1e8 + 0.1}, {1, 3e-8}, {2, 1}, {0, 0.3}},
      {{0, 1}, {1, 1e8}, {2, 3e-8}, {1, 0}},
      {{0, 3e-8}, {1, 0.7}, {2, 1e8 + 0.3}, {2, 7.1}},
      {{0, 5.5}, {1, 1e-3}, {2, 2.5}, {0, 0}}};
  bayes_params p;
  auto merged = [&](const std::vector<int>& order, bool one_call) {
    bayes_stats s;
    resize_stats(s, 3, p);
    std::vector<bayes_row> rows;
    for (int r : order) {
      rows.emplace_back();
      for (auto [pair, z] : data[size_t(r)]) rows.back().add(pair, z);
      if (!one_call) {
        merge_rows(s, rows, nullptr);
        rows.clear();
      }
    }
    if (one_call) merge_rows(s, rows, nullptr);
    return s;
  };
  auto bits = [](const bayes_stats& s) {
    std::vector<uint64_t> b;
    for (const pair_moments& m : s.m)
      for (double v : {m.n0, m.n1, m.mean, m.m2}) {
        uint64_t u;
        std::memcpy(&u, &v, sizeof u);
        b.push_back(u);
      }
    return b;
  };
  const auto together = bits(merged({0, 1, 2, 3}, true));
  CHECK(together == bits(merged({0, 1, 2, 3}, false)));
  CHECK(together != bits(merged({3, 2, 1, 0}, false)));  // (the order shows in the bits: the check above can fail)
}

TEST_CASE("decaying statistics scales the counts and keeps the mean", "[bayes]") {
  bayes_params p;
  bayes_stats s;
  resize_stats(s, 2, p);
  std::vector<bayes_row> rows(1);
  for (double z : {0.0, 1.0, 2.0, 0.0, 4.0}) rows[0].add(1, z);
  merge_rows(s, rows, nullptr);
  refresh_weights(s, nullptr, p, nullptr);
  double mean = s.m[1].mean, m2 = s.m[1].m2;
  decay_stats(s, 0.5);
  refresh_weights(s, nullptr, p, nullptr);
  CHECK(s.m[1].n0 == 1.0);
  CHECK(s.m[1].n1 == 1.5);
  CHECK(s.m[1].mean == mean);
  CHECK(s.m[1].m2 == 0.5 * m2);
  CHECK(rel_err(eval_weight(weight_of(s, 1, p), p, 0.2, 0.5),
                posterior_weight(p, 0.2, 1.0, std::sqrt(2.0), 1.0, 1.5, mean, 0.5 * m2)) < 1e-5);
}

namespace {

// A region of 3 clusters fed with synthetic observations at one point. Cluster j: Y = 0 with probability p0[j],
// else |N(k_j, h_j)| / d_j^2 with k_j = factor[j] * mu0_j (mu0_j the prior mean the bound gives) and
// sqrt(h_j) = cv[j] k_j <= k_j / 5 (negative draws have probability < 3e-7; folding them changes nothing visible).
// With all observations at one point the ideal pmf is proportional to sqrt(E[Y^2]) = sqrt((1 - p0)(k^2 + h)) / d^2
// (mean-only ablation: E[Y] = (1 - p0) k / d^2), whatever the distance-regression switch.
struct convergence_setup {
  double p0[3], factor[3], cv[3];
};

struct convergence_result {
  double learned[3], target[3], prior[3];
  double tolerance;       // on |learned / target - 1|, see below
  double mean_error = 0;  // worst relative error of the stored means against the recorded z
};

convergence_result run_convergence(const bayes_params& params, const convergence_setup& cs, int n, uint64_t seed) {
  three_lamps f = make_three_lamps(params);
  auto& t = f.t;
  bayes_sampler& s = f.sampler();
  shade_point pt = f.pt;
  auto& ctx = f.ctx;
  REQUIRE(s.regions.key[size_t(ctx->region)] == ctx->fine_key);  // the point's own fine region
  convergence_result r;
  // Region prior: the statistics hold the albedo-free z = (Y / (albedo / pi)) d^2.
  double y_scale = params.region_prior ? double(pt.albedo * inv_pi_f) : 1.0;
  double d[3], k[3], h[3], dist[3], y_per_z[3], o[3];
  for (int j = 0; j < 3; j++) {
    r.prior[j] = cluster_pmf(*ctx, j);
    prior_args a = prior_of(*t, s, *ctx, j, pt);
    dist[j] = cluster_distance(t->tree, ctx->nodes[j], pt.p);
    d[j] = dist[j];
    o[j] = a.o;
    double mu0 = a.scale * a.bound * d[j] * d[j] / o[j];  // prior mean of z
    k[j] = cs.factor[j] * mu0;
    h[j] = cs.cv[j] * cs.cv[j] * k[j] * k[j];
    y_per_z[j] = a.y_per_z;
  }
  // Feed n observations per cluster over 6 passes of 4 rows.
  pcg32 rng(seed, 6);
  size_t base = size_t(s.regions.pair_offset[size_t(ctx->region)]);
  std::vector<long double> zsum(3, 0.0L);
  std::vector<double> zcount(3, 0.0);
  for (int pass = 0; pass < 6; pass++) {
    std::vector<bayes_row> rows(4);
    for (int i = pass * n / 6; i < (pass + 1) * n / 6; i++)
      for (int j = 0; j < 3; j++) {
        float y = 0;
        if (!(unif64(rng) < cs.p0[j])) y = float(std::fabs(k[j] + std::sqrt(h[j]) * normal(rng)) * y_per_z[j]);
        light_choice c;
        c.cluster = j;
        c.light = j;
        s.record(rows[size_t(i % 4)], nee_event<cut_context>{ctx.get(), c, y});
        if (y > 0) {
          // What the statistics must hold: z = Y d^2 with the regression, z = Y without (Y / (albedo / pi) with
          // the region prior).
          double yy = params.region_prior ? double(y) / y_scale : double(y);
          // With the region prior the sampler divides by its float point factor (checked against the double
          // formula in the prior-only test), so the means agree to rounding.
          double z = params.region_prior ? yy / double(ctx->gfac[j])
                                         : (params.distance_regression ? yy * dist[j] * dist[j] : yy);
          zsum[size_t(j)] += z;
          zcount[size_t(j)] += 1;
        }
      }
    s.learn(rows);
  }
  for (int j = 0; j < 3; j++)
    r.mean_error =
        std::max(r.mean_error, rel_err(s.stats.m[base + size_t(j)].mean, double(zsum[size_t(j)] / zcount[size_t(j)])));
  s.prepare(*ctx, pt);
  double total = 0, sigma = 0, bias = 0;
  for (int j = 0; j < 3; j++) {
    r.learned[j] = cluster_pmf(*ctx, j);
    double p1 = 1 - cs.p0[j], k2 = k[j] * k[j], hh = h[j];
    double ez2 = k2 + hh, ez4 = k2 * k2 + 6 * k2 * hh + 3 * hh * hh;  // moments of z given non-zero
    double f = cs.factor[j], n1 = n * p1;
    if (params.second_moment) {
      r.target[j] = std::sqrt(p1 * ez2) / (d[j] * d[j]) * o[j];
      // w^2 estimates E[Z^2], Z = z 1{non-zero}: relative sd of w = sd(Z^2) / E[Z^2] / (2 sqrt(n)).
      sigma = std::max(sigma, 0.5 * std::sqrt((ez4 / (p1 * ez2 * ez2) - 1) / n));
    } else {
      r.target[j] = p1 * k[j] / (d[j] * d[j]) * o[j];
      sigma = std::max(sigma, std::sqrt((ez2 / (p1 * k2) - 1) / n));
    }
    // Pull of the prior, relative, of order 1 / n1 (see METHOD.md 4): Beta pseudo-counts, kappa0 on the mean,
    // beta0 and the (z - mu0)^2 term on the variance.
    double pull = (params.a0 + params.b0 + 2 * params.kappa0 * std::max(1.0, 1 / f) +
                   2 * (params.c * (params.alpha0 - 1) / (f * f) + params.kappa0 * (1 + 1 / f) * (1 + 1 / f) +
                        (params.alpha0 - 1))) /
                  n1;
    bias = std::max(bias, params.prior ? pull : 0.0);
    total += r.target[j];
  }
  for (int j = 0; j < 3; j++) r.target[j] /= total;
  // 5 standard deviations per cluster (two-sided 5.7e-7 each, < 2e-6 for the three) plus the prior's pull;
  // normalising can double a relative error.
  r.tolerance = 2 * (5 * sigma + bias);
  return r;
}

void check_convergence(const convergence_result& r, double epsilon) {
  double prior_gap = 0;
  for (int j = 0; j < 3; j++) {
    double target = (1 - epsilon) * r.target[j] + epsilon * r.prior[j];
    INFO("cluster " << j << " learned " << r.learned[j] << " target " << target << " prior " << r.prior[j]
                    << " tolerance " << r.tolerance);
    CHECK(std::fabs(r.learned[j] / target - 1) <= r.tolerance);
    prior_gap = std::max(prior_gap, std::fabs(r.prior[j] / target - 1));
  }
  // Decisive: the prior-only pmf is far outside the tolerance, so only learning can have brought it there.
  CHECK(prior_gap > 3 * r.tolerance);
  CHECK(r.mean_error < 1e-12);
}

const convergence_setup setup = {{0.2, 0.6, 0.9}, {0.5, 2.0, 1.0}, {0.2, 0.1, 0.15}};

}  // namespace

TEST_CASE("a learned pmf converges to the square root of the second moment", "[bayes]") {
  for (bool region : {true, false})
    for (bayes_params p : param_sets()) {
      p.region_prior = region;
      INFO("region prior " << region << " alpha0 " << p.alpha0 << " kappa0 " << p.kappa0);
      check_convergence(run_convergence(p, setup, 60000, 51), 0.0);
    }
}

TEST_CASE("the bayes ablations learn what their definitions say", "[bayes]") {
  for (bool region : {true, false}) {
    INFO("region prior " << region);
    bayes_params base;
    base.region_prior = region;
    SECTION("mean only: the pmf follows the posterior mean over d^2") {
      bayes_params p = base;
      p.second_moment = false;
      check_convergence(run_convergence(p, setup, 60000, 53), 0.0);
    }
    SECTION("no prior: plug-in moments mixed with 1e-3 of the prior-only pmf") {
      bayes_params p = base;
      p.prior = false;
      check_convergence(run_convergence(p, setup, 60000, 55), 1e-3);
    }
    SECTION("no distance regression: the statistics pool Y itself") {
      bayes_params p = base;
      p.distance_regression = false;
      check_convergence(run_convergence(p, setup, 60000, 57), 0.0);
    }
  }
}

TEST_CASE("the naive ablation follows plug in moments exactly", "[bayes]") {
  // After a handful of observations the no-prior pmf is the definition: (1 - eps) w / sum w + eps b / sum b with
  // w = sqrt(n1/n (mean^2 + m2/n1)) / d^2 (or the prior-only weight when a pair has no data), b the prior-only
  // weight (the bound at the point, or mu0 g with the region prior) and eps = 1e-3.
  for (bool region : {true, false}) {
    INFO("region prior " << region);
    bayes_params bp;
    bp.prior = false;
    bp.region_prior = region;
    three_lamps f = make_three_lamps(bp);
    auto& t = f.t;
    bayes_sampler& s = f.sampler();
    shade_point pt = f.pt;
    auto& ctx = f.ctx;
    REQUIRE(ctx->count == 3);
    double prior_pmf[3];
    for (int j = 0; j < 3; j++) prior_pmf[j] = cluster_pmf(*ctx, j);
    std::vector<bayes_row> rows(1);
    const float ys[2][4] = {{0, 0.5f, 0.25f, 0}, {0, 0, 0, 0}};  // cluster 2 gets nothing
    for (int j = 0; j < 2; j++)
      for (float y : ys[j]) {
        light_choice c;
        c.cluster = j;
        s.record(rows[0], nee_event<cut_context>{ctx.get(), c, y});
      }
    s.learn(rows);
    s.prepare(*ctx, pt);
    double w[3], b[3], sw = 0, sb = 0;
    for (int j = 0; j < 3; j++) {
      prior_args a = prior_of(*t, s, *ctx, j, pt);
      b[j] = a.prior_weight;
      if (j == 0) {
        std::vector<double> z = {0.5 / a.y_per_z, 0.25 / a.y_per_z};
        double mean = (z[0] + z[1]) / 2, var = ((z[0] - mean) * (z[0] - mean) + (z[1] - mean) * (z[1] - mean)) / 2;
        w[j] = std::sqrt(0.5 * (mean * mean + var)) / (a.d * a.d) * a.o;
      } else if (j == 1) {
        w[j] = 0;  // only zeros: the naive estimate starves the cluster (the mixing keeps it alive)
      } else {
        w[j] = a.scale * a.bound;
      }
      sw += w[j];
      sb += b[j];
    }
    for (int j = 0; j < 3; j++) {
      double expect = (1 - 1e-3) * w[j] / sw + 1e-3 * b[j] / sb;
      INFO("cluster " << j << " prior-only pmf " << prior_pmf[j]);
      CHECK(cluster_pmf(*ctx, j) == Approx(expect).epsilon(1e-5).margin(3e-7));
      CHECK(cluster_pmf(*ctx, j) > 0);
    }
  }
}

TEST_CASE("fine pairs lean on their coarse parent as the hierarchy defines", "[bayes]") {
  // A fine pair's Beta prior on p0 is centred on its coarse parent's posterior mean with concentration s:
  // E[1 - p0] = (s p1_parent + n1) / (s + n), p1_parent = (b0 + n1_parent) / (a0 + b0 + n_parent); the rest of the
  // posterior (k, h) is the fine pair's own. Every observation of the fine pair also counts for the parent pair.
  for (int mode = 0; mode < 4; mode++) {
    bool second_moment = mode & 1, region = mode & 2;
    INFO("second moment " << second_moment << " region prior " << region);
    bayes_params bp;
    bp.second_moment = second_moment;
    bp.region_prior = region;
    REQUIRE(bp.hierarchy > 0);
    three_lamps f = make_three_lamps(bp);
    auto& t = f.t;
    bayes_sampler& s = f.sampler();
    shade_point pt = f.pt;
    auto& ctx = f.ctx;
    int fine = ctx->region;
    REQUIRE(s.regions.key[size_t(fine)] == ctx->fine_key);
    int coarse = s.regions.parent[size_t(fine)];
    REQUIRE(coarse != invalid_id);
    size_t base = size_t(s.regions.pair_offset[size_t(fine)]);
    // Observations at the point: cluster 0 gets 5 non-zero and 3 zero samples, cluster 1 only zeros.
    std::vector<bayes_row> rows(1);
    const float ys[2][8] = {{0.2f, 0, 0.3f, 0.25f, 0, 0.5f, 0.1f, 0}, {0, 0, 0, 0, 0, 0, 0, 0}};
    for (int j = 0; j < 2; j++)
      for (float y : ys[j]) {
        light_choice c;
        c.cluster = j;
        s.record(rows[0], nee_event<cut_context>{ctx.get(), c, y});
      }
    s.learn(rows);
    for (int j = 0; j < 3; j++) {
      size_t i = base + size_t(j);
      int up = s.regions.pair_parent[i];
      REQUIRE(up == s.regions.pair_offset[size_t(coarse)] + j);
      CHECK(s.stats.m[size_t(up)].n0 == s.stats.m[i].n0);
      CHECK(s.stats.m[size_t(up)].n1 == s.stats.m[i].n1);
      CHECK(s.stats.m[size_t(up)].mean == s.stats.m[i].mean);
      CHECK(s.stats.m[size_t(up)].m2 == s.stats.m[i].m2);
    }
    // More observations of cluster 0 reach only the parent: its posterior now differs from the fine pair's.
    std::vector<bayes_row> more(1);
    for (int k = 0; k < 6; k++) more[0].add(s.regions.pair_offset[size_t(coarse)], 3.0 + k);
    merge_rows(s.stats, more, nullptr);
    refresh_weights(s.stats, &s.regions.pair_parent, s.params, &s.regions.pair_node);
    s.prepare(*ctx, pt);
    double w[3], own[3], sw = 0, sown = 0;
    for (int j = 0; j < 3; j++) {
      size_t i = base + size_t(j), up = size_t(s.regions.pair_parent[i]);
      prior_args a = prior_of(*t, s, *ctx, j, pt);
      // posterior_weight models the point factor 1 / d^2: the orientation factor o scales the prior mean of z by
      // 1 / o and the weight by o.
      double wf = a.o * posterior_weight(s.params, a.bound / a.o, a.scale, a.d, s.stats.m[i].n0, s.stats.m[i].n1,
                                         s.stats.m[i].mean, s.stats.m[i].m2);
      double wp = a.o * posterior_weight(s.params, a.bound / a.o, a.scale, a.d, s.stats.m[up].n0, s.stats.m[up].n1,
                                         s.stats.m[up].mean, s.stats.m[up].m2);
      const bayes_params& bp = s.params;
      double n = s.stats.m[i].n0 + s.stats.m[i].n1, np = s.stats.m[up].n0 + s.stats.m[up].n1;
      double p1_own = (bp.b0 + s.stats.m[i].n1) / (bp.a0 + bp.b0 + n);
      double p1_parent = (bp.b0 + s.stats.m[up].n1) / (bp.a0 + bp.b0 + np);
      double p1_h = (bp.hierarchy * p1_parent + s.stats.m[i].n1) / (bp.hierarchy + n);
      w[j] = second_moment ? wf * std::sqrt(p1_h / p1_own) : wf * (p1_h / p1_own);
      own[j] = wf;
      (void)wp;
      sw += w[j];
      sown += wf;
    }
    double gap = 0;
    for (int j = 0; j < 3; j++) {
      INFO("cluster " << j);
      CHECK(cluster_pmf(*ctx, j) == Approx(w[j] / sw).epsilon(1e-5).margin(3e-7));
      gap = std::max(gap, std::fabs(w[j] / sw - own[j] / sown) / (own[j] / sown));
    }
    INFO("largest relative move of a cluster probability due to the parent " << gap);
    CHECK(gap > 1e-2);  // decisive: the parent's extra data visibly moves the blend away from the fine posterior
  }
}

TEST_CASE("under the mean hierarchy a fine pair's prior mean is the lower of its bound and its parent's mean", "[bayes]") {
  // Region prior: a fine pair's prior mean of z is min(mu0, k_parent), k_parent = (kappa0 mu0_parent + n1 zbar) /
  // (kappa0 + n1) the parent's posterior mean under its own bound; W = sqrt(p1 Q(mean)) is evaluated there. The
  // parent pools the fine pair's samples and (here) more of its own, far below the bound.
  for (bool means : {true, false}) {
    INFO("mean hierarchy " << means);
    bayes_params bp;
    bp.mean_hierarchy = means;
    REQUIRE(bp.region_prior);
    three_lamps f = make_three_lamps(bp);
    bayes_sampler& s = f.sampler();
    shade_point pt = f.pt;
    auto& ctx = f.ctx;
    int fine = ctx->region, coarse = s.regions.parent[size_t(fine)];
    REQUIRE(coarse != invalid_id);
    size_t base = size_t(s.regions.pair_offset[size_t(fine)]);
    size_t cbase = size_t(s.regions.pair_offset[size_t(coarse)]);
    // A parent without data leaves every child at its own bound (the parent's bound covers a larger box).
    for (int j = 0; j < 3; j++) {
      size_t i = base + size_t(j);
      CHECK(s.stats.mu0[cbase + size_t(j)] >= s.stats.mu0[i]);
      CHECK(prior_mean(s.stats, i, s.regions.pair_parent[i], s.params) == double(s.stats.mu0[i]));
    }
    // Cluster 0: two samples at the fine point, then 40 more reach the parent only, at a hundredth of the bound.
    std::vector<bayes_row> rows(1);
    double y_bound = double(s.stats.mu0[base]) * ctx->gfac[0] * pt.albedo / M_PI;  // a sample with z = mu0
    REQUIRE(y_bound > 0);
    for (double f : {0.02, 0.03}) {
      light_choice c;
      c.cluster = 0;
      s.record(rows[0], nee_event<cut_context>{ctx.get(), c, float(f * y_bound)});
    }
    s.learn(rows);
    std::vector<bayes_row> more(1);
    double low = 0.01 * s.stats.mu0[base];
    for (int k = 0; k < 40; k++) more[0].add(int(cbase), low * (1 + 0.01 * k));
    merge_rows(s.stats, more, nullptr);
    refresh_weights(s.stats, &s.regions.pair_parent, s.params, &s.regions.pair_node);
    const pair_moments& mp = s.stats.m[cbase];
    REQUIRE(mp.n1 == 42);
    double k_parent = (s.params.kappa0 * s.stats.mu0[cbase] + mp.n1 * mp.mean) / (s.params.kappa0 + mp.n1);
    REQUIRE(k_parent < 0.1 * s.stats.mu0[base]);
    double expect = means ? std::min(double(s.stats.mu0[base]), k_parent) : double(s.stats.mu0[base]);
    CHECK(prior_mean(s.stats, base, int(cbase), s.params) == Approx(expect).epsilon(1e-12));
    pair_weight pw = folded_coeffs(s.stats, base, pair_p1(s.stats, base, int(cbase), s.params), s.params);
    double w_expect = eval_weight(pw, s.params, expect, 1.0);
    double w_bound = eval_weight(pw, s.params, s.stats.mu0[base], 1.0);
    CHECK(s.stats.w[base] == Approx(w_expect).epsilon(1e-6));
    if (means) CHECK(w_expect < 0.5 * w_bound);  // decisive: the parent's mean pulls the fine weight down
    CHECK(std::isfinite(s.stats.w[base]));
    CHECK(s.stats.w[base] > 0);
    // Clusters 1 and 2 (no data anywhere) keep their bound.
    for (int j = 1; j < 3; j++)
      CHECK(prior_mean(s.stats, base + size_t(j), int(cbase) + j, s.params) == double(s.stats.mu0[base + size_t(j)]));
  }
}

TEST_CASE("control variates apply at every vertex to clusters visible at least the threshold", "[bayes]") {
  // With a lamp threshold of 0.96: cluster 0 is always visible with a steady contribution, cluster 1 is visible half
  // the time, cluster 2 has no data. Cluster 0 gets the control variate c = E[1 - p0] k g and the pmf the residual's
  // weight sqrt(E[1 - p0] h + E[1 - p0] E[p0] k^2) g; clusters 1 and 2 (E[1 - p0] < cv_min_visible) keep the plain
  // weight and c = 0. At every vertex (the default), or with --bayes-cv-last-only only where NEE is unweighted
  // anyway (sp.last); elsewhere nothing changes then.
  for (bool every : {true, false}) {
    INFO("control variates at every vertex " << every);
    bayes_params bp;
    bp.cv_min_visible = 0.96;
    three_lamps f = make_three_lamps(bp, false, every);
    REQUIRE(f.sampler().params.control_variate);
    auto& t = f.t;
    bayes_sampler& s = f.sampler();
    shade_point pt = f.pt;
    auto& ctx = f.ctx;
    pcg32 rng(61, 8);
    std::vector<bayes_row> rows(1);
    for (int i = 0; i < 4000; i++) {
      for (int j = 0; j < 2; j++) {
        light_choice c;
        c.cluster = j;
        float y = j == 0 ? float(0.3 * (1 + 0.05 * normal(rng))) : (unif64(rng) < 0.5 ? 0.0f : 0.2f);
        s.record(rows[0], nee_event<cut_context>{ctx.get(), c, y});
      }
    }
    s.learn(rows);
    for (bool last : {false, true}) {
      INFO("last vertex " << last);
      shade_point q = pt;
      q.last = last;
      *ctx = cut_context{};
      s.prepare(*ctx, q);
      const bool on = last || every;
      CHECK(ctx->cv == on);
      double w[3], sum = 0;
      vec3f cv_sum = {0, 0, 0};
      for (int j = 0; j < 3; j++) {
        size_t i = size_t(ctx->pair_base + j);
        // g: the point factor, 1 / d^2 times the orientation factor.
        double d = cluster_distance(t->tree, ctx->nodes[j], pt.p);
        double g = orientation_of(*t, s, ctx->nodes[j], pt.p, pt.n) / (d * d);
        double p1 = pair_p1(s.stats, i, s.regions.pair_parent[i], s.params), k = 0, h = 0;
        bool learned = pair_posterior(s.stats, i, s.params, s.stats.mu0[i], k, h);
        bool cv = on && j == 0;
        CHECK((p1 >= s.params.cv_min_visible) == (j == 0));
        if (cv) {
          REQUIRE(learned);
          CHECK(double(s.stats.cv[i]) == Approx(p1 * k).epsilon(1e-6));
          CHECK(double(ctx->cvg[j]) == Approx(p1 * k * g).epsilon(1e-5));
          w[j] = std::sqrt(p1 * h + p1 * (1 - p1) * k * k) * g;
          CHECK(w[j] < 0.2 * double(s.stats.w[i]) * g);  // decisive: the residual is far smaller than the signal
        } else {
          w[j] = double(s.stats.w[i]) * g;
          if (on) CHECK(ctx->cvg[j] == 0);
        }
        if (on) cv_sum += s.cluster_color(*ctx, j) * ctx->cvg[j];
        sum += w[j];
      }
      for (int j = 0; j < 3; j++) CHECK(cluster_pmf(*ctx, j) == Approx(w[j] / sum).epsilon(1e-5).margin(3e-7));
      if (on) {
        CHECK(s.cv_total(*ctx).x == Approx(cv_sum.x));
        CHECK(s.cv_total(*ctx).y == Approx(cv_sum.y));
      }
    }
  }
}

TEST_CASE("a lamp's control variate applies at any visibility, the sun's only where the region nearly always sees it",
          "[bayes]") {
  // Defaults: lamp 0 and the sun are each visible 90 % of the time with a steady contribution, lamps 1 and 2 have no
  // data. Lamp 0 gets a control variate (E[1 - p0] above the lamps' threshold of 0), the sun none (below its own
  // 0.96), lamps 1 and 2 none (no samples: no mean to subtract). With the sun's threshold at 0.85 it gets one too.
  three_lamps f = make_three_lamps(bayes_params{}, true);
  bayes_sampler& s = f.sampler();
  REQUIRE(s.params.cv_min_visible == 0);
  REQUIRE(s.params.cv_sun_min_visible == 0.96);
  auto& ctx = f.ctx;
  pcg32 rng(62, 9);
  std::vector<bayes_row> rows(1);
  for (int i = 0; i < 4000; i++)
    for (int j : {0, 3}) {
      light_choice c;
      c.cluster = j;
      float y = unif64(rng) < 0.1 ? 0.0f : float(0.3 * (1 + 0.05 * normal(rng)));
      s.record(rows[0], nee_event<cut_context>{ctx.get(), c, y});
    }
  s.learn(rows);
  for (int j : {0, 3}) {
    size_t i = size_t(ctx->pair_base + j);
    double p1 = pair_p1(s.stats, i, s.regions.pair_parent[i], s.params);
    INFO("cluster " << j << ": E[1 - p0] = " << p1);
    CHECK(p1 > 0.85);
    CHECK(p1 < 0.94);  // decisive: below the sun's threshold by far more than the posterior's spread
  }
  for (double sun_threshold : {0.96, 0.85}) {
    INFO("the sun's threshold " << sun_threshold);
    s.params.cv_sun_min_visible = sun_threshold;
    s.refresh_all_weights();
    shade_point q = f.pt;
    q.last = true;
    *ctx = cut_context{};
    s.prepare(*ctx, q);
    REQUIRE(ctx->cv);
    REQUIRE(ctx->count == 4);
    auto cv_of = [&](int j) { return s.stats.cv[size_t(ctx->pair_base + j)]; };
    CHECK(cv_of(0) > 0);
    CHECK(ctx->cvg[0] > 0);
    CHECK(cv_of(1) == 0);
    CHECK(cv_of(2) == 0);
    CHECK((cv_of(3) > 0) == (sun_threshold < 0.9));
    CHECK((ctx->cvg[3] > 0) == (sun_threshold < 0.9));
  }
}
