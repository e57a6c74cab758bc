// Tests of texture decoding and lookup: the sRGB table, channel handling (alpha from grey or from an alpha
// channel), 16-bit images, repeat wrap, v = 0 at the bottom row, bilinear weights, and hostile files.
#include "errors.h"
#include "texture.h"

#include <catch2/catch.hpp>
#include <stb_image_write.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

using namespace bl;

namespace {

// A fresh temporary directory, removed with everything in it at the end of the test.
struct temp_dir {
  std::string path;
  temp_dir() {
    char tmpl[] = "/tmp/bl_texture_test_XXXXXX";
    REQUIRE(mkdtemp(tmpl) != nullptr);
    path = tmpl;
  }
  ~temp_dir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  std::string file(const std::string& name) const { return path + "/" + name; }
};

// Writes raw bytes to a file.
void write_bytes(const std::string& path, const std::string& bytes) { std::ofstream(path, std::ios::binary) << bytes; }

// Writes a w x h PNG with n 8-bit channels per pixel, rows top first.
std::string write_png(const temp_dir& dir, const std::string& name, int w, int h, int n,
                      const std::vector<unsigned char>& px) {
  std::string path = dir.file(name);
  REQUIRE(stbi_write_png(path.c_str(), w, h, n, px.data(), w * n) != 0);
  return path;
}

// The message of the input_error that loading path throws ("" when it loads).
std::string texture_error(const std::string& path) {
  try {
    load_texture(path);
  } catch (const input_error& e) {
    return e.what();
  }
  return "";
}

// A 2x1 16-bit grey+alpha PNG: texel 0 grey 0x8080 alpha 0xffff, texel 1 grey 0xffff alpha 0.
const unsigned char png16[] = {0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48, 0x44,
                               0x52, 0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00, 0x01, 0x10, 0x04, 0x00, 0x00, 0x00, 0x0e,
                               0xbb, 0x6b, 0x42, 0x00, 0x00, 0x00, 0x0f, 0x49, 0x44, 0x41, 0x54, 0x78, 0x9c, 0x63, 0x68,
                               0x68, 0xf8, 0x0f, 0x04, 0x0c, 0x0c, 0x00, 0x19, 0x77, 0x04, 0xfd, 0x7c, 0xba, 0x30, 0x17,
                               0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82};

}  // namespace

TEST_CASE("srgb8_to_linear follows the sRGB curve", "[texture]") {
  CHECK(srgb8_to_linear(0) == 0.0f);
  CHECK(srgb8_to_linear(255) == Approx(1.0f).margin(1e-6));
  CHECK(srgb8_to_linear(128) == Approx(0.2158605f).margin(1e-7));
  CHECK(srgb8_to_linear(10) == Approx(10.0f / 255.0f / 12.92f).margin(1e-9));  // linear segment
  for (int v = 1; v < 256; v++) CHECK(srgb8_to_linear((unsigned char)v) > srgb8_to_linear((unsigned char)(v - 1)));
}

TEST_CASE("an RGB PNG decodes to linear texels top row first", "[texture]") {
  temp_dir dir;
  // 1x2: top texel sRGB 128 grey, bottom texel pure red.
  auto path = write_png(dir, "a.png", 1, 2, 3, {128, 128, 128, 255, 0, 0});
  texture_data t = load_texture(path);
  REQUIRE(t.width == 1);
  REQUIRE(t.height == 2);
  CHECK(t.path == path);
  CHECK(texel_rgb(t, 0).x == srgb8_to_linear(128));
  CHECK(texel_rgb(t, 1).x == 1.0f);
  CHECK(texel_rgb(t, 1).y == 0.0f);
  // Without an alpha channel the mask is the luminance of the linear values (the MTL format's default for scalar
  // textures; the first channel until a review found a green mask cutting out its complement).
  CHECK(texel_alpha(t, 0) == Approx(128.0f / 255.0f));
  CHECK(texel_alpha(t, 1) == Approx(0.2126f));
  CHECK(texel_alpha(t, 1, 'r') == 1.0f);
  // Kept as the file's own bytes (3 per texel here), not as float RGB + alpha (16 per texel): a 4096² RGBA texture
  // takes 64 MiB, not 256 MiB.
  CHECK(t.channels == 3);
  CHECK(t.texels8 == std::vector<uint8_t>{128, 128, 128, 255, 0, 0});
  CHECK(t.texels16.empty());
}

