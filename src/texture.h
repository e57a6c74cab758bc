// texture: image textures of OBJ materials (map_Kd diffuse colour, map_d alpha cut-out mask).
// Invariants: texels are stored linear (8-bit sRGB images are decoded through a fixed float table), top row
// first; lookups wrap (repeat) in u and v, with v = 0 at the bottom of the image as in OBJ. All maths is
// float (powf for the sRGB tables, floorf for wrapping), so textures decode and filter identically on any CPU.
#pragma once

#include <string>
#include <vector>

#include "math.h"

namespace bl {

// Largest accepted image (width * height); 2^27 texels is 2 GiB of decoded rgb + alpha.
constexpr long long max_texture_texels = 1LL << 27;

// One decoded texture. rgb is linear; alpha is the cut-out mask in [0, 1] (from the alpha channel when the
// image has one, else from its first channel). Both have width*height entries, row-major, top row first.
struct texture_data {
  std::string path;
  int width = 0, height = 0;
  std::vector<vec3f> rgb;
  std::vector<float> alpha;
};

// Loads an image file (PNG, JPEG, TGA, BMP via stb_image); throws input_error naming the file on failure.
// 8-bit colour goes through the srgb8_to_linear table, 16-bit colour through the same sRGB curve in float;
// alpha is linear (value / max). HDR, GIF, PSD, PIC and PNM files are refused, as are images larger than
// max_texture_texels.
texture_data load_texture(const std::string& path);

// Linear RGB at texture coordinate uv (bilinear, repeat wrap).
vec3f eval_texture_rgb(const texture_data& tex, vec2f uv);
// Alpha mask at uv (nearest texel, repeat wrap): cut-outs keep hard edges and cost one fetch.
float eval_texture_alpha(const texture_data& tex, vec2f uv);

// sRGB-encoded 8-bit value to linear float (exact table of the sRGB EOTF in float maths).
float srgb8_to_linear(unsigned char v);

}  // namespace bl
