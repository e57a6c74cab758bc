// Weighted passes (render_params::pass_weighting): an adaptive sampler's image is sum_k w_k S_k / sum_k w_k n_k,
// S_k the sample sums of pass k, n_k its spp and w_k = pass_weight(spp before the first pass of k's stratified light
// set: pass k itself while the sampler learns, the first pass after bayes's fallback after it; the passes after a
// fallback, and after bayes's first 8 spp where learning paid, then have the share of a fixed schedule). Checked
// against renders without weighting (whose films give every pass's sums, since weighting never changes what is
// sampled or learned); non-adaptive and frozen samplers keep equal weights bit for bit; and on a scene where the
// prior is poor (a bright lamp shut in a box beside a dim one) weighting lowers the error, paired over seeds.
#include "bvh.h"
#include "light_sampler.h"
#include "lights.h"
#include "render.h"
#include "scene.h"
#include "scene_desc.h"
#include "scene_fixture.h"
#include "test_util.h"

#include <catch2/catch.hpp>

#include <chrono>
#include <thread>

#include <cmath>
#include <csignal>
#include <memory>

using namespace bl;
using namespace bl::test;

namespace {

// The boxed lamp of test_util.h: the bound prior sends most NEE samples to the shut-in lamp until learning moves
// them.
std::unique_ptr<test_scene> boxed_lamp_scene() {
  return build_test_scene(boxed_lamp_mesh(), fixed_camera({2, 4, 0.01f}, {2, 0, 0}, 40, {0, 0, -1}));
}

render_params small_params(sampler_kind kind, int spp, double weighting, uint64_t seed = 7) {
  render_params p;
  p.width = p.height = 12;
  p.spp = spp;
  p.max_depth = 1;
  p.threads = 2;
  p.seed = seed;
  p.sampler.kind = kind;
  p.pass_weighting = weighting;
  return p;
}

// A weighted render's film against the sums expected from unweighted ones: equal up to rounding.
void check_film_matches(const std::vector<double>& film, const std::vector<double>& expect) {
  double worst = 0, scale = 0;
  for (size_t i = 0; i < expect.size(); i++) {
    worst = std::max(worst, std::fabs(film[i] - expect[i]));
    scale = std::max(scale, std::fabs(expect[i]));
  }
  REQUIRE(scale > 0);
  CHECK(worst <= 1e-9 * scale);
}

double squared_error(const image_data& a, const image_data& ref) {
  double e = 0;
  for (size_t i = 0; i < a.pixels.size(); i++) e += std::pow(double(a.pixels[i]) - ref.pixels[i], 2);
  return e / double(a.pixels.size());
}

}  // namespace

TEST_CASE("pass weights start below one and approach it", "[passes]") {
  CHECK(pass_weight(0, 4) == Approx(0.2));
  CHECK(pass_weight(15, 4) == Approx(0.8));
  CHECK(pass_weight(1000, 4) > 0.99);
  CHECK(pass_weight(1000, 4) < 1.0);
  for (int n : {0, 3, 100}) CHECK(pass_weight(n, 0) == 1.0);
  for (int n = 0; n < 100; n++) CHECK(pass_weight(n + 1, 4) > pass_weight(n, 4));
}

TEST_CASE("bayes's first 8 spp weigh less, and its later passes less again where learning paid", "[passes]") {
  for (int n = 0; n < staged_spp; n++) CHECK(staged_pass_weight(n, 4, true) == pass_weight(n, 16));
  for (int n = 0; n < staged_spp; n++) CHECK(staged_pass_weight(n, 4, false) == pass_weight(n, 16));
  for (int n : {8, 20, 400}) {
    CHECK(staged_pass_weight(n, 4, false) == pass_weight(n, 4));
    CHECK(staged_pass_weight(n, 4, true) == pass_weight(n, 64));
  }
  for (int n : {0, 7, 8, 100}) CHECK(staged_pass_weight(n, 0, true) == 1.0);
}

