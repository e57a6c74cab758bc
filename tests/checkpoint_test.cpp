// Resumable renders: a render interrupted by SIGINT (checkpoint written on the way out) or killed by SIGKILL
// (after a checkpoint) and resumed to the same spp is byte-identical to an uninterrupted one, for the learning
// samplers too; a resume with another scene or other options, or from a corrupt file, is refused (exit 3).
#include "checkpoint.h"
#include "file_io.h"
#include "test_util.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>

using namespace bl;
using namespace bl::test;

namespace {

std::string base_args(const std::string& sampler) {
  return "render " + source_path("data/living_room/path.json") + " --sampler " + sampler +
         " --width 40 --height 30 --spp 27 --quiet";  // 27: the end of a scheduled pass (see pass_size)
}

// The Cornell box, direct, rendered with `sampler` at w x h (no spp: each use gives its own).
std::string cornell_args(const std::string& sampler, int w, int h) {
  return "render " + source_path("data/cornell/direct.json") + " --sampler " + sampler + " --width " +
         std::to_string(w) + " --height " + std::to_string(h) + " --quiet";
}

// Renders `args` to `spp` with a checkpoint at ck (the image to dir/a.pfm).
void render_checkpoint(const std::string& args, int spp, const temp_dir& dir, const std::string& ck) {
  REQUIRE(run_bayeslight(args + " --spp " + std::to_string(spp) + " -o " + (dir / "a.pfm") + " --checkpoint " + ck)
              .status == 0);
}

}  // namespace

TEST_CASE("interrupted and killed renders resume to the same bytes", "[checkpoint]") {
  temp_dir d;
  // bayes in direct illumination too: there its clusters are refined into members (region_params::max_members).
  // (An oracle's frozen model does not adapt: its passes weigh alike, which the checkpoint check must know.)
  // --light-points auto (the default): the tiles' statistics, which choose the next passes' point counts, come back
  // with the film; a fixed count needs none.
  for (const char* s : {"bound", "donikian", "bayes", "bayes --max-depth 1", "bayes --bayes-oracle 8",
                        "bayes --light-points 3", "power --max-depth 1"}) {
    INFO(s);
    std::string full = d / "full.pfm";
    REQUIRE(run_bayeslight(base_args(s) + " -o " + full).status == 0);
    // SIGINT after 9 passes: the checkpoint of the completed passes is written on the way out.
    std::string ck = d / "ck.bin", part = d / "part.pfm", out = d / "resumed.pfm";
    auto r1 = run_bayeslight(base_args(s) + " -o " + part + " --checkpoint " + ck + " --stop-after-passes 9");
    CHECK(r1.status == 130);
    REQUIRE(std::filesystem::exists(ck));
    CHECK(r1.output.find(ck + " holds the render; --resume " + ck + " continues it") != std::string::npos);
    auto r2 = run_bayeslight(base_args(s) + " -o " + out + " --resume " + ck);
    INFO(r2.output);
    REQUIRE(r2.status == 0);
    CHECK(read_file(out) == read_file(full));
    // SIGKILL right after the checkpoint of pass 11 (no chance to write anything else).
    std::string ck2 = d / "ck2.bin", out2 = d / "resumed2.pfm";
    auto r3 = run_bayeslight(base_args(s) + " -o " + (d / "k.pfm") + " --checkpoint " + ck2 +
                             " --checkpoint-every 1000 --kill-after-passes 11");
    CHECK(r3.status == 128 + 9);
    REQUIRE(std::filesystem::exists(ck2));
    REQUIRE(run_bayeslight(base_args(s) + " -o " + out2 + " --resume " + ck2).status == 0);
    CHECK(read_file(out2) == read_file(full));
  }
}

TEST_CASE("a resumed render says what it continues and what --time leaves", "[checkpoint]") {
  // The summary's spp and seconds are the render's totals, the checkpoint's included, and so is a --time budget: a
  // budget the checkpoint had spent rewrote its image without a word (and warned that the passes added, none, were
  // off schedule).
  temp_dir d;
  const std::string args = cornell_args("bayes", 32, 24), ck = d / "ck.bin";
  REQUIRE(run_bayeslight(args + " --spp 20 --checkpoint " + ck + " -o " + (d / "a.pfm")).status == 0);
  const std::string loud = args.substr(0, args.size() - std::string(" --quiet").size());
  auto more = run_bayeslight(loud + " --spp 40 --resume " + ck + " -o " + (d / "b.pfm"));
  INFO(more.output);
  REQUIRE(more.status == 0);
  CHECK(more.output.find(ck + ": resuming at 20 spp (") != std::string::npos);
  CHECK(more.output.find("rendered 40 spp") != std::string::npos);
  CHECK(more.output.find(" clusters or members per region") != std::string::npos);  // (members: beyond --max-cut)
  auto spent = run_bayeslight(loud + " --time 0.000001 --resume " + ck + " -o " + (d / "c.pfm"));
  INFO(spent.output);
  REQUIRE(spent.status == 0);
  CHECK(spent.output.find("--time 1e-06 counts them and is spent: no pass is added") != std::string::npos);
  CHECK(spent.output.find("not bit-identical") == std::string::npos);
  CHECK(spent.output.find("rendered 20 spp") != std::string::npos);
  CHECK(read_file(d / "c.pfm") == read_file(d / "a.pfm"));
  auto same = run_bayeslight(loud + " --spp 20 --resume " + ck + " -o " + (d / "c.pfm"));
  REQUIRE(same.status == 0);
  CHECK(same.output.find("; --spp 20: no pass is added") != std::string::npos);
  auto quiet = run_bayeslight(args + " --spp 40 --resume " + ck + " -o " + (d / "b.pfm"));
  CHECK(quiet.status == 0);
  CHECK(quiet.output.find("resuming") == std::string::npos);
  // A resume refused for its --spp says nothing of resuming (it had said "resuming at 20 spp" first).
  auto fewer = run_bayeslight(loud + " --spp 10 --resume " + ck + " -o " + (d / "b.pfm"));
  CHECK(fewer.status == 2);
  CHECK(fewer.output.find("resuming") == std::string::npos);
}