TEST_CASE("v equal to zero is the bottom row of the image", "[texture]") {
  temp_dir dir;
  auto path = write_png(dir, "rows.png", 1, 2, 1, {255, 0});  // top white, bottom black
  texture_data t = load_texture(path);
  CHECK(eval_texture_rgb(t, {0.5f, 0.25f}).x == 0.0f);  // centre of the bottom row
  CHECK(eval_texture_rgb(t, {0.5f, 0.75f}).x == 1.0f);  // centre of the top row
  CHECK(eval_texture_alpha(t, {0.5f, 0.1f}) == 0.0f);
  CHECK(eval_texture_alpha(t, {0.5f, 0.9f}) == 1.0f);
}

TEST_CASE("a colour image that is also the cut-out blends its solid texels only", "[texture]") {
  // An RGBA leaf whose holes store black darkened to 0.56 within half a texel of its edge (a review): the holes'
  // colours are no colour of the surface. Texel 0 white and solid, texel 1 black and a hole, texel 2 grey and solid.
  temp_dir dir;
  auto path = write_png(dir, "leaf.png", 3, 1, 4, {255, 255, 255, 255, 0, 0, 0, 0, 188, 188, 188, 255});
  texture_data t = load_texture(path);
  const char channel = 0;
  const float third = 1.0f / 3.0f;
  CHECK(eval_texture_rgb(t, {0.5f * third, 0.5f}).x == 1.0f);  // a texel centre: itself either way
  CHECK(eval_texture_rgb(t, {third, 0.5f}).x == Approx(0.5f));  // between white and the hole: blended as usual
  CHECK(eval_texture_rgb(t, {third, 0.5f}, false, &channel).x == 1.0f);  // the solid one alone
  CHECK(eval_texture_rgb(t, {0.9f, 0.5f}, false, &channel).x != 1.0f);  // grey blended with white across the seam
  // Where none of the four is solid, all four as usual (a point the cut-out lets through is never shaded anyway).
  auto holes = write_png(dir, "holes.png", 2, 1, 4, {255, 255, 255, 0, 0, 0, 0, 0});
  texture_data h = load_texture(holes);
  CHECK(eval_texture_rgb(h, {0.5f, 0.5f}, false, &channel).x == Approx(0.5f));
  // The mask's channel is the material's: by red, texel 1 (black) is a hole and texel 0 solid.
  const char red = 'r';
  CHECK(eval_texture_rgb(t, {third, 0.5f}, false, &red).x == 1.0f);
}

TEST_CASE("bilinear lookup weighs the two nearest texel centres", "[texture]") {
  temp_dir dir;
  auto path = write_png(dir, "ramp.png", 2, 1, 1, {0, 255});  // linear 0 and 1
  texture_data t = load_texture(path);
  CHECK(eval_texture_rgb(t, {0.25f, 0.5f}).x == 0.0f);            // centre of texel 0
  CHECK(eval_texture_rgb(t, {0.75f, 0.5f}).x == 1.0f);            // centre of texel 1
  CHECK(eval_texture_rgb(t, {0.5f, 0.5f}).x == Approx(0.5f));     // midpoint
  CHECK(eval_texture_rgb(t, {0.375f, 0.5f}).x == Approx(0.25f));  // a quarter of the way
  CHECK(eval_texture_rgb(t, {0.0f, 0.5f}).x == Approx(0.5f));     // the seam blends with the wrapped texel
  CHECK(eval_texture_alpha(t, {0.49f, 0.5f}) == 0.0f);            // nearest, no blending
  CHECK(eval_texture_alpha(t, {0.51f, 0.5f}) == 1.0f);
}

TEST_CASE("clamped lookups keep the edge texels beyond [0, 1] and at the seam", "[texture]") {
  temp_dir dir;
  auto path = write_png(dir, "ramp.png", 2, 1, 1, {0, 255});  // linear 0 and 1
  texture_data t = load_texture(path);
  CHECK(eval_texture_rgb(t, {0.0f, 0.5f}, true).x == 0.0f);  // no blend with the other edge (wrapped: 0.5)
  CHECK(eval_texture_rgb(t, {1.0f, 0.5f}, true).x == 1.0f);
  CHECK(eval_texture_rgb(t, {1.7f, 0.5f}, true).x == 1.0f);  // (wrapped: 0.7 lies between the centres)
  CHECK(eval_texture_rgb(t, {-3.0f, 0.5f}, true).x == 0.0f);
  CHECK(eval_texture_rgb(t, {0.5f, 0.5f}, true).x == Approx(0.5f));  // inside, as wrapped
  CHECK(eval_texture_alpha(t, {1.2f, 0.5f}, true) == 1.0f);            // (wrapped: texel 0)
  CHECK(eval_texture_alpha(t, {1.2f, 0.5f}) == 0.0f);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  CHECK(eval_texture_rgb(t, {nan, nan}, true).x == 0.0f);
  // MTL -s and -o: the image is read at uv * scale + offset.
  texture_transform xf;
  xf.scale = {2, 3};
  xf.offset = {0.25f, -0.5f};
  vec2f uv = transform_uv(xf, {0.5f, 0.5f});
  CHECK(uv.x == 1.25f);
  CHECK(uv.y == 1.0f);
}