TEST_CASE("an image of staged passes is the first passes' mean and the later ones' in fixed shares", "[passes]") {
  // One pixel: first passes of weight 2 summing (2, 4, 6), later ones of weight 3 among themselves summing (9, 3, 0),
  // whose plain weight is 6: shares 2 / 8 and 6 / 8.
  render_result r;
  r.width = r.height = 1;
  r.spp = 20;
  r.early_film = {2, 4, 6};
  r.early_weight = 2;
  r.film = {2 + 9, 4 + 3, 6 + 0};
  r.film_weight = 2 + 3;
  r.late_ref_weight = 6;
  r.late_learns = true;
  image_data img = film_image(r);
  CHECK(img.pixels[0] == Approx(0.25 * 1 + 0.75 * 3));
  CHECK(img.pixels[1] == Approx(0.25 * 2 + 0.75 * 1));
  CHECK(img.pixels[2] == Approx(0.25 * 3 + 0.75 * 0));
  // Without the first passes kept apart, the film's weighted mean.
  r.early_film.clear();
  r.late_learns = false;
  img = film_image(r);
  CHECK(img.pixels[0] == Approx(11.0 / 5));
}

TEST_CASE("where bayes's check finds learning to pay by 8 spp, its later direct passes weigh apart", "[passes]") {
  // 256 x 256 pixels: the first check window (spp 4-7, 262144 samples) completes by 8 spp and finds learning paying
  // by far (the bound prior sends most samples to the shut-in lamp). The first 8 spp's film is a render of 8 spp's,
  // bit for bit; the later passes' sums (from unweighted renders stopped at each pass, which sample and learn the
  // same) weigh pass_weight(n, 64) among themselves; their share is that of pass_weight(n, 4).
  auto b = boxed_lamp_scene();
  auto params = [](int spp, double weighting) {
    render_params p = small_params(sampler_kind::bayes, spp, weighting);
    p.width = p.height = 256;
    return p;
  };
  render_result r8 = render(b->scene, b->bvh, b->lights, params(8, 4));
  REQUIRE(r8.late_learns);
  CHECK(r8.early_film == r8.film);
  render_result r15 = render(b->scene, b->bvh, b->lights, params(15, 4));
  REQUIRE(r15.late_learns);
  CHECK(r15.early_film == r8.film);
  CHECK(r15.early_weight == r8.film_weight);
  const int ends[] = {8, 10, 12, 15};
  std::vector<std::vector<double>> cumulative;
  for (int e : ends) cumulative.push_back(render(b->scene, b->bvh, b->lights, params(e, 0)).film);
  std::vector<double> late(r15.film.size(), 0.0);
  double late_weight = 0, late_ref = 0;
  for (size_t k = 1; k < cumulative.size(); k++) {
    const int before = ends[k - 1], count = ends[k] - before;
    late_weight += pass_weight(before, 64) * count;
    late_ref += pass_weight(before, 4) * count;
    for (size_t i = 0; i < late.size(); i++)
      late[i] += pass_weight(before, 64) * (cumulative[k][i] - cumulative[k - 1][i]);
  }
  CHECK(r15.late_ref_weight == Approx(late_ref).epsilon(1e-12));
  const double share = r8.film_weight / (r8.film_weight + late_ref);
  image_data img = film_image(r15);
  double worst = 0, scale = 0;
  for (size_t i = 0; i < late.size(); i++) {
    const double expect = share * r8.film[i] / r8.film_weight + (1 - share) * late[i] / late_weight;
    worst = std::max(worst, std::fabs(img.pixels[i] - expect));
    scale = std::max(scale, std::fabs(expect));
  }
  REQUIRE(scale > 0);
  CHECK(worst <= 1e-6 * scale);
  // Two threads or one: the same film and the same first passes.
  render_params one = params(15, 4);
  one.threads = 1;
  render_result r1 = render(b->scene, b->bvh, b->lights, one);
  CHECK(r1.film == r15.film);
  CHECK(r1.early_film == r15.early_film);
  // Path traced, every pass keeps the plain weight (the bounces' noise, which learning leaves, dominates them).
  render_params path = params(9, 4);
  path.max_depth = 2;
  render_result rp = render(b->scene, b->bvh, b->lights, path);
  CHECK_FALSE(rp.late_learns);
  CHECK(rp.early_film.empty());
  double plain = 0;
  for (int n = 0; n < 9; n++) plain += pass_weight(n, 4);
  CHECK(rp.film_weight == Approx(plain).epsilon(1e-12));
}

