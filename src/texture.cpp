// texture: decodes images with stb_image (implementation in libstb) into linear float texels, and filters them.
// Invariants: only the PNG, JPEG, BMP and TGA decoders are ever reached (other formats are refused by their
// magic bytes first: they are the least hardened parts of stb_image); the file is read once into memory; the
// decoded orientation is pinned (top row first) whatever stb's global flip flag says.
#include "texture.h"

#include "errors.h"
#include "file_io.h"

#include <stb_image.h>

#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>

namespace bl {

// sRGB EOTF of a code value c in [0, 1], in float maths (powf is bit-identical across x86-64 CPUs).
static float srgb_to_linear(float c) { return c <= 0.04045f ? c / 12.92f : powf((c + 0.055f) / 1.055f, 2.4f); }

float srgb8_to_linear(unsigned char v) { return srgb_to_linear(float(v) / 255.0f); }

// Reads a regular file into memory (a FIFO would block forever); throws input_error with the reason.
static std::string read_image_file(const std::string& path) {
  std::error_code ec;
  auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) throw input_error(path, "cannot open image: no such file");
  if (!std::filesystem::is_regular_file(status)) throw input_error(path, "cannot open image: not a regular file");
  return read_file(path);
}

// Name of an image format stb_image could decode but we refuse, from the file's first bytes ("" if none).
static const char* refused_format(const std::string& b) {
  auto starts = [&](const char* magic) { return b.compare(0, std::strlen(magic), magic) == 0; };
  if (starts("#?RADIANCE") || starts("#?RGBE")) return "HDR (Radiance)";
  if (starts("GIF8")) return "GIF";
  if (starts("8BPS")) return "PSD";
  if (starts("\x53\x80\xF6\x34")) return "PIC";
  if (b.size() >= 2 && b[0] == 'P' && b[1] >= '1' && b[1] <= '7') return "PNM";
  return "";
}

// True when the first bytes are those of a PNG, JPEG or BMP file, or the name ends in .tga (TGA has no magic).
static bool accepted_format(const std::string& b, const std::string& path) {
  auto starts = [&](const char* magic, size_t n) { return b.size() >= n && std::memcmp(b.data(), magic, n) == 0; };
  if (starts("\x89PNG\r\n\x1a\n", 8) || starts("\xFF\xD8\xFF", 3) || starts("BM", 2)) return true;
  return lower_extension(path) == ".tga";
}

// Little-endian integer of n bytes at offset off of b (0 past the end).
static long long le(const std::string& b, size_t off, int n) {
  long long v = 0;
  for (int i = n - 1; i >= 0; i--) v = v * 256 + (off + size_t(i) < b.size() ? (unsigned char)b[off + size_t(i)] : 0);
  return v;
}
// The big-endian 32-bit value at off (PNG fields), 0 past the end.
static long long be32(const std::string& b, size_t off) {
  long long v = 0;
  for (size_t i = 0; i < 4; i++) v = v * 256 + (off + i < b.size() ? (unsigned char)b[off + i] : 0);
  return v;
}

// Smallest file that can hold the pixels of an uncompressed or run-length encoded TGA, or an uncompressed BMP, of
// w x h texels (0 for other formats): stb_image reads zeros past the end of these, so a truncated file would
// otherwise decode without error (as black).
static long long uncompressed_size(const std::string& b, long long w, long long h) {
  if (b.size() >= 18 && b.compare(0, 2, "BM") != 0) {  // TGA (only .tga files without PNG/JPEG magic get here)
    long long type = (unsigned char)b[2], bytes_pp = ((unsigned char)b[16] + 7) / 8;
    long long palette = b[1] ? le(b, 5, 2) * (((unsigned char)b[7] + 7) / 8) : 0;
    // stb_image skips as many bytes as the colour map's first entry index (le(b, 3, 2)) before the palette.
    long long data = 18 + (unsigned char)b[0] + (b[1] ? le(b, 3, 2) : 0) + palette;
    if (type >= 1 && type <= 3) return data + w * h * bytes_pp;
    if (type >= 9 && type <= 11) {
      // Packets: a header byte, then one pixel repeated (high bit set) or (header & 127) + 1 raw pixels; each
      // covers (header & 127) + 1 pixels. Walked until they cover the image or the file ends (then one byte more
      // than the file: truncated). At most one step per byte of the file.
      long long off = data, covered = 0, size = (long long)b.size();
      while (covered < w * h) {
        if (off >= size) return size + 1;
        unsigned header = (unsigned char)b[size_t(off)];
        long long count = (header & 127) + 1;
        off += 1 + (header & 128 ? 1 : count) * std::max(bytes_pp, 1LL);
        covered += count;
      }
      return off;
    }
  } else if (b.size() >= 30 && b.compare(0, 2, "BM") == 0) {
    long long header = le(b, 14, 4), bpp = header == 12 ? le(b, 24, 2) : le(b, 28, 2);
    long long compression = header >= 40 ? le(b, 30, 4) : 0;
    if (compression == 0 || compression == 3) return le(b, 10, 4) + (w * bpp + 31) / 32 * 4 * h;
  }
  return 0;
}

