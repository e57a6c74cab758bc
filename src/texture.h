// texture: image textures of OBJ materials (map_Kd diffuse colour, map_d alpha cut-out mask).
// Invariants: texels are stored linear (8-bit sRGB images are decoded through a fixed float table), top row
// first; lookups wrap (repeat) in u and v, with v = 0 at the bottom of the image as in OBJ.
#pragma once

#include "math.h"

#include <string>
#include <vector>

namespace bl {

// One decoded texture. rgb is linear; alpha is the cut-out mask in [0, 1] (from the alpha channel when the
// image has one, else from its first channel). Both have width*height entries, row-major, top row first.
struct texture_data {
  std::string path;
  int width = 0, height = 0;
  std::vector<vec3f> rgb;
  std::vector<float> alpha;
};

// Loads an image file (PNG, JPEG, TGA, BMP via stb_image); throws input_error naming the file on failure.
texture_data load_texture(const std::string& path);

// Linear RGB at texture coordinate uv (bilinear, repeat wrap).
vec3f eval_texture_rgb(const texture_data& tex, vec2f uv);
// Alpha mask at uv (nearest texel, repeat wrap): cut-outs keep hard edges and cost one fetch.
float eval_texture_alpha(const texture_data& tex, vec2f uv);

// sRGB-encoded 8-bit value to linear float (exact table of the sRGB EOTF in float maths).
float srgb8_to_linear(unsigned char v);

}  // namespace bl