TEST_CASE("a checkpoint written in pieces resumes to the same bytes", "[checkpoint]") {
  // Checkpoints are streamed to the file in pieces of about 4 MB with a running checksum (the whole was held in
  // memory, adding its size to the process's; a review): one of many pieces must resume as one render does.
  temp_dir d;
  const std::string args = "render " + source_path("data/hall/direct.json") + " --width 160 --height 120 --quiet";
  const std::string ck = d / "ck.bin";
  REQUIRE(run_bayeslight(args + " --spp 2 -o " + (d / "a.pfm") + " --checkpoint " + ck).status == 0);
  CHECK(read_file(ck).size() > (size_t(12) << 20));  // (several pieces)
  auto r = run_bayeslight(args + " --spp 3 -o " + (d / "resumed.pfm") + " --resume " + ck);
  INFO(r.output);
  REQUIRE(r.status == 0);
  REQUIRE(run_bayeslight(args + " --spp 3 -o " + (d / "full.pfm")).status == 0);
  CHECK(read_file(d / "resumed.pfm") == read_file(d / "full.pfm"));
}

TEST_CASE("a render resumed after bayes fell back continues its stratified set", "[checkpoint]") {
  // The path-traced Cornell box at 40x30 falls back to power sampling at the end of pass 27 (485 spp; see
  // golden/manifest.txt): from pass 28 on the model stays, and its samples form one stratified set starting at
  // 485, which a resume after pass 29 must restore (a set restarted at the resume gives other bytes).
  temp_dir d;
  std::string args = "render " + source_path("data/cornell/path.json") +
                     " --sampler bayes --width 40 --height 30 --spp 677 --quiet";
  auto full = run_bayeslight(args + " -o " + (d / "full.pfm") + " --log " + (d / "log.csv"));
  REQUIRE(full.status == 0);
  resume_run r = stop_and_resume(d, args, 29, d / "full.pfm");
  INFO(r.resumed.output);
  CHECK(r.stopped == 130);
  REQUIRE(r.resumed.status == 0);
  CHECK(r.same);
  // The fallback did happen before the interruption (else the test would not test the set's start).
  auto check = run_bayeslight("render " + source_path("data/cornell/path.json") +
                              " --sampler bayes --width 40 --height 30 --spp 549 -o " + (d / "c.pfm"));
  INFO(check.output);
  CHECK(check.output.find("power sampling after 485 spp") != std::string::npos);
}

TEST_CASE("a render of radiance 1e28 resumes to the same bytes", "[checkpoint]") {
  // Samples whose squares overflow float: every weight and check column a checkpoint saves must stay finite, or the
  // resume refuses the file as corrupt. Direct (members: the floor sees 20 lamps) and path traced.
  temp_dir d;
  std::string obj = "mtllib m.mtl\nusemtl floor\nv -5 0 -5\nv -5 0 5\nv 5 0 5\nv 5 0 -5\nf 1 2 3 4\nusemtl lamp\n";
  for (int i = 0; i < 20; i++) {
    float x = -4.5f + float(i % 5) * 2, z = -4 + float(i / 5) * 2;
    obj += "v " + std::to_string(x) + " 3 " + std::to_string(z) + "\nv " + std::to_string(x + 0.2f) + " 3 " +
           std::to_string(z) + "\nv " + std::to_string(x) + " 3 " + std::to_string(z + 0.2f) + "\nf -3 -2 -1\n";
  }
  write_text(d / "m.obj", obj);
  write_text(d / "m.mtl", "newmtl floor\nKd 0.5 0.5 0.5\nnewmtl lamp\nKd 0 0 0\nKe 1e28 1e28 1e28\n");
  write_text(d / "m.json", R"({"mesh": "m.obj", "camera": {"eye": [0, 6, 9], "target": [0, 0, 0], "fov_y_deg": 50}})");
  for (const char* depth : {"1", "2"}) {
    INFO("max depth " << depth);
    std::string args = "render " + (d / "m.json") + " --sampler bayes --width 40 --height 30 --spp 27 --quiet " +
                       "--max-depth " + depth;
    REQUIRE(run_bayeslight(args + " -o " + (d / "full.pfm")).status == 0);
    std::string ck = d / "ck.bin";
    CHECK(run_bayeslight(args + " -o " + (d / "part.pfm") + " --checkpoint " + ck + " --stop-after-passes 9").status ==
          130);
    auto resumed = run_bayeslight(args + " -o " + (d / "resumed.pfm") + " --resume " + ck);
    INFO(resumed.output);
    REQUIRE(resumed.status == 0);
    CHECK(read_file(d / "resumed.pfm") == read_file(d / "full.pfm"));
  }
}

