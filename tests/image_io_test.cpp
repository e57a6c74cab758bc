// Tests of image_io: bit-exact .exr and .pfm round trips (negative, huge, tiny, signed zero, inf, NaN), PNG
// quantisation within half a code value, hand-made greyscale and big-endian PFMs, half-float and one-channel
// EXRs from tinyexr, hand-made EXRs in any line order, grey with alpha and of undecodable compressions, and
// malformed or truncated files rejected with an input_error naming the file.
#include "errors.h"
#include "file_io.h"
#include "image_io.h"
#include "test_util.h"

#include <catch2/catch.hpp>
#include <stb_image.h>
#include <tinyexr.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <unistd.h>

using namespace bl;

// A w x h image whose values cover hard cases: negatives, huge, denormal, signed zero, inf, NaN, ramps.
static image_data test_image(int w, int h) {
  const float specials[] = {-0.0f, 0.0f, -1.5f, 3.4e38f, -3.4e38f, 1e-42f, 1e30f, 0.1f,
                            std::numeric_limits<float>::infinity(), std::numeric_limits<float>::quiet_NaN()};
  image_data img;
  img.width = w;
  img.height = h;
  img.pixels.resize(size_t(w) * h * 3);
  for (size_t i = 0; i < img.pixels.size(); ++i)
    img.pixels[i] = i < 10 ? specials[i] : float(i % 97) * 0.37f - float(i % 13) * 5.1f;
  return img;
}

// True when both images have the same size and the same pixel bits.
static bool same_bits(const image_data& a, const image_data& b) {
  return a.width == b.width && a.height == b.height && a.pixels.size() == b.pixels.size() &&
         std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * 4) == 0;
}

// The message of the input_error read_image(path) throws; fails the test when it throws none.
static std::string read_error(const std::string& path) {
  try {
    read_image(path);
  } catch (const input_error& e) {
    CHECK(e.file == path);
    return e.what();
  }
  FAIL("no input_error for " << path);
  return "";
}

// Little- or big-endian bytes of f.
static std::string float_bytes(float f, bool little) {
  uint32_t u;
  std::memcpy(&u, &f, 4);
  std::string s(4, '\0');
  for (int k = 0; k < 4; ++k) s[size_t(little ? k : 3 - k)] = char(u >> (8 * k));
  return s;
}

TEST_CASE("image_format_of goes by the extension in any case", "[image_io]") {
  CHECK(image_format_of("a/b.exr") == image_format::exr);
  CHECK(image_format_of("B.EXR") == image_format::exr);
  CHECK(image_format_of("x.Pfm") == image_format::pfm);
  CHECK(image_format_of("dir.png/x.png") == image_format::png);
  CHECK(image_format_of("x.jpg") == image_format::unknown);
  CHECK(image_format_of("dir.exr/x") == image_format::unknown);
  CHECK(image_format_of("dir/.exr") == image_format::unknown);
  CHECK(image_format_of("exr") == image_format::unknown);
}

TEST_CASE("EXR and PFM round trips are bit-exact", "[image_io]") {
  test::temp_dir dir;
  for (auto [w, h] : {std::pair{1, 1}, std::pair{7, 5}, std::pair{37, 19}}) {
    const image_data img = test_image(w, h);
    for (const char* ext : {".exr", ".pfm"}) {
      const std::string path = dir / ("img" + std::to_string(w) + ext);
      write_image(path, img);
      CHECK(same_bits(read_image(path), img));
    }
  }
}

TEST_CASE("PFM output is little-endian with rows from the bottom up", "[image_io]") {
  test::temp_dir dir;
  image_data img;
  img.width = 2;
  img.height = 2;
  img.pixels = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};  // top row: pixels 1-6
  write_image(dir / "a.pfm", img);
  const std::string bytes = read_file(dir / "a.pfm");
  const std::string header = "PF\n2 2\n-1.0\n";
  REQUIRE(bytes.size() == header.size() + 48);
  CHECK(bytes.substr(0, header.size()) == header);
  CHECK(bytes.substr(header.size(), 4) == float_bytes(7, true));
  CHECK(bytes.substr(header.size() + 24, 4) == float_bytes(1, true));
}

