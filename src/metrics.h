// metrics: image error against a reference (SPEC.md section 6), computed in double in a fixed order.
// relMSE = mean over pixels and channels of (x - r)^2 / (r^2 + 0.01); MSE = mean of (x - r)^2;
// maxabs = max |x - r|. Non-finite pixel values make the metrics non-finite (they are never skipped).
#pragma once

#include "image_io.h"

#include <cstddef>
#include <string>
#include <vector>

namespace bl {

// Error of an image against a reference of the same size.
struct error_metrics {
  double relmse = 0, mse = 0, maxabs = 0;
};

// Metrics of n floats x against n floats ref (all zero when n = 0).
error_metrics compute_error(const float* x, const float* ref, size_t n);
// Metrics of two images; throws input_error if their sizes differ (names both sizes).
error_metrics compute_error(const image_data& x, const image_data& ref);
// The same, with the reference's file name as the input_error's file (the two-argument form uses "reference").
error_metrics compute_error(const image_data& x, const image_data& ref, const std::string& ref_name);
// Where an image's relMSE lies (diff --worst, --error-map): pixel i's term is the mean over its three channels of
// (x - r)^2 / (r^2 + 0.01), so that the relMSE is the mean of the terms. The shares are those of the relMSE held by
// the worst 0.1 %, 1 % and 5 % of the pixels (each at least one pixel; 0 where the relMSE is 0); `worst` holds the
// indices of the `count` worst pixels (at most all), worst first, ties by index. Throws input_error if the sizes
// differ, as compute_error does.
struct error_spread {
  std::vector<double> term;
  size_t tail_pixels[3] = {0, 0, 0};
  double tail_share[3] = {0, 0, 0};
  std::vector<size_t> worst;
};
inline constexpr double error_tail_fractions[3] = {0.001, 0.01, 0.05};
error_spread spread_of_error(const image_data& x, const image_data& ref, size_t count);
// True when both images have the same size and bit-identical pixel data.
bool bit_identical(const image_data& a, const image_data& b);

}  // namespace bl