TEST_CASE("a render of a lamp of radiance FLT_MAX in view resumes", "[checkpoint]") {
  // Pixels whose every sample is FLT_MAX: their film sums may round a hair above FLT_MAX times the film weight, yet the
  // image holds FLT_MAX; a range check with no room for that rounding refused such checkpoints (at 3, 8, 9, ... spp).
  temp_dir d;
  write_text(d / "q.obj", "mtllib q.mtl\nusemtl lamp\nv 0 0 0\nv 2e-5 0 0\nv 2e-5 2e-5 0\nv 0 2e-5 0\nf 1 2 3 4\n");
  write_text(d / "q.mtl", "newmtl lamp\nKd 0 0 0\nKe 3.4028234663852886e38 3.4028234663852886e38 "
                          "3.4028234663852886e38\n");
  for (const char* sampler : {"bayes", "donikian"})
    for (int spp : {3, 8, 9}) {
      INFO(sampler << " " << spp << " spp");
      std::string args = "render " + (d / "q.obj") + " --sampler " + sampler + " --width 32 --height 24 --quiet " +
                         "--max-depth 1 --checkpoint " + (d / "ck.bin") + " -o " + (d / "a.pfm");
      REQUIRE(run_bayeslight(args + " --spp " + std::to_string(spp)).status == 0);
      auto resumed = run_bayeslight(args + " --spp " + std::to_string(spp + 3) + " --resume " + (d / "ck.bin"));
      INFO(resumed.output);
      CHECK(resumed.status == 0);
    }
}

TEST_CASE("renders whose NEE estimates overflow float resume, learners included", "[checkpoint]") {
  // A 2-micrometre lamp of radiance 3e38 a tenth of a micrometre above a glossy floor (Phong exponent 1000), seen
  // past its edge where the floor mirrors it: NEE estimates in its highlight overflow (dropped from the image). bayes
  // recorded them (a pair's mean inf, its squared deviations NaN), donikian summed their overflowing ratios into its
  // estimates: either render's own checkpoint was then refused as corrupt.
  temp_dir d;
  write_text(d / "t.obj", "mtllib t.mtl\nv 0 0 0\nv 1e-5 0 0\nv 1e-5 1e-5 0\nv 0 1e-5 0\nv 4e-6 4e-6 1e-7\n"
                          "v 4e-6 6e-6 1e-7\nv 6e-6 6e-6 1e-7\nv 6e-6 4e-6 1e-7\nusemtl floor\nf 1 2 3\nf 1 3 4\n"
                          "usemtl lamp\nf 5 6 7\nf 5 7 8\n");
  write_text(d / "t.mtl", "newmtl floor\nKd 0.3 0.3 0.3\nKs 0.5 0.5 0.5\nNs 1000\n"
                          "newmtl lamp\nKd 0 0 0\nKe 3e38 3e38 3e38\n");
  write_text(d / "t.json", "{\"mesh\": \"t.obj\", \"camera\": {\"eye\": [1e-6, 5e-6, 4e-7], \"target\": [4.2e-6, 5e-6, 0], "
                           "\"up\": [0, 0, 1], \"fov_y_deg\": 10}}\n");
  for (const char* sampler : {"bayes", "donikian"})
    for (const char* depth : {"1", "3"}) {
      INFO(sampler << " max depth " << depth);
      std::string args = "render " + (d / "t.json") + " --sampler " + sampler + " --max-depth " + depth +
                         " --width 64 --height 64 --checkpoint " + (d / "ck.bin") + " -o " + (d / "a.pfm");
      auto first = run_bayeslight(args + " --spp 16");
      INFO(first.output);
      REQUIRE(first.status == 0);
      CHECK(first.output.find("non-finite samples discarded") != std::string::npos);  // the scene does overflow
      auto resumed = run_bayeslight(args + " --spp 24 --quiet --resume " + (d / "ck.bin"));
      INFO(resumed.output);
      CHECK(resumed.status == 0);
    }
}