TEST_CASE("an adaptive sampler's film is each pass's sums times the pass's fixed weight", "[passes]") {
  auto b = boxed_lamp_scene();
  for (sampler_kind kind : {sampler_kind::bayes, sampler_kind::donikian}) {
    INFO(sampler_name(kind));
    // Unweighted renders that stop at every pass boundary up to 15 spp: their films are the cumulative sums.
    const int ends[] = {1, 2, 3, 4, 5, 6, 7, 8, 10, 12, 15};
    std::vector<std::vector<double>> cumulative;
    for (int e : ends) {
      render_result r = render(b->scene, b->bvh, b->lights, small_params(kind, e, 0));
      REQUIRE(r.spp == e);
      CHECK(r.film_weight == double(e));
      cumulative.push_back(r.film);
    }
    render_result w = render(b->scene, b->bvh, b->lights, small_params(kind, 15, 4));
    REQUIRE(w.spp == 15);
    CHECK_FALSE(w.late_learns);  // (144 pixels: bayes's first check window is far from complete at 8 spp)
    REQUIRE(w.passes == 11);
    double weight = 0;
    std::vector<double> expect(w.film.size(), 0.0);
    int before = 0;
    for (size_t k = 0; k < cumulative.size(); k++) {
      double wk = kind == sampler_kind::bayes ? staged_pass_weight(before, 4, false) : pass_weight(before, 4);
      weight += wk * (ends[k] - before);
      for (size_t i = 0; i < expect.size(); i++)
        expect[i] += wk * (cumulative[k][i] - (k > 0 ? cumulative[k - 1][i] : 0.0));
      before = ends[k];
    }
    CHECK(w.film_weight == Approx(weight).epsilon(1e-12));
    CHECK(w.film_weight < 15);
    check_film_matches(w.film, expect);
  }
}

TEST_CASE("after bayes falls back, the later passes weigh alike, with the plain schedule's share", "[passes]") {
  // The passes after a fallback sample one stratified light set (power sampling's): weights that went on growing with
  // each pass's start undid its stratification (the Cornell box, direct, 640 x 480: 1.9-2.0x power's relMSE at 32
  // spp, 1.4x with one weight). But their share of the image must not follow the fallback's spp, which the check drew
  // from the samples it weighs: with every later pass weighing as the first one after the fallback, it did, and the
  // image was biased (a 4 x 4 Cornell box, 16 spp, windows of 16 samples: its mean 4.6e-4 +- 1.4e-4 below the
  // unweighted one's over 8000 seeds, at a level of 0.107). So the passes before the fallback are kept apart, and the
  // later ones have the share that their weights by their own starts, a fixed schedule, give them. A fallback forced
  // by a huge threshold, with windows of one spp of the 144 pixels.
  auto b = boxed_lamp_scene();
  auto params = [](int spp, double weighting) {
    render_params p = small_params(sampler_kind::bayes, spp, weighting);
    p.sampler.bayes.fallback_ratio = 1e9;
    p.sampler.bayes.fallback_window = 144;
    return p;
  };
  render_result w = render(b->scene, b->bvh, b->lights, params(40, 4));
  REQUIRE(w.spp == 40);
  const int f = w.fallback_spp;
  REQUIRE(f > 0);
  CHECK(w.stratum_base == f);
  CHECK(w.late_fallback);
  CHECK_FALSE(w.late_learns);
  std::vector<int> ends;
  for (const pass_record& p : w.log) ends.push_back(p.spp);
  int after = 0;
  for (int e : ends) after += e > f;
  REQUIRE(after >= 3);  // several passes after the fallback
  // Unweighted renders that stop at every pass end: their films are the cumulative sums (weighting never changes what
  // is sampled, learned or decided).
  double weight = 0, early = 0, late_ref = 0;
  const size_t n = w.film.size();
  std::vector<double> expect(n, 0.0), before_film(n, 0.0), early_sum(n, 0.0), late_sum(n, 0.0);
  int before = 0;
  for (int e : ends) {
    render_result r = render(b->scene, b->bvh, b->lights, params(e, 0));
    REQUIRE(r.spp == e);
    CHECK(r.fallback_spp == (e >= f ? f : 0));
    CHECK_FALSE(r.late_fallback);  // (unweighted: nothing to keep apart)
    const double wk = staged_pass_weight(std::min(before, f), 4, false);  // the film's weight: the set's first pass's
    const double plain = staged_pass_weight(before, 4, false);             // the pass's own, for the shares
    weight += wk * (e - before);
    (before < f ? early : late_ref) += plain * (e - before);
    for (size_t i = 0; i < n; i++) {
      const double sum = r.film[i] - before_film[i];
      expect[i] += wk * sum;
      (before < f ? early_sum[i] : late_sum[i]) += (before < f ? wk : 1.0) * sum;
    }
    before_film = r.film;
    before = e;
  }
  CHECK(w.film_weight == Approx(weight).epsilon(1e-12));
  check_film_matches(w.film, expect);
  CHECK(w.early_weight == Approx(early).epsilon(1e-12));
  CHECK(w.late_ref_weight == Approx(late_ref).epsilon(1e-12));
  // The image: the earlier passes' weighted mean and the later passes' plain mean, in the shares of the schedule.
  const double share = early / (early + late_ref);
  const int late_spp = 40 - f;
  const image_data img = film_image(w);
  double worst = 0, scale = 0;
  for (size_t i = 0; i < n; i++) {
    const double v = share * early_sum[i] / early + (1 - share) * late_sum[i] / late_spp;
    worst = std::max(worst, std::fabs(double(img.pixels[i]) - v));
    scale = std::max(scale, std::fabs(v));
  }
  REQUIRE(scale > 0);
  CHECK(worst <= 1e-6 * scale);
}

