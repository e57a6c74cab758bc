// bayes_stats: the per (region, cluster) statistics of the Bayesian sampler and its posterior (METHOD.md 3-5).
// Data model: a sample Y of a cluster at distance d is zero with probability p0, else z = Y d^2 ~ N(k, h).
// Priors: p0 ~ Beta(a0, b0); (k, h) ~ Normal-inverse-gamma(mu0, kappa0, alpha0, beta0) with mu0 from the
// bound and beta0 = c mu0^2 (alpha0 - 1) (scale-free). Invariants: statistics are kept as count, mean and sum of
// squared deviations (Welford/Chan: no cancellation); rows are folded in image order, so the result never
// depends on thread timing; every posterior weight of a cluster with a non-zero bound is finite and > 0.
#pragma once

#include "cut_sampling.h"

#include <cstdint>
#include <vector>

namespace bl {

// Prior strengths and ablation switches.
struct bayes_params {
  double a0 = 1, b0 = 1;         // Beta prior of the zero-sample probability p0
  double kappa0 = 1;             // prior pseudo-count of the mean
  double alpha0 = 2;             // inverse-gamma shape (> 1)
  double c = 1;                  // prior squared coefficient of variation: beta0 = c mu0^2 (alpha0 - 1)
  double epsilon = 0;            // defensive mixing with the bound pmf
  bool second_moment = true;     // false: pmf from the posterior mean only (ablation)
  bool distance_regression = true;  // false: z = Y, no 1/d^2 model (ablation)
  bool prior = true;             // false: plug-in sample moments, the naive adaptive method (ablation)
  double decay = 1;              // statistics scale per animation frame (1: keep everything)
};

// Statistics columns, one entry per (region, cluster) pair.
struct bayes_stats {
  std::vector<double> n0, n1, mean, m2;
};

// Grows the columns to `pairs` entries (new pairs start empty).
void resize_stats(bayes_stats& s, int64_t pairs);
// Scales all statistics by gamma (animation: the prior regains weight).
void decay_stats(bayes_stats& s, double gamma);

// One pair's statistics accumulated within one image row (Welford).
struct pair_accum {
  int pair;
  double n0, n1, mean, m2;
};

// The per-row state of the Bayesian sampler: region requests and pair accumulators (open addressing).
struct bayes_row {
  region_requests requests;
  std::vector<int> slots;        // power-of-two table of indices into acc (-1: empty)
  std::vector<pair_accum> acc;   // in first-touch order (deterministic within the row)
  void clear();
  void add(int pair, double z);
};

// Folds the rows, in order, into the statistics (Chan's parallel update).
void merge_rows(bayes_stats& s, const std::vector<bayes_row>& rows);

// Posterior sampling weight of one cluster: sqrt((1 - p0)(k^2 + h)) / d^2 (or the ablations), from its statistics
// and the prior mean mu0 = scale * bound * d^2. Returns 0 when bound is 0.
double posterior_weight(const bayes_params& p, double bound, double scale, double d, double n0, double n1,
                        double mean, double m2);

}  // namespace bl