// False when a JPEG Huffman table (DHT) declares more than 256 codes. stb_image 2.27 (Debian 12) trusts the 16
// code-length counts: when they sum past 256, stbi__build_huffman (stb_image.h:1990) writes past its size[257]
// table into the rest of its decoder state (heap corruption). Walks the marker segments as stb's decoder does
// (fill bytes skipped, entropy-coded data skipped up to the next marker; a DHT's tables are read while its
// length lasts, bytes past the end of the file reading as 0) and checks every table it would build.
// Files that are no JPEG to stb (no SOI marker, optionally after fill bytes, at the start) pass.
static bool jpeg_huffman_tables_ok(const std::string& b) {
  auto byte = [&](size_t i) { return i < b.size() ? (unsigned char)b[i] : 0u; };
  size_t i = 0;
  while (byte(i) == 0xFF) i++;
  if (i == 0 || byte(i) != 0xD8) return true;
  i++;  // after SOI
  while (i + 1 < b.size()) {
    unsigned m = byte(i + 1);
    // Not a marker, a fill byte, stuffing, TEM or RSTn/SOI/EOI (no length field): move on.
    if (byte(i) != 0xFF || m == 0xFF || m == 0x00 || m == 0x01 || (m >= 0xD0 && m <= 0xD9)) {
      i++;
      continue;
    }
    long length = long(byte(i + 2) << 8 | byte(i + 3));
    if (m != 0xC4) {
      i += 2 + size_t(length);
      continue;
    }
    long left = length - 2;
    size_t p = i + 4;
    while (left > 0) {
      long codes = 0;
      for (size_t k = 1; k <= 16; k++) codes += long(byte(p + k));
      if (codes > 256) return false;
      p += 17 + size_t(codes);
      left -= 17 + codes;
    }
    i = p;
  }
  return true;
}

// stb_image's reason for the last failure (never null).
// Drops the zero-length IDAT chunks of a PNG (they carry no data, so the image is unchanged): stb_image 2.27 copies
// such a chunk with memcpy(NULL, ..., 0) before its first allocation (stb_image.h:1663, found by fuzzing), which is
// undefined behaviour. From the first chunk that does not fit the file on, the bytes stay as they are for stb to
// judge.
static void drop_empty_idat_chunks(std::string& b) {
  static const char sig[8] = {'\x89', 'P', 'N', 'G', '\r', '\n', '\x1a', '\n'};
  if (b.size() < 8 || b.compare(0, 8, std::string(sig, 8)) != 0) return;
  std::string out = b.substr(0, 8);
  size_t pos = 8;
  while (pos + 12 <= b.size()) {
    unsigned long long len = (unsigned long long)(unsigned char)b[pos] << 24 | (unsigned char)b[pos + 1] << 16 |
                             (unsigned char)b[pos + 2] << 8 | (unsigned char)b[pos + 3];
    if (len > b.size() - pos - 12) break;  // truncated or corrupt: the rest stays as it is
    bool empty_idat = len == 0 && b.compare(pos + 4, 4, "IDAT") == 0;
    if (!empty_idat) out.append(b, pos, size_t(len) + 12);
    pos += size_t(len) + 12;
  }
  out.append(b, pos, std::string::npos);
  b.swap(out);
}

static std::string stb_reason() {
  const char* r = stbi_failure_reason();
  std::string s = r ? r : "unknown error";
  // stb_image quotes a corrupt file's own bytes (an unknown chunk's type): keep the message printable.
  for (char& c : s)
    if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) c = '?';
  // Its reasons are terse: say what they mean where that is clear (the file's magic bytes were accepted already).
  if (s.size() <= 4) return "corrupt or truncated file (an unexpected chunk \"" + s + "\")";
  if (s == "unknown image type") return "corrupt file, or a variant of its format stb_image does not read";
  if (s == "outofdata" || s == "read past buffer" || s == "not enough pixels") return "truncated file (" + s + ")";
  return s;
}

// Most texels a file byte may claim (see load_texture).
constexpr long long max_texels_per_byte = 16384;

// Frees stb_image's pixel buffers.
struct stbi_deleter {
  void operator()(void* p) const { stbi_image_free(p); }
};

// The colour decode tables: 8-bit values through srgb8_to_linear, 16-bit ones through the same curve in float.
static const float* table8() {
  static const std::vector<float> t = [] {
    std::vector<float> v(256);
    for (int i = 0; i < 256; i++) v[size_t(i)] = srgb8_to_linear((unsigned char)i);
    return v;
  }();
  return t.data();
}
static const float* table16() {
  static const std::vector<float> t = [] {
    std::vector<float> v(65536);
    for (int i = 0; i < 65536; i++) v[size_t(i)] = srgb_to_linear(float(i) / 65535.0f);
    return v;
  }();
  return t.data();
}

