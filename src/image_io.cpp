// image_io: .exr (tinyexr, fp32 RGB), .pfm (own code) and .png (stb_image_write, 8-bit sRGB) files.
// Invariants: pixels are RGB interleaved, top row first; reads reject anything malformed with an input_error
// naming the file; every write is encoded in memory first and handed to write_file_atomic, so a failure never
// leaves a partial file. The PNG encoding uses float maths only (powf), so it is the same on every x86-64 CPU.
#include "image_io.h"

#include "errors.h"
#include "file_io.h"

#include <stb_image_write.h>
#include <tinyexr.h>

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>

namespace bl {

// Largest accepted width or height, and pixel count, of an input image (guards allocations on bad headers).
static constexpr int64_t max_image_side = int64_t(1) << 20;
static constexpr int64_t max_image_pixels = int64_t(1) << 28;

image_format image_format_of(const std::string& path) {
  const std::string ext = lower_extension(path);  // ("x/.exr" and "x.exr/" have none)
  if (ext == ".exr") return image_format::exr;
  if (ext == ".pfm") return image_format::pfm;
  if (ext == ".png") return image_format::png;
  return image_format::unknown;
}

// "WxH" for messages.
static std::string size_text(int64_t w, int64_t h) { return std::to_string(w) + "x" + std::to_string(h); }

// Throws input_error unless w x h is a sensible image size.
static void check_input_size(const std::string& path, int64_t w, int64_t h) {
  if (w <= 0 || h <= 0 || w > max_image_side || h > max_image_side || w * h > max_image_pixels)
    throw input_error(path, "unsupported image size " + size_text(w, h));
}

// ---------------------------------------------------------------------------------------------------------
// PFM: "PF" (RGB) or "Pf" (grey), width, height, scale (< 0: little-endian floats; its magnitude, a brightness
// scale in some writers, is not applied), one whitespace byte, then rows of floats from the bottom row up.

// True for the whitespace bytes the netpbm header grammar allows.
static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f'; }

// The next whitespace-separated header token at pos (advanced past it); empty at the end of the data.
static std::string next_token(const std::string& b, size_t& pos) {
  while (pos < b.size() && is_space(b[pos])) ++pos;
  size_t start = pos;
  while (pos < b.size() && !is_space(b[pos]) && pos - start < 64) ++pos;
  return b.substr(start, pos - start);
}

// A PFM width or height token: decimal digits only.
static int64_t parse_pfm_int(const std::string& path, const std::string& tok, const char* what) {
  int64_t v = 0;
  auto [end, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), v);
  if (tok.empty() || ec != std::errc() || end != tok.data() + tok.size() || tok[0] == '-')
    throw input_error(path, std::string("malformed PFM header: bad ") + what + " '" + tok + "'");
  return v;
}

// Decodes the 4 bytes at p as a float of the given byte order (independent of the host's order).
static float load_float(const unsigned char* p, bool little) {
  uint32_t u = little ? uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24
                      : uint32_t(p[3]) | uint32_t(p[2]) << 8 | uint32_t(p[1]) << 16 | uint32_t(p[0]) << 24;
  float f;
  std::memcpy(&f, &u, 4);
  return f;
}