TEST_CASE("lookups repeat and survive huge negative and NaN coordinates", "[texture]") {
  temp_dir dir;
  auto path = write_png(dir, "wrap.png", 4, 3, 3,
                        {10,  20,  30,  40,  50,  60,  70,  80, 90, 100, 110, 120, 130, 140, 150, 160, 170, 180,
                         190, 200, 210, 220, 230, 240, 250, 5,  15, 25,  35,  45,  55,  65,  75,  85,  95,  105});
  texture_data t = load_texture(path);
  for (float u : {0.1f, 0.3f, 0.62f, 0.9f})
    for (float v : {0.2f, 0.5f, 0.8f}) {
      vec3f a = eval_texture_rgb(t, {u, v});
      vec3f b = eval_texture_rgb(t, {u + 3.0f, v - 2.0f});
      CHECK(a.x == Approx(b.x).margin(1e-5));
      CHECK(a.z == Approx(b.z).margin(1e-5));
      CHECK(eval_texture_alpha(t, {u, v}) == eval_texture_alpha(t, {u - 5.0f, v + 7.0f}));
    }
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  for (vec2f uv : {vec2f{nan, nan}, vec2f{inf, -inf}, vec2f{1e30f, -1e30f}, vec2f{-1e-9f, -1e-9f}}) {
    vec3f c = eval_texture_rgb(t, uv);
    CHECK(is_finite(c));
    CHECK(c.x >= 0.0f);
    CHECK(c.x <= 1.0f);
    float a = eval_texture_alpha(t, uv);
    CHECK(a >= 0.0f);
    CHECK(a <= 1.0f);
  }
  // NaN is treated as 0.
  CHECK(eval_texture_alpha(t, {nan, nan}) == eval_texture_alpha(t, {0.0f, 0.0f}));
  CHECK(eval_texture_rgb(t, {nan, 0.3f}).y == eval_texture_rgb(t, {0.0f, 0.3f}).y);
}

TEST_CASE("alpha comes from the alpha channel when there is one and from grey otherwise", "[texture]") {
  temp_dir dir;
  texture_data grey = load_texture(write_png(dir, "g.png", 1, 1, 1, {51}));
  texture_data grey_alpha = load_texture(write_png(dir, "ga.png", 1, 1, 2, {51, 204}));
  texture_data rgba = load_texture(write_png(dir, "rgba.png", 1, 1, 4, {255, 0, 0, 102}));
  CHECK(texel_alpha(grey, 0) == Approx(0.2f));
  CHECK(texel_rgb(grey, 0).y == srgb8_to_linear(51));
  CHECK(texel_alpha(grey_alpha, 0) == Approx(0.8f));
  CHECK(texel_rgb(grey_alpha, 0).z == srgb8_to_linear(51));
  CHECK(texel_alpha(rgba, 0) == Approx(0.4f));
  CHECK(texel_rgb(rgba, 0).x == 1.0f);
  CHECK(texel_rgb(rgba, 0).y == 0.0f);
}

TEST_CASE("16-bit images decode through the same sRGB curve", "[texture]") {
  temp_dir dir;
  write_bytes(dir.file("p16.png"), std::string(reinterpret_cast<const char*>(png16), sizeof png16));
  texture_data t = load_texture(dir.file("p16.png"));
  REQUIRE(t.width == 2);
  REQUIRE(t.height == 1);
  float c = 32896.0f / 65535.0f;
  CHECK(texel_rgb(t, 0).x == Approx(std::pow((c + 0.055) / 1.055, 2.4)).epsilon(1e-6));
  CHECK(texel_rgb(t, 1).x == 1.0f);
  CHECK(texel_alpha(t, 0) == 1.0f);
  CHECK(texel_alpha(t, 1) == 0.0f);
  CHECK(t.texels8.empty());  // 16 bits per channel kept as such
  CHECK(t.texels16.size() == size_t(2 * t.channels));
}

