// Animations (render --frames): the sun moves from sun.direction to sun.direction_end. Frame k of a
// non-learning sampler equals, bit for bit, a single render of a scene file stating that frame's sun; a
// learning sampler's frame 0 does too, its later frames (which start from the decayed statistics of the earlier
// ones) agree statistically with a single render, and animations are deterministic across thread counts.
#include "checkpoint.h"
#include "file_io.h"
#include "image_io.h"
#include "metrics.h"
#include "rng.h"
#include "scene_desc.h"
#include "test_util.h"

#include <catch2/catch.hpp>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <unistd.h>

using namespace bl;
using namespace bl::test;

namespace {

// A floor, a wall that shadows part of it, a small lamp and a sun that swings over the wall.
struct anim_scene {
  temp_dir dir;
  std::string obj = dir / "a.obj";
  anim_scene() {
    write_text(obj,
               "mtllib a.mtl\n"
               "v -3 0 -3\nv 3 0 -3\nv 3 0 3\nv -3 0 3\n"
               "v -3 0 0\nv 3 0 0\nv 3 2 0\nv -3 2 0\n"
               "v -0.3 2.5 1\nv 0.3 2.5 1\nv 0.3 2.5 1.6\nv -0.3 2.5 1.6\n"
               "usemtl floor\nf 1 4 3 2\nf 5 6 7 8\n"
               "usemtl lamp\nf 9 10 11 12\n");
    write_text(dir / "a.mtl", "newmtl floor\nKd 0.6 0.6 0.6\nnewmtl lamp\nKd 0 0 0\nKe 20 20 20\n");
  }
  // A scene file with the given sun direction (and optionally an end direction).
  std::string scene(const std::string& name, vec3f sun, const vec3f* end) {
    char buf[1024];
    std::string end_json;
    if (end) {
      std::snprintf(buf, sizeof buf, ", \"direction_end\": [%.9g, %.9g, %.9g]", end->x, end->y, end->z);
      end_json = buf;
    }
    std::snprintf(buf, sizeof buf,
                  "{\"mesh\": \"a.obj\", \"camera\": {\"eye\": [0, 4, 5], \"target\": [0, 0, 0]},"
                  " \"image\": {\"width\": 24, \"height\": 18}, \"render\": {\"spp\": 4, \"max_depth\": 2},"
                  " \"sun\": {\"direction\": [%.9g, %.9g, %.9g], \"irradiance\": [5, 5, 5]%s}}",
                  sun.x, sun.y, sun.z, end_json.c_str());
    std::string path = dir / name;
    write_text(path, buf);
    return path;
  }
};

const vec3f sun_start = {0.6f, 0.5f, -0.6f}, sun_end = {-0.5f, 0.6f, 0.6f};

}  // namespace

