// Tests of metrics: relMSE, MSE and maxabs on hand-computed values, size mismatch, NaN propagation and
// bit-identity (+0 and -0 differ; equal NaN bits are identical).
#include "errors.h"
#include "metrics.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

using namespace bl;

// A width x height image with the given values.
static image_data make_image(int width, int height, std::vector<float> pixels) {
  image_data img;
  img.width = width;
  img.height = height;
  img.pixels = std::move(pixels);
  return img;
}

TEST_CASE("metrics match hand-computed values", "[metrics]") {
  // d = x - r = {0, 1, -0.25, 2, 0, -1}; r^2 + 0.01 = {1.01, 1.01, 0.26, 0.01, 4.01, 1.01}.
  const image_data x = make_image(2, 1, {1, 2, 0.25f, 2, -2, 0});
  const image_data r = make_image(2, 1, {1, 1, 0.5f, 0, -2, 1});
  const error_metrics m = compute_error(x, r);
  const double rel = (0 / 1.01 + 1 / 1.01 + 0.0625 / 0.26 + 4 / 0.01 + 0 / 4.01 + 1 / 1.01) / 6;
  CHECK(m.relmse == Approx(rel).epsilon(1e-15));
  CHECK(m.mse == Approx((0 + 1 + 0.0625 + 4 + 0 + 1) / 6.0).epsilon(1e-15));
  CHECK(m.maxabs == 2.0);
  const error_metrics same = compute_error(x, x);
  CHECK(same.relmse == 0.0);
  CHECK(same.mse == 0.0);
  CHECK(same.maxabs == 0.0);
}

TEST_CASE("metrics of raw arrays equal those of images and are zero when empty", "[metrics]") {
  const float x[3] = {0.5f, 3, -1}, r[3] = {0.25f, 3, 1};
  const error_metrics m = compute_error(x, r, 3);
  CHECK(m.mse == Approx((0.0625 + 0 + 4) / 3).epsilon(1e-15));
  CHECK(m.maxabs == 2.0);
  const error_metrics e = compute_error(x, r, 0);
  CHECK(e.relmse == 0.0);
  CHECK(e.mse == 0.0);
  CHECK(e.maxabs == 0.0);
}

TEST_CASE("a size mismatch is an input_error naming both sizes", "[metrics]") {
  const image_data a = make_image(2, 1, std::vector<float>(6, 0.0f));
  const image_data b = make_image(1, 2, std::vector<float>(6, 0.0f));
  try {
    compute_error(a, b, "ref.exr");
    FAIL("no input_error");
  } catch (const input_error& e) {
    CHECK(e.file == "ref.exr");
    CHECK_THAT(e.what(), Catch::Contains("1x2") && Catch::Contains("2x1"));
  }
  CHECK_THROWS_AS(compute_error(a, b), input_error);
}

TEST_CASE("non-finite values propagate into the metrics", "[metrics]") {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const image_data x = make_image(1, 2, {nan, 0, 0, 0, 100, 0});
  const image_data r = make_image(1, 2, {0, 0, 0, 0, 0, 0});
  const error_metrics m = compute_error(x, r);
  CHECK(std::isnan(m.relmse));
  CHECK(std::isnan(m.mse));
  CHECK(std::isnan(m.maxabs));  // a later, larger finite error does not hide the NaN
  const image_data inf = make_image(1, 1, {std::numeric_limits<float>::infinity(), 0, 0});
  CHECK(std::isinf(compute_error(inf, make_image(1, 1, {0, 0, 0})).mse));
}

TEST_CASE("bit_identical compares sizes and bits", "[metrics]") {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const image_data a = make_image(2, 1, {0.0f, 1, 2, 3, 4, nan});
  CHECK(bit_identical(a, a));
  image_data b = a;
  b.pixels[0] = -0.0f;  // equal as floats, different bits
  CHECK_FALSE(bit_identical(a, b));
  CHECK_FALSE(bit_identical(a, make_image(1, 2, a.pixels)));
  b = a;
  b.pixels[3] = std::nextafter(3.0f, 4.0f);
  CHECK_FALSE(bit_identical(a, b));
  CHECK(bit_identical(image_data{}, image_data{}));
}