TEST_CASE("a finished render can be resumed further", "[checkpoint]") {
  temp_dir d;
  std::string ck = d / "ck.bin";
  REQUIRE(run_bayeslight(base_args("bayes") + " -o " + (d / "a.pfm") + " --checkpoint " + ck).status == 0);
  std::string more = "render " + source_path("data/living_room/path.json") +
                     " --sampler bayes --width 40 --height 30 --spp 45 --quiet";
  REQUIRE(run_bayeslight(more + " -o " + (d / "resumed.pfm") + " --resume " + ck).status == 0);
  REQUIRE(run_bayeslight(more + " -o " + (d / "full.pfm")).status == 0);
  CHECK(read_file(d / "resumed.pfm") == read_file(d / "full.pfm"));
}

TEST_CASE("a checkpoint resumed for one spp more after a pass of several goes on", "[checkpoint]") {
  // The pass after 10 spp is cut to one spp by the total of 11; the fallback check had no columns for a pass of one
  // after one of several, and the resumed render crashed (exit 139) at its first pixel (a review).
  temp_dir d;
  std::string ck = d / "ck.bin";
  std::string args = cornell_args("bayes", 80, 60);
  render_checkpoint(args, 10, d, ck);
  auto resumed = run_bayeslight(args + " --spp 11 -o " + (d / "resumed.pfm") + " --resume " + ck);
  INFO(resumed.output);
  REQUIRE(resumed.status == 0);
  REQUIRE(run_bayeslight(args + " --spp 11 -o " + (d / "full.pfm")).status == 0);
  CHECK(read_file(d / "resumed.pfm") == read_file(d / "full.pfm"));
}

TEST_CASE("a checkpoint's header says how many passes it holds", "[checkpoint]") {
  // saved_passes: read before the render sets up (a resume whose checkpoint holds no pass of its frame has no image
  // to write for a signal). 10 spp: the passes 1 2 3 4 5 6 7 8 10.
  temp_dir d;
  std::string ck = d / "ck.bin";
  render_checkpoint(cornell_args("bound", 16, 12), 10, d, ck);
  CHECK(saved_passes(ck, 1) == 9);
  CHECK(saved_passes(d / "a.pfm", 1) == -1);        // not a checkpoint
  CHECK(saved_passes(d / "missing.bin", 1) == -1);  // no file
  CHECK(saved_passes(d.path.string(), 1) == -1);    // a folder
  // Another version, or cut short in its header: not read.
  std::string bytes = read_file(ck);
  std::string other = bytes;
  other[16] ^= 1;
  write_text(d / "other.bin", other);
  CHECK(saved_passes(d / "other.bin", 1) == -1);
  write_text(d / "short.bin", bytes.substr(0, checkpoint_frame_offset + 3));
  CHECK(saved_passes(d / "short.bin", 1) == -1);
  write_text(d / "header.bin", bytes.substr(0, checkpoint_frame_offset + 4));
  CHECK(saved_passes(d / "header.bin", 1) == 9);
}

TEST_CASE("resuming with other options or a corrupt checkpoint is refused", "[checkpoint]") {
  temp_dir d;
  std::string ck = d / "ck.bin";
  REQUIRE(run_bayeslight(base_args("bayes") + " -o " + (d / "a.pfm") + " --checkpoint " + ck).status == 0);
  // Each refusal names what differs (it had said only "a different scene or different render options", whatever the
  // slip: a forgotten --width, another seed).
  const std::string size_args =
      "render " + source_path("data/living_room/path.json") + " --sampler bayes --spp 27 --quiet";
  struct other_render {
    std::string args, differs;
  };
  for (const other_render& other :
       {other_render{base_args("bayes") + " --seed 5", "the seed"},
        other_render{base_args("bayes") + " --max-depth 2", "--max-depth"},
        other_render{base_args("bound"), "the sampler"},  // (its options come with it)
        other_render{base_args("bound") + " --seed 5", "the seed, the sampler"},
        other_render{base_args("bayes") + " --bayes-b0 2", "the bayes options (--bayes-*)"},
        other_render{base_args("bayes") + " --light-samples 2",
                     "the light samples (--independent-samples, --light-samples, --light-points)"},
        other_render{base_args("bayes") + " --light-points 1",
                     "the light samples (--independent-samples, --light-samples, --light-points)"},
        other_render{base_args("bayes") + " --grid 32",  // (16 is the automatic grid at 40x30)
                     "the region options (--grid, --max-cut, --cut-*, --region-*, --shared-cut-lights, --fine-depth)"},
        // (the automatic pair budget follows the image size: the region options are not named too)
        other_render{size_args, "the image size (40x30 there)"},
        other_render{"render " + source_path("data/cornell/path.json") +
                         " --sampler bayes --width 40 --height 30 --spp 30 --quiet",
                     "the scene (its mesh, materials, textures, camera, sun or two_sided_emitters)"}}) {
    auto r = run_bayeslight(other.args + " -o " + (d / "x.pfm") + " --resume " + ck);
    INFO(other.args << "\n" << r.output);
    CHECK(r.status == 3);
    CHECK(r.output.find("ck.bin: checkpoint was written for a different scene or different render options; what "
                        "differs: " + other.differs + "\n") != std::string::npos);
    CHECK(!std::filesystem::exists(d / "x.pfm"));
  }
  // A flipped byte, a truncated file, a file that is not a checkpoint.
  std::string bytes = read_file(ck);
  std::string flipped = bytes;
  flipped[flipped.size() / 2] ^= 0x40;
  write_text(d / "flipped.bin", flipped);
  write_text(d / "short.bin", bytes.substr(0, bytes.size() / 3));
  write_text(d / "junk.bin", "hello");
  for (const char* bad : {"flipped.bin", "short.bin", "junk.bin", "missing.bin"}) {
    auto r = run_bayeslight(base_args("bayes") + " -o " + (d / "x.pfm") + " --resume " + (d / bad));
    INFO(bad << "\n" << r.output);
    CHECK(r.status == 3);
    CHECK(r.output.find(bad) != std::string::npos);
  }
}

