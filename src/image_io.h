// image_io: reading and writing linear float RGB images (.exr, .pfm) and 8-bit sRGB PNGs.
// Invariants: pixels are RGB interleaved, row-major, top row first. Writes never leave a partial file at the
// destination: data go to a temporary file in the same directory, which is renamed over it when complete.
#pragma once

#include <string>
#include <vector>

namespace bl {

// A linear RGB float image.
struct image_data {
  int width = 0, height = 0;
  std::vector<float> pixels;  // 3 * width * height
};

enum class image_format { exr, pfm, png, unknown };
// The format chosen by the file's extension (case-insensitive).
image_format image_format_of(const std::string& path);

// Reads an .exr or .pfm image; throws input_error naming the file on any problem.
image_data read_image(const std::string& path);
// Reads a reference image for a render of width x height: its size must match and every value be finite (a
// NaN would make every error figure NaN); throws input_error naming the file otherwise.
image_data read_reference(const std::string& path, int width, int height);
// Throws input_error (exit 3) naming `path` and the first pixel (x, y from the top) with a NaN or infinite value.
void require_finite(const image_data& img, const std::string& path, const std::string& what);
// Writes by extension (.exr fp32, .pfm, .png sRGB 8-bit clamped); atomic; throws output_error on failure.
void write_image(const std::string& path, const image_data& img);

}  // namespace bl
