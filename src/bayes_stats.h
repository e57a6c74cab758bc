// bayes_stats: the per (region, cluster) statistics of the Bayesian sampler and its posterior (METHOD.md 3-5).
// Data model: a sample Y of a cluster at distance d is zero with probability p0, else z = Y d^2 ~ N(k, h).
// Priors: p0 ~ Beta(a0, b0); (k, h) ~ Normal-inverse-gamma(mu0, kappa0, alpha0, beta0) with mu0 from the
// bound and beta0 = c mu0^2 (alpha0 - 1) (scale-free). Invariants: statistics are kept as count, mean and sum of
// squared deviations (Welford/Chan: no cancellation); rows are folded in image order, so the result never
// depends on thread timing; every posterior weight of a cluster with a non-zero bound is finite and > 0.
#pragma once

#include "cut_sampling.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace bl {

// Prior strengths and ablation switches.
struct bayes_params {
  double a0 = 0.3, b0 = 0.03;    // Beta prior of the zero-sample probability p0 (b0 << a0: a cluster is believed
                                 // mostly occluded until it shows non-zero samples; a0 + b0 << 1: its own first
                                 // samples outweigh that belief; see README, choosing the defaults)
  double kappa0 = 1;             // prior pseudo-count of the mean
  double alpha0 = 2;             // inverse-gamma shape (> 1)
  double c = 0.3;                // prior squared coefficient of variation: beta0 = c mu0^2 (alpha0 - 1)
  double epsilon = 0;            // defensive mixing with the bound pmf
  bool second_moment = true;     // false: pmf from the posterior mean only (ablation)
  bool distance_regression = true;  // false: z = Y, no 1/d^2 model (ablation)
  bool prior = true;             // false: plug-in sample moments, the naive adaptive method (ablation)
  double decay = 1;              // statistics scale per animation frame (1: keep everything)
  int oracle_spp = 0;            // > 0: learn for this many spp first (independent seed), then freeze (oracle mode)
  double hierarchy = 1;          // concentration of a fine pair's Beta prior on p0, centred on its coarse parent's
                                 // posterior mean (0: no hierarchy, every pair uses Beta(a0, b0))
  bool region_prior = true;      // true: prior mean mu0 per (region, cluster) from the bound over the region's box,
                                 // so a shading point only scales each pair's posterior weight by 1 / d^2 (the
                                 // regression) and drops clusters behind its surface; false (ablation): mu0 from the
                                 // bound at every shading point, which then evaluates full cone bounds per cluster
  double cv_min_visible = 0;     // control variates only for lamp pairs with E[1 - p0] at least this (README: any
                                 // visibility gained on the data/ scenes: a lamp's shadows are soft)
  double cv_sun_min_visible = 0.96;  // ... and for the sun's pairs (its shadow edges are sharp: 0.94 and below gave the
                                     // living room fireflies in dark pixels next to them)
  double unseen_cap = 8;          // region prior: a cluster none of whose members (nor their coarse parents) has shown
                                 // a non-zero sample after this many samples (its own and its parent's) weighs at a
                                 // point at most the heaviest cluster there that has, and such a member inside a
                                 // cluster at most its heaviest seen member (0: off). Its prior mean is the bound,
                                 // which no count of zero samples overturns: its weight falls only as 1 / sqrt(n0),
                                 // and a lamp 1e6 times brighter shut in a box kept 99 % of the samples after 1024
                                 // spp (110x uniform's relMSE; README, Unseen lights)
  double refold_tolerance = 0.05;  // hierarchy: a coarse pair's children are refolded when its p1 has moved by more
                                   // than this fraction (of max(p1, 0.1)) since their last fold (a child's p1 moves
                                   // by at most that fraction too); 0: whenever it changes at all
  bool bsdf_factor = true;       // region prior: at a glossy point the factor also holds the Phong lobe's largest
                                 // value toward the cluster's bounding sphere (over the albedo scale), and a region
                                 // with members is weighed member by member there (a highlight is sharper than a
                                 // region: which lights it mirrors changes across the region); no control variates
                                 // at such points (a learned mean times a factor far above the diffuse one)
  bool orientation = true;       // region prior: the point factor of a cluster is its receiver cosine bound / d^2
                                 // (z = Y d^2 / cos), not 1 / d^2 alone: the regression also learns what the
                                 // orientation of the point explains
  bool mean_hierarchy = true;    // region prior with the hierarchy: a fine pair's prior mean of z is the lower of its
                                 // bound mu0 and its coarse parent's posterior mean (which pools the samples of all
                                 // its fine regions), so a new fine region starts from what its surroundings learned
  double fallback_ratio = 1.5;   // fall back to power sampling for the rest of the render when the estimated relMSE
                                 // per sample of power sampling is below this many times the learned one's in two
                                 // check windows in a row (from 4 spp on): where learning cannot pay for its own
                                 // cost (bayes costs 1.4-2.6x power's time per sample on the data/ scenes); 0: never
                                 // (1.25 until the lamps' control variates raised the Cornell box's estimate to a
                                 // hair under 2.5: README)
  double fallback_bvh_ratio = 1;  // fall back to the bvh sampler instead where its estimated relMSE per sample is
                                  // below this many times the learned one's and power's is not below its threshold
                                  // (two windows in a row, as above): many lights that every point sees alike, in
                                  // clusters the learned model cannot split (64 small lamps over a floor, path
                                  // traced, where bvh had 1/25 of bayes's relMSE at equal spp); 0: never
  double fallback_stratified = 2;  // the threshold's factor when the first vertex is stratified (the default): the
                                   // check estimates both sides as if samples were independent, but stratification
                                   // helps a fixed choice more (the Cornell box, direct: estimated 1.86x, about 1.3x
                                   // measured against stratified power); 1 with --independent-samples
  bool stratified = true;          // set from the render (render_inputs::stratify)
  bool path_traced = false;        // set from the render (max depth above 1): stratification then helps only the first
                                   // vertex's share of power sampling's variance (bayes_sampler::stratified_factor)
  double fallback_window = 262144;  // samples (pixels x spp) a fallback check sums before it votes: the events that
                                    // make power sampling bad can be rare (points by a lamp's rim)
  int early_draws = 4;           // a direct render's NEE draws per camera sample in its first early_spp spp (render.cpp,
  int early_spp = 16;            // pass_draws): the passes it learns most from; draws at most light_samples, or 0 spp: off
  bool cv_every_vertex = true;   // control variates at every path vertex, not only where NEE is unweighted anyway:
                                 // a light they cover is sampled by NEE alone there (unweighted; its BSDF-sampled
                                 // hits weigh 0). Path traced, 32 spp, seeds 12 / 13: relMSE 0.88 / 0.89x of the last
                                 // vertex's alone in the plant room, 0.87 / 0.86x living room, 0.76 / 0.79x hall
  bool control_variate = true;   // region prior only: at a diffuse point (at every path vertex with cv_every_vertex,
                                 // else where NEE is unweighted anyway), add the learned mean c_j = E[1 - p0] k_j / d^2
                                 // of every cluster and estimate the residual (Y_J - c_J) / P_J, with P_j
                                 // proportional to the root of the residual's second moment
                                 // E[1 - p0] h + E[1 - p0] E[p0] k^2 (METHOD.md 5)
};