TEST_CASE("non-adaptive and frozen samplers keep equal weights bit for bit", "[passes]") {
  auto b = boxed_lamp_scene();
  for (sampler_kind kind : {sampler_kind::uniform, sampler_kind::power, sampler_kind::bvh, sampler_kind::bound}) {
    INFO(sampler_name(kind));
    render_result a = render(b->scene, b->bvh, b->lights, small_params(kind, 12, 0));
    render_result w = render(b->scene, b->bvh, b->lights, small_params(kind, 12, 4));
    CHECK(w.film_weight == 12.0);
    CHECK(w.film == a.film);
  }
  render_params p0 = small_params(sampler_kind::bayes, 12, 0), p4 = small_params(sampler_kind::bayes, 12, 4);
  p0.sampler.bayes.oracle_spp = p4.sampler.bayes.oracle_spp = 16;
  render_result a = render(b->scene, b->bvh, b->lights, p0);
  render_result w = render(b->scene, b->bvh, b->lights, p4);
  CHECK(w.film_weight == 12.0);
  CHECK(w.film == a.film);
}

TEST_CASE("passes of a tiny image grow to 65536 samples, so their records stay few", "[passes]") {
  // Every pass keeps a record (log, checkpoint): a 1-pixel image in 64-spp passes held 3 GB of them at 2^31 spp.
  CHECK(pass_size(3, 2, 1) == 1);  // the first 8 passes: 1 spp
  CHECK(pass_size(20, 1 << 20, 1) == 65536);
  CHECK(pass_size(20, 1 << 20, 16) == 4096);
  CHECK(pass_size(20, 1 << 20, 1024) == 64);  // 1024 pixels and more: the 64-spp passes
  CHECK(pass_size(20, 1 << 20, 640 * 480) == 64);
  CHECK(pass_size(20, 100, 1) == 25);  // a quarter of the samples so far
  auto b = boxed_lamp_scene();
  render_params p = small_params(sampler_kind::uniform, 1 << 20, 0);
  p.width = p.height = 1;
  render_result r = render(b->scene, b->bvh, b->lights, p);
  CHECK(r.spp == 1 << 20);
  CHECK(r.passes < 80);  // about 67 (16,400 in 64-spp passes)
}

