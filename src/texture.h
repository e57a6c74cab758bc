// texture: image textures of OBJ materials (map_Kd diffuse colour, map_d alpha cut-out mask).
// Invariants: texels are stored as the file's 8- or 16-bit values and decoded to linear through fixed float tables,
// top row first; lookups wrap (repeat) in u and v, or clamp to the edge texels (MTL -clamp on), with v = 0 at the
// bottom of the image as in OBJ. All maths is
// float (powf for the sRGB tables, floorf for wrapping), so textures decode and filter identically on any CPU.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "math.h"

namespace bl {

// Largest accepted image (width * height); 2^27 texels is 512 MiB of 8-bit RGBA (1 GiB at 16 bits).
constexpr long long max_texture_texels = 1LL << 27;
// Most memory all of a scene's decoded textures may take together (each within max_texture_texels): a few MB of
// well-compressed PNGs could otherwise claim any amount (four 1 MB files of 2^27 16-bit RGBA texels took 5 GB).
constexpr uint64_t max_textures_bytes = uint64_t(1) << 32;

// One decoded texture, kept as the file's own 8- or 16-bit channels (a quarter of the memory of float RGB + alpha:
// a 4096² RGBA texture takes 64 MiB), decoded per lookup through a fixed table: texel_rgb is linear RGB, texel_alpha
// the cut-out mask in [0, 1] (by default from the alpha channel when the image has one, else its luminance).
// Texels are row-major, top row first.
struct texture_data {
  std::string path;
  int width = 0, height = 0;
  int channels = 0;                   // 1 grey, 2 grey + alpha, 3 RGB, 4 RGBA
  std::vector<uint8_t> texels8;       // 8-bit images: width * height * channels values
  std::vector<uint16_t> texels16;     // 16-bit images (then texels8 is empty)
  const float* to_linear = nullptr;   // the colour decode table of the bit depth (256 or 65536 entries); set by
                                      // load_texture and texture_from_texels8 (the only ways to make a texture)
};

// Linear RGB and alpha mask of texel i (row-major index); the texture must hold width * height texels.
template <class T>  // uint8_t or uint16_t
inline vec3f decode_texel(const texture_data& t, const T* p) {
  return t.channels >= 3 ? vec3f{t.to_linear[p[0]], t.to_linear[p[1]], t.to_linear[p[2]]}
                         : vec3f{t.to_linear[p[0]], t.to_linear[p[0]], t.to_linear[p[0]]};
}
inline vec3f texel_rgb(const texture_data& t, size_t i) {
  size_t c = i * size_t(t.channels);
  return t.texels8.empty() ? decode_texel(t, t.texels16.data() + c) : decode_texel(t, t.texels8.data() + c);
}
// The cut-out mask of texel i from `channel` (texture_transform::channel), values linear (value / max): 'm' and the
// default take the alpha channel of an image that has one; 'l' and the default, of an RGB image without one, its
// luminance (the MTL format's default for scalar textures; the red channel alone before: a green mask cut out its
// complement); 'r', 'g', 'b' that channel; a grey image's grey value wherever there is no such channel.
inline float texel_alpha(const texture_data& t, size_t i, char channel = 0) {
  const size_t c = i * size_t(t.channels);
  auto value = [&](int k) {
    return t.texels8.empty() ? float(t.texels16[c + size_t(k)]) * (1.0f / 65535.0f)
                             : float(t.texels8[c + size_t(k)]) * (1.0f / 255.0f);
  };
  const bool alpha = t.channels == 2 || t.channels == 4, rgb = t.channels >= 3;
  if (alpha && (channel == 0 || channel == 'm')) return value(t.channels - 1);
  if (rgb && (channel == 'r' || channel == 'g' || channel == 'b')) return value(channel == 'r' ? 0 : channel == 'g' ? 1 : 2);
  if (rgb) return 0.2126f * value(0) + 0.7152f * value(1) + 0.0722f * value(2);
  return value(0);
}
// Whether t holds all its texels at one bit depth (a default-constructed texture holds none).
inline bool texture_complete(const texture_data& t) {
  size_t n = size_t(t.width) * size_t(t.height) * size_t(t.channels);
  bool eight = t.texels8.size() == n && t.texels16.empty(), sixteen = t.texels16.size() == n && t.texels8.empty();
  return t.width > 0 && t.height > 0 && t.channels >= 1 && t.channels <= 4 && t.to_linear && n > 0 &&
         (eight || sixteen);
}

// Loads an image file (PNG, JPEG, TGA, BMP via stb_image); throws input_error naming the file on failure.
// 8-bit colour goes through the srgb8_to_linear table, 16-bit colour through the same sRGB curve in float;
// alpha is linear (value / max). HDR, GIF, PSD, PIC and PNM files are refused, as are images larger than
// max_texture_texels.
// `budget`: the decoded bytes still allowed (max_textures_bytes less what the scene's other textures take); an image
// that would take more is refused before it is decoded.
texture_data load_texture(const std::string& path, uint64_t budget = max_textures_bytes);
// Decoded bytes a texture holds.
inline uint64_t texture_bytes(const texture_data& t) { return t.texels8.size() + 2 * uint64_t(t.texels16.size()); }

// A texture of 8-bit texels (width * height * channels values, row-major, top row first; colour sRGB-encoded).
texture_data texture_from_texels8(std::string path, int width, int height, int channels, std::vector<uint8_t> texels);

// Linear RGB at texture coordinate uv (bilinear; repeat wrap, or with clamp the edge texels beyond [0, 1]).
// solid_channel (when given): the texture is also the cut-out mask, read by that channel (texture_transform::channel):
// only its solid texels are blended.
vec3f eval_texture_rgb(const texture_data& tex, vec2f uv, bool clamp = false, const char* solid_channel = nullptr);
// Alpha mask at uv (nearest texel; repeat wrap or clamp): cut-outs keep hard edges and cost one fetch.
float eval_texture_alpha(const texture_data& tex, vec2f uv, bool clamp = false, char channel = 0);

// How a material's texture statement maps surface coordinates onto its image: MTL -s (scale) and -o (offset), u and
// v (w has no use on a 2D image): the image is read at uv * scale + offset; -clamp on: not repeated.
struct texture_transform {
  vec2f scale = {1, 1};
  vec2f offset = {0, 0};
  bool clamp = false;
  char channel = 0;  // map_d's -imfchan: 'r', 'g', 'b', 'm' (the alpha channel) or 'l' (luminance); 0: the default
};
// Whether two maps read an image at the same uv (scale, offset and clamp; the channel read may differ).
inline bool same_lookup(const texture_transform& a, const texture_transform& b) {
  return a.scale.x == b.scale.x && a.scale.y == b.scale.y && a.offset.x == b.offset.x && a.offset.y == b.offset.y &&
         a.clamp == b.clamp;
}
inline vec2f transform_uv(const texture_transform& t, vec2f uv) {
  return {uv.x * t.scale.x + t.offset.x, uv.y * t.scale.y + t.offset.y};
}

// sRGB-encoded 8-bit value to linear float (exact table of the sRGB EOTF in float maths).
float srgb8_to_linear(unsigned char v);

}  // namespace bl
