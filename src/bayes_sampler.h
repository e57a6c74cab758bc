// bayes_sampler: the paper's method — Bayesian online regression of each (region, cluster) pair's
// contribution, with the bound as prior; clusters are chosen proportionally to the posterior estimate of the
// square root of their second moment, sqrt((1 - p0)(k^2 + h)) / d^2, optionally mixed with the bound pmf.
// Invariants: during a pass the statistics are frozen (read-only); between passes the rows' observations are
// folded in image order and requested regions are created, so images are identical for any thread count.
#pragma once

#include "bayes_stats.h"
#include "cut_sampling.h"
#include "bvh_sampler.h"
#include "simple_samplers.h"

#include <vector>

namespace bl {

// The Bayesian sampler; owns its regions and statistics, reads a light tree it does not own.
struct bayes_sampler {
  static constexpr bool learns = true;
  // Image rows per observation state: the rows of a band share one accumulator table, so a region seen by several
  // rows of the band folds as one record between passes (fewer records, same statistics up to rounding).
  static constexpr int rows_per_state = 4;
  using context = cut_context;
  using row_state = bayes_row;
  const light_tree_data* tree = nullptr;
  const light_data* lights = nullptr;
  region_state regions;
  bayes_stats stats;
  bayes_params params;
  float sun_sin = 0, sun_cos = 1;
  vec3f sun_color = {1, 1, 1};  // the sun's irradiance over its luminance
  bool frozen = false;  // oracle mode: statistics and regions no longer change
  // One light (a single emissive triangle, or the sun alone): nothing to choose, so nothing to learn. The sampler is
  // power sampling from the start (fallback set, no check, no learning, no region but the root, passes unweighted):
  // its image is `power`'s. (It learned for 33 spp first, and its pass weights cost it 0.83x power's relMSE at equal
  // spp in a sun-only scene; a review.)
  bool one_light = false;
  learn_timing timing;
  // Per pair: the fine pairs of a coarse pair as a linked list: a coarse pair's first child, a fine pair's next
  // sibling (two levels: a coarse pair has no siblings, a fine one no children); invalid_id ends the list.
  std::vector<int> child_link;
  size_t parent_pairs = 0;  // pairs with a list of children (coarse pairs whose fine regions exist)

  // Fallback (bayes_params::fallback_ratio, fallback_bvh_ratio): once on, lights are chosen by power (or, with
  // fallback_bvh, by the bvh sampler) and nothing more is learned.
  power_sampler power;
  bvh_sampler bvh;          // (its tree unset: no bvh alternative is checked)
  bool fallback = false;
  // The fallback chose the bvh sampler: its window voted for bvh and not for power. Where both vote, power is taken:
  // it costs half of bvh's time per sample, and stratification gains it more where every light is seen alike (a lamp
  // in 128 triangles, path traced, 3 s: falling back to power 7.3e-6 at 1195 spp, to bvh 1.05e-5 at 580, though the
  // estimates said power 2.7x and bvh 0.39x learning's error per sample).
  bool fallback_bvh = false;
  int fallback_votes = 0;  // consecutive check windows whose ratio was below the threshold
  double window_var = 0, window_delta = 0, window_samples = 0;  // the current window's sums (see check_fallback)
  double window_first = 0;  // ... and of power sampling's second moment at first vertices (path-traced renders)
  int fallback_spp = 0;    // spp rendered when it fell back (reports)
  bool check_done = false; // a window found learning to pay by at least twice the threshold: no more checks
  double check_ratio = 0;  // the last window's estimated relMSE ratio, power over learned (0: none yet)
  double check_ratio_bvh = 0;  // ... bvh over learned (0: none yet or not checked)
  // The current window's sums for bvh, over the pixels it checks (bvh_check_stride): the learned estimator's variance,
  // and bvh's second-moment change (as window_var's and window_delta's).
  double window_var_bvh = 0, window_delta_bvh = 0;
  // Per pixel, for the fallback check of the current pass (empty while it does not run): the sum over its samples
  // of their luminance's variance, and of its NEE events' second-moment change under power sampling. Each pixel is
  // written by the one task rendering its row (no races), and summed in pixel order.
  mutable std::vector<double> px_var, px_delta;  // (double: squares of radiance beyond float's range)
  mutable std::vector<double> px_delta_bvh;      // the same change under bvh sampling (empty: bvh is not checked)
  // bvh's probability costs a descent of the tree per NEE event (checked at every pixel, the first 24 spp took 1.5x as
  // long under 128 lights at 320 x 240, 1.17x in the hall): it is checked in the first max_bvh_windows windows only,
  // where a fallback gains most, and at every bvh_check_stride-th pixel only (a 320 x 240 window then holds 32768
  // samples' events; 1.0-1.07x and 1.04x).
  static constexpr int max_bvh_windows = 4;
  static constexpr int bvh_check_stride = 8;
  int bvh_windows = 0;  // windows that checked bvh so far
  bool checks_bvh() const {
    return bvh.tree != nullptr && params.fallback_bvh_ratio > 0 && bvh_windows < max_bvh_windows;
  }
  // Path-traced renders: per pixel, the sum over its first vertices' NEE events of their second moment under power
  // sampling (what stratifying the first vertex can make smaller; empty in direct renders, where that is every event).
  mutable std::vector<double> px_first;
  mutable std::vector<float> px_prev;  // passes of one spp: each pixel's sample luminance in the pass before (NaN: none)
  mutable std::vector<float> px_cur;   // ... and in the pass being rendered, which becomes px_prev once the pass is
                                       // complete (check_fallback): an interrupted pass leaves px_prev as it was
  bool check_pairs = false;            // the last pass had one spp: px_prev holds its samples
  // Before a pass whose NEE draws differ from the last pass's: half the squared difference of a pixel's samples in the
  // two passes would mix their variances (a 4-draw sample's beside a 1-draw one's underestimates the latter), so a
  // pass of one spp is then not checked (its samples still pair with the next pass's).
  void unpair() { check_pairs = false; }
  void flush_check(const row_state& row) const;
  // Forgets the check's state (a new frame: its film starts empty); the fallback itself stays.
  void restart_check();