TEST_CASE("greyscale and big-endian PFM files are read", "[image_io]") {
  test::temp_dir dir;
  // Pf, little-endian, 2x2, bottom row {1, 2}, top row {3, 4}.
  std::string grey = "Pf\n2 2\n-1.0\n";
  for (float v : {1.0f, 2.0f, 3.0f, 4.0f}) grey += float_bytes(v, true);
  write_file_atomic(dir / "grey.pfm", grey);
  const image_data g = read_image(dir / "grey.pfm");
  REQUIRE(g.width == 2);
  REQUIRE(g.height == 2);
  CHECK(g.pixels == std::vector<float>{3, 3, 3, 4, 4, 4, 1, 1, 1, 2, 2, 2});
  // PF, big-endian (positive scale), 2x1, header tokens split over lines.
  std::string big = "PF\n2\n1\n1.0\n";
  for (float v : {1.5f, -2.0f, 1e20f, 0.25f, -0.0f, 7.0f}) big += float_bytes(v, false);
  write_file_atomic(dir / "big.pfm", big);
  const image_data b = read_image(dir / "big.pfm");
  REQUIRE(b.width == 2);
  REQUIRE(b.height == 1);
  CHECK(b.pixels == std::vector<float>{1.5f, -2.0f, 1e20f, 0.25f, -0.0f, 7.0f});
  CHECK(std::signbit(b.pixels[4]));
}

TEST_CASE("a PFM scale line may end in blanks and CRLF", "[image_io]") {
  // "-1.0 \n" was "1 unexpected bytes after the PFM pixel data" (a review). Data whose first bytes are whitespace
  // codes stay data: the line's end is skipped only where the data then fit exactly.
  test::temp_dir dir;
  float first;
  const uint32_t bits = 0x3f80000au;  // 1.0000012, its first little-endian byte '\n'
  std::memcpy(&first, &bits, 4);
  const std::string px = float_bytes(first, true) + float_bytes(2, true) + float_bytes(3, true);
  for (const char* end : {"\n", "\r\n", " \n", "\t \r\n", " "}) {
    INFO("scale line end " << int(end[0]) << " of " << std::strlen(end) << " bytes");
    write_file_atomic(dir / "s.pfm", std::string("PF\n1 1\n-1.0") + end + px);
    CHECK(read_image(dir / "s.pfm").pixels == std::vector<float>{first, 2, 3});
  }
}

TEST_CASE("malformed PFM files are input errors naming the file", "[image_io]") {
  test::temp_dir dir;
  const std::string px = float_bytes(1, true) + float_bytes(2, true) + float_bytes(3, true);
  const std::pair<const char*, std::string> cases[] = {
      {"empty.pfm", ""},
      {"magic.pfm", "P6\n1 1\n255\n" + px},
      {"negative.pfm", "PF\n-1 1\n-1.0\n" + px},
      {"noheight.pfm", "PF\n1"},
      {"letters.pfm", "PF\n1x 1\n-1.0\n" + px},
      {"zeroscale.pfm", "PF\n1 1\n0\n" + px},
      {"nanscale.pfm", "PF\n1 1\nnan\n" + px},
      {"zerosize.pfm", "PF\n0 1\n-1.0\n"},
      {"huge.pfm", "PF\n100000000 100000000\n-1.0\n" + px},
      {"short.pfm", "PF\n2 1\n-1.0\n" + px},
      {"long.pfm", "PF\n1 1\n-1.0\n" + px + "x"},
      {"noend.pfm", "PF\n1 1\n-1.0"},
  };
  for (const auto& [name, bytes] : cases) {
    INFO(name);
    write_file_atomic(dir / name, bytes);
    CHECK_THAT(read_error(dir / name), Catch::StartsWith((dir / name) + ": "));
  }
  CHECK_THAT(read_error(dir / "short.pfm"), Catch::Contains("truncated"));
  CHECK_THAT(read_error(dir / "missing.pfm"), Catch::Contains("No such file"));
}

