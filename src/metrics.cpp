// metrics: relMSE, MSE and max |x - r| of an image against a reference (SPEC.md section 6).
// Sums run in double over the float values in index order (pixels, then channels), so the result does not
// depend on threads or on the machine. NaN and infinities propagate into the metrics instead of being skipped.
#include "metrics.h"

#include "errors.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace bl {

namespace {
// One channel's term of the relMSE: (x - r)^2 / (r^2 + 0.01), in double.
double relative_sq_error(double x, double r) {
  const double d = x - r;
  return d * d / (r * r + 0.01);
}
}  // namespace

error_metrics compute_error(const float* x, const float* ref, size_t n) {
  error_metrics m;
  if (n == 0) return m;
  double sum_rel = 0, sum_sq = 0, maxabs = 0;
  for (size_t i = 0; i < n; ++i) {
    const double r = ref[i], d = double(x[i]) - r, d2 = d * d;
    sum_rel += relative_sq_error(x[i], r);
    sum_sq += d2;
    const double ad = std::fabs(d);
    if (ad > maxabs || std::isnan(ad)) maxabs = ad;  // once NaN, stays NaN (NaN compares false)
  }
  m.relmse = sum_rel / double(n);
  m.mse = sum_sq / double(n);
  m.maxabs = maxabs;
  return m;
}

error_metrics compute_error(const image_data& x, const image_data& ref, const std::string& ref_name) {
  if (x.width != ref.width || x.height != ref.height || x.pixels.size() != ref.pixels.size())
    throw input_error(ref_name, "reference is " + std::to_string(ref.width) + "x" + std::to_string(ref.height) +
                                    " but the image is " + std::to_string(x.width) + "x" + std::to_string(x.height));
  return compute_error(x.pixels.data(), ref.pixels.data(), x.pixels.size());
}

error_metrics compute_error(const image_data& x, const image_data& ref) { return compute_error(x, ref, "reference"); }

error_spread spread_of_error(const image_data& x, const image_data& ref, size_t count) {
  if (x.width != ref.width || x.height != ref.height || x.pixels.size() != ref.pixels.size())
    compute_error(x, ref);  // (throws the size mismatch's error)
  error_spread s;
  const size_t n = ref.pixels.size() / 3;
  s.term.resize(n);
  double total = 0;
  for (size_t i = 0; i < n; i++) {
    double t = 0;
    for (size_t c = 0; c < 3; c++) t += relative_sq_error(x.pixels[3 * i + c], ref.pixels[3 * i + c]);
    s.term[i] = t / 3;
    total += s.term[i];
  }
  if (n == 0) return s;
  // Worst first, ties by index (a total order: the same list on every machine).
  auto worse = [&](size_t a, size_t b) { return s.term[a] > s.term[b] || (s.term[a] == s.term[b] && a < b); };
  size_t widest = 0;
  for (int k = 0; k < 3; k++) {
    s.tail_pixels[k] = std::max<size_t>(1, size_t(std::floor(error_tail_fractions[k] * double(n))));
    widest = std::max(widest, s.tail_pixels[k]);
  }
  const size_t ranked = std::min(n, std::max(widest, count));
  std::vector<size_t> order(n);
  for (size_t i = 0; i < n; i++) order[i] = i;
  std::partial_sort(order.begin(), order.begin() + ptrdiff_t(ranked), order.end(), worse);
  double run = 0;
  for (size_t k = 0, next = 0; k < 3; k++) {
    for (; next < s.tail_pixels[k]; next++) run += s.term[order[next]];
    s.tail_share[k] = total > 0 ? run / total : 0.0;
  }
  order.resize(std::min(count, n));
  s.worst = std::move(order);
  return s;
}

bool bit_identical(const image_data& a, const image_data& b) {
  if (a.width != b.width || a.height != b.height || a.pixels.size() != b.pixels.size()) return false;
  return a.pixels.empty() || std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(float)) == 0;
}

}  // namespace bl
