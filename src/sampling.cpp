// sampling: discrete distributions (the rest of the warps are inline in the header).
#include "sampling.h"

#include <algorithm>

namespace bl {

bool fill_cdf(const double* w, int n, double* cdf) {
  double total = 0;
  for (int i = 0; i < n; i++) total += w[i] > 0 ? w[i] : 0.0;
  cdf[0] = 0;
  if (!(total > 0) || !std::isfinite(total)) {
    for (int i = 0; i < n; i++) cdf[i + 1] = 0;
    return false;
  }
  // Floor every positive weight so that no item that can contribute rounds to probability zero (written without
  // branches: zero weights come in unpredictable patterns).
  double floor = total * min_positive_share, acc = 0;
  int last = -1;
  for (int i = 0; i < n; i++) {
    bool positive = w[i] > 0;
    acc += positive ? std::max(w[i], floor) : 0.0;
    last = positive ? i : last;
    cdf[i + 1] = acc;
  }
  double inv = 1 / acc;
  for (int i = 0; i < n; i++) cdf[i + 1] *= inv;
  for (int i = last; i < n; i++) cdf[i + 1] = 1.0;  // exact end point
  return true;
}

discrete_data make_discrete(const float* weights, int n) {
  discrete_data d;
  std::vector<double> w(static_cast<size_t>(n));
  for (int i = 0; i < n; i++) w[size_t(i)] = weights[i];
  d.cdf.resize(size_t(n) + 1);
  if (!fill_cdf(w.data(), n, d.cdf.data())) d.cdf.clear();
  return d;
}

int sample_cdf(const double* cdf, int n, double u) {
  // First cdf entry > u, minus one: the item whose half-open cell [cdf[i], cdf[i+1]) contains u.
  int i = int(std::upper_bound(cdf + 1, cdf + n + 1, u) - (cdf + 1));
  return std::min(std::max(i, 0), n - 1);
}

}  // namespace bl