texture_data texture_from_texels8(std::string path, int width, int height, int channels, std::vector<uint8_t> texels) {
  texture_data t;
  t.path = std::move(path);
  t.width = width;
  t.height = height;
  t.channels = channels;
  t.texels8 = std::move(texels);
  t.to_linear = table8();
  return t;
}

texture_data load_texture(const std::string& path, uint64_t budget) {
  std::string bytes = read_image_file(path);
  if (bytes.empty()) throw input_error(path, "cannot decode image: empty file");
  if (bytes.size() > size_t(std::numeric_limits<int>::max())) throw input_error(path, "image file too large");
  if (const char* fmt = refused_format(bytes); *fmt)
    throw input_error(path,
                      std::string("unsupported image format ") + fmt + " (use 8- or 16-bit PNG, JPEG, BMP or TGA)");
  if (!accepted_format(bytes, path)) throw input_error(path, "cannot decode image: not a PNG, JPEG, BMP or TGA file");
  if (!jpeg_huffman_tables_ok(bytes))
    throw input_error(path, "cannot decode image: corrupt JPEG (Huffman table with more than 256 codes)");
  drop_empty_idat_chunks(bytes);
  auto data = reinterpret_cast<const stbi_uc*>(bytes.data());
  int len = int(bytes.size());
  int w = 0, h = 0, n = 0;
  // A PNG's size, from its header: stb_image refuses one of more than 2^30 bytes decoded with "unknown image type"
  // (its other decoders' verdict), which would hide the reason.
  if (bytes.size() >= 24 && bytes.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0 && bytes.compare(12, 4, "IHDR") == 0) {
    uint64_t pw = be32(bytes, 16), ph = be32(bytes, 20);  // (each below 2^32: the product fits, unsigned)
    if (pw * ph > uint64_t(max_texture_texels))
      throw input_error(path, "image too large (" + std::to_string(pw) + "x" + std::to_string(ph) + " texels)");
  }
  if (!stbi_info_from_memory(data, len, &w, &h, &n)) throw input_error(path, "cannot decode image: " + stb_reason());
  // stb_image 2.27's BMP info reports a top-down BMP (negative height in the file) with its negative height;
  // its decoder uses the magnitude. INT_MIN has none (abs() would overflow in stb) and stays rejected below.
  if (h < 0 && h != std::numeric_limits<int>::min() && bytes.compare(0, 2, "BM") == 0) h = -h;
  if (w <= 0 || h <= 0 || n < 1 || n > 4) throw input_error(path, "cannot decode image: bad header");
  long long texels = (long long)w * h;
  if (texels > max_texture_texels)
    throw input_error(path, "image too large (" + std::to_string(w) + "x" + std::to_string(h) + " texels)");
  // No real encoder packs more than ~8300 texels in a byte (1-bit PNG at deflate's limit): a tiny file that
  // claims a huge image is corrupt, and decoding it would only cost memory.
  if (texels > (1LL << 20) && texels > max_texels_per_byte * (long long)bytes.size())
    throw input_error(path, "cannot decode image: " + std::to_string(w) + "x" + std::to_string(h) +
                                " texels cannot fit in " + std::to_string(bytes.size()) + " bytes (corrupt?)");
  if ((long long)bytes.size() < uncompressed_size(bytes, w, h))
    throw input_error(path, "cannot decode image: truncated");

  const bool sixteen = stbi_is_16_bit_from_memory(data, len);
  const uint64_t decoded = uint64_t(texels) * uint64_t(n) * (sixteen ? 2 : 1);
  if (decoded > budget)
    throw input_error(path, "image of " + std::to_string(w) + "x" + std::to_string(h) + " texels (" +
                                std::to_string(decoded >> 20) + " MiB decoded) would take the scene's textures past " +
                                std::to_string(max_textures_bytes >> 30) + " GiB in all");
  texture_data tex;
  tex.path = path;
  stbi_set_flip_vertically_on_load_thread(0);
  int dw = 0, dh = 0, dn = 0;
  if (sixteen) {
    std::unique_ptr<stbi_us, stbi_deleter> px(stbi_load_16_from_memory(data, len, &dw, &dh, &dn, 0));
    if (!px) throw input_error(path, "cannot decode image: " + stb_reason());
    if (dw != w || dh != h || dn < 1 || dn > 4) throw input_error(path, "cannot decode image: inconsistent header");
    tex.width = dw;
    tex.height = dh;
    tex.channels = dn;
    tex.texels16.assign(px.get(), px.get() + size_t(dw) * size_t(dh) * size_t(dn));
    tex.to_linear = table16();
  } else {
    std::unique_ptr<stbi_uc, stbi_deleter> px(stbi_load_from_memory(data, len, &dw, &dh, &dn, 0));
    if (!px) throw input_error(path, "cannot decode image: " + stb_reason());
    if (dw != w || dh != h || dn < 1 || dn > 4) throw input_error(path, "cannot decode image: inconsistent header");
    tex = texture_from_texels8(path, dw, dh, dn,
                               std::vector<uint8_t>(px.get(), px.get() + size_t(dw) * size_t(dh) * size_t(dn)));
  }
  return tex;
}

