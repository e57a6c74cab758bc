// bayes_stats: accumulation, merging and the conjugate posterior.
#include "bayes_stats.h"

#include "rng.h"

#include <algorithm>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <xmmintrin.h>
#include <cmath>

namespace bl {

void resize_stats(bayes_stats& s, int64_t pairs, const bayes_params& p) {
  size_t old = s.m.size(), n = size_t(pairs);
  s.empty = pair_coefficients(pair_moments{}, p);
  s.m.resize(n);
  s.weight.resize(p.region_prior ? 0 : n);
  s.mu0.resize(n, 0.0f);
  s.w.resize(n + 4, 0.0f);
  s.w_cv.resize(n + 4, 0.0f);
  s.cv.resize(n + 4, 0.0f);
  s.unseen.resize(n + 16, 0);
  if (n > old) {
    // All empty pairs share the prior-only coefficients (and, without data anywhere, the same weight).
    fold_weight(s, old, invalid_id, p, false);  // (no samples: no control variate, lamp or sun)
    for (size_t i = old + 1; i < n; i++) {
      if (!p.region_prior) s.weight[i] = s.weight[old];
      s.w[i] = s.w[old];
      s.w_cv[i] = s.w_cv[old];
      s.cv[i] = s.cv[old];
      s.unseen[i] = s.unseen[old];
    }
  }
  s.p1_folded.resize(n, n == 0 ? 1.0f : own_p1(s, n - 1, p));
  s.k_folded.resize(n, 0.0f);  // a parentless pair's is set by bayes_sampler::refold and refresh_weights
}

void decay_stats(bayes_stats& s, double gamma) {
  for (size_t i = 0; i < s.m.size(); i++) {
    s.m[i].n0 *= gamma;
    s.m[i].n1 *= gamma;
    s.m[i].m2 *= gamma;  // the mean is unchanged by scaling all weights
  }
}

void bayes_row::clear() {
  requests.clear();
  for (int h : used) slots[size_t(h)].first = -1;
  used.clear();
  blocks.clear();
  acc.clear();
  generation++;
  check_pixel = -1;
  check_n = check_mean = check_m2 = 0;
}

int bayes_row::block_of(int first, int count) {
  // Fibonacci hashing of the first pair (regions' first pairs are distinct, tens apart).
  auto home = [](int key, size_t mask) {
    return size_t((uint64_t(uint32_t(key)) * 0x9e3779b97f4a7c15ull) >> 32) & mask;
  };
  if (2 * (used.size() + 1) > slots.size()) {
    // Grow and rehash (load <= 1/2).
    size_t n = std::max<size_t>(64, slots.size() * 2);
    std::vector<block_slot> old(n, block_slot{-1, 0});
    old.swap(slots);
    used.clear();
    for (const block_slot& b : old) {
      if (b.first < 0) continue;
      size_t h = home(b.first, n - 1);
      while (slots[h].first >= 0) h = (h + 1) & (n - 1);
      slots[h] = b;
      used.push_back(int(h));
    }
  }
  size_t mask = slots.size() - 1;
  size_t h = home(first, mask);
  while (slots[h].first >= 0 && slots[h].first != first) h = (h + 1) & mask;
  if (slots[h].first < 0) {
    slots[h] = {first, int(blocks.size())};
    used.push_back(int(h));
    blocks.resize(blocks.size() + size_t(count), -1);
  }
  return slots[h].offset;
}

void bayes_row::add_at(int index, double z) {
  pair_accum& a = acc[size_t(index)];
  if (z == 0) {
    a.n0 += 1;
    return;
  }
  a.n1 += 1;
  double delta = z - a.mean;
  a.mean += delta / a.n1;
  a.m2 += delta * (z - a.mean);
}

void refresh_weights(bayes_stats& s, const std::vector<int>* parents, const bayes_params& p,
                     const std::vector<int>* nodes) {
  // Every pair independently (the result does not depend on how the range is split).
  tbb::parallel_for(tbb::blocked_range<size_t>(0, s.m.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i < r.end(); i++) {
      int up = parents ? (*parents)[i] : invalid_id;
      fold_weight(s, i, up, p, nodes && (*nodes)[i] == sun_cluster);
      if (up < 0) {
        s.p1_folded[i] = own_p1(s, i, p);
        s.k_folded[i] = float(own_posterior_mean(s, i, p));
      }
    }
  });
}

// Chan's parallel update of a pair's statistics with an accumulator.
static void merge_accum(pair_moments& m, const pair_accum& a) {
  m.n0 += a.n0;
  if (a.n1 > 0) {
    double n = m.n1 + a.n1;
    double delta = a.mean - m.mean;
    m.mean += delta * (a.n1 / n);
    m.m2 += a.m2 + delta * delta * (m.n1 * a.n1 / n);
    m.n1 = n;
  }
}