TEST_CASE("malformed and truncated EXR files are input errors naming the file", "[image_io]") {
  test::temp_dir dir;
  write_file_atomic(dir / "text.exr", "this is not an OpenEXR file");
  CHECK_THAT(read_error(dir / "text.exr"), Catch::Contains("not an OpenEXR file"));
  write_image(dir / "good.exr", test_image(37, 19));
  const std::string good = read_file(dir / "good.exr");
  // Every cut through the header, and a spread of cuts through the offset table and pixel chunks.
  for (size_t len = 0; len < good.size(); len += len < 400 ? 1 : 97) {
    INFO("truncated to " << len << " of " << good.size() << " bytes");
    const std::string cut = dir / ("cut" + std::to_string(len) + ".exr");  // fresh names: no fsync, no truncation
    std::ofstream(cut, std::ios::binary) << good.substr(0, len);
    read_error(cut);
  }
  CHECK_THAT(read_error(dir / "missing.exr"), Catch::Contains("No such file"));
}

TEST_CASE("half-float and one-channel EXR files from tinyexr are read", "[image_io]") {
  test::temp_dir dir;
  const float rgb[6] = {0.5f, -2.0f, 1024.0f, 0.125f, 3.0f, -0.0f};  // all exact in half precision
  const char* err = nullptr;
  REQUIRE(SaveEXR(rgb, 2, 1, 3, 1, (dir / "half.exr").c_str(), &err) == TINYEXR_SUCCESS);
  CHECK(read_image(dir / "half.exr").pixels == std::vector<float>(rgb, rgb + 6));
  const float grey[2] = {0.75f, 8.0f};  // SaveEXR writes one component as channel "A"
  REQUIRE(SaveEXR(grey, 1, 2, 1, 0, (dir / "grey.exr").c_str(), &err) == TINYEXR_SUCCESS);
  CHECK(read_image(dir / "grey.exr").pixels == std::vector<float>{0.75f, 0.75f, 0.75f, 8, 8, 8});
}

// An uncompressed scanline EXR (OpenEXR 2 layout) of float channels written by hand: planes[c] holds channel
// names[c]'s w x h values, top row first; names in the alphabetical order OpenEXR stores them. line_order 1
// (DECREASING_Y) writes the chunks from the bottom row up; the offset table stays in y order. compression is the
// header's code (the data stay uncompressed: only a reader's check of the header can use it). overscan > 0 makes
// the display window that many pixels smaller on every side than the data window, < 0 larger.
static std::string handmade_exr(int w, int h, const std::vector<std::string>& names,
                                const std::vector<std::vector<float>>& planes, int line_order, int compression = 0,
                                int overscan = 0) {
  auto u32 = [](uint32_t v) { return std::string{char(v), char(v >> 8), char(v >> 16), char(v >> 24)}; };
  auto attr = [&](const std::string& name, const std::string& type, const std::string& data) {
    return name + '\0' + type + '\0' + u32(uint32_t(data.size())) + data;
  };
  std::string channels;
  for (const std::string& n : names) channels += n + '\0' + u32(2) + u32(0) + u32(1) + u32(1);  // FLOAT, linear 0
  channels += '\0';
  const std::string box = u32(0) + u32(0) + u32(uint32_t(w - 1)) + u32(uint32_t(h - 1));
  const std::string display = u32(uint32_t(overscan)) + u32(uint32_t(overscan)) + u32(uint32_t(w - 1 - overscan)) +
                              u32(uint32_t(h - 1 - overscan));
  std::string header = u32(20000630) + u32(2) + attr("channels", "chlist", channels) +
                       attr("compression", "compression", std::string(1, char(compression))) +
                       attr("dataWindow", "box2i", box) + attr("displayWindow", "box2i", display) +
                       attr("lineOrder", "lineOrder", std::string(1, char(line_order))) +
                       attr("pixelAspectRatio", "float", float_bytes(1, true)) +
                       attr("screenWindowCenter", "v2f", float_bytes(0, true) + float_bytes(0, true)) +
                       attr("screenWindowWidth", "float", float_bytes(1, true)) + '\0';
  std::vector<std::string> chunks(static_cast<size_t>(h));
  for (int y = 0; y < h; ++y) {
    std::string data;
    for (const auto& plane : planes)
      for (int x = 0; x < w; ++x) data += float_bytes(plane[size_t(y * w + x)], true);
    chunks[size_t(y)] = u32(uint32_t(y)) + u32(uint32_t(data.size())) + data;
  }
  std::vector<uint64_t> offsets(static_cast<size_t>(h));
  std::string body;
  uint64_t at = header.size() + 8 * size_t(h);
  for (int k = 0; k < h; ++k) {
    const int y = line_order == 0 ? k : h - 1 - k;
    offsets[size_t(y)] = at + body.size();
    body += chunks[size_t(y)];
  }
  std::string table;
  for (uint64_t o : offsets) table += u32(uint32_t(o)) + u32(uint32_t(o >> 32));
  return header + table + body;
}