// Reads a PF or Pf file of either byte order.
static image_data read_pfm(const std::string& path) {
  const std::string b = read_file(path);
  if (b.size() < 3 || b[0] != 'P' || (b[1] != 'F' && b[1] != 'f') || !is_space(b[2]))
    throw input_error(path, "not a PFM file (expected 'PF' or 'Pf')");
  const int channels = b[1] == 'F' ? 3 : 1;
  size_t pos = 2;
  int64_t w = parse_pfm_int(path, next_token(b, pos), "width");
  int64_t h = parse_pfm_int(path, next_token(b, pos), "height");
  std::string scale_tok = next_token(b, pos);
  double scale = 0;
  auto [end, ec] = std::from_chars(scale_tok.data(), scale_tok.data() + scale_tok.size(), scale);
  if (scale_tok.empty() || ec != std::errc() || end != scale_tok.data() + scale_tok.size() ||
      !std::isfinite(scale) || scale == 0)
    throw input_error(path, "malformed PFM header: bad scale '" + scale_tok + "'");
  if (pos >= b.size() || !is_space(b[pos])) throw input_error(path, "truncated PFM header");
  check_input_size(path, w, h);
  const size_t expected = size_t(w) * size_t(h) * size_t(channels) * 4;
  // The single whitespace byte that ends the header; or, when the data then fit exactly, the rest of the scale's
  // line: blanks and a CRLF or LF ("-1.0 \n" was "1 unexpected bytes after the PFM pixel data"; a review).
  size_t eol = pos;
  while (eol < b.size() && (b[eol] == ' ' || b[eol] == '\t')) ++eol;
  if (eol < b.size() && b[eol] == '\r') ++eol;
  if (eol < b.size() && b[eol] == '\n') ++eol;
  pos = eol > pos + 1 && b[eol - 1] == '\n' && b.size() - eol == expected ? eol : pos + 1;
  const size_t found = b.size() - pos;
  if (found < expected)
    throw input_error(path, "truncated PFM data: " + size_text(w, h) + " needs " + std::to_string(expected) +
                                " bytes, found " + std::to_string(found));
  if (found > expected)
    throw input_error(path, std::to_string(found - expected) + " unexpected bytes after the PFM pixel data");

  image_data img;
  img.width = int(w);
  img.height = int(h);
  img.pixels.resize(size_t(w) * size_t(h) * 3);
  const bool little = scale < 0;
  const auto* data = reinterpret_cast<const unsigned char*>(b.data()) + pos;
  for (int64_t fy = 0; fy < h; ++fy) {
    const int64_t y = h - 1 - fy;  // file rows run bottom to top
    for (int64_t x = 0; x < w; ++x) {
      const unsigned char* src = data + size_t((fy * w + x) * channels) * 4;
      float* dst = &img.pixels[size_t(y * w + x) * 3];
      for (int c = 0; c < 3; ++c) dst[c] = load_float(src + (channels == 3 ? c : 0) * 4, little);
    }
  }
  return img;
}

// Little-endian PF bytes (scale -1), rows from the bottom up.
static std::string encode_pfm(const image_data& img) {
  std::string out = "PF\n" + std::to_string(img.width) + " " + std::to_string(img.height) + "\n-1.0\n";
  const size_t header = out.size();
  out.resize(header + img.pixels.size() * 4);
  unsigned char* dst = reinterpret_cast<unsigned char*>(&out[header]);
  const size_t row = size_t(img.width) * 3;
  for (int fy = 0; fy < img.height; ++fy) {
    const float* src = &img.pixels[size_t(img.height - 1 - fy) * row];
    for (size_t i = 0; i < row; ++i, dst += 4) {
      uint32_t u;
      std::memcpy(&u, &src[i], 4);
      for (int k = 0; k < 4; ++k) dst[k] = static_cast<unsigned char>(u >> (8 * k));
    }
  }
  return out;
}

// ---------------------------------------------------------------------------------------------------------
// EXR through tinyexr's header/image API (LoadEXR leaks on errors and misreads UINT channels).

// A parsed EXR header and its loaded image; frees both on every exit path.
struct exr_file_data {
  EXRHeader header;
  EXRImage image;
  exr_file_data() {
    InitEXRHeader(&header);
    InitEXRImage(&image);
  }
  ~exr_file_data() {
    FreeEXRImage(&image);
    FreeEXRHeader(&header);
  }
  exr_file_data(const exr_file_data&) = delete;
  exr_file_data& operator=(const exr_file_data&) = delete;
};

// tinyexr's error text (freed here) or fallback.
static std::string take_exr_error(const char* err, const std::string& fallback) {
  std::string msg = err ? std::string(err) : fallback;
  if (err) FreeEXRErrorMessage(err);
  while (!msg.empty() && is_space(msg.back())) msg.pop_back();
  return msg;
}

// Index of the channel named name, or -1.
static int find_channel(const EXRHeader& h, const char* name) {
  for (int c = 0; c < h.num_channels; ++c)
    if (std::strcmp(h.channels[c].name, name) == 0) return c;
  return -1;
}