// Statistics columns, one entry per (region, cluster) pair, with the posterior folded into per-pair
// coefficients. The predicted second moment is E[1 - p0] * (mu_n^2 + h); mu_n^2 + h is a quadratic in the prior
// mean mu0. With the prior mean of Y at the point v = scale * bound (so mu0 = v d^2) and g = 1 / d^2:
//   w = sqrt(p1 * max(q2 v^2 + q1 v g + q0 g^2, qc v^2))      (qc v^2 = the prior-variance term, a lower bound)
// and for the mean-only ablation w = p1 (q2 v + q1 g). p1 = E[1 - p0]: the pair's own posterior mean under
// Beta(a0, b0), or for a fine pair under the hierarchical prior Beta(s (1 - p1_parent), s p1_parent),
// p1 = (s p1_parent + n1) / (s + n). Between passes p1 is folded into the coefficients (`weight`), so a shading
// point reads 16 bytes per cluster and evaluates w = sqrt(max((w2 v + w1 g) v + w0 g^2, wc v^2)).
struct pair_coeffs {
  float q2, q1, q0, qc;  // the quadratic's coefficients (see above)
  float p1;              // posterior mean of 1 - p0 under Beta(a0, b0) (plug-in n1 / n for the naive ablation)
};
// The same in double (a fold whose float coefficients overflow: see fold_weight).
struct pair_coeffs_d {
  double q2, q1, q0, qc, p1;
};
// What sampling reads of one pair: the coefficients with the (hierarchical) p1 folded in.
struct pair_weight {
  float w2, w1, w0, wc;
};
struct pair_weight_d {
  double w2, w1, w0, wc;
};
// The largest weight, control-variate weight or mean a pair keeps: a cluster's sums over up to 1024 members stay
// finite in float. Only absurd radiance scales reach it (the float coefficients overflow from z of about 1.8e19).
constexpr double max_pair_weight = 1e35;
// The least weight of a pair that can reach its region (float's least normal number).
constexpr double min_pair_weight = 0x1p-126;