TEST_CASE("EXR files in any line order, and grey ones with alpha, read as written", "[image_io]") {
  test::temp_dir dir;
  const int w = 3, h = 4;
  std::vector<std::vector<float>> bgr(3, std::vector<float>(size_t(w * h)));
  for (int c = 0; c < 3; ++c)
    for (int i = 0; i < w * h; ++i) bgr[size_t(c)][size_t(i)] = float(100 * c + i);  // B, G, R planes
  std::vector<float> expected;
  for (int i = 0; i < w * h; ++i)
    for (int c = 2; c >= 0; --c) expected.push_back(bgr[size_t(c)][size_t(i)]);
  for (int order : {0, 1, 2}) {  // INCREASING_Y, DECREASING_Y, RANDOM_Y (chunks written bottom up)
    INFO("line order " << order);
    const std::string path = dir / ("order" + std::to_string(order) + ".exr");
    write_file_atomic(path, handmade_exr(w, h, {"B", "G", "R"}, bgr, order));
    image_data img = read_image(path);
    CHECK(img.width == w);
    CHECK(img.height == h);
    CHECK(img.pixels == expected);
  }
  // Luminance with alpha: Y is the grey, whatever the other channels.
  std::vector<float> alpha(size_t(w * h), 0.5f), lum(size_t(w * h));
  for (int i = 0; i < w * h; ++i) lum[size_t(i)] = 0.25f * float(i);
  write_file_atomic(dir / "ya.exr", handmade_exr(w, h, {"A", "Y"}, {alpha, lum}, 1));
  image_data ya = read_image(dir / "ya.exr");
  REQUIRE(ya.pixels.size() == size_t(w * h * 3));
  for (int i = 0; i < w * h * 3; ++i) CHECK(ya.pixels[size_t(i)] == lum[size_t(i / 3)]);
  // Luminance/chroma (Y with RY and BY): not grey, refused.
  write_file_atomic(dir / "yc.exr", handmade_exr(w, h, {"BY", "RY", "Y"}, {alpha, alpha, lum}, 0));
  CHECK_THAT(read_error(dir / "yc.exr"), Catch::Contains("luminance/chroma"));
  // CIE XYZ: Y alone would be read as a grey image without a word (a review); refused.
  write_file_atomic(dir / "xyz.exr", handmade_exr(w, h, {"X", "Y", "Z"}, {alpha, lum, alpha}, 0));
  CHECK_THAT(read_error(dir / "xyz.exr"), Catch::Contains("CIE XYZ"));
  // Two channels, neither R, G, B nor Y: refused, naming what the file has.
  write_file_atomic(dir / "uv.exr", handmade_exr(w, h, {"U", "V"}, {alpha, lum}, 0));
  CHECK_THAT(read_error(dir / "uv.exr"), Catch::Contains("found: U, V"));
  // One layer of R, G and B in a multi-layer file (Blender's "OpenEXR MultiLayer": ViewLayer.Combined.R, ...): that
  // layer is the image (it was refused as having no R, G and B; a review). Two such layers: refused, naming both.
  write_file_atomic(dir / "layer.exr",
                    handmade_exr(w, h,
                                 {"ViewLayer.Combined.A", "ViewLayer.Combined.B", "ViewLayer.Combined.G",
                                  "ViewLayer.Combined.R", "ViewLayer.Depth.Z"},
                                 {alpha, bgr[0], bgr[1], bgr[2], lum}, 0));
  image_data layered = read_image(dir / "layer.exr");
  CHECK(layered.pixels == expected);
  write_file_atomic(dir / "layers.exr", handmade_exr(w, h, {"a.B", "a.G", "a.R", "b.B", "b.G", "b.R"},
                                                     {bgr[0], bgr[1], bgr[2], bgr[0], bgr[1], bgr[2]}, 0));
  CHECK_THAT(read_error(dir / "layers.exr"), Catch::Contains("2 layers with R, G and B (a, b)"));
  // A data window that is not the display window (a crop, an overscan) was read as if it were the image (a review).
  for (int overscan : {1, -1}) {
    write_file_atomic(dir / "window.exr", handmade_exr(w, h, {"B", "G", "R"}, bgr, 0, 0, overscan));
    CHECK_THAT(read_error(dir / "window.exr"), Catch::Contains("is not the display window"));
  }
}