// The layer names P for which P.R, P.G and P.B are all channels of h (a multi-layer file in one part, as Blender's
// "OpenEXR MultiLayer" writes: ViewLayer.Combined.R, ...), in the order of their R channels.
static std::vector<std::string> rgb_layers(const EXRHeader& h) {
  std::vector<std::string> layers;
  for (int c = 0; c < h.num_channels; ++c) {
    const std::string name = h.channels[c].name;
    if (name.size() < 3 || name.compare(name.size() - 2, 2, ".R") != 0) continue;
    const std::string layer = name.substr(0, name.size() - 2);
    if (find_channel(h, (layer + ".G").c_str()) >= 0 && find_channel(h, (layer + ".B").c_str()) >= 0)
      layers.push_back(layer);
  }
  return layers;
}

// Sample i of loaded channel plane p (FLOAT after the HALF->FLOAT request, or UINT).
static float exr_sample(const unsigned char* p, int pixel_type, size_t i) {
  if (pixel_type == TINYEXR_PIXELTYPE_UINT) return float(reinterpret_cast<const unsigned int*>(p)[i]);
  return reinterpret_cast<const float*>(p)[i];
}

// Zero bytes kept after the file's data in memory (not part of what tinyexr is told it got): tinyexr 1.0.1's PIZ
// decoder reads its bitmap (up to 8 KiB) and a length past the end of a short chunk before checking the chunk's
// size (DecompressPiz, tinyexr.h:3095-3116); with the padding those reads stay inside our buffer.
static constexpr size_t exr_read_padding = 64 * 1024;

// What read_exr checks in the EXR header at mem (after the 8-byte magic and version) before tinyexr parses it,
// reading attributes as tinyexr's ParseEXRHeader does (on a malformed header both stay empty and tinyexr then
// fails on its own):
// - type: the first non-empty "type" attribute that is not "scanlineimage" ("" when there is none). tinyexr 1.0.1
//   asserts on type values that disagree with the version flags (ConvertHeader, tinyexr.h:4536-4548), and Debian
//   builds it with assertions on: an unknown type aborts the process. Every type attribute counts, not only the
//   last: fuzzing found headers with two, the first one bad, that still reached the assertion.
// - compression: the name of a valid OpenEXR compression tinyexr cannot decode (PXR24, B44, B44A, DWAA, DWAB),
//   which it would report as an "unknown" type of a malformed header ("" when none).
struct exr_precheck {
  std::string type, compression;
};
static exr_precheck exr_header_precheck(const unsigned char* mem, size_t size) {
  static const char* const undecodable[] = {"PXR24", "B44", "B44A", "DWAA", "DWAB"};  // codes 5-9
  exr_precheck out;
  size_t pos = 8;
  while (pos < size && mem[pos] != 0) {
    const char* p = reinterpret_cast<const char*>(mem + pos);
    size_t left = size - pos;
    size_t name_len = strnlen(p, left);
    if (name_len == left) break;
    size_t type_len = strnlen(p + name_len + 1, left - name_len - 1);
    if (type_len == left - name_len - 1) break;
    size_t head = name_len + 1 + type_len + 1;
    if (left - head < 4) break;
    uint32_t len = uint32_t(mem[pos + head]) | uint32_t(mem[pos + head + 1]) << 8 |
                   uint32_t(mem[pos + head + 2]) << 16 | uint32_t(mem[pos + head + 3]) << 24;
    if (left - head - 4 < len) break;
    const char* data = p + head + 4;
    if (std::strcmp(p, "type") == 0 && len > 0 && data[0] != 0) {
      std::string t(data, strnlen(data, len));
      if (t != "scanlineimage" && out.type.empty()) out.type = t;
    }
    if (std::strcmp(p, "compression") == 0 && len > 0 && out.compression.empty()) {
      unsigned code = static_cast<unsigned char>(data[0]);
      if (code >= 5 && code <= 9) out.compression = undecodable[code - 5];
    }
    pos += head + 4 + len;
  }
  for (char& c : out.type) c = c >= 32 && c < 127 ? c : '?';  // for the message
  return out;
}