// Region-prior mode (bayes_params::region_prior): observations are recorded as z = (Y / s) d^2 with s = albedo / pi
// of the shading point (an irradiance times d^2, free of the surface's albedo), mu0 is fixed per pair when its region
// is created, and the weight at a point is w = W g with W = sqrt(p1 max(w2 mu0^2 + w1 mu0 + w0, wc mu0^2)) per pair.
// A pair's sufficient statistics: counts of zero and non-zero samples, mean and sum of squared deviations of the
// non-zero ones. One 32-byte record per pair: the fold between passes touches one cache line per update.
struct pair_moments {
  double n0 = 0, n1 = 0, mean = 0, m2 = 0;
};

// Scratch of merge_rows, kept between passes so that a pass allocates nothing once capacities have settled.
struct merge_buffers {
  std::vector<std::vector<int>> touched;       // per bucket: the pairs it updated
  std::vector<uint8_t> seen;                   // per pair: already in a touched list (all zero between calls)
  std::vector<uint8_t> dirty;                  // per pair: refolded in this refold (members; all zero between calls)
  std::vector<float> low;                      // refold's scan of children: per moved parent, the lower of its means
};

struct bayes_stats {
  std::vector<pair_moments> m;           // statistics: read and written between passes only (the posterior's
                                         // coefficients are computed from them when a weight is folded: not kept)
  std::vector<pair_weight> weight;       // point-prior mode: read by every shading point (empty in region-prior mode,
                                         // whose points read `w`, a function of these and mu0)
  std::vector<float> mu0;                // region-prior mode: the pair's prior mean of z (set with its region)
  std::vector<float> w;                  // region-prior mode: W per pair (+ 4 padding entries for SSE loads)
  std::vector<float> w_cv, cv;           // control variates: W of the residual, and E[1 - p0] k (+ 4 padding each)
  std::vector<uint8_t> unseen;           // region prior, per pair: 1 when bayes_params::unseen_cap applies to it (set
                                         // as its weight is folded; + 16 padding)
  std::vector<float> p1_folded;          // hierarchy, per pair: a parent's p1 when its children were last examined;
                                         // a child's p1 folded into its weight
  std::vector<float> k_folded;           // mean hierarchy, per parent pair: its posterior mean when its children were
                                         // last examined for it
  std::vector<float> gw, gw_cv, gcv;     // members (region_state::members), per cut entry: the sums of its members'
                                         // w, w_cv and cv (+ 4 padding each), what a point weighs the cluster by
  std::vector<double> gtot, gtot_cv;     // members, per cut entry: the total a member is chosen from inside the cluster
                                         // (its members' positive w, resp. w_cv, each floored at a tiny share of gw)
  std::vector<vec3f> gcol;               // members, per cut entry: the sum of its members' colour times cv (a point's
                                         // control-variate total adds it times the cluster's point factor)
  std::vector<uint8_t> gunseen;          // members, per cut entry: every member unseen (+ 16 padding)
  std::vector<float> mw, mw_cv;          // members, per pair: its w and w_cv as its cluster chooses members by them
                                         // (+ 4 padding each): an unseen member's at most the heaviest seen member's
                                         // of its cluster (bayes_params::unseen_cap), else its own; the cluster sums
                                         // and totals above are of these
  merge_buffers scratch;
  pair_coeffs empty = {};  // pair_coefficients of a pair without samples (set by resize_stats from the parameters)
};