TEST_CASE("EXR compressions tinyexr cannot decode are named, not called malformed", "[image_io]") {
  test::temp_dir dir;
  std::vector<std::vector<float>> grey(1, std::vector<float>(4, 1.0f));
  const char* names[] = {"PXR24", "B44", "B44A", "DWAA", "DWAB"};
  for (int code = 5; code <= 9; ++code) {
    const std::string path = dir / (std::string(names[code - 5]) + ".exr");
    write_file_atomic(path, handmade_exr(2, 2, {"Y"}, grey, 0, code));
    const std::string msg = read_error(path);
    CHECK_THAT(msg, Catch::Contains(std::string("compression ") + names[code - 5] + " is not supported"));
    CHECK_THAT(msg, !Catch::Contains("malformed"));
  }
  write_file_atomic(dir / "none.exr", handmade_exr(2, 2, {"Y"}, grey, 0, 0));
  CHECK(read_image(dir / "none.exr").pixels == std::vector<float>(12, 1.0f));
}

TEST_CASE("PNG output is sRGB within half a code value of the exact encoding", "[image_io]") {
  test::temp_dir dir;
  image_data img;
  img.width = 64;
  img.height = 3;
  for (int i = 0; i < img.width * img.height * 3; ++i) img.pixels.push_back(float(i) / 400.0f - 0.1f);
  img.pixels[0] = std::numeric_limits<float>::quiet_NaN();
  img.pixels[1] = std::numeric_limits<float>::infinity();
  img.pixels[2] = 0.001f;  // the linear segment
  write_image(dir / "a.png", img);
  const std::string bytes = read_file(dir / "a.png");
  int w = 0, h = 0, n = 0;
  unsigned char* codes =
      stbi_load_from_memory(reinterpret_cast<const unsigned char*>(bytes.data()), int(bytes.size()), &w, &h, &n, 3);
  REQUIRE(codes != nullptr);
  REQUIRE(w == 64);
  REQUIRE(h == 3);
  CHECK(n == 3);
  CHECK(codes[0] == 0);    // NaN
  CHECK(codes[1] == 255);  // +inf clamps
  for (size_t i = 2; i < img.pixels.size(); ++i) {
    const double v = std::min(std::max(double(img.pixels[i]), 0.0), 1.0);
    const double s = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055;
    INFO("value " << img.pixels[i] << " code " << int(codes[i]));
    CHECK(std::fabs(double(codes[i]) - s * 255.0) <= 0.5 + 1e-4);
  }
  stbi_image_free(codes);
}

TEST_CASE("bad writes are output errors and leave nothing behind", "[image_io]") {
  test::temp_dir dir;
  const image_data img = test_image(3, 2);
  CHECK_THROWS_AS(write_image(dir / "a.jpg", img), output_error);
  CHECK_THROWS_AS(write_image(dir / "missing/a.exr", img), output_error);
  CHECK_THROWS_AS(write_image("/dev/full", img), output_error);  // no extension: rejected before writing
  image_data bad = img;
  bad.pixels.pop_back();
  CHECK_THROWS_AS(write_image(dir / "bad.pfm", bad), output_error);
  CHECK_THROWS_AS(read_image(dir / "a.png"), input_error);
  CHECK(std::filesystem::is_empty(dir.path.string()));
  // An .exr name that is a link to a full device: written in place, the failure reported.
  REQUIRE(::symlink("/dev/full", (dir / "full.exr").c_str()) == 0);
  CHECK_THROWS_WITH(write_image(dir / "full.exr", img), Catch::Contains("No space left on device"));
}