TEST_CASE("each frame of a non learning sampler equals a single render with that frame's sun and seed", "[animation]") {
  anim_scene a;
  std::string anim = a.scene("anim.json", sun_start, &sun_end);
  scene_desc desc = load_scene_desc(anim);
  const int frames = 4;
  for (const char* s : {"power", "bvh", "bound"}) {
    auto r = run_bayeslight("render " + anim + " --sampler " + s + " --frames 4 --quiet -o " + (a.dir / "f_%02d.pfm"));
    INFO(s << "\n" << r.output);
    REQUIRE(r.status == 0);
    for (int k = 0; k < frames; k++) {
      vec3f d = animated_sun_direction(desc.sun, k, frames);
      // (The last frame as a scene written with the end direction itself: the same image, to the bit.)
      // Frame k draws the streams of frame_seed(seed, k) (the scene's seed is 0).
      std::string single = k == 0 ? anim : a.scene("single.json", k == frames - 1 ? sun_end : d, nullptr);
      REQUIRE(run_bayeslight("render " + single + " --sampler " + s + " --seed " + std::to_string(frame_seed(0, k)) +
                             " --quiet -o " + (a.dir / "s.pfm")).status == 0);
      char name[32];
      std::snprintf(name, sizeof name, "f_%02d.pfm", k);
      INFO("frame " << k);
      CHECK(bit_identical(read_image(a.dir / name), read_image(a.dir / "s.pfm")));
    }
  }
  // The first and last frames have the start and end suns.
  auto same = [](vec3f u, vec3f v) { return u.x == v.x && u.y == v.y && u.z == v.z; };
  CHECK(same(animated_sun_direction(desc.sun, 0, frames), desc.sun.direction));
  CHECK(same(animated_sun_direction(desc.sun, frames - 1, frames), desc.sun.direction_end));
  // (This scene's pair happens to slerp exactly onto its end; most pairs do not, and the last frame is exact anyway.)
  sun_params other;
  other.animated = true;
  other.direction = normalize(vec3f{0.3f, 0.8f, 0.1f});
  other.direction_end = normalize(vec3f{-0.7f, 0.2f, 0.5f});
  for (int n : {2, 3, 5, 7, 24}) {
    INFO(n << " frames");
    CHECK(same(animated_sun_direction(other, n - 1, n), other.direction_end));
  }
  CHECK(length(desc.sun.direction_end - normalize(sun_end)) < 1e-6f);
}

TEST_CASE("the sun moves along the great circle, over the zenith between opposite directions", "[animation]") {
  // Slerp at t = k / (N - 1): the angle to the start grows evenly. A sunrise [1, 0, 0] to a sunset [-1, 0, 0] has no
  // one great circle: it went round the horizon (a dark animation, a review); it passes overhead now.
  sun_params sun;
  sun.animated = true;
  sun.direction = normalize(vec3f{1, 1, 0});
  sun.direction_end = normalize(vec3f{-1, 1, 0});
  for (int k = 0; k < 5; k++) {
    vec3f d = animated_sun_direction(sun, k, 5);
    CHECK(std::acos(std::min(1.0f, dot(d, sun.direction))) == Approx(0.25 * k * M_PI / 2).margin(1e-3));  // (float acos near 1)
    CHECK(d.z == Approx(0).margin(1e-6));
  }
  struct pair_case {
    vec3f from, mid;  // the opposite end is -from; mid: the halfway direction
  };
  for (const pair_case& c : {pair_case{{1, 0, 0}, {0, 1, 0}}, pair_case{{0, 0, -1}, {0, 1, 0}},
                             pair_case{{0, 1, 0}, {1, 0, 0}}, pair_case{{0, -1, 0}, {1, 0, 0}}}) {
    sun.direction = c.from;
    sun.direction_end = c.from * -1.0f;
    vec3f mid = animated_sun_direction(sun, 2, 5);
    INFO(c.from.x << " " << c.from.y << " " << c.from.z << " -> " << mid.x << " " << mid.y << " " << mid.z);
    CHECK(length(mid - c.mid) < 1e-5f);
  }
}