TEST_CASE("resuming with options of another sampler is accepted and changes nothing", "[checkpoint]") {
  // The fingerprint held every sampler's options: a uniform render resumed with --grid 3 was refused as a different
  // render, though its image cannot depend on it. Options of the sampler in use are still checked (test above).
  struct variant {
    const char* sampler;
    std::string others;  // options the sampler does not read
    std::string own;     // an option it reads
  };
  // Nor options the sampler's other options leave without effect (named as ignored by the same command; a review
  // found such a resume refused right after that warning).
  for (const variant& v : {variant{"uniform", " --grid 3 --bayes-b0 2 --pass-weighting 0 --max-cut 5", ""},
                           variant{"bvh", " --max-cut 5 --bayes-c 0.5", ""},
                           variant{"bound", " --bayes-b0 2 --pass-weighting 0", " --grid 3"},
                           variant{"donikian", " --bayes-b0 2", " --pass-weighting 0"},
                           variant{"donikian --max-depth 1", " --grid 3 --region-budget 100", " --max-cut 5"},
                           variant{"bayes", "", " --pass-weighting 0"},
                           variant{"bayes --bayes-naive", " --bayes-a0 2 --bayes-c 0.5", " --bayes-epsilon 0.1"},
                           variant{"bayes --bayes-prior point", " --bayes-no-cv --bayes-no-orientation", " --bayes-b0 2"},
                           variant{"bayes --bayes-no-cv", " --bayes-cv-min-visible 0.5", " --bayes-c 0.5"},
                           variant{"bayes --bayes-oracle 3", " --pass-weighting 8", " --bayes-c 0.5"},
                           // bayes's early draws: direct illumination only, and none at or below --light-samples (the
                           // checkpoint after 5 passes lies inside the first 16 spp, where they apply)
                           variant{"bayes", " --bayes-early-draws 2 --bayes-early-spp 4", " --pass-weighting 0"},
                           variant{"bayes --max-depth 1", " --bayes-early-draws 4", " --bayes-early-draws 2"},
                           variant{"bayes --max-depth 1 --light-samples 4", " --bayes-early-draws 2",
                                   " --bayes-early-draws 8"}}) {
    temp_dir d;
    std::string ck = d / "ck.bin", full = d / "full.pfm", part = d / "part.pfm";
    INFO(v.sampler);
    REQUIRE(run_bayeslight(base_args(v.sampler) + " -o " + full).status == 0);
    REQUIRE(run_bayeslight(base_args(v.sampler) + " -o " + part + " --checkpoint " + ck + " --stop-after-passes 5")
                .status == 130);
    auto r = run_bayeslight(base_args(v.sampler) + v.others + " -o " + part + " --resume " + ck);
    INFO(r.output);
    REQUIRE(r.status == 0);
    CHECK(read_file(part) == read_file(full));
    if (!v.own.empty()) CHECK(run_bayeslight(base_args(v.sampler) + v.own + " -o " + part + " --resume " + ck).status == 3);
  }
}

