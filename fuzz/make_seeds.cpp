// make_seeds: writes the binary seed files of fuzz/corpus/texture and fuzz/corpus/image (the text seeds of
// scene/ and obj/ are written by hand). Built with the fuzz targets as fuzz_make_seeds; run once as
//   build-fuzz/fuzz_make_seeds fuzz/corpus
// after a change here. Every file is tiny (2x2 to 5x3 pixels) and valid unless its name says otherwise
// ("bad_*", "trunc_*"): small valid files of every format variant the decoders handle are what let a fuzzer
// reach their deep paths (PNG bit depths, palettes and Adam7; BMP palettes, bit fields and RLE; TGA RLE and
// colour maps; EXR pixel types and every compression tinyexr writes; PFM byte orders).
#include <stb_image_write.h>
#include <tinyexr.h>
#include <zlib.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace {

std::string out_dir;

// Writes bytes to out_dir/sub/name.
void save(const std::string& sub, const std::string& name, const std::string& bytes) {
  std::string path = out_dir + "/" + sub + "/" + name;
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f || std::fwrite(bytes.data(), 1, bytes.size(), f) != bytes.size() || std::fclose(f) != 0) {
    std::fprintf(stderr, "cannot write %s\n", path.c_str());
    std::exit(1);
  }
}

void put_be32(std::string& s, uint32_t v) {
  for (int k = 3; k >= 0; k--) s += char((v >> (8 * k)) & 0xff);
}
void put_le(std::string& s, uint32_t v, int n) {
  for (int k = 0; k < n; k++) s += char((v >> (8 * k)) & 0xff);
}

// ---- PNG (hand-made, for what stb_image_write cannot write: bit depths 1-16, palettes, tRNS, Adam7) ----

void png_chunk(std::string& png, const char* type, const std::string& data) {
  put_be32(png, uint32_t(data.size()));
  std::string body = std::string(type, 4) + data;
  png += body;
  put_be32(png, uint32_t(crc32(0, reinterpret_cast<const Bytef*>(body.data()), uInt(body.size()))));
}

// Bits of sample value v (bit depth `depth`) packed into scanline bytes.
struct bit_writer {
  std::string bytes;
  int used = 8;
  void put(uint32_t v, int depth) {
    if (depth >= 8) {
      for (int k = depth / 8 - 1; k >= 0; k--) bytes += char((v >> (8 * k)) & 0xff);
      return;
    }
    if (used == 8) bytes += '\0', used = 0;
    bytes.back() = char(uint8_t(bytes.back()) | uint8_t(v << (8 - depth - used)));
    used += depth;
  }
};

// A PNG of w x h pixels with `channels` samples each: sample(x, y, c) gives the value (< 2^depth).
template <typename F>
std::string make_png(int w, int h, int depth, int color_type, int channels, bool adam7, F sample,
                     const std::string& plte = "", const std::string& trns = "") {
  std::string raw;
  auto add_pass = [&](int x0, int y0, int dx, int dy) {
    for (int y = y0; y < h; y += dy) {
      bit_writer row;
      for (int x = x0; x < w; x += dx)
        for (int c = 0; c < channels; c++) row.put(uint32_t(sample(x, y, c)), depth);
      if (row.bytes.empty()) continue;
      raw += char(y % 5);  // every filter type (None, Sub, Up, Average, Paeth) on the raw bytes: see below
      raw += row.bytes;
    }
  };
  if (adam7) {
    const int p[7][4] = {{0, 0, 8, 8}, {4, 0, 8, 8}, {0, 4, 4, 8}, {2, 0, 4, 4}, {0, 2, 2, 4}, {1, 0, 2, 2}, {0, 1, 1, 2}};
    for (auto& q : p) add_pass(q[0], q[1], q[2], q[3]);
  } else {
    add_pass(0, 0, 1, 1);
  }
  // The filter bytes above make the decoder "unfilter" raw sample bytes: the image is still valid, just
  // different pixels, which is all a seed needs.
  uLongf zlen = compressBound(uLong(raw.size()));
  std::string z(zlen, '\0');
  compress2(reinterpret_cast<Bytef*>(&z[0]), &zlen, reinterpret_cast<const Bytef*>(raw.data()), uLong(raw.size()), 9);
  z.resize(zlen);
  std::string png = "\x89PNG\r\n\x1a\n";
  std::string ihdr;
  put_be32(ihdr, uint32_t(w));
  put_be32(ihdr, uint32_t(h));
  ihdr += char(depth), ihdr += char(color_type), ihdr += '\0', ihdr += '\0', ihdr += char(adam7 ? 1 : 0);
  png_chunk(png, "IHDR", ihdr);
  if (!plte.empty()) png_chunk(png, "PLTE", plte);
  if (!trns.empty()) png_chunk(png, "tRNS", trns);
  png_chunk(png, "IDAT", z);
  png_chunk(png, "IEND", "");
  return png;
}

