// sampling: discrete distributions (the rest of the warps are inline in the header).
#include "sampling.h"

#include <algorithm>

namespace bl {

discrete_data make_discrete(const float* weights, int n) {
  discrete_data d;
  double total = 0;
  for (int i = 0; i < n; i++) total += weights[i] > 0 ? double(weights[i]) : 0.0;
  if (!(total > 0) || !std::isfinite(total)) return d;
  d.cdf.resize(size_t(n) + 1);
  double acc = 0;
  d.cdf[0] = 0;
  for (int i = 0; i < n; i++) {
    acc += weights[i] > 0 ? double(weights[i]) : 0.0;
    d.cdf[size_t(i) + 1] = float(acc / total);
  }
  // Exact end point; items after the last positive weight get zero width.
  int last = n - 1;
  while (last > 0 && !(weights[last] > 0)) last--;
  for (int i = last; i < n; i++) d.cdf[size_t(i) + 1] = 1.0f;
  return d;
}

int sample_discrete(const discrete_data& d, float u) {
  if (d.cdf.empty()) return -1;
  // First cdf entry > u, minus one: the item whose half-open cell [cdf[i], cdf[i+1]) contains u.
  auto it = std::upper_bound(d.cdf.begin(), d.cdf.end(), u);
  int i = int(it - d.cdf.begin()) - 1;
  int n = int(d.cdf.size()) - 1;
  return std::min(std::max(i, 0), n - 1);
}

}  // namespace bl