namespace {

// Checkpoint surgery for the test below: fields located by walking the layout of checkpoint.cpp, and the file
// re-sealed with its checksum, so that only the checks of the values themselves can refuse it.
struct checkpoint_bytes {
  std::string b;
  size_t pos = 0;
  template <class T>
  T get(size_t at) const {
    T v;
    std::memcpy(&v, b.data() + at, sizeof v);
    return v;
  }
  template <class T>
  void put(size_t at, T v) {
    std::memcpy(&b[at], &v, sizeof v);
  }
  size_t value(size_t size) { return (pos += size) - size; }
  // Skips a column of `size`-byte entries; returns where its data start.
  size_t column(size_t size) {
    uint64_t n = get<uint64_t>(pos);
    pos += 8;
    size_t at = pos;
    pos += n * size;
    return at;
  }
  std::string sealed() const {
    std::string body = b.substr(0, b.size() - 8);
    uint64_t h = checkpoint_checksum(body);
    return body + std::string(reinterpret_cast<const char*>(&h), 8);
  }
};

// A pass record: pass, spp, seconds, has_error, relmse, mse, maxabs.
constexpr size_t pass_record_bytes = 4 + 4 + 8 + 1 + 3 * 8;

// Offsets of the fields the test edits.
struct checkpoint_fields {
  size_t passes, log, film, film_weight, point_stats, cut_nodes, pair_parent, pending, pending_slots, pending_count, moments;
  size_t late_flags;  // late_learns, late_fallback (a byte each)
  size_t regions, regions_end;  // the region state: from its first column to the end of its pending table
  uint64_t parents = 0;  // entries of the pair_parent column
};
checkpoint_fields locate_fields(checkpoint_bytes c, bool bayes) {
  checkpoint_fields f{};
  c.pos = checkpoint_frame_offset;  // (a still's checkpoint has no frame index: its passes follow)
  f.passes = c.value(4);
  c.value(4 + 4 + 8 + 8 * 8);  // spp, stratum base, seconds, counters
  uint64_t log = c.get<uint64_t>(c.value(8));
  f.log = c.value(log * pass_record_bytes);
  f.film = c.column(8);
  f.film_weight = c.value(8);
  f.late_flags = c.pos;
  const bool late_learns = c.get<uint8_t>(c.value(1)) != 0, late_fallback = c.get<uint8_t>(c.value(1)) != 0;
  if (late_learns || late_fallback) {  // bayes's staged or fallback weights: the first passes' film, its weight, the
    c.column(8);                       // later ones'
    c.value(8 + 8);
  }
  f.point_stats = c.column(8);  // (--light-points auto's; empty otherwise)
  f.regions = c.pos;
  for (int k = 0; k < 5; k++) c.column(k == 0 ? 8 : 4);  // key, cut_offset, cut_size, pair_offset, parent
  f.cut_nodes = c.column(4);
  f.parents = c.get<uint64_t>(c.pos);
  f.pair_parent = c.column(4);
  c.value(8 + 1);                               // pairs, members
  for (int k = 0; k < 4; k++) c.column(4);      // member_begin, pair_count, pair_node, pair_slot
  f.pending_slots = c.get<uint64_t>(c.pos);
  f.pending = c.column(16);                     // {key, id} slots
  f.pending_count = c.value(8);
  f.regions_end = c.pos;
  if (bayes) f.moments = c.column(8);           // n0
  return f;
}

}  // namespace

TEST_CASE("resuming with an option's automatic value given explicitly is accepted", "[checkpoint]") {
  // The fingerprint held the options as given: --cut-members 128 in direct illumination (its automatic value), the
  // automatic pair budget written out, or --cut-members with bound (which has no members) were refused as another
  // render, though they render the same bytes. What each option resolves to is checked instead.
  struct variant {
    const char* scene;
    const char* sampler;
    std::string same;   // the automatic values, given explicitly (40 x 30: bayes's budget is 32 x 1200 pairs)
    std::string other;  // a value that changes the render
  };
  for (const variant& v : {variant{"direct", "bayes", " --cut-members 128 --region-budget 38400", " --cut-members 64"},
                           variant{"path", "bayes", " --cut-members 0", " --region-budget 38399"},
                           variant{"direct", "bound", " --cut-members 5 --region-budget 1572864", " --max-cut 32"}}) {
    temp_dir d;
    const std::string args = "render " + source_path(std::string("data/living_room/") + v.scene + ".json") +
                             " --sampler " + v.sampler + " --width 40 --height 30 --spp 27 --quiet";
    std::string ck = d / "ck.bin", full = d / "full.pfm", part = d / "part.pfm";
    INFO(v.scene << " " << v.sampler);
    REQUIRE(run_bayeslight(args + " -o " + full).status == 0);
    REQUIRE(run_bayeslight(args + " -o " + part + " --checkpoint " + ck + " --stop-after-passes 5").status == 130);
    auto r = run_bayeslight(args + v.same + " -o " + part + " --resume " + ck);
    INFO(r.output);
    REQUIRE(r.status == 0);
    CHECK(read_file(part) == read_file(full));
    CHECK(run_bayeslight(args + v.other + " -o " + part + " --resume " + ck).status == 3);
  }
}

TEST_CASE("the checkpoint fingerprint sees every texture option of every material", "[checkpoint]") {
  // -s, -o and -clamp change the image: a checkpoint of one must not resume with another.
  camera_params cam;
  scene_data scene = build_scene(boxed_lamp_mesh(), cam, sun_params{}, false, 1.0f);
  REQUIRE(!scene.mesh.materials.empty());
  render_params p;
  const uint64_t base = render_fingerprint(scene, p).total;
  for (int map = 0; map < 2; map++)
    for (int field = 0; field < 5; field++) {
      scene_data changed = scene;
      texture_transform& t = map == 0 ? changed.mesh.materials[0].kd_map : changed.mesh.materials[0].alpha_map;
      float* v[4] = {&t.scale.x, &t.scale.y, &t.offset.x, &t.offset.y};
      if (field < 4) *v[field] += 0.5f;
      else t.clamp = true;
      INFO("map " << map << ", field " << field);
      CHECK(render_fingerprint(changed, p).total != base);
      CHECK(render_fingerprint(changed, p).parts[fp_scene] != render_fingerprint(scene, p).parts[fp_scene]);
    }
}

