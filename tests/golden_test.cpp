// Golden images: small renders of every data/ scene with every sampler must reproduce golden/ bit for bit
// (SPEC.md section 5). A deliberate change of output regenerates them with `make golden`.
#include "image_io.h"
#include "metrics.h"
#include "test_util.h"

#include <catch2/catch.hpp>

using namespace bl;
using namespace bl::test;

TEST_CASE("every golden render reproduces its image bit for bit", "[golden]") {
  std::ifstream manifest(source_path("golden/manifest.txt"));
  REQUIRE(manifest);
  temp_dir d;
  std::string line;
  int checked = 0;
  while (std::getline(manifest, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::string file = line.substr(0, line.find(' '));
    std::string args = line.substr(line.find(' ') + 1);
    // Scene paths in the manifest are relative to the source tree.
    std::string out = d / file;
    auto r = run_bayeslight("render " + source_path("") + args + " -o " + out);
    INFO(line << "\n" << r.output);
    REQUIRE(r.status == 0);
    image_data got = read_image(out), want = read_image(source_path("golden/" + file));
    bool same = bit_identical(got, want);
    if (!same && got.width == want.width && got.height == want.height) {
      error_metrics e = compute_error(got, want);
      INFO("relmse " << e.relmse << " maxabs " << e.maxabs);
      CHECK(same);
    } else {
      CHECK(same);
    }
    checked++;
  }
  CHECK(checked >= 48);
}