TEST_CASE("learning samplers animate deterministically and agree with single renders", "[animation]") {
  anim_scene a;
  std::string anim = a.scene("anim.json", sun_start, &sun_end);
  scene_desc desc = load_scene_desc(anim);
  for (const char* s : {"bayes", "donikian"}) {
    INFO(s);
    std::string base = " --sampler " + std::string(s) + " --frames 3 --quiet --spp 64";
    REQUIRE(run_bayeslight("render " + anim + base + " --threads 1 -o " + (a.dir / "t1_%d.pfm")).status == 0);
    REQUIRE(run_bayeslight("render " + anim + base + " --threads 2 -o " + (a.dir / "t2_%d.pfm")).status == 0);
    for (int k = 0; k < 3; k++)
      CHECK(read_file(a.dir / ("t1_" + std::to_string(k) + ".pfm")) == read_file(a.dir / ("t2_" + std::to_string(k) + ".pfm")));
    // Frame 0 starts from nothing learned: exactly the single render.
    REQUIRE(run_bayeslight("render " + anim + " --sampler " + s + " --quiet --spp 64 -o " + (a.dir / "s0.pfm")).status == 0);
    CHECK(bit_identical(read_image(a.dir / "t1_0.pfm"), read_image(a.dir / "s0.pfm")));
    // The last frame started from decayed statistics: same expectation as a fresh render of its sun. Pixel
    // means of the two images (independent seeds) must agree within 4.4 standard errors (99.999%).
    std::string single = a.scene("single.json", animated_sun_direction(desc.sun, 2, 3), nullptr);
    REQUIRE(run_bayeslight("render " + single + " --sampler " + s + " --quiet --spp 64 --seed 7 -o " + (a.dir / "s2.pfm")).status == 0);
    image_data x = read_image(a.dir / "t1_2.pfm"), y = read_image(a.dir / "s2.pfm");
    std::vector<double> dx;
    for (size_t i = 0; i < x.pixels.size(); i += 3) dx.push_back(double(x.pixels[i]) - double(y.pixels[i]));
    mean_se m = mean_and_se(dx);
    double level = 0;
    for (size_t i = 0; i < y.pixels.size(); i += 3) level += y.pixels[i];
    level /= double(y.pixels.size() / 3);
    INFO("mean difference " << m.mean << " +- " << m.se << " image mean " << level);
    CHECK(m.se < 0.02 * level);
    CHECK(std::fabs(m.mean) < 4.4 * m.se);
  }
}

TEST_CASE("a learning sampler's later frames are not biased by the samples it learned from", "[animation]") {
  // Every frame drew the same random streams: frame 1 began with statistics learned from the very samples it drew
  // again, so its light choices depended on their own outcomes (a review: bayes without control variates 1 % dark,
  // z -22). With a sun that does not move, frames 0 and 1 estimate the same image: the mean over 24 seeds of the
  // difference of their image means must be within 4.4 standard errors of 0 (99.999 %). (The seeds are the
  // independent units: a render's pixels share what it learned, and over pixels the standard error came out two to
  // three times too small, so that four seeds of unbiased renders read -4.6 to +3.2 of it.)
  // A floor, a cube, a wall beside it, two small lamps and a sun that does not move.
  temp_dir dir;
  write_text(dir / "s.obj",
             "mtllib s.mtl\n"
             "v -3 0 -3\nv 3 0 -3\nv 3 0 3\nv -3 0 3\n"
             "v -0.5 0 -0.5\nv 0.5 0 -0.5\nv 0.5 0 0.5\nv -0.5 0 0.5\n"
             "v -0.5 1 -0.5\nv 0.5 1 -0.5\nv 0.5 1 0.5\nv -0.5 1 0.5\n"
             "v 1.5 0 -2\nv 1.5 0 2\nv 1.5 2 2\nv 1.5 2 -2\n"
             "v -1.5 2.2 1\nv -1.2 2.2 1\nv -1.2 2.2 1.3\nv -1.5 2.2 1.3\n"
             "v 0.8 2.2 -1.5\nv 1.1 2.2 -1.5\nv 1.1 2.2 -1.2\nv 0.8 2.2 -1.2\n"
             "usemtl white\nf 1 4 3 2\nf 9 12 11 10\nf 5 6 10 9\nf 8 12 11 7\nf 5 9 12 8\nf 6 7 11 10\n"
             "f 13 14 15 16\n"
             "usemtl lamp\nf 17 18 19 20\nf 21 22 23 24\n");
  write_text(dir / "s.mtl", "newmtl white\nKd 0.7 0.7 0.7\nnewmtl lamp\nKd 0.5 0.5 0.5\nKe 30 30 30\n");
  std::string still = dir / "still.json";
  write_text(still, "{\"mesh\": \"s.obj\", \"camera\": {\"eye\": [0, 5, 6], \"target\": [0, 0, 0]},"
                    " \"render\": {\"max_depth\": 1}, \"sun\": {\"direction\": [0.6, 0.7, 0.2], \"irradiance\": [5, 5, 5],"
                    " \"angular_diameter_deg\": 2, \"direction_end\": [0.6, 0.7, 0.2]}}");
  for (const char* s : {"bayes --bayes-no-cv", "bayes", "donikian"}) {
    std::vector<double> diff;
    double level = 0;
    const int seeds = 24;
    for (int seed = 1; seed <= seeds; seed++) {
      std::string base = dir / ("f" + std::to_string(seed));
      auto r = run_bayeslight("render " + still + " --sampler " + s + " --frames 2 --quiet --spp 64 --width 32 --height 24 --seed " +
                              std::to_string(seed) + " -o " + base + "_%d.pfm");
      INFO(s << ": " << r.output);
      REQUIRE(r.status == 0);
      image_data f0 = read_image(base + "_0.pfm"), f1 = read_image(base + "_1.pfm");
      double d = 0, l = 0;
      for (size_t i = 0; i < f0.pixels.size(); i++) d += double(f1.pixels[i]) - double(f0.pixels[i]), l += f0.pixels[i];
      diff.push_back(d / double(f0.pixels.size()));
      level += l / double(f0.pixels.size()) / seeds;
    }
    mean_se m = mean_and_se(diff);
    INFO(s << ": mean difference " << m.mean << " +- " << m.se << ", image mean " << level);
    CHECK(m.se < 0.01 * level);
    CHECK(std::fabs(m.mean) < 4.4 * m.se);
  }
}