TEST_CASE("a texture that would take the scene's textures past their budget is refused before decoding", "[texture]") {
  // Nothing capped the sum: four 1 MB PNGs of 2^27 16-bit RGBA texels each decoded to 5 GB (a review). The loader
  // passes what the scene's other textures leave of max_textures_bytes; the 16-bit 2x1 grey+alpha image takes 8 bytes.
  temp_dir dir;
  write_bytes(dir.file("p16.png"), std::string(reinterpret_cast<const char*>(png16), sizeof png16));
  CHECK(texture_bytes(load_texture(dir.file("p16.png"), 8)) == 8);
  CHECK_THROWS_WITH(load_texture(dir.file("p16.png"), 7),
                    Catch::Contains("p16.png") && Catch::Contains("past 4 GiB in all"));
  auto path = write_png(dir, "rgb.png", 3, 2, 3, std::vector<unsigned char>(18, 7));  // 8-bit: 18 bytes
  CHECK(texture_bytes(load_texture(path, 18)) == 18);
  CHECK_THROWS_WITH(load_texture(path, 17), Catch::Contains("past 4 GiB"));
}

TEST_CASE("missing garbage truncated and unsupported images are input errors", "[texture]") {
  temp_dir dir;
  CHECK_THAT(texture_error(dir.file("none.png")), Catch::Contains("none.png") && Catch::Contains("cannot open"));
  CHECK_THAT(texture_error(dir.path), Catch::Contains("not a regular file"));
  write_bytes(dir.file("empty.png"), "");
  CHECK_THAT(texture_error(dir.file("empty.png")), Catch::Contains("empty.png: cannot decode"));
  std::string garbage;
  for (int i = 0; i < 5000; i++) garbage += char((i * 7919 + 13) % 251);
  write_bytes(dir.file("garbage.png"), garbage);
  CHECK_THAT(texture_error(dir.file("garbage.png")), Catch::Contains("garbage.png: cannot decode"));
  // A real PNG cut after its header, and one with its pixel data corrupted.
  std::vector<unsigned char> px(64 * 64 * 3);
  for (size_t i = 0; i < px.size(); i++) px[i] = (unsigned char)(i * 31);
  auto good = write_png(dir, "good.png", 64, 64, 3, px);
  std::ifstream in(good, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  write_bytes(dir.file("cut.png"), bytes.substr(0, 60));
  CHECK_THAT(texture_error(dir.file("cut.png")), Catch::Contains("cut.png: cannot decode"));
  std::string corrupt = bytes;
  for (size_t i = 60; i < corrupt.size(); i += 3) corrupt[i] = char(corrupt[i] ^ 0x5a);
  write_bytes(dir.file("corrupt.png"), corrupt);
  CHECK_THAT(texture_error(dir.file("corrupt.png")), Catch::Contains("corrupt.png: cannot decode"));
  // HDR and GIF are refused by name.
  float hdr[3] = {1, 2, 3};
  REQUIRE(stbi_write_hdr(dir.file("sky.hdr").c_str(), 1, 1, 3, hdr) != 0);
  CHECK_THAT(texture_error(dir.file("sky.hdr")), Catch::Contains("unsupported image format HDR"));
  write_bytes(dir.file("anim.gif"), "GIF89a\x01\x00\x01\x00");
  CHECK_THAT(texture_error(dir.file("anim.gif")), Catch::Contains("unsupported image format GIF"));
}

TEST_CASE("truncated TGA and BMP files and impossible sizes are input errors", "[texture]") {
  temp_dir dir;
  // Uncompressed 2x1 true-colour TGA (BGR texels), whole and cut short: stb_image alone would read zeros.
  const unsigned char tga_bytes[24] = {0, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 1, 0, 24, 0x20,
                                       0x10, 0x20, 0x30, 0x40, 0x50, 0x60};
  std::string tga(reinterpret_cast<const char*>(tga_bytes), sizeof tga_bytes);
  REQUIRE(tga.size() == 24);
  write_bytes(dir.file("ok.tga"), tga);
  texture_data t = load_texture(dir.file("ok.tga"));
  REQUIRE(t.width == 2);
  CHECK(texel_rgb(t, 0).x == srgb8_to_linear(0x30));
  write_bytes(dir.file("cut.tga"), tga.substr(0, 21));
  CHECK_THAT(texture_error(dir.file("cut.tga")), Catch::Contains("cut.tga: cannot decode image: truncated"));
  // Run-length encoded 4x1 (type 10): a run of 3 of one texel, then one raw texel. Whole, then cut inside its
  // packets and to its header: stb_image alone loaded those as black.
  const unsigned char rle_bytes[26] = {0, 0, 10, 0, 0, 0, 0, 0, 0, 0, 0, 0, 4, 0, 1, 0, 24, 0x20,
                                       0x82, 0x10, 0x20, 0x30, 0x00, 0x40, 0x50, 0x60};
  std::string rle(reinterpret_cast<const char*>(rle_bytes), sizeof rle_bytes);
  write_bytes(dir.file("rle.tga"), rle);
  texture_data r = load_texture(dir.file("rle.tga"));
  REQUIRE(r.width == 4);
  CHECK(texel_rgb(r, 2).x == srgb8_to_linear(0x30));
  CHECK(texel_rgb(r, 3).x == srgb8_to_linear(0x60));
  for (size_t cut : {25, 22, 18}) {
    write_bytes(dir.file("rle_cut.tga"), rle.substr(0, cut));
    INFO(cut << " bytes");
    CHECK_THAT(texture_error(dir.file("rle_cut.tga")), Catch::Contains("rle_cut.tga: cannot decode image: truncated"));
  }
  // Colour-mapped 4x4 (type 1): 16 bytes skipped before a palette of two 24-bit entries (the colour map's first
  // index), then 16 index bytes. The guard left out those 16 bytes: cut by 14, it decoded the missing indices as 0.
  std::string mapped("\0\x01\x01\x10\0\x02\0\x18\0\0\0\0\x04\0\x04\0\x08\x20", 18);
  mapped += std::string(16, '\0') + std::string("\0\0\xff\0\xff\0", 6) + std::string(16, '\x01');
  write_bytes(dir.file("mapped.tga"), mapped);
  texture_data m = load_texture(dir.file("mapped.tga"));
  REQUIRE(m.width == 4);
  CHECK(texel_rgb(m, 15).y == srgb8_to_linear(0xff));  // index 1: green
  CHECK(texel_rgb(m, 15).x == 0);
  for (size_t cut : {size_t(55), size_t(42), size_t(35)}) {
    write_bytes(dir.file("mapped_cut.tga"), mapped.substr(0, cut));
    INFO(cut << " bytes");
    CHECK_THAT(texture_error(dir.file("mapped_cut.tga")),
               Catch::Contains("mapped_cut.tga: cannot decode image: truncated"));
  }
  // A BMP written by stb, whole and cut short.
  std::vector<unsigned char> px(8 * 8 * 3, 77);
  REQUIRE(stbi_write_bmp(dir.file("ok.bmp").c_str(), 8, 8, 3, px.data()) != 0);
  std::ifstream in(dir.file("ok.bmp"), std::ios::binary);
  std::string bmp((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK(texel_rgb(load_texture(dir.file("ok.bmp")), 63).y == srgb8_to_linear(77));
  write_bytes(dir.file("cut.bmp"), bmp.substr(0, bmp.size() - 10));
  CHECK_THAT(texture_error(dir.file("cut.bmp")), Catch::Contains("cut.bmp: cannot decode image: truncated"));
  // 22 bytes that claim 1537x65281 texels (found by fuzzing: 1.6 GB of decoded zeros).
  write_bytes(dir.file("tiny.tga"),
              std::string("\x01\0\x02\0\0\0\0\xdb\0\x04\0\0\x01\x06\x01\xff\x18\x41\x78\x05\x06\x07", 22));
  CHECK_THAT(texture_error(dir.file("tiny.tga")), Catch::Contains("cannot fit in 22 bytes"));
  // A PNG header of 20000x20000 texels: its size is the reason given (stb_image alone says "unknown image type").
  std::string ihdr("\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR\0\0\x4e\x20\0\0\x4e\x20\x08\x06\0\0\0\0\0\0\0", 33);
  write_bytes(dir.file("huge.png"), ihdr + std::string(64, '\0'));
  CHECK_THAT(texture_error(dir.file("huge.png")), Catch::Contains("huge.png: image too large (20000x20000 texels)"));
  // The largest sizes a PNG header holds: their product overflowed a signed 64-bit integer (found by fuzzing).
  std::string max_ihdr("\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR\xff\xff\xff\xff\xff\xff\xff\xff\x08\x06\0\0\0\0\0\0\0", 33);
  write_bytes(dir.file("max.png"), max_ihdr + std::string(64, '\0'));
  CHECK_THAT(texture_error(dir.file("max.png")), Catch::Contains("image too large (4294967295x4294967295 texels)"));
}

TEST_CASE("an empty texture looks up as black and opaque", "[texture]") {
  texture_data t;
  CHECK(is_black(eval_texture_rgb(t, {0.5f, 0.5f})));
  CHECK(eval_texture_alpha(t, {0.5f, 0.5f}) == 1.0f);
}