// ---- stb_image_write (PNG, BMP, TGA, JPEG of 1-4 channels) ----

void append(void* ctx, void* data, int size) { static_cast<std::string*>(ctx)->append(static_cast<char*>(data), size_t(size)); }

std::vector<unsigned char> pixels8(int w, int h, int n) {
  std::vector<unsigned char> px(size_t(w * h * n));
  for (size_t i = 0; i < px.size(); i++) px[i] = (unsigned char)(i * 37 + 11);
  return px;
}

// ---- BMP (hand-made: palettes, 16/32-bit bit fields, RLE8, top-down) ----

// header_size 40 (BITMAPINFOHEADER), 108 (V4) or 12 (OS/2 core); pixel bytes as given.
std::string make_bmp(int w, int h, int bpp, int compression, const std::string& palette, const std::string& pixels,
                     int header_size = 40, const std::vector<uint32_t>& masks = {}) {
  std::string info;
  if (header_size == 12) {
    put_le(info, 12, 4), put_le(info, uint32_t(w), 2), put_le(info, uint32_t(h), 2), put_le(info, 1, 2),
        put_le(info, uint32_t(bpp), 2);
  } else {
    put_le(info, uint32_t(header_size), 4), put_le(info, uint32_t(w), 4), put_le(info, uint32_t(h), 4);
    put_le(info, 1, 2), put_le(info, uint32_t(bpp), 2), put_le(info, uint32_t(compression), 4);
    put_le(info, uint32_t(pixels.size()), 4), put_le(info, 2835, 4), put_le(info, 2835, 4);
    put_le(info, bpp <= 8 ? uint32_t(palette.size() / 4) : 0, 4), put_le(info, 0, 4);
    if (header_size == 40)
      for (uint32_t m : masks) put_le(info, m, 4);  // BI_BITFIELDS masks follow a v3 header
    if (header_size >= 108) {
      for (size_t k = 0; k < 4; k++) put_le(info, k < masks.size() ? masks[k] : 0, 4);
      info += std::string(size_t(header_size) - 56, '\0');
    }
  }
  std::string bmp = "BM";
  uint32_t offset = uint32_t(14 + info.size() + palette.size());
  put_le(bmp, uint32_t(offset + pixels.size()), 4), put_le(bmp, 0, 4), put_le(bmp, offset, 4);
  return bmp + info + palette + pixels;
}

// Rows of `row_bytes` bytes each padded to 4 bytes.
std::string bmp_rows(int h, int row_bytes) {
  std::string px;
  for (int y = 0; y < h; y++) {
    for (int i = 0; i < row_bytes; i++) px += char(y * 31 + i * 7 + 1);
    px += std::string(size_t((4 - row_bytes % 4) % 4), '\0');
  }
  return px;
}

// ---- TGA (hand-made colour-mapped and 16-bit files) ----