TEST_CASE("frame patterns are required for animated outputs", "[animation]") {
  anim_scene a;
  std::string anim = a.scene("anim.json", sun_start, &sun_end);
  auto r = run_bayeslight("render " + anim + " --frames 3 --quiet -o " + (a.dir / "plain.pfm"));
  CHECK(r.status == 2);
  CHECK(r.output.find("frame pattern") != std::string::npos);
}

TEST_CASE("without --frames an output name is taken literally, % and all", "[animation]") {
  anim_scene a;
  std::string scene = a.scene("still.json", sun_start, nullptr);
  std::string pattern = a.dir / "still_%d.pfm", log = a.dir / "still_%02d.csv";
  auto r = run_bayeslight("render " + scene + " --spp 2 --quiet -o " + pattern + " --log " + log);
  REQUIRE(r.status == 0);
  CHECK(std::filesystem::exists(pattern));
  CHECK(std::filesystem::exists(log));
  CHECK_FALSE(std::filesystem::exists(a.dir / "still_0.pfm"));
  CHECK_FALSE(std::filesystem::exists(a.dir / "still_00.csv"));
  // ... with a warning, even under --quiet (a forgotten --frames), for an image; a name with a '%' that is no frame
  // pattern draws none.
  CHECK(r.output.find("warning: -o " + pattern + " is a frame pattern, but without --frames") != std::string::npos);
  auto plain = run_bayeslight("render " + scene + " --spp 2 --quiet -o " + (a.dir / "100%.pfm"));
  REQUIRE(plain.status == 0);
  CHECK(plain.output.find("warning") == std::string::npos);
  // Nor does the default output of a scene whose name is one (no -o was given: nothing was forgotten).
  std::filesystem::copy_file(scene, a.dir / "sc_%d.json");
  auto named = run_bayeslight("render " + (a.dir / "sc_%d.json") + " --spp 2 --width 8 --height 6 --quiet");
  REQUIRE(named.status == 0);
  CHECK(named.output.find("warning") == std::string::npos);
  CHECK(std::filesystem::exists("sc_%d.exr"));
  std::filesystem::remove("sc_%d.exr");
}

