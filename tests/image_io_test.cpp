// Tests of image_io: bit-exact .exr and .pfm round trips (negative, huge, tiny, signed zero, inf, NaN), PNG
// quantisation within half a code value, hand-made greyscale and big-endian PFMs, half-float and one-channel
// EXRs from tinyexr, and malformed or truncated files rejected with an input_error naming the file.
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