TEST_CASE("a --time render sizes its last pass from the last pass's speed, scaled to its NEE draws", "[passes]") {
  // A quarter more than fits, rounded up; the scheduled size where it fits or no speed is known.
  CHECK(fit_pass_to_time(8, 1.0, 0.5) == 3);   // ceil(1.25 * 2)
  CHECK(fit_pass_to_time(8, 10.0, 0.5) == 8);
  CHECK(fit_pass_to_time(8, 1.0, 0.0) == 8);
  CHECK(fit_pass_to_time(8, 0.01, 0.5) == 1);
  // After bayes's early draws (4 per camera sample) a pass of one draw takes about half the time per spp: timed by
  // the 4-draw pass, a budget that ended inside the next pass cut it to 0.6 of what fitted (a review: the render
  // stopped 1-3 spp early).
  CHECK(seconds_per_spp_at(0.06, 4, 1) == Approx(0.03));
  CHECK(seconds_per_spp_at(0.03, 1, 4) == Approx(0.06));
  CHECK(seconds_per_spp_at(0.06, 4, 4) == 0.06);
  CHECK(seconds_per_spp_at(0.06, 0, 1) == 0.06);  // draws of the timed pass unknown
  CHECK(fit_pass_to_time(4, 0.11, seconds_per_spp_at(0.056, 4, 1)) == 4);  // the living room's switch: all 4 fit
  CHECK(fit_pass_to_time(4, 0.11, 0.056) == 3);
}

TEST_CASE("time spent between passes (checkpoints) counts in the render's seconds and its time budget", "[passes]") {
  // A 4096^2 render's checkpoints took 30 s of a 42 s run whose summary and log said 9.1 s, and a --time budget
  // ignored them (a review). Each call between passes here takes at least 50 ms (a sleep: a lower bound, not a timing).
  auto b = boxed_lamp_scene();
  render_params p = small_params(sampler_kind::uniform, 6, 0);
  int calls = 0;
  p.on_pass = [&](const render_result&, const light_sampler&, bool last) {
    if (last) return;  // (the last one comes with the outputs, after the render)
    calls++;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  };
  render_result r = render(b->scene, b->bvh, b->lights, p);
  REQUIRE(calls == 5);  // between passes: not after the last one (the final call, last = true, comes then)
  CHECK(r.seconds >= 0.25);
  REQUIRE(r.log.size() == 6);
  CHECK(r.log[5].seconds - r.log[0].seconds >= 0.25);  // the calls after passes 1-5 fall within the log's times
  CHECK(r.seconds == r.log[5].seconds);  // (the summary's time is the log's last)
  // A budget of 0.2 s is spent by the calls after four passes at the latest, whatever the passes take.
  render_params t = p;
  t.spp = 0;
  t.time_budget = 0.2;
  calls = 0;
  render_result timed = render(b->scene, b->bvh, b->lights, t);
  CHECK(timed.passes <= 5);
  // (After the pass that spends the budget there is no call; where a call itself spends it, that call came after
  // what turned out to be the last pass.)
  CHECK(calls >= timed.passes - 1);
  CHECK(calls <= timed.passes);
  // A budget the first pass spends by itself (any pass takes longer than a nanosecond): no call comes after it, and
  // the summary's time is the log's.
  t.time_budget = 1e-9;
  calls = 0;
  render_result one = render(b->scene, b->bvh, b->lights, t);
  CHECK(one.passes == 1);
  CHECK(calls == 0);
  REQUIRE(one.log.size() == 1);
  CHECK(one.seconds == one.log[0].seconds);
}

TEST_CASE("an oracle interrupted while it learns leaves no frozen model behind", "[passes]") {
  // What a checkpoint saves on the way out of an interrupted oracle: an empty model, not frozen, so that a resumed
  // render learns the oracle's model anew (a half-learned frozen one would give other bytes than a render never
  // interrupted).
  auto b = boxed_lamp_scene();
  render_params p = small_params(sampler_kind::bayes, 4, 4);
  p.sampler.bayes.oracle_spp = 16;
  bool saved = false, frozen = true;
  double observations = -1;
  p.on_pass = [&](const render_result&, const light_sampler& ls, bool last) {
    if (!last) return;
    const bayes_sampler& s = std::get<bayes_sampler>(ls);
    saved = true;
    frozen = s.frozen;
    observations = 0;
    for (const pair_moments& m : s.stats.m) observations += m.n0 + m.n1;
  };
  install_interrupt_handlers();
  REQUIRE(interrupted_before_render() == 0);  // set-up over (until then a signal would end the process at once)
  std::raise(SIGINT);  // the handler only notes it: the oracle's first pass stops, and so does the render
  render_result r = render(b->scene, b->bvh, b->lights, p);
  reset_interrupt();
  CHECK(r.interrupted);
  CHECK(r.spp == 0);
  REQUIRE(saved);
  CHECK(!frozen);
  CHECK(observations == 0);
  // Uninterrupted, the oracle learns and freezes.
  render_result full = render(b->scene, b->bvh, b->lights, p);
  CHECK(full.spp == 4);
  CHECK(frozen);
  CHECK(observations > 0);
}