// The posterior point estimates of pair i for prior mean mu0: k (mean of z) and h (variance of z); false when the
// naive ablation has no data (then there is no learned mean).
inline bool pair_posterior(const bayes_stats& s, size_t i, const bayes_params& p, double mu0, double& k, double& h) {
  double n1 = s.m[i].n1, z = s.m[i].mean, m2 = s.m[i].m2;
  if (!p.prior) {
    if (s.m[i].n0 + n1 == 0) return false;
    k = z;
    h = n1 >= 2 ? m2 / n1 : 0.0;
    return true;
  }
  double kn = p.kappa0 + n1;
  k = (p.kappa0 * mu0 + n1 * z) / kn;
  double an = p.alpha0 + 0.5 * n1;
  double dm = z - mu0;
  double bn = p.c * mu0 * mu0 * (p.alpha0 - 1) + 0.5 * (m2 + p.kappa0 * n1 * dm * dm / kn);
  h = bn / (an - 1);
  return true;
}

// Grows the columns to `pairs` entries (new pairs start empty, with prior-only weights).
void resize_stats(bayes_stats& s, int64_t pairs, const bayes_params& p);
// The coefficients of a pair's posterior (without the hierarchy) from its statistics, before rounding (inline, as
// pair_posterior above: fold_weight, between passes once per refolded pair, then drops what it does not read).
inline pair_coeffs_d pair_coefficients_d(const pair_moments& m, const bayes_params& p) {
  double n0 = m.n0, n1 = m.n1, z = m.mean, m2 = m.m2;
  double n = n0 + n1;
  double q2, q1 = 0, q0 = 0, qc = 0, p1;
  if (!p.prior) {
    // Naive plug-in moments; a pair without samples follows its bound (w = v).
    if (n == 0) {
      p1 = 1;
      q2 = 1;  // second moment: sqrt(v^2) = v; mean only: v
    } else {
      p1 = n1 / n;
      q2 = 0;
      if (p.second_moment) q0 = z * z + (n1 >= 2 ? m2 / n1 : 0.0);
      else q1 = z;
    }
  } else {
    // p1 = E[1 - p0]; mu_n = A mu0 + B; h = C mu0^2 + D + E (z - mu0)^2 (see bayes_stats.h).
    p1 = (p.b0 + n1) / (p.a0 + p.b0 + n);
    double kn = p.kappa0 + n1;
    double a = p.kappa0 / kn, b = n1 * z / kn;
    if (!p.second_moment) {
      q2 = a;
      q1 = b;
    } else {
      double am1 = p.alpha0 + 0.5 * n1 - 1;
      double c = p.c * (p.alpha0 - 1) / am1, d = 0.5 * m2 / am1, e = 0.5 * p.kappa0 * n1 / (kn * am1);
      q2 = a * a + c + e;
      q1 = 2 * a * b - 2 * e * z;
      q0 = b * b + d + e * z * z;
      qc = c;
    }
  }
  return {q2, q1, q0, qc, p1};
}
// The same rounded to float.
inline pair_coeffs pair_coefficients(const pair_moments& m, const bayes_params& p) {
  pair_coeffs_d c = pair_coefficients_d(m, p);
  return {float(c.q2), float(c.q1), float(c.q0), float(c.qc), float(c.p1)};
}
// Scales all statistics by gamma (animation: the prior regains weight); weights are refolded by the caller.
void decay_stats(bayes_stats& s, double gamma);