TEST_CASE("the checkpoint fingerprint sees the camera, the sun and two_sided_emitters", "[checkpoint]") {
  // Each changes the image: a checkpoint of one must not resume with another, and the refusal names the scene.
  camera_params cam;
  scene_data scene = build_scene(boxed_lamp_mesh(), cam, sun_params{}, false, 1.0f);
  render_params p;
  const render_fingerprint_data base = render_fingerprint(scene, p);
  std::vector<std::pair<const char*, void (*)(scene_data&)>> changes = {
      {"eye", [](scene_data& s) { s.camera.eye.x += 0.5f; }},
      {"target", [](scene_data& s) { s.camera.target.y += 0.5f; }},
      {"up", [](scene_data& s) { s.camera.up = {1, 0, 0}; }},
      {"fov", [](scene_data& s) { s.camera.fov_y_deg += 1; }},
      {"sun", [](scene_data& s) { s.sun.enabled = !s.sun.enabled; }},
      {"sun direction", [](scene_data& s) { s.sun.direction = {1, 0, 0}; }},
      {"sun irradiance", [](scene_data& s) { s.sun.irradiance.z += 1; }},
      {"sun diameter", [](scene_data& s) { s.sun.angular_diameter_deg *= 2; }},
      {"two_sided_emitters", [](scene_data& s) { s.two_sided_emitters = !s.two_sided_emitters; }}};
  for (const auto& [name, change] : changes) {
    scene_data changed = scene;
    change(changed);
    INFO(name);
    const render_fingerprint_data f = render_fingerprint(changed, p);
    CHECK(f.total != base.total);
    CHECK(f.parts[fp_scene] != base.parts[fp_scene]);
    for (int part = 0; part < fp_part_count; part++)
      if (part != fp_scene) CHECK(f.parts[part] == base.parts[part]);
  }
}