// Reads R, G, B of a single-part scanline EXR (without them the one layer's L.R, L.G, L.B, or Y, or a file's only
// channel, replicated to grey; luminance/chroma and XYZ files, and several RGB layers, are refused);
// alpha and other channels are ignored. Tiled files are rejected: tinyexr's tiled error paths free memory unreliably.
static image_data read_exr(const std::string& path) {
  std::string bytes = read_file(path);
  const size_t size = bytes.size();
  bytes.resize(size + exr_read_padding, '\0');
  const auto* mem = reinterpret_cast<const unsigned char*>(bytes.data());
  EXRVersion version;
  if (ParseEXRVersionFromMemory(&version, mem, size) != TINYEXR_SUCCESS)
    throw input_error(path, "not an OpenEXR file");
  if (version.multipart || version.non_image || version.tiled)
    throw input_error(path, "tiled, multi-part and deep OpenEXR files are not supported (write scanline RGB)");
  const exr_precheck pre = exr_header_precheck(mem, size);
  if (!pre.type.empty())
    throw input_error(path,
                      "OpenEXR image type \"" + pre.type.substr(0, 40) + "\" is not supported (write scanline RGB)");
  if (!pre.compression.empty())
    throw input_error(path, "OpenEXR compression " + pre.compression +
                                " is not supported (save it with ZIP, PIZ, RLE or no compression)");
  exr_file_data exr;
  const char* err = nullptr;
  if (ParseEXRHeaderFromMemory(&exr.header, &version, mem, size, &err) != TINYEXR_SUCCESS)
    throw input_error(path, "malformed OpenEXR header: " + take_exr_error(err, "unknown error"));
  const EXRHeader& h = exr.header;
  int rgb[3] = {find_channel(h, "R"), find_channel(h, "G"), find_channel(h, "B")};
  if (rgb[0] < 0 || rgb[1] < 0 || rgb[2] < 0) {
    const std::vector<std::string> layers = rgb_layers(h);
    if (layers.size() == 1)
      for (int c = 0; c < 3; ++c) rgb[c] = find_channel(h, (layers[0] + "." + "RGB"[c]).c_str());
    if (layers.size() > 1) {
      std::string names;
      for (size_t i = 0; i < layers.size() && i < 8; ++i) names += (i ? ", " : "") + layers[i];
      throw input_error(path, "OpenEXR file has " + std::to_string(layers.size()) + " layers with R, G and B (" +
                                  names + (layers.size() > 8 ? ", ..." : "") +
                                  "): which is the image is not clear; save that layer alone");
    }
  }
  if (rgb[0] < 0 || rgb[1] < 0 || rgb[2] < 0) {
    if (find_channel(h, "RY") >= 0 || find_channel(h, "BY") >= 0)
      throw input_error(path, "luminance/chroma OpenEXR files (Y, RY, BY) are not supported (write R, G, B)");
    if (find_channel(h, "X") >= 0 && find_channel(h, "Z") >= 0)
      throw input_error(path, "CIE XYZ OpenEXR files (X, Y, Z) are not supported (write R, G, B)");
    const int y = find_channel(h, "Y");  // luminance (with alpha or others): grey
    if (y >= 0) {
      rgb[0] = rgb[1] = rgb[2] = y;
    } else if (h.num_channels != 1) {
      std::string names;
      for (int c = 0; c < h.num_channels && c < 8; ++c) names += std::string(c ? ", " : "") + h.channels[c].name;
      throw input_error(path, "OpenEXR file has no R, G and B or Y channels (found: " + names + ")");
    } else {
      rgb[0] = rgb[1] = rgb[2] = 0;  // one channel (A, ...): grey
    }
  }
  for (int c : rgb)
    if (h.channels[c].x_sampling != 1 || h.channels[c].y_sampling != 1)
      throw input_error(path, "subsampled OpenEXR channels are not supported");
  check_input_size(path, int64_t(h.data_window.max_x) - h.data_window.min_x + 1,
                   int64_t(h.data_window.max_y) - h.data_window.min_y + 1);
  {
    // The image is the display window; pixels outside the data window have no value. A data window other than the
    // display window was read as if it were the image (a 5x3 crop of a 7x5 image was "5x3"; a review).
    const EXRBox2i &d = h.data_window, &v = h.display_window;
    if (d.min_x != v.min_x || d.min_y != v.min_y || d.max_x != v.max_x || d.max_y != v.max_y) {
      auto box = [](const EXRBox2i& b) {
        return "(" + std::to_string(b.min_x) + ", " + std::to_string(b.min_y) + ")-(" + std::to_string(b.max_x) +
               ", " + std::to_string(b.max_y) + ")";
      };
      throw input_error(path, "OpenEXR data window " + box(d) + " is not the display window " + box(v) +
                                  " (a cropped or overscanned image; save the whole image)");
    }
  }
  for (int c = 0; c < h.num_channels; ++c)
    if (h.pixel_types[c] == TINYEXR_PIXELTYPE_HALF) exr.header.requested_pixel_types[c] = TINYEXR_PIXELTYPE_FLOAT;
  // tinyexr 1.0.1 sets num_channels only on success, but on a decoding failure frees the planes up to
  // num_channels (leaking them when it is 0) and leaves the freed pointers in place: preset the count so the
  // planes are freed, and forget the pointers afterwards so that the destructor does not free them twice.
  exr.image.num_channels = h.num_channels;
  if (LoadEXRImageFromMemory(&exr.image, &exr.header, mem, size, &err) != TINYEXR_SUCCESS) {
    InitEXRImage(&exr.image);
    throw input_error(path, "malformed OpenEXR data: " + take_exr_error(err, "unknown error"));
  }

  const EXRImage& im = exr.image;
  if (h.tiled || !im.images) throw input_error(path, "OpenEXR file has no scanline pixel data");
  check_input_size(path, im.width, im.height);
  image_data img;
  img.width = im.width;
  img.height = im.height;
  img.pixels.resize(size_t(im.width) * size_t(im.height) * 3);
  // tinyexr 1.0.1 stores the rows of a file whose line order is not INCREASING_Y bottom up (tinyexr.h:3994 and its
  // siblings), yet every chunk carries its own y: the line order only says in which order the chunks were written.
  const bool flipped = h.line_order != 0;
  const size_t w = size_t(im.width), rows = size_t(im.height);
  for (size_t y = 0; y < rows; ++y) {
    const size_t src = (flipped ? rows - 1 - y : y) * w;
    for (size_t x = 0; x < w; ++x)
      for (int k = 0; k < 3; ++k)
        img.pixels[(y * w + x) * 3 + size_t(k)] = exr_sample(im.images[rgb[k]], h.pixel_types[rgb[k]], src + x);
  }
  return img;
}