TEST_CASE("weighting the first passes lowers bayes's error where the prior is poor", "[passes]") {
  // Paired over 16 seeds (the same samples with and without weighting): the mean of e_0 - e_w, the difference of
  // squared errors against a 16384-spp reference, must exceed 3.7 standard errors (one-sided 99.99 %).
  auto b = boxed_lamp_scene();
  render_params rp = small_params(sampler_kind::bayes, 16384, 4, 987654321);
  image_data ref = film_image(render(b->scene, b->bvh, b->lights, rp));
  std::vector<double> diff;
  for (uint64_t seed = 1; seed <= 16; seed++) {
    image_data plain = film_image(render(b->scene, b->bvh, b->lights, small_params(sampler_kind::bayes, 27, 0, seed)));
    image_data weighted = film_image(render(b->scene, b->bvh, b->lights, small_params(sampler_kind::bayes, 27, 4, seed)));
    diff.push_back(squared_error(plain, ref) - squared_error(weighted, ref));
  }
  mean_se m = mean_and_se(diff);
  INFO("mean gain " << m.mean << " +- " << m.se);
  CHECK(m.mean > 3.7 * m.se);
}

TEST_CASE("a --time render's last pass takes what the last pass's speed says fits the time left", "[passes]") {
  CHECK(fit_pass_to_time(8, 0.35, 0.1) == 5);   // 1.25 × 3.5 = 4.375, rounded up
  CHECK(fit_pass_to_time(8, 0.01, 0.1) == 1);   // at least 1
  CHECK(fit_pass_to_time(8, 5.0, 0.1) == 8);    // the whole pass fits: as scheduled
  CHECK(fit_pass_to_time(8, 0.6, 0.1) == 8);    // 7.5 rounds up to the whole pass
  CHECK(fit_pass_to_time(8, 0.55, 0.1) == 7);   // 6.875: 7
  CHECK(fit_pass_to_time(1, 0.001, 0.1) == 1);
  CHECK(fit_pass_to_time(8, 0.35, 0.0) == 8);   // no pass timed yet
  CHECK(fit_pass_to_time(8, 1e300, 1e-300) == 8);  // (no overflow into int)
  CHECK(fit_pass_to_time(64, 1e-9, 1e300) == 1);
  CHECK(fit_pass_to_time(8, NAN, 0.1) == 8);
  CHECK(fit_pass_to_time(8, 0.35, NAN) == 8);
}

TEST_CASE("a --time render ends with a pass cut to the budget, the image of the --spp render of its total",
          "[passes]") {
  // A whole pass started just before the budget ran a render up to a quarter past it. Here every run of samples
  // sleeps 50 ms per spp first (a lower bound on its time, whatever the load): with a budget of 1.7 s the passes of
  // 1, ..., 1, 2, 2, 3, 3, 4, 5, 6 spp end after 33 spp at 1.65 s or later, and the next scheduled pass (8 spp) would
  // end at 2.05 s or later, 41 spp. Cut to what fits the time left (a quarter more, rounded up; the speed it is sized
  // by is at least 50 ms per spp), and continued in pieces sized alike where it ends short of the budget, the render
  // ends at 35 spp or fewer, whatever the machine's speed.
  auto b = boxed_lamp_scene();
  render_params p = small_params(sampler_kind::bayes, 1, 4);
  p.time_budget = 1.7;
  std::vector<int> runs;
  p.on_samples = [&](int spp) {
    runs.push_back(spp);
    std::this_thread::sleep_for(std::chrono::milliseconds(50 * spp));
  };
  render_result r = render(b->scene, b->bvh, b->lights, p);
  std::string pieces;
  for (int k : runs) pieces += std::to_string(k) + " ";
  INFO("spp " << r.spp << ", seconds " << r.seconds << ", runs of samples: " << pieces);
  CHECK(r.spp <= 35);
  // The --spp render of the same total: the same passes, the last cut at the same place, the same image.
  render_params q = small_params(sampler_kind::bayes, r.spp, 4);
  render_result s = render(b->scene, b->bvh, b->lights, q);
  CHECK(s.passes == r.passes);
  CHECK(s.film == r.film);
  CHECK(s.film_weight == r.film_weight);
}

