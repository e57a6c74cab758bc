// Resumable renders: a render interrupted by SIGINT (checkpoint written on the way out) or killed by SIGKILL
// (after a checkpoint) and resumed to the same spp is byte-identical to an uninterrupted one, for the learning
// samplers too; a resume with another scene or other options, or from a corrupt file, is refused (exit 3).
#include "file_io.h"
#include "test_util.h"

#include <catch2/catch.hpp>

using namespace bl;
using namespace bl::test;

namespace {

std::string base_args(const std::string& sampler) {
  return "render " + source_path("data/living_room/path.json") + " --sampler " + sampler +
         " --width 40 --height 30 --spp 27 --quiet";  // 27: the end of a scheduled pass (see pass_size)
}

}  // namespace

TEST_CASE("interrupted and killed renders resume to the same bytes", "[checkpoint]") {
  temp_dir d;
  // bayes in direct illumination too: there its clusters are refined into members (region_params::max_members).
  for (const char* s : {"bound", "donikian", "bayes", "bayes --max-depth 1"}) {
    INFO(s);
    std::string full = d / "full.pfm";
    REQUIRE(run_bayeslight(base_args(s) + " -o " + full).status == 0);
    // SIGINT after 9 passes: the checkpoint of the completed passes is written on the way out.
    std::string ck = d / "ck.bin", part = d / "part.pfm", out = d / "resumed.pfm";
    auto r1 = run_bayeslight(base_args(s) + " -o " + part + " --checkpoint " + ck + " --stop-after-passes 9");
    CHECK(r1.status == 130);
    REQUIRE(std::filesystem::exists(ck));
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

TEST_CASE("a render resumed after bayes fell back continues its stratified set", "[checkpoint]") {
  // The path-traced Cornell box at 40x30 falls back to power sampling at the end of pass 27 (485 spp; see
  // golden/manifest.txt): from pass 28 on the model stays, and its samples form one stratified set starting at
  // 485, which a resume after pass 29 must restore (a set restarted at the resume gives other bytes).
  temp_dir d;
  std::string args = "render " + source_path("data/cornell/path.json") +
                     " --sampler bayes --width 40 --height 30 --spp 677 --quiet";
  auto full = run_bayeslight(args + " -o " + (d / "full.pfm") + " --log " + (d / "log.csv"));
  REQUIRE(full.status == 0);
  std::string ck = d / "ck.bin";
  CHECK(run_bayeslight(args + " -o " + (d / "part.pfm") + " --checkpoint " + ck + " --stop-after-passes 29").status == 130);
  auto resumed = run_bayeslight(args + " -o " + (d / "resumed.pfm") + " --resume " + ck);
  INFO(resumed.output);
  REQUIRE(resumed.status == 0);
  CHECK(read_file(d / "resumed.pfm") == read_file(d / "full.pfm"));
  // The fallback did happen before the interruption (else the test would not test the set's start).
  auto check = run_bayeslight("render " + source_path("data/cornell/path.json") +
                              " --sampler bayes --width 40 --height 30 --spp 549 -o " + (d / "c.pfm"));
  INFO(check.output);
  CHECK(check.output.find("power sampling after 485 spp") != std::string::npos);
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

TEST_CASE("resuming with other options or a corrupt checkpoint is refused", "[checkpoint]") {
  temp_dir d;
  std::string ck = d / "ck.bin";
  REQUIRE(run_bayeslight(base_args("bayes") + " -o " + (d / "a.pfm") + " --checkpoint " + ck).status == 0);
  for (const std::string& other : {base_args("bayes") + " --seed 5", base_args("bayes") + " --max-depth 2",
                                   base_args("bound"), base_args("bayes") + " --bayes-b0 2",
                                   "render " + source_path("data/cornell/path.json") +
                                       " --sampler bayes --width 40 --height 30 --spp 30 --quiet"}) {
    auto r = run_bayeslight(other + " -o " + (d / "x.pfm") + " --resume " + ck);
    INFO(other << "\n" << r.output);
    CHECK(r.status == 3);
    CHECK(r.output.find("ck.bin") != std::string::npos);
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
