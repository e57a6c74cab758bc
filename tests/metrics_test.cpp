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

TEST_CASE("the spread of the error ranks pixels and gives the worst ones' shares", "[metrics]") {
  // 40 x 50 = 2000 pixels against a reference of zeros: pixel i's term is (d^2 / 0.01) averaged over its channels.
  // Pixel 1234 errs by 1 in one channel (term 100 / 3), pixels 0-19 by 0.1 in all three (term 1), pixel 7 by 0.2
  // (term 4), 1999 and 1998 by 0.05 in all three (0.25 each: a tie broken by index), the rest not at all.
  const int w = 40, h = 50;
  std::vector<float> x(size_t(w) * h * 3, 0.0f);
  x[3 * 1234 + 1] = 1;
  for (int i = 0; i < 20; i++) x[3 * i] = x[3 * i + 1] = x[3 * i + 2] = 0.1f;
  x[3 * 7] = x[3 * 7 + 1] = x[3 * 7 + 2] = 0.2f;
  for (int i : {1998, 1999}) x[3 * i] = x[3 * i + 1] = x[3 * i + 2] = 0.05f;
  const image_data a = make_image(w, h, x), r = make_image(w, h, std::vector<float>(x.size(), 0.0f));
  const error_spread s = spread_of_error(a, r, 23);
  REQUIRE(s.term.size() == 2000);
  auto term_of = [](double d) { return double(float(d)) * double(float(d)) / 0.01; };
  CHECK(s.term[1234] == Approx(100.0 / 3).epsilon(1e-12));
  CHECK(s.term[3] == Approx(term_of(0.1)).epsilon(1e-12));
  CHECK(s.term[7] == Approx(term_of(0.2)).epsilon(1e-12));
  CHECK(s.term[100] == 0.0);
  // Their mean is the relMSE.
  double sum = 0;
  for (double t : s.term) sum += t;
  CHECK(sum / 2000 == Approx(compute_error(a, r).relmse).epsilon(1e-12));
  // The worst 0.1 % (2 pixels), 1 % (20), 5 % (100).
  CHECK(s.tail_pixels[0] == 2);
  CHECK(s.tail_pixels[1] == 20);
  CHECK(s.tail_pixels[2] == 100);
  CHECK(s.tail_share[0] == Approx((s.term[1234] + s.term[7]) / sum).epsilon(1e-12));
  // (1 %: 1234, 7 and 18 of the other 19 of term 1; pixel 19, the last of them by index, and the 0.25s are left.)
  CHECK(s.tail_share[1] == Approx((sum - s.term[19] - 2 * s.term[1998]) / sum).epsilon(1e-12));
  CHECK(s.tail_share[2] == Approx(1.0).epsilon(1e-12));
  // Worst first; the 19 pixels of term 1 by index (7 is among the worse), then the tie of 0.25 by index.
  std::vector<size_t> want = {1234, 7};
  for (size_t i = 0; i < 20; i++)
    if (i != 7) want.push_back(i);
  want.push_back(1998);
  want.push_back(1999);
  CHECK(s.worst == want);
  // Fewer pixels than asked: all of them; a zero error: shares of zero.
  CHECK(spread_of_error(make_image(1, 1, {1, 0, 0}), make_image(1, 1, {0, 0, 0}), 5).worst.size() == 1);
  const error_spread none = spread_of_error(r, r, 3);
  CHECK(none.tail_share[0] == 0.0);
  CHECK(none.worst.size() == 3);
  CHECK_THROWS_AS(spread_of_error(make_image(2, 1, std::vector<float>(6, 0.0f)),
                                  make_image(1, 2, std::vector<float>(6, 0.0f)), 1),
                  input_error);
}