TEST_CASE("a cut pass continued in pieces is the image of one pass of its samples", "[passes]") {
  // The pieces go on from the pass's sums in the order one pass adds them: bit for bit the --spp render's pass. The
  // first 15 runs of samples (passes of 1, ..., 1, 2, 2, 3, 3, 4, 5, 6 spp: 33 spp) sleep 20 ms per spp, the later
  // ones not at all. The pass after them (8 spp scheduled) is sized by that slow speed: with 0.80 s of budget and
  // about 0.67 s spent, it is cut to a few spp, which then take a millisecond, so it goes on in a second piece, up to
  // 7 spp, and the render ends there, short of its budget (the machine "sped up" 20-fold).
  for (sampler_kind kind : {sampler_kind::bayes, sampler_kind::donikian, sampler_kind::power}) {
    auto b = boxed_lamp_scene();
    render_params p = small_params(kind, 1, 4);
    p.time_budget = 0.8;
    std::vector<int> runs;
    p.on_samples = [&](int spp) {
      runs.push_back(spp);
      if (runs.size() <= 15) std::this_thread::sleep_for(std::chrono::milliseconds(20 * spp));
    };
    render_result r = render(b->scene, b->bvh, b->lights, p);
    std::string pieces;
    for (int k : runs) pieces += std::to_string(k) + " ";
    INFO(int(kind) << ": spp " << r.spp << ", seconds " << r.seconds << ", runs of samples: " << pieces);
    // Only the last pass may be in pieces, and it stays shorter than scheduled: what bayes learns from a pass in
    // pieces differs in the last bits from what it learns from one run of it, so no later pass may follow one.
    REQUIRE(runs.size() >= size_t(r.passes));
    int at = 0;
    for (int k = 0; k + 1 < r.passes; k++) {
      CHECK(runs[size_t(k)] == pass_size(k, at, 144));
      at += runs[size_t(k)];
    }
    if (runs.size() > size_t(r.passes)) CHECK(r.spp - at < pass_size(r.passes - 1, at, 144));
    // (On a machine slow enough that 15 passes of 144 pixels take a tenth of a second more, no pass is cut there.)
    else WARN("no pass went on in pieces");
    render_result s = render(b->scene, b->bvh, b->lights, small_params(kind, r.spp, 4));
    CHECK(s.passes == r.passes);
    CHECK(s.film == r.film);
  }
}

TEST_CASE("staged weights keep bayes's image unbiased", "[passes]") {
  // The boxed lamp at 256 x 256, 12 spp: bayes's later passes weigh apart from its first 8 spp (late_learns) and its
  // image is the two groups' means in fixed shares. Over 12 seeds the image mean of bayes minus that of uniform (other
  // seeds) must lie within 4 standard errors of 0 (two-sided, 99.99 %); a share or a normalisation gone wrong (the
  // first group's share counted twice, say) moves it by many. (A standard error of about 1e-4 of the image's level:
  // a bias of 0.05 % would show.)
  auto b = boxed_lamp_scene();
  auto image_mean = [&](sampler_kind kind, uint64_t seed, bool& staged) {
    render_params p = small_params(kind, 12, 4, seed);
    p.width = p.height = 256;
    render_result r = render(b->scene, b->bvh, b->lights, p);
    staged = r.late_learns;
    image_data img = film_image(r);
    double sum = 0;
    for (float v : img.pixels) sum += v;
    return sum / double(img.pixels.size());
  };
  std::vector<double> diff;
  double level = 0;
  for (uint64_t seed = 1; seed <= 12; seed++) {
    bool staged = false, plain = false;
    const double m_bayes = image_mean(sampler_kind::bayes, seed, staged);
    const double m_uniform = image_mean(sampler_kind::uniform, 1000 + seed, plain);
    REQUIRE(staged);
    diff.push_back(m_bayes - m_uniform);
    level += m_uniform / 12;
  }
  mean_se m = mean_and_se(diff);
  INFO("bayes - uniform: " << m.mean << " +- " << m.se << " at a level of " << level);
  REQUIRE(m.se > 0);
  CHECK(std::fabs(m.mean) < 4 * m.se);
  CHECK(m.se < 2e-4 * level);
}