// fp32 B, G, R planes (the channel order viewers expect), ZIP-compressed (lossless), scanline.
static std::string encode_exr(const std::string& path, const image_data& img) {
  const size_t n = size_t(img.width) * size_t(img.height);
  std::vector<float> planes[3];  // B, G, R
  for (int c = 0; c < 3; ++c) {
    planes[c].resize(n);
    for (size_t i = 0; i < n; ++i) planes[c][i] = img.pixels[i * 3 + size_t(2 - c)];
  }
  float* plane_ptrs[3] = {planes[0].data(), planes[1].data(), planes[2].data()};
  EXRImage image;
  InitEXRImage(&image);
  image.images = reinterpret_cast<unsigned char**>(plane_ptrs);
  image.width = img.width;
  image.height = img.height;
  image.num_channels = 3;
  EXRChannelInfo channels[3] = {};
  const char* names[3] = {"B", "G", "R"};
  int pixel_types[3], requested[3];
  for (int c = 0; c < 3; ++c) {
    std::strcpy(channels[c].name, names[c]);
    pixel_types[c] = requested[c] = TINYEXR_PIXELTYPE_FLOAT;
  }
  EXRHeader header;  // points at the arrays above: not freed with FreeEXRHeader
  InitEXRHeader(&header);
  header.num_channels = 3;
  header.channels = channels;
  header.pixel_types = pixel_types;
  header.requested_pixel_types = requested;
  header.compression_type = TINYEXR_COMPRESSIONTYPE_ZIP;
  unsigned char* mem = nullptr;
  const char* err = nullptr;
  size_t size = SaveEXRImageToMemory(&image, &header, &mem, &err);
  if (size == 0 || !mem) {
    std::free(mem);
    throw output_error("cannot write " + path + ": OpenEXR encoding failed: " + take_exr_error(err, "unknown error"));
  }
  std::string out(reinterpret_cast<const char*>(mem), size);
  std::free(mem);
  return out;
}