TEST_CASE("an animation of one frame (--frames 1) takes frame patterns, and a '%' in a name is written %%",
          "[animation]") {
  // A script passing --frames $N broke for N = 1: names were taken literally. A scene named with a '%' had its own
  // default output refused as not a frame pattern.
  anim_scene a;
  std::string anim = a.scene("anim.json", sun_start, &sun_end);
  auto one = run_bayeslight("render " + anim + " --frames 1 --spp 1 --quiet -o " + (a.dir / "one_%02d.pfm") +
                            " --log " + (a.dir / "one_%d.csv"));
  INFO(one.output);
  REQUIRE(one.status == 0);
  CHECK(std::filesystem::exists(a.dir / "one_00.pfm"));
  CHECK(std::filesystem::exists(a.dir / "one_0.csv"));
  std::filesystem::copy_file(anim, a.dir / "my%20scene.json");
  std::string cmd = "cd " + a.dir.path.string() + " && " + BAYESLIGHT_BINARY +
                    " render 'my%20scene.json' --frames 2 --spp 1 --quiet 2>/dev/null";
  REQUIRE(std::system(cmd.c_str()) == 0);
  CHECK(std::filesystem::exists(a.dir / "my%20scene_0000.exr"));
  CHECK(std::filesystem::exists(a.dir / "my%20scene_0001.exr"));
  // "%%" is a '%' in a pattern; two directives are not a pattern, and the message says what one is.
  auto pct = run_bayeslight("render " + anim + " --frames 2 --spp 1 --quiet -o " + (a.dir / "p_%%_%d.pfm"));
  REQUIRE(pct.status == 0);
  CHECK(std::filesystem::exists(a.dir / "p_%_1.pfm"));
  auto two = run_bayeslight("render " + anim + " --frames 2 --spp 1 --quiet -o " + (a.dir / "t_%d_%d.pfm"));
  CHECK(two.status == 2);
  CHECK(two.output.find("one %d such as out_%04d.exr") != std::string::npos);
}

TEST_CASE("frames of a sun that does not move are rendered with a warning", "[animation]") {
  // A sun without direction_end gives every frame the same image: rendered (it is no error), but said.
  anim_scene a;
  std::string still = a.scene("still.json", sun_start, nullptr), anim = a.scene("anim.json", sun_start, &sun_end);
  auto r = run_bayeslight("render " + still + " --frames 2 --spp 1 --quiet -o " + (a.dir / "s_%d.pfm"));
  INFO(r.output);
  CHECK(r.status == 0);
  CHECK(r.output.find("warning: the sun has no \"direction_end\"") != std::string::npos);
  CHECK(std::filesystem::exists(a.dir / "s_1.pfm"));
  auto moving = run_bayeslight("render " + anim + " --frames 2 --spp 1 --quiet -o " + (a.dir / "m_%d.pfm"));
  CHECK(moving.status == 0);
  CHECK(moving.output.find("warning") == std::string::npos);
}

TEST_CASE("every frame's output and log are checked before the first frame renders", "[animation]") {
  // Only frame 0's files were checked up front: with a folder for frame 0 alone, every frame rendered, frame 0 was
  // written and the others failed at the end.
  anim_scene a;
  std::string anim = a.scene("anim.json", sun_start, &sun_end);
  std::filesystem::create_directory(a.dir / "d0");
  auto out = run_bayeslight("render " + anim + " --frames 3 --spp 1 --quiet -o " + (a.dir / "d%d/x.pfm"));
  CHECK(out.status == 1);
  CHECK(out.output.find("d1") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(a.dir / "d0/x.pfm"));
  std::filesystem::create_directory(a.dir / "f2.pfm");  // frame 2's output is a folder
  auto dir = run_bayeslight("render " + anim + " --frames 3 --spp 1 --quiet -o " + (a.dir / "f%d.pfm"));
  CHECK(dir.status == 1);
  CHECK(dir.output.find("is a directory") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(a.dir / "f0.pfm"));
  auto log = run_bayeslight("render " + anim + " --frames 3 --spp 1 --quiet -o " + (a.dir / "g%d.pfm") + " --log " +
                            (a.dir / "d%d/l.csv"));
  CHECK(log.status == 1);
  CHECK_FALSE(std::filesystem::exists(a.dir / "g0.pfm"));
}

