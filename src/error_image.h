// error_image: false-colour images of per-pixel relative error against a reference, for comparing samplers.
// Invariants: the error of a pixel is |x - r| / (|r| + 0.1) averaged over RGB; it is mapped logarithmically
// from the fixed range [min_error, max_error] (never from the image's own range, so images of different
// samplers compare directly) onto the perceptual viridis ramp; errors outside the range take the end colours,
// non-finite ones the top colour.
#pragma once

#include "image_io.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace bl {

// Options of the false-colour mapping.
struct error_image_params {
  float min_error = 1e-3f;  // relative error at the bottom of the ramp (dark purple) and below
  float max_error = 1;      // relative error at the top of the ramp (yellow) and above
};

// Per-pixel relative error, one float per pixel, row-major; throws std::invalid_argument when sizes differ.
std::vector<float> relative_error_map(const image_data& x, const image_data& ref);
// The 8-bit sRGB colour of t on the viridis ramp (t clamped to [0, 1]; NaN gives the top colour).
std::array<uint8_t, 3> viridis_srgb8(float t);
// PNG bytes of the false-colour error image of x against ref.
std::string encode_error_png(const image_data& x, const image_data& ref, const error_image_params& params);
// Writes the false-colour error image to a .png path atomically; throws output_error on failure.
void write_error_image(const std::string& path, const image_data& x, const image_data& ref,
                       const error_image_params& params);

}  // namespace bl
