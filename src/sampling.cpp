// sampling: discrete distributions (the rest of the warps are inline in the header).
#include "sampling.h"

#include <emmintrin.h>

#include <algorithm>

namespace bl {

namespace {

// max(w, floor) where w > 0, else 0 (NaN included), without a branch.
inline double floored(double w, double floor) {
  __m128d x = _mm_set_sd(w);
  __m128d positive = _mm_cmpgt_sd(x, _mm_setzero_pd());
  return _mm_cvtsd_f64(_mm_and_pd(_mm_max_sd(x, _mm_set_sd(floor)), positive));
}

// c[j] = (c[j] + off) * inv for j < n, two at a time (the same IEEE operations as the scalar form; x + 0 == x).
inline void scale_cdf(double* c, int n, double off, double inv) {
  const __m128d o = _mm_set1_pd(off), s = _mm_set1_pd(inv);
  int j = 0;
  for (; j + 2 <= n; j += 2) _mm_storeu_pd(c + j, _mm_mul_pd(_mm_add_pd(_mm_loadu_pd(c + j), o), s));
  if (j < n) c[j] = (c[j] + off) * inv;
}

}  // namespace

bool fill_cdf(const double* w, int n, double* cdf) {
  // Sums run as four interleaved chains (instruction-level parallelism; a fixed order, so deterministic): the total
  // over four lanes, and the running sums over the array's four quarters, each quarter then shifted by the sum of
  // the quarters before it. Shifted boundaries agree bit for bit (the same addition), so cdf is non-decreasing and
  // an item of weight zero keeps probability exactly zero.
  double lane[4] = {0, 0, 0, 0};
  int i = 0;
  for (; i + 4 <= n; i += 4)
    for (int l = 0; l < 4; l++) lane[l] += std::max(0.0, w[i + l]);  // maxsd: NaN and negatives give 0
  for (; i < n; i++) lane[0] += std::max(0.0, w[i]);
  double total = (lane[0] + lane[1]) + (lane[2] + lane[3]);
  cdf[0] = 0;
  if (!(total > 0) || !std::isfinite(total)) {
    for (int k = 0; k < n; k++) cdf[k + 1] = 0;
    return false;
  }
  // Floor every positive weight so that no item that can contribute rounds to probability zero (written without
  // branches: zero weights come in unpredictable patterns).
  const double floor = total * min_positive_share;
  // Running sums: short cdfs (most cuts) in one chain, longer ones over four quarters [0, q), [q, 2q), [2q, 3q) (full:
  // 3q <= n for n >= 9) and the rest, each quarter then shifted by the sum of the quarters before it.
  if (n < 9) {
    double a = 0;
    for (int k = 0; k < n; k++) cdf[k + 1] = a += floored(w[k], floor);
    scale_cdf(cdf + 1, n, 0.0, 1 / a);
  } else {
    const int q = (n + 3) / 4;
    const int tail = n - 3 * q;
    double a0 = 0, a1 = 0, a2 = 0, a3 = 0;
    const double* w1 = w + q;
    const double* w2 = w + 2 * q;
    const double* w3 = w + 3 * q;
    double* c0 = cdf + 1;
    double* c1 = cdf + 1 + q;
    double* c2 = cdf + 1 + 2 * q;
    double* c3 = cdf + 1 + 3 * q;
    for (int k = 0; k < tail; k++) {
      c0[k] = a0 += floored(w[k], floor);
      c1[k] = a1 += floored(w1[k], floor);
      c2[k] = a2 += floored(w2[k], floor);
      c3[k] = a3 += floored(w3[k], floor);
    }
    for (int k = tail; k < q; k++) {
      c0[k] = a0 += floored(w[k], floor);
      c1[k] = a1 += floored(w1[k], floor);
      c2[k] = a2 += floored(w2[k], floor);
    }
    const double off1 = a0, off2 = a1 + off1, off3 = a2 + off2;
    const double inv = 1 / (a3 + off3);
    scale_cdf(c0, q, 0.0, inv);
    scale_cdf(c1, q, off1, inv);
    scale_cdf(c2, q, off2, inv);
    scale_cdf(c3, tail, off3, inv);
  }
  int last = n - 1;
  while (last >= 0 && !(w[last] > 0)) last--;
  for (int k = last; k < n; k++) cdf[k + 1] = 1.0;  // exact end point
  return true;
}

discrete_data make_discrete(const float* weights, int n) {
  discrete_data d;
  std::vector<double> w(static_cast<size_t>(n));
  for (int i = 0; i < n; i++) w[size_t(i)] = weights[i];
  d.cdf.resize(size_t(n) + 1);
  if (!fill_cdf(w.data(), n, d.cdf.data())) {
    d.cdf.clear();
    return d;
  }
  if (n > 16) {
    d.guide.resize(size_t(n));
    for (int k = 0; k < n; k++) d.guide[size_t(k)] = sample_cdf(d.cdf.data(), n, double(k) / n);
  }
  return d;
}

int sample_discrete(const discrete_data& d, double u) {
  if (d.cdf.empty()) return -1;
  int n = int(d.cdf.size()) - 1;
  if (d.guide.empty()) return sample_cdf(d.cdf.data(), n, u);
  // From the item at the start of u's guide cell, walk to the one whose [cdf[i], cdf[i+1]) holds u (back as well,
  // should rounding put u below the cell's start): the item sample_cdf finds.
  int i = d.guide[size_t(std::min(std::max(int(u * n), 0), n - 1))];
  while (i > 0 && d.cdf[size_t(i)] > u) i--;
  while (i < n - 1 && d.cdf[size_t(i) + 1] <= u) i++;
  return i;
}

int sample_cdf(const double* cdf, int n, double u) {
  // First cdf entry > u, minus one: the item whose half-open cell [cdf[i], cdf[i+1]) contains u. Short cdfs
  // (most cuts: a handful of clusters) count the entries <= u without branches, which is the same index for a
  // non-decreasing cdf and avoids the binary search's unpredictable jumps.
  int i;
  if (n <= 16) {
    i = 0;
    for (int k = 1; k <= n; k++) i += cdf[k] <= u;
  } else {
    i = int(std::upper_bound(cdf + 1, cdf + n + 1, u) - (cdf + 1));
  }
  return std::min(std::max(i, 0), n - 1);
}

}  // namespace bl