// ---------------------------------------------------------------------------------------------------------
// PNG: 8-bit sRGB.

// Linear value to an 8-bit sRGB code: NaN -> 0, clamp to [0, 1], sRGB OETF in float, round to nearest.
static unsigned char linear_to_srgb8(float v) {
  if (!(v > 0.0f)) return 0;  // also NaN
  if (v >= 1.0f) return 255;
  const float s = v <= 0.0031308f ? 12.92f * v : 1.055f * powf(v, 1.0f / 2.4f) - 0.055f;  // float libm
  return static_cast<unsigned char>(s * 255.0f + 0.5f);
}

// stb callback appending the encoded bytes to a std::string.
static void append_bytes(void* context, void* data, int size) {
  static_cast<std::string*>(context)->append(static_cast<const char*>(data), size_t(size));
}

// RGB 8-bit PNG bytes of img.
static std::string encode_png(const std::string& path, const image_data& img) {
  std::vector<unsigned char> codes(img.pixels.size());
  for (size_t i = 0; i < codes.size(); ++i) codes[i] = linear_to_srgb8(img.pixels[i]);
  std::string out;
  if (!stbi_write_png_to_func(append_bytes, &out, img.width, img.height, 3, codes.data(), img.width * 3))
    throw output_error("cannot write " + path + ": PNG encoding failed");
  return out;
}

// ---------------------------------------------------------------------------------------------------------

image_data read_image(const std::string& path) {
  switch (image_format_of(path)) {
    case image_format::exr: return read_exr(path);
    case image_format::pfm: return read_pfm(path);
    case image_format::png: throw input_error(path, "PNG is 8-bit display output; read images must be .exr or .pfm");
    case image_format::unknown: break;
  }
  throw input_error(path, "unknown image format (expected .exr or .pfm)");
}

void write_image(const std::string& path, const image_data& img) {
  if (img.width <= 0 || img.height <= 0 || img.pixels.size() != size_t(img.width) * size_t(img.height) * 3)
    throw output_error("cannot write " + path + ": invalid " + size_text(img.width, img.height) + " image with " +
                       std::to_string(img.pixels.size()) + " values");
  switch (image_format_of(path)) {
    case image_format::exr: return write_file_atomic(path, encode_exr(path, img));
    case image_format::pfm: return write_file_atomic(path, encode_pfm(img));
    case image_format::png: return write_file_atomic(path, encode_png(path, img));
    case image_format::unknown: break;
  }
  throw output_error("cannot write " + path + ": unknown image format (expected .exr, .pfm or .png)");
}

image_data read_reference(const std::string& path, int width, int height) {
  image_data ref = read_image(path);
  if (ref.width != width || ref.height != height)
    throw input_error(path, "reference is " + std::to_string(ref.width) + "x" + std::to_string(ref.height) +
                                " but the render is " + std::to_string(width) + "x" + std::to_string(height));
  require_finite(ref, path, "reference");
  return ref;
}

void require_finite(const image_data& img, const std::string& path, const std::string& what) {
  for (size_t i = 0; i < img.pixels.size(); i++)
    if (!std::isfinite(img.pixels[i])) {
      size_t px = i / 3, w = size_t(std::max(img.width, 1));
      throw input_error(path, what + " has a non-finite value at pixel (" + std::to_string(px % w) + ", " +
                                  std::to_string(px / w) + ")");
    }
}

}  // namespace bl
