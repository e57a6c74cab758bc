// metrics: image error against a reference (SPEC.md section 6), computed in double in a fixed order.
// relMSE = mean over pixels and channels of (x - r)^2 / (r^2 + 0.01); MSE = mean of (x - r)^2;
// maxabs = max |x - r|. Non-finite pixel values make the metrics non-finite (they are never skipped).
#pragma once

#include "image_io.h"

#include <cstddef>
#include <string>

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
// True when both images have the same size and bit-identical pixel data.
bool bit_identical(const image_data& a, const image_data& b);

}  // namespace bl
