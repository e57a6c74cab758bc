// error_image: relative error map, viridis ramp (9 stops of matplotlib's viridis, interpolated linearly in
// sRGB 8-bit space) and PNG encoding with stb_image_write, written through write_file_atomic.
#include "error_image.h"

#include "errors.h"
#include "file_io.h"

#include <stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace bl {

// Stop k of viridis at t = k / 8, sRGB 8-bit.
static const uint8_t viridis_stops[9][3] = {{0x44, 0x01, 0x54}, {0x47, 0x2d, 0x7b}, {0x3b, 0x52, 0x8b},
                                            {0x2c, 0x72, 0x8e}, {0x21, 0x91, 0x8c}, {0x28, 0xae, 0x80},
                                            {0x5e, 0xc9, 0x62}, {0xad, 0xdc, 0x30}, {0xfd, 0xe7, 0x25}};

// stb_image_write's output callback: appends to a std::string.
static void append_png_bytes(void* context, void* data, int size) {
  static_cast<std::string*>(context)->append(static_cast<const char*>(data), size_t(size));
}

std::vector<float> relative_error_map(const image_data& x, const image_data& ref) {
  if (x.width != ref.width || x.height != ref.height || x.pixels.size() != ref.pixels.size())
    throw std::invalid_argument("relative_error_map: image and reference sizes differ");
  size_t n = size_t(x.width) * size_t(x.height);
  std::vector<float> err(n);
  for (size_t i = 0; i < n; i++) {
    double sum = 0;
    for (int c = 0; c < 3; c++) {
      double xv = x.pixels[3 * i + c], rv = ref.pixels[3 * i + c];
      sum += std::fabs(xv - rv) / (std::fabs(rv) + 0.1);
    }
    err[i] = float(sum / 3);
  }
  return err;
}

std::array<uint8_t, 3> viridis_srgb8(float t) {
  if (!(t >= 0)) t = std::isnan(t) ? 1.0f : 0.0f;
  if (t > 1) t = 1;
  float s = t * 8;
  int k = std::min(7, int(s));
  float f = s - float(k);
  std::array<uint8_t, 3> c;
  for (int j = 0; j < 3; j++)
    c[j] = uint8_t(std::lround(float(viridis_stops[k][j]) * (1 - f) + float(viridis_stops[k + 1][j]) * f));
  return c;
}

std::string encode_error_png(const image_data& x, const image_data& ref, const error_image_params& params) {
  std::vector<float> err = relative_error_map(x, ref);
  std::vector<unsigned char> codes(err.size() * 3);
  // t = log(e / min) / log(max / min): equal ratios of error are equal steps along the ramp.
  double lo = std::log(double(std::max(params.min_error, 1e-30f)));
  double span = std::log(double(std::max(params.max_error, params.min_error * 10))) - lo;
  for (size_t i = 0; i < err.size(); i++) {
    float t = !std::isfinite(err[i]) ? 1.0f : err[i] <= 0 ? 0.0f : float((std::log(double(err[i])) - lo) / span);
    std::array<uint8_t, 3> c = viridis_srgb8(t);
    for (int j = 0; j < 3; j++) codes[3 * i + j] = c[j];
  }
  std::string out;
  if (x.width <= 0 || x.height <= 0 ||
      !stbi_write_png_to_func(append_png_bytes, &out, x.width, x.height, 3, codes.data(), x.width * 3))
    throw output_error("PNG encoding of the error image failed");
  return out;
}

void write_error_image(const std::string& path, const image_data& x, const image_data& ref,
                       const error_image_params& params) {
  std::string bytes;
  try {
    bytes = encode_error_png(x, ref, params);
  } catch (const output_error& e) {
    throw output_error("cannot write " + path + ": " + e.what());
  }
  write_file_atomic(path, bytes);
}

}  // namespace bl