std::vector<int> merge_rows(bayes_stats& s, std::vector<bayes_row>& rows, const std::vector<int>* parents) {
  // Each accumulator updates its pair and that pair's parent. The updates of one pair must happen in row order (the
  // order fixes the floating-point result). Buckets (disjoint pair ranges) fold in parallel, each taking its updates
  // row by row in order: bit for bit the sequential fold for any number of buckets, so the count may follow the
  // thread count. Work: a few passes over the rows' accumulators, nothing per pair.
  size_t n = s.m.size();
  merge_buffers& mb = s.scratch;
  const size_t buckets = std::clamp<size_t>(4 * size_t(tbb::this_task_arena::max_concurrency()), 1, 256);
  const size_t span = std::max<size_t>(1, (n + buckets - 1) / buckets);
  // Per row, in parallel: the parents, and the row's updates sorted by bucket (a counting sort that keeps their
  // order within each bucket).
  tbb::parallel_for(size_t(0), rows.size(), [&](size_t r) {
    bayes_row& row = rows[r];
    row.start.assign(buckets + 1, 0);
    for (pair_accum& a : row.acc) {
      a.up = parents ? (*parents)[size_t(a.pair)] : invalid_id;
      row.start[size_t(a.pair) / span + 1]++;
      if (a.up != invalid_id) row.start[size_t(a.up) / span + 1]++;
    }
    for (size_t b = 0; b < buckets; b++) row.start[b + 1] += row.start[b];
    row.order.resize(row.start[buckets]);
    uint32_t* pos = row.start.data();  // advanced while filling, then restored below
    for (size_t k = 0; k < row.acc.size(); k++) {
      const pair_accum& a = row.acc[k];
      row.order[pos[size_t(a.pair) / span]++] = uint32_t(2 * k);
      if (a.up != invalid_id) row.order[pos[size_t(a.up) / span]++] = uint32_t(2 * k + 1);
    }
    for (size_t b = buckets; b > 0; b--) row.start[b] = row.start[b - 1];  // pos[b] ended at the next start
    row.start[0] = 0;
  });
  mb.touched.resize(buckets);
  if (mb.seen.size() < n) mb.seen.resize(n, 0);
  tbb::parallel_for(size_t(0), buckets, [&](size_t b) {
    std::vector<int>& touched = mb.touched[b];
    touched.clear();
    const size_t lo = b * span;
    // The pair an update goes to (its statistics and flag are fetched `ahead` updates early: they are scattered over
    // the columns, and each update waits on their loads).
    constexpr uint32_t ahead = 8;
    auto target = [](const bayes_row& row, uint32_t k) {
      uint32_t t = row.order[k];
      const pair_accum& a = row.acc[t >> 1];
      return (t & 1) ? a.up : a.pair;
    };
    for (const bayes_row& row : rows)
      for (uint32_t k = row.start[b], e = row.start[b + 1]; k < e; k++) {
        if (k + ahead < e) {
          int next = target(row, k + ahead);
          _mm_prefetch(reinterpret_cast<const char*>(&s.m[size_t(next)]), _MM_HINT_T0);
          _mm_prefetch(reinterpret_cast<const char*>(&mb.seen[size_t(next)]), _MM_HINT_T0);
        }
        uint32_t t = row.order[k];
        const pair_accum& a = row.acc[t >> 1];
        int pair = (t & 1) ? a.up : a.pair;
        merge_accum(s.m[size_t(pair)], a);
        uint8_t& seen = mb.seen[size_t(pair)];
        if (!seen) seen = 1, touched.push_back(pair);
      }
    // The touched pairs in pair order for the locality of the weight refold that follows, where most of the bucket
    // was touched (by a scan of its flags).
    if (touched.size() * 16 > span) {
      touched.clear();
      for (size_t i = lo, e = std::min(n, size_t(lo) + span); i < e; i++)
        if (mb.seen[i]) touched.push_back(int(i));
    }
    for (int i : touched) mb.seen[size_t(i)] = 0;
  });
  std::vector<int> out;
  size_t total = 0;
  for (size_t b = 0; b < buckets; b++) total += mb.touched[b].size();
  out.reserve(total);
  for (size_t b = 0; b < buckets; b++) out.insert(out.end(), mb.touched[b].begin(), mb.touched[b].end());
  return out;
}

double posterior_weight(const bayes_params& p, double bound, double scale, double d, double n0, double n1,
                        double mean, double m2) {
  if (!(bound > 0)) return 0;
  double d2 = d * d;
  double mu0 = scale * bound * d2;
  if (!p.prior) {
    // Naive plug-in estimates; a cluster without samples follows its bound.
    double n = n0 + n1;
    if (n == 0) return mu0 / d2;
    double p1 = n1 / n;  // (E[1 - p0] formed directly: 1 - p0 cancels when n0 is large, a review)
    double h = n1 >= 2 ? m2 / n1 : 0.0;
    if (!p.second_moment) return p1 * mean / d2;
    return std::sqrt(p1 * (mean * mean + h)) / d2;
  }
  double p1 = (p.b0 + n1) / (p.a0 + p.b0 + n0 + n1);
  double kn = p.kappa0 + n1;
  double mun = (p.kappa0 * mu0 + n1 * mean) / kn;
  if (!p.second_moment) return p1 * mun / d2;
  double an = p.alpha0 + 0.5 * n1;
  double beta0 = p.c * mu0 * mu0 * (p.alpha0 - 1);
  double dm = mean - mu0;
  double bn = beta0 + 0.5 * (m2 + p.kappa0 * n1 * dm * dm / kn);
  double h = bn / (an - 1);
  return std::sqrt(p1 * (mun * mun + h)) / d2;
}

}  // namespace bl