  void locate(context& ctx, const shade_point& sp) const {
    if (!fallback) locate_region(ctx, regions, sp);
  }
  void prepare(context& ctx, const shade_point& sp) const;
  // Region-prior mode's weights at a point (prepare's fast path): W of each pair times its point factor (1 / d^2, the
  // receiver's cosine bound, and at a glossy point the Phong lobe's bound: over the members where the region has
  // them), zero for clusters entirely behind the point's surface.
  // `cv_allowed` false: no control variates at this point (their sum at it is beyond float).
  void prepare_region_prior(context& ctx, const shade_point& sp, bool cv_allowed = true) const;
  // A cluster by the point's cdf, then (a cluster of several members) a member by its weight, the cluster's share
  // of u rescaled to [0, 1) choosing it (so a stratified u stays stratified inside the cluster), then a light of the
  // member by intensity, from u's place inside the member's cell (place_in_cell). light_choice::cluster is the member
  // (the pair within the region).
  light_choice sample(const context& ctx, double u, double u_inner) const {
    if (fallback) return power.sample({}, u, u_inner);
    if (ctx.pair_count == ctx.count) return sample_cut(ctx, *tree, *lights, u, u_inner);
    return sample_members(ctx, u, u_inner);
  }
  float pmf(const context& ctx, int light) const {
    if (fallback) return power.pmf({}, light);
    return ctx.pair_count == ctx.count ? cut_pmf(ctx, *tree, *lights, light) : members_pmf(ctx, light);
  }
  light_choice sample_members(const context& ctx, double u, double u_inner) const;
  float members_pmf(const context& ctx, int light) const;
  // The cluster (cut entry) of member m of the context's region.
  int group_of(const context& ctx, int m) const {
    return ctx.pair_count == ctx.count ? m : regions.pair_slot[size_t(ctx.pair_base + m)] - ctx.group_base;
  }
  void record(row_state& row, const nee_event<context>& e) const;
  void sample_done(row_state& row, int pixel, vec3f l) const;
  // Between passes, before learn: the pass's estimated relMSE ratio of power sampling over the learned sampler
  // (pixel weights from `film`, sum_i w_i x_i over `weight` in RGB, which includes the pass); falls back when it was
  // below the threshold in two check windows in a row. Checked: passes that end at 4 spp or more, of two spp or more
  // (a pixel's variance from its own samples) or of one spp after one (from the pair); a window sums checked passes
  // until they hold bayes_params::fallback_window samples. A window whose ratio is at least twice the threshold ends
  // the checks (learning pays; it only improves). `pass_spp`: the pass's spp, `spp`: the total after it.
  // The check's columns are sized for the film's pixels.
  void check_fallback(const std::vector<row_state>& rows, const std::vector<double>& film, double weight,
                      int pass_spp, int spp);
  // The threshold's factor for a stratified first vertex, given a window's estimate of power sampling's variance
  // (`power_var`, relMSE-weighted) and its first vertices' second moment (`first`). Direct renders: every NEE event is
  // at the first vertex, and the factor is fallback_stratified s. Path-traced ones: stratification cuts only the first
  // vertex's share, at most min(power_var, first) (a variance is at most its second moment), to 1 / s of itself; the
  // factor is power_var over what is left, between 1 and s. 1 without stratification.
  double stratified_factor(double power_var, double first) const;
  // Control variates (prepare set ctx.cv): the emission colour of cluster j (luminance 1), the colour-weighted sum
  // of every cluster's learned mean c_j, and c_J of one cluster in colour.
  vec3f cluster_color(const context& ctx, int j) const {
    int node = ctx.members[j];
    return node == sun_cluster ? sun_color : tree->color[size_t(node)];
  }
  vec3f cv_total(const context& ctx) const { return ctx.cv_sum; }
  // c_m of member m (a cluster when every cluster is its own member, then from ctx.cvg).
  vec3f cv_cluster(const context& ctx, int m) const {
    if (ctx.pair_count == ctx.count) return cluster_color(ctx, m) * ctx.cvg[m];
    return cluster_color(ctx, m) * (stats.cv[size_t(ctx.pair_base + m)] * ctx.gfac[group_of(ctx, m)]);
  }
  // Whether member m has a control variate at the point (ctx.cv and a learned mean c_m != 0): NEE of its lights is
  // then unweighted at any vertex, and BSDF-sampled hits on them weigh 0 (cv_covers_light).
  bool cv_covers(const context& ctx, int m) const {
    if (!ctx.cv || m < 0) return false;
    return ctx.pair_count == ctx.count ? ctx.cvg[m] != 0
                                       : stats.cv[size_t(ctx.pair_base + m)] * ctx.gfac[group_of(ctx, m)] != 0;
  }
  bool cv_covers_light(const context& ctx, int light) const;
  void learn(std::vector<row_state>& rows);
  // Sizes the statistics for every region and sets the region-level prior means of the pairs of regions
  // [first_region, end) (a function of each region's box and cut only). Weights are refolded by the caller.
  void add_pairs(int first_region);
  // Reserves the columns for the pairs and cut entries of the regions, and room for what passes may add: every pair
  // the budget allows where that stays within max_reserved_bytes of address space, else half as many again (the
  // data/ scenes add 0-24 % at 320x240, the real Cornell box with its light in 128 triangles 23 %, but 53 % at
  // 128x96): growing a column copies it and touches its new pages, a pause of tenths of a second for the million
  // pairs of a scene with many lights, and the old and new copies add to the peak memory. Room never used costs
  // little (untouched pages are never mapped).
  void reserve_growth();
  // Reserves every column that grows with the pairs or the cut entries for that many; returns the bytes that takes
  // (count_only: only counts them).
  size_t reserve_columns(size_t pairs, size_t entries, bool count_only = false);
  static constexpr size_t max_reserved_bytes = size_t(1) << 30;
  // Refolds the weights of the pairs whose inputs changed in a pass: the touched pairs, the pairs new since
  // `old_pairs`, and the children of coarse pairs whose p1 moved by more than the refold tolerance. Work scales
  // with the pass's records and the moved parents' children; where more than 1/16 of the parents moved (the first
  // passes), with the pairs (one scan of them, and every cluster's sums again).
  void refold(const std::vector<int>& touched, size_t old_pairs);
  // Recomputes every derived column (prior means, coefficients, weights) from the regions and statistics.
  void rebuild_posterior();
  // Folds every pair's weight afresh, with the parents refold uses (none without the hierarchy: a fine pair's control
  // variate then never takes its coarse parent's mean either), and the clusters' sums.
  void refresh_all_weights();
  // Members: recomputes the cluster columns (gw, gw_cv, gcv) of the clusters of the given pairs (nullptr: all) from
  // their members' weights. Each cluster's sum runs over its members in order: a function of the weights only.
  // Given pairs must be listed once each and flagged in stats.scratch.dirty (refold does both). `dirty_only` (with
  // nullptr): only the clusters with a member flagged in stats.scratch.dirty (the others hold their sums already).
  void refresh_groups(const std::vector<int>* pairs, bool dirty_only = false);
  // Scales every statistic by `decay` (the prior regains weight) and refreshes the weights.
  void begin_frame(double decay);
};

}  // namespace bl