// E[1 - p0] of pair i under Beta(a0, b0) (plug-in n1 / n for the naive ablation), rounded to float: pair_coefficients'
// p1, without the rest.
inline float own_p1(const bayes_stats& s, size_t i, const bayes_params& p) {
  const pair_moments& m = s.m[i];
  double n = m.n0 + m.n1;
  if (!p.prior) return n == 0 ? 1.0f : float(m.n1 / n);
  return float((p.b0 + m.n1) / (p.a0 + p.b0 + n));
}
// E[1 - p0] of pair i, under the hierarchical prior when `up` (its parent pair) is valid.
inline double pair_p1(const bayes_stats& s, size_t i, int up, const bayes_params& p) {
  if (up < 0 || !(p.hierarchy > 0) || !p.prior) return own_p1(s, i, p);
  return (p.hierarchy * double(own_p1(s, size_t(up), p)) + s.m[i].n1) / (p.hierarchy + s.m[i].n0 + s.m[i].n1);
}
// Posterior mean of z of pair i under its own prior mean mu0 (what its fine children may start from).
inline double own_posterior_mean(const bayes_stats& s, size_t i, const bayes_params& p) {
  const pair_moments& m = s.m[i];
  return (p.kappa0 * double(s.mu0[i]) + m.n1 * m.mean) / (p.kappa0 + m.n1);
}
// Whether fine pairs take their prior mean from their coarse parents (region prior, hierarchy on, Bayesian prior).
inline bool uses_mean_hierarchy(const bayes_params& p) {
  return p.mean_hierarchy && p.region_prior && p.hierarchy > 0 && p.prior;
}
// Prior mean of z of pair i: its bound mu0, or under the mean hierarchy, for a fine pair (`up` its parent), the
// parent's posterior mean where that is lower. The parent's bound covers a larger box (never below the child's),
// so a parent without data changes nothing; the bound stays an upper limit of the prior mean.
inline double prior_mean(const bayes_stats& s, size_t i, int up, const bayes_params& p) {
  double mu0 = s.mu0[i];
  if (up < 0 || !uses_mean_hierarchy(p)) return mu0;
  return std::min(mu0, own_posterior_mean(s, size_t(up), p));
}
// Whether pair i is unseen (bayes_params::unseen_cap): no non-zero sample of its own nor of its parent `up` (when
// valid), after at least unseen_cap samples of the two together.
inline uint8_t pair_unseen(const bayes_stats& s, size_t i, int up, const bayes_params& p) {
  if (!(p.unseen_cap > 0) || !p.prior) return 0;
  double n1 = s.m[i].n1, n = s.m[i].n0;
  if (up >= 0) n1 += s.m[size_t(up)].n1, n += s.m[size_t(up)].n0;
  return n1 == 0 && n >= p.unseen_cap ? 1 : 0;
}
// Pair i's coefficients with p1 folded in: what a shading point evaluates in point-prior mode.
inline pair_weight folded_coeffs(const bayes_stats& s, size_t i, double p1, const bayes_params& p) {
  const pair_moments& m = s.m[i];
  // Most fine pairs have no samples of their own in a render's first passes (their weights follow their parents'):
  // their coefficients are the same constants.
  const bool none = m.n0 == 0 && m.n1 == 0 && m.mean == 0 && m.m2 == 0;
  const pair_coeffs c = none ? s.empty : pair_coefficients(m, p);
  return {float(p1 * c.q2), float(p1 * c.q1), float(p1 * c.q0), float(p1 * c.qc)};
}
// Folds pair i's p1 (and, under the mean hierarchy, its parent's mean) into its sampling weight.
template <class H>
inline double eval_weight(const H& h, const bayes_params& p, double v, double g);
// `sun`: the pair is the sun's (its control variate needs cv_sun_min_visible).
inline void fold_weight(bayes_stats& s, size_t i, int up, const bayes_params& p, bool sun) {
  double p1 = pair_p1(s, i, up, p);
  if (up >= 0) s.p1_folded[i] = float(p1);  // a child: the p1 its weight now holds (see bayes_sampler::refold)
  pair_weight pw = folded_coeffs(s, i, p1, p);
  if (!p.region_prior) {
    s.weight[i] = pw;  // read by every shading point in point-prior mode
    return;
  }
  // With v = mu0 g the weight is g times its value at g = 1 (see pair_coeffs): W = eval_weight(v = mu0, g = 1).
  double mu0 = prior_mean(s, i, up, p);
  double W = eval_weight(pw, p, mu0, 1.0);
  if (!(W <= max_pair_weight)) {
    // Squares of z beyond float's range: the weight from the coefficients in double, at most max_pair_weight (a
    // weight that is not finite would make every member of its cluster unchoosable).
    pair_coeffs_d c = pair_coefficients_d(s.m[i], p);
    W = eval_weight(pair_weight_d{p1 * c.q2, p1 * c.q1, p1 * c.q0, p1 * c.qc}, p, mu0, 1.0);
    if (!(W <= max_pair_weight)) W = max_pair_weight;
  }
  // A pair that can reach its region keeps a positive weight: the naive ablation's plug-in p1 is 0 after zero
  // samples only, and inside a cluster nothing else would keep such a member choosable.
  if (mu0 > 0 && W < min_pair_weight) W = min_pair_weight;
  s.w[i] = float(W);
  s.unseen[i] = pair_unseen(s, i, up, p);
  if (!p.control_variate) return;
  double k, h;
  // For the sun only where the region nearly always sees it: its shadow edges are sharp, so where its visibility is
  // mixed the region holds points fully in its shadow, often dark ones, at which c_J / P_J of a mean that large is a
  // firefly. A lamp's shadows are soft and its mean is one part of a point's light among others: its control
  // variate paid at any visibility on the data/ scenes (README).
  bool cv = p.second_moment && p1 >= (sun ? p.cv_sun_min_visible : p.cv_min_visible) &&
            pair_posterior(s, i, p, mu0, k, h);
  // The control variate's mean of z, cm: the posterior mean k, but never above the mean of the samples themselves
  // (the pair's own, or where it has none its parent's), and none where neither has a sample. A prior mean alone
  // can be far too large (a bound is an upper limit: a lamp facing a ceiling 1 mm away, which the rest of the
  // ceiling sees edge-on, has a bound there 10^4 times its contribution), and c_j from it made every estimate
  // (sum_j c_j - c_J / P_J + Y_J / P_J) noisier, there 100 times more than without control variates. Any c is
  // unbiased.
  double cm = k;
  if (cv) {
    if (s.m[i].n1 > 0) cm = std::min(k, s.m[i].mean);
    else if (up >= 0 && s.m[size_t(up)].n1 > 0) cm = std::min(k, s.m[size_t(up)].mean);
    else cv = false;
  }
  // Residual second moment E[(Z - c)^2] with c = p1 cm: p1 (k^2 + h) - 2 p1^2 cm k + p1^2 cm^2, which for cm = k is
  // p1 h + p1 (1 - p1) k^2.
  double w_cv = !cv ? 0.0
                : cm == k ? std::sqrt(p1 * h + p1 * (1 - p1) * k * k)
                          : std::sqrt(std::max(p1 * (k * k + h) - 2 * p1 * p1 * cm * k + p1 * p1 * cm * cm, 0.0));
  if (!cv || !(w_cv <= max_pair_weight && p1 * cm <= max_pair_weight)) {
    s.w_cv[i] = s.w[i];  // no learned mean (or the mean-only ablation, or one beyond float): no control variate
    s.cv[i] = 0;
    return;
  }
  if (mu0 > 0 && w_cv < min_pair_weight) w_cv = min_pair_weight;  // (the naive ablation's is 0 after one sample)
  s.w_cv[i] = float(w_cv);
  s.cv[i] = float(p1 * cm);
}
// Whether pair i's statistics and what sampling reads of it (its weight columns where the mode keeps them) are finite.
inline bool pair_state_finite(const bayes_stats& s, size_t i) {
  const pair_moments& m = s.m[i];
  bool ok = std::isfinite(m.n0) && std::isfinite(m.n1) && std::isfinite(m.mean) && std::isfinite(m.m2);
  if (i < s.weight.size()) {
    const pair_weight& x = s.weight[i];
    ok = ok && std::isfinite(x.w2) && std::isfinite(x.w1) && std::isfinite(x.w0) && std::isfinite(x.wc);
  }
  if (i < s.w.size()) ok = ok && std::isfinite(s.w[i]) && std::isfinite(s.w_cv[i]) && std::isfinite(s.cv[i]);
  return ok;
}
// Folds every pair's p1 into its weight (parents: region_state::pair_parent, or nullptr for none; nodes:
// region_state::pair_node, whose sun_cluster entries mark the sun's pairs, or nullptr where none is the sun): the
// sweep that ends learning between passes.
void refresh_weights(bayes_stats& s, const std::vector<int>* parents, const bayes_params& p,
                     const std::vector<int>* nodes);