TEST_CASE("a fallback decided from the samples it weighs leaves bayes's image unbiased", "[passes]") {
  // The fallback check decides from the very samples the image weighs, so a share of the passes before the fallback
  // that follows the decision biases the image. Stop 57's rule did (every later pass weighing as the first one after
  // the fallback), and so did a fade of the passes before a fallback as the later ones come, tried at stop 61 (it would
  // have taken bayes under 64 lamps, path traced, from 1.7e-5 to 6.1e-6 at 300 spp; docs/HISTORY.md). A stress case:
  // the Cornell box, direct light and one bounce, 2 x 2 pixels, 32 spp, check windows of 4 samples and a threshold
  // (0.6) that falls back in about 2 renders of 3. Paired by seed against the same samples unweighted (weighting never
  // changes what is sampled, learned or decided; the unweighted image weighs every sample alike: unbiased), the mean
  // difference over 24000 seeds must lie within 4 standard errors of 0 (two-sided, 99.99 %). Measured over 20000 seeds
  // (a program rebuilding each rule from the result's films; level 0.107): this rule +8e-5 +- 1.2e-4, the fade
  // +1.4e-3 +- 2.7e-4 (this test, with the fade applied after any fallback: +1.37e-3 +- 2.46e-4, failed at 5.5
  // standard errors), stop 57's rule -2.7e-4 +- 1.1e-4 (not caught at this count: it takes about 100000 seeds, 3
  // minutes here).
  scene_data scene = build_scene(load_scene_desc(source_path("data/cornell/direct.json")), 1.0f);
  bvh_data bvh = build_bvh(scene);
  light_data lights = build_lights(scene);
  auto params = [](uint64_t seed, double weighting) {
    render_params p;
    p.width = p.height = 2;
    p.spp = 32;
    p.max_depth = 2;
    p.threads = 1;
    p.seed = seed;
    p.sampler.kind = sampler_kind::bayes;
    p.pass_weighting = weighting;
    p.sampler.bayes.fallback_ratio = 0.6;
    p.sampler.bayes.fallback_bvh_ratio = 0;
    p.sampler.bayes.fallback_window = 4;
    return p;
  };
  auto image_mean = [](const render_result& r) {
    const image_data img = film_image(r);
    double sum = 0;
    for (float v : img.pixels) sum += v;
    return sum / double(img.pixels.size());
  };
  // Under the sanitizers a render of these costs over 100 times as much (240 seeds took 57 s under ASan + UBSan):
  // there the test renders 40 seeds for memory safety, and its statistics are only as good as so few can be.
  constexpr int seeds = sanitized_build ? 40 : 24000, workers = 2;
  constexpr bool full = !sanitized_build;
  std::vector<double> diff(seeds), level(seeds);
  std::vector<int> fell(seeds);
  std::vector<std::thread> pool;
  for (int t = 0; t < workers; t++)
    pool.emplace_back([&, t] {
      for (int k = t; k < seeds; k += workers) {
        render_result w = render(scene, bvh, lights, params(uint64_t(k) + 1, 4));
        render_result u = render(scene, bvh, lights, params(uint64_t(k) + 1, 0));
        level[size_t(k)] = image_mean(u);
        diff[size_t(k)] = image_mean(w) - level[size_t(k)];
        fell[size_t(k)] = w.fallback_spp > 0;
      }
    });
  for (std::thread& t : pool) t.join();
  int fallbacks = 0;
  double mean_level = 0;
  for (int k = 0; k < seeds; k++) fallbacks += fell[size_t(k)], mean_level += level[size_t(k)] / seeds;
  mean_se m = mean_and_se(diff);
  INFO("weighted - unweighted: " << m.mean << " +- " << m.se << " at a level of " << mean_level << "; fell back in "
                                 << fallbacks << " of " << seeds);
  if (full) {  // (the decision goes both ways, most often to the fallback)
    CHECK(fallbacks > seeds / 2);
    CHECK(fallbacks < seeds * 9 / 10);
  }
  REQUIRE(m.se > 0);
  CHECK(std::fabs(m.mean) < 4 * m.se);
  // (The test's power: a standard error of at most 0.2 % of the level, about 1e-4 at 24000 seeds, shows a bias of
  // 0.8 % at 4 standard errors.)
  if (full) CHECK(m.se < 2e-3 * mean_level);
}