// Fractional part in [0, 1); NaN, infinities (and the rare round-up to 1) map to 0.
static float wrap01(float x) {
  float f = x - floorf(x);
  return (f >= 0.0f && f < 1.0f) ? f : 0.0f;
}

// x limited to [0, 1]; NaN maps to 0.
static float clamp01(float x) { return x >= 0.0f ? (x <= 1.0f ? x : 1.0f) : 0.0f; }

// Bilinear footprint along one axis of n texels: lower texel i0, upper i1 and the weight of i1; beyond the first and
// last texel centres i1 wraps to the other edge, or with clamp both are the edge texel.
// Texel k covers [k, k+1) / n, its centre at (k + 0.5) / n.
static void axis_footprint(float f, int n, bool clamp, int& i0, int& i1, float& w1) {
  float s = f * float(n) - 0.5f;  // in [-0.5, n - 0.5] (n - 0.5 only when clamped at 1)
  float fl = floorf(s);
  w1 = s - fl;
  int k = int(fl);  // in [-1, n - 1]
  if (clamp) {
    i0 = k < 0 ? 0 : (k > n - 1 ? n - 1 : k);
    i1 = k + 1 < 0 ? 0 : (k + 1 > n - 1 ? n - 1 : k + 1);
    return;
  }
  if (k < 0) k = n - 1;
  if (k > n - 1) k = n - 1;
  i0 = k;
  i1 = k + 1 < n ? k + 1 : 0;
}

// Nearest texel index along one axis of n texels for f in [0, 1] (1: the last).
static int axis_nearest(float f, int n) {
  int k = int(f * float(n));
  return k < 0 ? 0 : (k > n - 1 ? n - 1 : k);
}

vec3f eval_texture_rgb(const texture_data& tex, vec2f uv, bool clamp, const char* solid_channel) {
  if (!texture_complete(tex)) return {0, 0, 0};
  int x0, x1, b0, b1;
  float wx, wb;
  axis_footprint(clamp ? clamp01(uv.x) : wrap01(uv.x), tex.width, clamp, x0, x1, wx);
  // v counts rows from the bottom: bottom-based row b is image row height - 1 - b.
  axis_footprint(clamp ? clamp01(uv.y) : wrap01(uv.y), tex.height, clamp, b0, b1, wb);
  int y0 = tex.height - 1 - b0, y1 = tex.height - 1 - b1;
  auto index = [&](int x, int y) { return size_t(y) * size_t(tex.width) + size_t(x); };
  auto at = [&](int x, int y) { return texel_rgb(tex, index(x, y)); };
  if (solid_channel) {
    // The image is also the surface's cut-out: its holes' colours (often black) are no colour of the surface, and
    // blending them in darkened a leaf within half a texel of its edge (a review). Only solid texels are blended,
    // their weights renormalised; where none of the four is solid, all four as usual.
    const int xs[4] = {x0, x1, x0, x1}, ys[4] = {y0, y0, y1, y1};
    const float ws[4] = {(1 - wx) * (1 - wb), wx * (1 - wb), (1 - wx) * wb, wx * wb};
    vec3f sum = {0, 0, 0};
    float total = 0;
    for (int k = 0; k < 4; k++)
      if (texel_alpha(tex, index(xs[k], ys[k]), *solid_channel) >= 0.5f) {
        sum += at(xs[k], ys[k]) * ws[k];
        total += ws[k];
      }
    if (total > 0) return sum / total;
  }
  vec3f lo = at(x0, y0) * (1.0f - wx) + at(x1, y0) * wx;
  vec3f hi = at(x0, y1) * (1.0f - wx) + at(x1, y1) * wx;
  return lo * (1.0f - wb) + hi * wb;
}

float eval_texture_alpha(const texture_data& tex, vec2f uv, bool clamp, char channel) {
  if (!texture_complete(tex)) return 1.0f;
  int x = axis_nearest(clamp ? clamp01(uv.x) : wrap01(uv.x), tex.width);
  int y = tex.height - 1 - axis_nearest(clamp ? clamp01(uv.y) : wrap01(uv.y), tex.height);
  return texel_alpha(tex, size_t(y) * size_t(tex.width) + size_t(x), channel);
}

}  // namespace bl