// Weight of a pair for a point with prior mean v (= scale * bound) and g = 1 / d^2; 0 when v is 0.
template <class H>
inline double eval_weight(const H& h, const bayes_params& p, double v, double g) {
  if (!(v > 0)) return 0;
  if (!p.second_moment) return double(h.w2) * v + double(h.w1) * g;
  double val = (double(h.w2) * v + double(h.w1) * g) * v + double(h.w0) * g * g;
  return std::sqrt(std::max(val, double(h.wc) * v * v));
}

// One pair's statistics accumulated within one image row (Welford).
struct pair_accum {
  int pair;
  int up;  // the pair's parent (set by merge_rows)
  double n0, n1, mean, m2;
};

// The per-row state of the Bayesian sampler: region requests and pair accumulators. A region's pairs are consecutive,
// so accumulators are found by region: per region recorded into, a block of accumulator indices, one per pair (-1:
// none yet), found by the region's first pair (open addressing): one lookup per change of region, none per pair.
struct bayes_row {
  struct block_slot {
    int first;   // the block's first pair (-1: empty slot)
    int offset;  // the block's offset in `blocks`
  };
  region_requests requests;
  std::vector<block_slot> slots; // power-of-two table of blocks
  std::vector<int> blocks;       // per block, per pair of it: index into acc (-1: none yet)
  std::vector<pair_accum> acc;   // in first-touch order (deterministic within the row)
  std::vector<int> used;         // slots in use (cleared one by one: cheaper than refilling the table)
  std::vector<uint32_t> order;   // merge_rows: the row's updates (acc index * 2 + 1 for the parent's) by bucket
  std::vector<uint32_t> start;   // merge_rows: where each bucket's updates begin in `order` (buckets + 1)
  uint64_t generation = 0;      // incremented by clear(): caches of accumulator indices check it
  // The fallback check (bayes_sampler::check_fallback): the pixel being rendered and the Welford sums of its
  // samples' luminance in this pass (the pixel's variance goes to the sampler's column when the next one starts).
  int check_pixel = -1;
  double check_n = 0, check_mean = 0, check_m2 = 0;
  // The sum over the current pixel's samples of their variance: n s^2 with s^2 the unbiased sample variance.
  double check_pending() const { return check_n >= 2 ? check_m2 * check_n / (check_n - 1) : 0.0; }
  void clear();
  // Offset in `blocks` of the block of pairs [first, first + count) (a region's; created if absent). A block is
  // always asked for with the same count while the row state is not cleared (regions are frozen during a pass).
  int block_of(int first, int count);
  // Index in acc of the accumulator of pair first + j of the block at `offset` (created empty if absent).
  int slot_at(int offset, int first, int j) {
    int& s = blocks[size_t(offset + j)];
    if (s < 0) {
      s = int(acc.size());
      pair_accum& a = acc.emplace_back();  // (zeroed in place: a temporary's copy stalled on its own stores)
      a.pair = first + j;
      a.up = invalid_id;
    }
    return s;
  }
  // Index in acc of pair's accumulator (created empty if absent), in a block of its own (a row records either
  // through regions' blocks, bayes_sampler::record, or pair by pair, not both).
  int slot_of(int pair) { return slot_at(block_of(pair, 1), pair, 0); }
  // Adds sample z to accumulator acc[index] (Welford).
  void add_at(int index, double z);
  void add(int pair, double z) { add_at(slot_of(pair), z); }
};

// Folds the rows, in order, into the statistics (Chan's parallel update) — each accumulator into its pair and
// into that pair's parent (`parents` = region_state::pair_parent, or nullptr for none). Weights are not refolded
// (see fold_weight). Returns the touched pairs (each
// once, in an order fixed by the rows). Work and memory scale with the rows' accumulators, not with the pairs.
std::vector<int> merge_rows(bayes_stats& s, std::vector<bayes_row>& rows, const std::vector<int>* parents);

// Reference form of the weight (the conjugate posterior written out, in double): sqrt((1 - p0)(k^2 + h)) / d^2
// (or the ablations) from a pair's statistics and mu0 = scale * bound * d^2. eval_weight must agree with it.
double posterior_weight(const bayes_params& p, double bound, double scale, double d, double n0, double n1,
                        double mean, double m2);

}  // namespace bl
