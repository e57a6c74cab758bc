// Determinism as SPEC.md section 5 promises it, through the binary as users run it: for every sampler the same
// render with 1 and 2 threads gives byte-identical files, re-runs are identical, and a --time run equals the
// --spp run with the same number of samples (adaptive samplers included).
#include "file_io.h"
#include "image_io.h"
#include "test_util.h"

#include <catch2/catch.hpp>

#include <string>
#include <utility>
#include <vector>

using namespace bl;
using namespace bl::test;

namespace {

const char* samplers[] = {"uniform", "power", "bvh", "bound", "donikian", "bayes"};

// A small render of a data/ scene: by default one with occlusion, a sun and textures (the living room, path traced).
std::string render_args(const std::string& sampler, const std::string& extra,
                        const std::string& scene = "data/living_room/path.json") {
  return "render " + source_path(scene) + " --width 40 --height 30 --sampler " + sampler + " --quiet " + extra;
}

}  // namespace

TEST_CASE("one and two threads give byte identical files for every sampler", "[determinism]") {
  temp_dir d;
  // Every sampler, and bayes in direct illumination too (where its clusters are refined into members), also in the
  // plant room (a glossy statue: its points weigh members one by one with the Phong lobe).
  struct run {
    std::string label, sampler, scene;
  };
  std::vector<run> runs;
  for (const char* s : samplers) runs.push_back({s, s, "data/living_room/path.json"});
  runs.push_back({"bayes_direct", "bayes --max-depth 1", "data/living_room/path.json"});
  runs.push_back({"bayes_glossy", "bayes", "data/plant_room/direct.json"});
  // Several light samples per vertex: each draw records its own observation, in the same order for any thread count.
  runs.push_back({"bayes_light_samples", "bayes --light-samples 3", "data/living_room/path.json"});
  runs.push_back({"donikian_light_samples", "donikian --light-samples 3", "data/living_room/path.json"});
  for (const auto& [label, s, scene] : runs) {
    std::string a = d / (label + "_1.exr"), b = d / (label + "_2.exr");
    std::string pa = d / (label + "_1.pfm"), pb = d / (label + "_2.pfm");
    auto r1 = run_bayeslight(render_args(s, "--spp 6 --threads 1 -o " + a + " -o " + pa, scene));
    auto r2 = run_bayeslight(render_args(s, "--spp 6 --threads 2 -o " + b + " -o " + pb, scene));
    INFO(s << "\n" << r1.output << r2.output);
    REQUIRE(r1.status == 0);
    REQUIRE(r2.status == 0);
    CHECK(read_file(a) == read_file(b));
    CHECK(read_file(pa) == read_file(pb));
    // A re-run with the same options is identical too.
    auto r3 = run_bayeslight(render_args(s, "--spp 6 --threads 2 -o " + a, scene));
    REQUIRE(r3.status == 0);
    CHECK(read_file(a) == read_file(b));
  }
}

TEST_CASE("light points chosen per tile give byte identical files on one and two threads", "[determinism]") {
  // --light-points auto (the default): each tile's statistics are summed in pixel and row order, and read between
  // passes only. 24 spp: past the exploration (8 spp), so tiles choose counts other than 2 (the summary's mean says
  // they did); 100 spp: past the first pass that holds whole blocks of 8 samples (63 to 78), so blocks measure too.
  temp_dir d;
  for (auto [scene, spp] : {std::pair{"data/plant_room/direct.json", 24}, std::pair{"data/living_room/path.json", 24},
                            std::pair{"data/cornell/direct.json", 100}})
    for (const char* s : {"bayes", "bound"}) {
      std::string a = d / "a.pfm", b = d / "b.pfm";
      const std::string args = std::string(s) + " --light-points auto --spp " + std::to_string(spp);
      auto r1 = run_bayeslight(render_args(args, "--threads 1 -o " + a, scene));
      // (Without --quiet: the summary.)
      auto r2 = run_bayeslight("render " + source_path(scene) + " --width 40 --height 30 --sampler " + args +
                               " --threads 2 -o " + b);
      INFO(scene << " " << s << "\n" << r1.output << r2.output);
      REQUIRE(r1.status == 0);
      REQUIRE(r2.status == 0);
      CHECK(read_file(a) == read_file(b));
      CHECK(r2.output.find(" light points per first-vertex NEE sample") != std::string::npos);
      CHECK(r2.output.find("; 2.00 light points per first-vertex NEE sample") == std::string::npos);
    }
}

TEST_CASE("a time budget run equals the spp run of the same sample count", "[determinism]") {
  temp_dir d;
  for (const char* s : {"power", "bound", "donikian", "bayes", "bayes --light-points 3"}) {
    std::string t = d / "t.pfm", n = d / "n.pfm", log = d / "t.csv";
    auto rt = run_bayeslight(render_args(s, "--time 0.3 --threads 2 -o " + t + " --log " + log));
    INFO(s << "\n" << rt.output);
    REQUIRE(rt.status == 0);
    std::ifstream f(log);
    std::string line, last;
    while (std::getline(f, line)) last = line;
    // sampler,pass,spp,seconds,relmse,mse
    size_t c1 = last.find(','), c2 = last.find(',', c1 + 1), c3 = last.find(',', c2 + 1);
    int spp = std::stoi(last.substr(c2 + 1, c3 - c2 - 1));
    REQUIRE(spp > 0);
    auto rn = run_bayeslight(render_args(s, "--spp " + std::to_string(spp) + " --threads 1 -o " + n));
    REQUIRE(rn.status == 0);
    INFO("spp " << spp);
    CHECK(read_file(t) == read_file(n));
  }
}

TEST_CASE("a different seed changes the image", "[determinism]") {
  temp_dir d;
  std::string a = d / "a.pfm", b = d / "b.pfm";
  REQUIRE(run_bayeslight(render_args("bayes", "--spp 2 --seed 1 -o " + a)).status == 0);
  REQUIRE(run_bayeslight(render_args("bayes", "--spp 2 --seed 2 -o " + b)).status == 0);
  CHECK(read_file(a) != read_file(b));
}