std::string tga_header(int id_len, int cmap_type, int type, int cmap_len, int cmap_bits, int w, int h, int bpp,
                       int descriptor) {
  std::string t;
  t += char(id_len), t += char(cmap_type), t += char(type);
  put_le(t, 0, 2), put_le(t, uint32_t(cmap_len), 2), t += char(cmap_bits);
  put_le(t, 0, 2), put_le(t, 0, 2), put_le(t, uint32_t(w), 2), put_le(t, uint32_t(h), 2);
  t += char(bpp), t += char(descriptor);
  return t + std::string(size_t(id_len), 'i');
}

// ---- EXR (tinyexr) ----

// An EXR of w x h with the named channels of pixel type `type`, compressed with `compression`.
std::string make_exr(int w, int h, const std::vector<const char*>& names, int type, int compression) {
  int n = int(names.size());
  std::vector<std::vector<unsigned char>> planes(static_cast<size_t>(n));
  std::vector<unsigned char*> ptrs(static_cast<size_t>(n));
  for (int c = 0; c < n; c++) {
    planes[size_t(c)].resize(size_t(w * h * 4));
    for (int i = 0; i < w * h; i++) {
      float f = 0.1f * float(i) + 0.7f * float(c);
      if (type == TINYEXR_PIXELTYPE_UINT) {
        uint32_t u = uint32_t(i * 3 + c);
        std::memcpy(&planes[size_t(c)][size_t(i) * 4], &u, 4);
      } else {
        std::memcpy(&planes[size_t(c)][size_t(i) * 4], &f, 4);  // HALF is converted from FLOAT on save
      }
    }
    ptrs[size_t(c)] = planes[size_t(c)].data();
  }
  EXRImage image;
  InitEXRImage(&image);
  image.images = ptrs.data();
  image.width = w;
  image.height = h;
  image.num_channels = n;
  std::vector<EXRChannelInfo> ch(static_cast<size_t>(n));
  std::vector<int> in_types(size_t(n), type == TINYEXR_PIXELTYPE_UINT ? type : TINYEXR_PIXELTYPE_FLOAT),
      out_types(size_t(n), type);
  for (int c = 0; c < n; c++) std::strcpy(ch[size_t(c)].name, names[size_t(c)]);
  EXRHeader header;
  InitEXRHeader(&header);
  header.num_channels = n;
  header.channels = ch.data();
  header.pixel_types = in_types.data();
  header.requested_pixel_types = out_types.data();
  header.compression_type = compression;
  unsigned char* mem = nullptr;
  const char* err = nullptr;
  size_t size = SaveEXRImageToMemory(&image, &header, &mem, &err);
  if (size == 0) {
    std::fprintf(stderr, "tinyexr: %s\n", err ? err : "?");
    std::exit(1);
  }
  std::string out(reinterpret_cast<char*>(mem), size);
  std::free(mem);
  return out;
}

// ---- PFM ----