TEST_CASE("an edited checkpoint with a valid checksum is refused, never followed", "[checkpoint]") {
  // Indices out of range crashed the resumed render, a full pending table or a pair whose parent has a parent made it
  // loop for ever, non-finite film values gave NaN pixels (and values beyond float's range infinite ones): each is an
  // input error naming the file now.
  temp_dir d;
  auto args = [&](const char* sampler) {
    return "render " + source_path("data/cornell/direct.json") + " --sampler " + std::string(sampler) +
           " --width 32 --height 24 --threads 1 --quiet --shared-cut-lights 0";  // regions of clustered cuts: bound
                                                                                 // keeps none under a shared cut
  };
  for (const char* sampler : {"bound", "bayes"}) {
    bool bayes = std::string(sampler) == "bayes";
    std::string ck = d / "ck.bin";
    REQUIRE(run_bayeslight(args(sampler) + " --spp 8 --checkpoint " + ck + " -o " + (d / "a.exr")).status == 0);
    checkpoint_bytes base{read_file(ck)};
    checkpoint_fields f = locate_fields(base, bayes);
    REQUIRE(f.pending_slots >= 2);
    std::vector<std::pair<std::string, checkpoint_bytes>> cases;
    auto edit = [&](const std::string& name, auto change) {
      checkpoint_bytes c = base;
      change(c);
      cases.push_back({name, c});
    };
    edit("cluster node out of range", [&](checkpoint_bytes& c) { c.put<int>(f.cut_nodes, 1000000); });
    if (f.parents > 0) edit("pair parent below -1", [&](checkpoint_bytes& c) { c.put<int>(f.pair_parent, -2); });
    edit("pending table full", [&](checkpoint_bytes& c) {
      for (uint64_t k = 0; k < f.pending_slots; k++) c.put<uint64_t>(f.pending + 16 * k, k);
    });
    edit("film NaN", [&](checkpoint_bytes& c) { c.put<double>(f.film, std::nan("")); });
    // Finite in double, but a mean beyond float's range: the resumed render wrote an infinite pixel with exit 0.
    edit("film beyond float", [&](checkpoint_bytes& c) { c.put<double>(f.film, 1e300); });
    edit("film weight infinite", [&](checkpoint_bytes& c) { c.put<double>(f.film_weight, HUGE_VAL); });
    edit("passes", [&](checkpoint_bytes& c) { c.put<int>(f.passes, 2147483647); });
    // Weights kept apart for a fallback that never happened (the film as the earlier passes' film, its weight as
    // theirs, none after): an image of other shares than the render's.
    if (bayes)
      edit("fallback weights without a fallback", [&](checkpoint_bytes& c) {
        REQUIRE(c.get<uint8_t>(f.late_flags) == 0);
        REQUIRE(c.get<uint8_t>(f.late_flags + 1) == 0);
        c.put<uint8_t>(f.late_flags + 1, 1);
        const std::string film = base.b.substr(f.film - 8, f.film_weight - f.film + 8),  // (with its count)
            weight = base.b.substr(f.film_weight, 8);
        c.b = c.b.substr(0, f.late_flags + 2) + film + weight + std::string(8, '\0') + c.b.substr(f.late_flags + 2);
      });
    // A pass that adds no samples (the second pass's total as the first's): bound's passes weigh alike, so the film's
    // weight, the last pass's total, still matches.
    if (!bayes)
      edit("pass adding no samples", [&](checkpoint_bytes& c) {
        c.put<int>(f.log + pass_record_bytes + 4, c.get<int>(f.log + 4));
      });
    // More than half the pending table's slots in use, its count to match (a full one sent lookups round for ever).
    edit("pending table over half full", [&](checkpoint_bytes& c) {
      uint64_t used = c.get<uint64_t>(f.pending_count);
      for (uint64_t k = 0; k < f.pending_slots && 2 * used <= f.pending_slots; k++)
        if (c.get<uint64_t>(f.pending + 16 * k) == empty_region_key) {
          c.put<uint64_t>(f.pending + 16 * k, (uint64_t(1) << 61) + k);  // (a cell no render point reaches)
          used++;
        }
      REQUIRE(2 * used > f.pending_slots);
      c.put<uint64_t>(f.pending_count, used);
    });
    if (bayes) edit("statistics NaN", [&](checkpoint_bytes& c) { c.put<double>(f.moments, std::nan("")); });
    // No region at all (every column empty, the counts 0): the render looked up the root region, which every render
    // has, and crashed.
    if (!bayes)
      edit("no regions", [&](checkpoint_bytes& c) {
        std::string empty(7 * 8 + 8 + 1 + 5 * 8 + 8, '\0');  // 7 columns, pairs, members, 5 columns, pending count
        c.b = base.b.substr(0, f.regions) + empty + base.b.substr(f.regions_end);
      });
    // The fallback check's pixel count (the value before its last column) far beyond the image's, that column
    // empty: the count was allocated before it was compared with the image, and 2^40 ran out of memory (exit 1).
    if (bayes)
      edit("fallback check beyond the image", [&](checkpoint_bytes& c) {
        const size_t end = c.b.size() - 8, pixels = 32 * 24;  // before the checksum
        size_t at = end - 8 - 8;                               // an empty last column
        if (c.get<uint64_t>(end - 8 - 4 * pixels) == pixels) at = end - 8 - 4 * pixels - 8;
        REQUIRE(c.get<uint64_t>(at) == (at == end - 16 ? 0 : pixels));
        c.b = c.b.substr(0, at) + std::string(16, '\0') + c.b.substr(end);
        c.put<uint64_t>(at, uint64_t(1) << 40);
      });
    // The unedited file, re-sealed the same way, resumes: the edits alone are refused.
    write_text(d / "same.bin", base.sealed());
    auto ok = run_bayeslight(args(sampler) + " --spp 16 --resume " + (d / "same.bin") + " -o " + (d / "ok.exr"));
    INFO(ok.output);
    REQUIRE(ok.status == 0);
    for (const auto& [name, c] : cases) {
      write_text(d / "edited.bin", c.sealed());
      auto r = run_bayeslight(args(sampler) + " --spp 16 --resume " + (d / "edited.bin") + " -o " + (d / "x.exr"));
      INFO(sampler << ": " << name << "\n" << r.output);
      CHECK(r.status == 3);
      CHECK(r.output.find("edited.bin: corrupt checkpoint") != std::string::npos);
      CHECK(!std::filesystem::exists(d / "x.exr"));
    }
  }
}

TEST_CASE("resuming to fewer spp than a checkpoint holds says where the smaller count came from", "[checkpoint]") {
  // Without --spp the count is the scene's render.spp; the message said "--spp 64", an option never given (a review).
  temp_dir d;
  std::string ck = d / "ck.bin";
  std::string args = cornell_args("power", 16, 12);
  render_checkpoint(args, 100, d, ck);
  auto given = run_bayeslight(args + " --spp 50 -o " + (d / "b.pfm") + " --resume " + ck);
  INFO(given.output);
  CHECK(given.status == 2);
  CHECK(given.output.find("--spp 50 is below the 100 spp already in " + ck) != std::string::npos);
  auto scene = run_bayeslight(args + " -o " + (d / "b.pfm") + " --resume " + ck);
  INFO(scene.output);
  CHECK(scene.status == 2);
  CHECK(scene.output.find("the scene's render.spp (64) is below the 100 spp already in " + ck +
                          ": give --spp 100 or more, or --time") != std::string::npos);
  CHECK(!std::filesystem::exists(d / "b.pfm"));
}