TEST_CASE("an animation says a frame's unwritable output when it happens, and goes on", "[animation]") {
  // Frame 1's image links to /dev/full: its write fails (ENOSPC) after every check before the render passed. The
  // failure was named only after the last frame (a review); now at once, and the count at the end (exit 1).
  anim_scene a;
  std::string anim = a.scene("anim.json", sun_start, &sun_end);
  const std::string full = a.dir / "f_1.pfm";
  REQUIRE(::symlink("/dev/full", full.c_str()) == 0);
  auto r = run_bayeslight("render " + anim + " --sampler power --frames 3 -o " + (a.dir / "f_%d.pfm"));
  INFO(r.output);
  CHECK(r.status == 1);
  size_t said = r.output.find("f_1.pfm");
  size_t error = r.output.find("bayeslight: error: ");
  size_t next = r.output.find("frame 2: ");
  REQUIRE(said != std::string::npos);
  REQUIRE(error != std::string::npos);
  REQUIRE(next != std::string::npos);
  CHECK(error < next);
  CHECK(r.output.find("1 output could not be written (each named above)") != std::string::npos);
  CHECK(std::filesystem::file_size(a.dir / "f_0.pfm") > 24 * 18 * 12);
  CHECK(std::filesystem::file_size(a.dir / "f_2.pfm") > 24 * 18 * 12);
}