std::string make_pfm(const std::string& magic, int w, int h, const std::string& scale, bool little,
                     const std::string& sep = "\n") {
  std::string s = magic + sep + std::to_string(w) + " " + std::to_string(h) + sep + scale + sep;
  int ch = magic == "PF" ? 3 : 1;
  for (int i = 0; i < w * h * ch; i++) {
    float f = 0.25f * float(i) - 1.0f;
    uint32_t u;
    std::memcpy(&u, &f, 4);
    for (int k = 0; k < 4; k++) s += char((u >> (8 * (little ? k : 3 - k))) & 0xff);
  }
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s CORPUS_DIR   (writes CORPUS_DIR/texture/* and CORPUS_DIR/image/*)\n", argv[0]);
    return 2;
  }
  out_dir = argv[1];

  // Textures: stb_image_write's PNG, BMP, TGA (raw and RLE) and baseline JPEG for 1-4 channels.
  for (int n = 1; n <= 4; n++) {
    std::string s, tag = std::to_string(n) + "ch";
    auto px = pixels8(3, 2, n);
    s.clear(), stbi_write_png_to_func(append, &s, 3, 2, n, px.data(), 3 * n), save("texture", "stb_" + tag + ".png", s);
    if (n == 3 || n == 4)
      s.clear(), stbi_write_bmp_to_func(append, &s, 3, 2, n, px.data()), save("texture", "stb_" + tag + ".bmp", s);
    stbi_write_tga_with_rle = 0;
    s.clear(), stbi_write_tga_to_func(append, &s, 3, 2, n, px.data()), save("texture", "stb_" + tag + ".tga", s);
    stbi_write_tga_with_rle = 1;
    s.clear(), stbi_write_tga_to_func(append, &s, 3, 2, n, px.data()), save("texture", "stb_rle_" + tag + ".tga", s);
    if (n == 1 || n == 3)
      s.clear(), stbi_write_jpg_to_func(append, &s, 9, 7, n, pixels8(9, 7, n).data(), 90),
          save("texture", "stb_" + tag + ".jpg", s);
  }
  // PNG: every colour type and bit depth stb_image decodes, palettes with tRNS, Adam7 interlacing.
  auto ramp = [](int bits) { return [bits](int x, int y, int c) { return (x * 5 + y * 3 + c * 7) % (1 << bits); }; };
  for (int d : {1, 2, 4, 8, 16}) save("texture", "png_grey" + std::to_string(d) + ".png", make_png(5, 3, d, 0, 1, false, ramp(d)));
  for (int d : {8, 16}) {
    save("texture", "png_rgb" + std::to_string(d) + ".png", make_png(3, 2, d, 2, 3, false, ramp(d)));
    save("texture", "png_greyalpha" + std::to_string(d) + ".png", make_png(3, 2, d, 4, 2, false, ramp(d)));
    save("texture", "png_rgba" + std::to_string(d) + ".png", make_png(3, 2, d, 6, 4, false, ramp(d)));
  }
  std::string plte("\xff\x00\x00\x00\xff\x00\x00\x00\xff\x10\x20\x30", 12);
  for (int d : {1, 2, 4, 8}) {
    auto idx = [d](int x, int y, int) { return (x + y) % (d == 1 ? 2 : 4); };
    save("texture", "png_palette" + std::to_string(d) + ".png", make_png(5, 3, d, 3, 1, false, idx, plte));
  }
  save("texture", "png_palette_trns.png",
       make_png(3, 2, 8, 3, 1, false, [](int x, int y, int) { return (x + y) % 4; }, plte, std::string("\x00\x80", 2)));
  save("texture", "png_grey_trns.png", make_png(3, 2, 8, 0, 1, false, ramp(8), "", std::string("\x00\x05", 2)));
  save("texture", "png_rgb_trns16.png", make_png(3, 2, 16, 2, 3, false, ramp(16), "", std::string(6, '\x01')));
  save("texture", "png_adam7_rgba8.png", make_png(9, 9, 8, 6, 4, true, ramp(8)));
  save("texture", "png_adam7_grey1.png", make_png(11, 5, 1, 0, 1, true, ramp(1)));
  save("texture", "png_adam7_rgb16.png", make_png(5, 6, 16, 2, 3, true, ramp(16)));
  {
    std::string good = make_png(3, 2, 8, 2, 3, false, ramp(8));
    save("texture", "trunc_png.png", good.substr(0, good.size() - 20));
    std::string badcrc = good;
    badcrc[29] ^= 0x55;  // inside IHDR's CRC
    save("texture", "crc_mismatch.png", badcrc);
  }
  // BMP: OS/2 and V4 headers, 1/4/8-bit palettes, RLE4/RLE8 (stb_image refuses RLE), 16-bit 555/565, 32-bit with alpha bit fields,
  // top-down rows (negative height).
  std::string pal4 = std::string("\x00\x00\x00\x00\xff\xff\xff\x00\x00\x00\xff\x00\x00\xff\x00\x00", 16);
  save("texture", "bmp_pal1.bmp", make_bmp(5, 3, 1, 0, pal4.substr(0, 8), bmp_rows(3, 1)));
  save("texture", "bmp_pal4.bmp", make_bmp(5, 3, 4, 0, pal4, bmp_rows(3, 3)));
  save("texture", "bmp_pal8.bmp", make_bmp(5, 3, 8, 0, pal4, bmp_rows(3, 5)));
  save("texture", "bmp_os2_pal8.bmp", make_bmp(5, 3, 8, 0, std::string("\x00\x00\xff\x00\xff\x00", 6),
                                               bmp_rows(3, 5), 12));
  save("texture", "bad_bmp_rle8.bmp",
       make_bmp(5, 3, 8, 1, pal4, std::string("\x03\x01\x02\x02\x00\x00\x05\x03\x00\x00\x00\x03\x01\x02\x03\x00\x00\x01", 18)));
  save("texture", "bad_bmp_rle4.bmp",
       make_bmp(5, 3, 4, 2, pal4, std::string("\x05\x12\x00\x00\x05\x21\x00\x00\x05\x33\x00\x01", 12)));
  save("texture", "bmp_rgb555.bmp", make_bmp(3, 2, 16, 0, "", bmp_rows(2, 6)));
  save("texture", "bmp_rgb565.bmp", make_bmp(3, 2, 16, 3, "", bmp_rows(2, 6), 40, {0xf800, 0x07e0, 0x001f}));
  save("texture", "bmp_argb32_v4.bmp",
       make_bmp(3, 2, 32, 3, "", bmp_rows(2, 12), 108, {0x00ff0000, 0x0000ff00, 0x000000ff, 0xff000000}));
  save("texture", "bmp_topdown24.bmp", make_bmp(3, -2, 24, 0, "", bmp_rows(2, 9)));
  // TGA: colour-mapped (raw and RLE), 16-bit, bottom-up and top-down, with an image ID field.
  {
    std::string cmap("\x00\x00\xff\x00\xff\x00\xff\x00\x00\x10\x20\x30", 12);
    std::string idx = std::string("\x00\x01\x02\x03\x00\x01", 6);
    save("texture", "tga_cmap.tga", tga_header(3, 1, 1, 4, 24, 3, 2, 8, 0) + cmap + idx);
    save("texture", "tga_cmap_rle.tga",
         tga_header(0, 1, 9, 4, 24, 3, 2, 8, 0x20) + cmap + std::string("\x82\x01\x02\x03\x02\x00", 6));
    save("texture", "tga_rgb16.tga", tga_header(0, 0, 2, 0, 0, 3, 2, 16, 0x20) + bmp_rows(1, 12));
    save("texture", "tga_grey_rle.tga", tga_header(0, 0, 11, 0, 0, 3, 2, 8, 0) + std::string("\x85\x40", 2));
    save("texture", "trunc_tga.tga", tga_header(0, 0, 2, 0, 0, 30, 20, 24, 0) + "short");
  }
  // Formats refused by their magic bytes, and garbage.
  save("texture", "bad_gif.gif", "GIF89a\x02\x00\x02\x00");
  save("texture", "bad_hdr.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 2\n");
  save("texture", "bad_pnm.ppm", "P6\n2 2\n255\n0123456789ab");
  save("texture", "bad_psd.psd", "8BPS\x00\x01");
  save("texture", "bad_huge_png.png", make_png(3, 2, 8, 2, 3, false, ramp(8)).replace(16, 8, "\x00\x01\x00\x00\x00\x01\x00\x00", 8));

  // EXR: FLOAT, HALF and UINT; every compression tinyexr writes; grey and RGBA channel sets.
  const std::vector<const char*> bgr = {"B", "G", "R"};
  const struct { int type; const char* name; } types[] = {
      {TINYEXR_PIXELTYPE_FLOAT, "float"}, {TINYEXR_PIXELTYPE_HALF, "half"}, {TINYEXR_PIXELTYPE_UINT, "uint"}};
  const struct { int c; const char* name; } comps[] = {{TINYEXR_COMPRESSIONTYPE_NONE, "none"},
                                                       {TINYEXR_COMPRESSIONTYPE_RLE, "rle"},
                                                       {TINYEXR_COMPRESSIONTYPE_ZIPS, "zips"},
                                                       {TINYEXR_COMPRESSIONTYPE_ZIP, "zip"},
                                                       {TINYEXR_COMPRESSIONTYPE_PIZ, "piz"}};
  for (auto& t : types)
    for (auto& c : comps)
      if (t.type != TINYEXR_PIXELTYPE_UINT || c.c == TINYEXR_COMPRESSIONTYPE_ZIP)
        save("image", std::string("exr_") + t.name + "_" + c.name + ".exr", make_exr(5, 3, bgr, t.type, c.c));
  save("image", "exr_rgba_half_piz.exr", make_exr(4, 20, {"A", "B", "G", "R"}, TINYEXR_PIXELTYPE_HALF,
                                                  TINYEXR_COMPRESSIONTYPE_PIZ));
  save("image", "exr_y_float.exr", make_exr(3, 2, {"Y"}, TINYEXR_PIXELTYPE_FLOAT, TINYEXR_COMPRESSIONTYPE_NONE));
  save("image", "bad_exr_no_rgb.exr", make_exr(3, 2, {"U", "V"}, TINYEXR_PIXELTYPE_FLOAT, TINYEXR_COMPRESSIONTYPE_NONE));
  {
    std::string good = make_exr(5, 3, bgr, TINYEXR_PIXELTYPE_HALF, TINYEXR_COMPRESSIONTYPE_ZIP);
    save("image", "trunc_exr.exr", good.substr(0, good.size() - 7));
    save("image", "trunc_exr_header.exr", good.substr(0, 40));
  }
  // PFM: RGB and grey, both byte orders, CRLF after the scale, scale with exponent; malformed headers.
  save("image", "pfm_rgb_le.pfm", make_pfm("PF", 3, 2, "-1.0", true));
  save("image", "pfm_rgb_be.pfm", make_pfm("PF", 3, 2, "1.0", false));
  save("image", "pfm_grey_le.pfm", make_pfm("Pf", 2, 3, "-0.5", true));
  save("image", "pfm_grey_be.pfm", make_pfm("Pf", 1, 1, "2e0", false));
  {
    std::string crlf = make_pfm("PF", 2, 2, "-1", true);
    crlf.replace(crlf.find("-1\n"), 3, "-1\r\n");
    save("image", "pfm_crlf.pfm", crlf);
    std::string tabs = make_pfm("PF", 2, 1, "-1", true, "\t");
    save("image", "pfm_tabs.pfm", tabs);
  }
  std::string good_pfm = make_pfm("PF", 3, 2, "-1.0", true);
  save("image", "trunc_pfm.pfm", good_pfm.substr(0, good_pfm.size() - 1));
  save("image", "bad_pfm_extra.pfm", good_pfm + "x");
  save("image", "bad_pfm_huge.pfm", "PF\n1048577 1\n-1\n");
  save("image", "bad_pfm_overflow.pfm", "PF\n99999999999999999999 1\n-1\n");
  save("image", "bad_pfm_scale.pfm", "PF\n1 1\nnan\n0000");
  save("image", "bad_pfm_zero_scale.pfm", "PF\n1 1\n0\n000000000000");
  save("image", "bad_pfm_negative.pfm", "Pf\n-1 1\n-1\n0000");
  save("image", "bad_pfm_no_data.pfm", "PF\n1 1\n-1");
  save("image", "bad_empty.exr", "");
  save("image", "bad_magic.exr", "not an exr at all");
  return 0;
}