TEST_CASE("an animation killed, interrupted or stopped between frames resumes to the same frames", "[animation][checkpoint]") {
  // A checkpoint holds the frame under way; --resume continues there (its learned state carries the earlier frames'
  // statistics), so every frame equals the uninterrupted animation's, bit for bit.
  anim_scene a;
  std::string anim = a.scene("anim.json", sun_start, &sun_end);
  const std::string ck = a.dir / "ck.bin";
  auto frame = [&](const std::string& stem, int k) { return a.dir / (stem + "_" + std::to_string(k) + ".pfm"); };
  for (const char* s : {"bayes", "donikian", "bound"}) {
    INFO(s);
    // 27 spp: 14 passes a frame, so pass 17 is frame 1's third.
    const std::string args = "render " + anim + " --sampler " + s + " --frames 3 --spp 27 --quiet";
    REQUIRE(run_bayeslight(args + " -o " + (a.dir / "full_%d.pfm")).status == 0);
    struct stop {
      const char* how;
      int status;
      int frames_left;  // frames written by the stopped run
    };
    // (--signal-in-frame 1: a signal during frame 1's first pass, which stops at once: the checkpoint then holds
    // frame 1 without a pass, its statistics as frame 0 left them; before, nothing was saved.)
    for (const stop& st : {stop{"--checkpoint-every 1000 --kill-after-passes 17", 128 + 9, 1},
                           stop{"--stop-after-passes 17", 130, 2}, stop{"--signal-after-last-pass", 130, 1},
                           stop{"--checkpoint-every 1000 --signal-in-frame 1", 130, 1}}) {
      INFO(st.how);
      for (int k = 0; k < 3; k++) std::filesystem::remove(frame("part", k));
      std::filesystem::remove(ck);
      auto r1 = run_bayeslight(args + " -o " + (a.dir / "part_%d.pfm") + " --checkpoint " + ck + " " + st.how);
      INFO(r1.output);
      CHECK(r1.status == st.status);
      for (int k = 0; k < 3; k++) CHECK(std::filesystem::exists(frame("part", k)) == (k < st.frames_left));
      if (std::string(st.how) == "--signal-after-last-pass")
        CHECK(r1.output.find("after frame 0; frames 1 to 2 were not rendered; --resume " + ck) != std::string::npos);
      if (std::string(st.how) == "--stop-after-passes 17")
        CHECK(r1.output.find("the animation stopped in frame 1 of 3; frame 2 was not rendered; --resume " + ck +
                             " continues it") != std::string::npos);
      if (std::string(st.how) == "--checkpoint-every 1000 --signal-in-frame 1") {
        // Its resume interrupted in the set-up: frame 1 has no pass to write, so it ends there, the checkpoint as it
        // was (it promised "the image of the checkpoint's passes", and wrote nothing).
        const std::string saved = read_file(ck);
        auto early = run_bayeslight(args + " -o " + (a.dir / "part_%d.pfm") + " --resume " + ck +
                                    " --checkpoint " + ck + " --signals-in-setup 1");
        INFO(early.output);
        CHECK(early.status == 130);
        CHECK(early.output.find("bayeslight: interrupted (SIGINT) while setting up the render; nothing written\n") !=
              std::string::npos);
        CHECK(early.output.find("going on") == std::string::npos);
        CHECK(read_file(ck) == saved);
        CHECK(!std::filesystem::exists(frame("part", 1)));
      }
      auto r2 = run_bayeslight(args + " -o " + (a.dir / "part_%d.pfm") + " --resume " + ck);
      INFO(r2.output);
      REQUIRE(r2.status == 0);
      for (int k = 0; k < 3; k++) CHECK(read_file(frame("part", k)) == read_file(frame("full", k)));
    }
  }
  // Resumed with another frame count or decay (other suns, other statistics): refused. A frame's file lost after the
  // checkpoint is named (it cannot be rendered alone).
  const std::string base = "render " + anim + " --spp 27 --quiet -o " + (a.dir / "part_%d.pfm");
  const std::string args = base + " --frames 3";
  REQUIRE(run_bayeslight(args + " --checkpoint " + ck + " --stop-after-passes 17").status == 130);
  CHECK(run_bayeslight(base + " --frames 4 --resume " + ck).status == 3);
  auto decay = run_bayeslight(args + " --frame-decay 0.7 --resume " + ck);
  CHECK(decay.status == 3);
  CHECK(decay.output.find("; what differs: --pass-weighting or --frame-decay\n") != std::string::npos);
  // (the message named every option but --frame-decay)
  // Nor with other samples per frame: frame 0 was rendered with 27 spp and frame 1 learned from it.
  auto more = run_bayeslight("render " + anim + " --spp 40 --frames 3 --quiet -o " + (a.dir / "part_%d.pfm") +
                             " --resume " + ck);
  CHECK(more.status == 3);
  CHECK(more.output.find("; what differs: the animation (--frames, the sun's direction_end, --spp or --time)\n") !=
        std::string::npos);
  CHECK(run_bayeslight("render " + anim + " --spp 27 --quiet -o " + (a.dir / "still.pfm") + " --resume " + ck).status == 3);
  // The frame index edited out of range and the file re-sealed with its checksum: refused, never followed.
  const std::string saved = read_file(ck);
  for (int bad : {-1, 3, 1 << 30}) {
    std::string body = saved.substr(0, saved.size() - 8);
    std::memcpy(&body[checkpoint_frame_offset], &bad, sizeof bad);
    uint64_t h = checkpoint_checksum(body);
    write_text(a.dir / "edited.bin", body + std::string(reinterpret_cast<const char*>(&h), 8));
    auto e = run_bayeslight(args + " --resume " + (a.dir / "edited.bin"));
    INFO(bad << ": " << e.output);
    CHECK(e.status == 3);
    CHECK(e.output.find("edited.bin: corrupt checkpoint: frame") != std::string::npos);
  }
  std::filesystem::remove(frame("part", 0));
  auto r = run_bayeslight(args + " --resume " + ck);
  CHECK(r.status == 0);
  CHECK(r.output.find("resuming the animation at frame 1 of 3, ") != std::string::npos);
  CHECK(r.output.find(" spp into it (") != std::string::npos);
  CHECK(r.output.find("; frame 0 was rendered before)") != std::string::npos);
  CHECK(r.output.find("part_0.pfm is missing") != std::string::npos);
}
