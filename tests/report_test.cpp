// Tests of a render's one-line summary (report.h): its counts and rates worked out by hand from a render_result (the
// pass count's plural, the share of NEE samples that contribute nothing, the clusters or members per region).
#include "report.h"

#include <catch2/catch.hpp>

#include <string>

using namespace bl;

namespace {

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

TEST_CASE("the render summary gives passes, rates, idle NEE samples and pairs per region as counted", "[report]") {
  render_result r;
  r.spp = 4;
  r.seconds = 2;
  r.passes = 1;
  r.stats.camera_rays = 1000000, r.stats.shadow_rays = 1500000, r.stats.bounce_rays = 500000;
  r.stats.nee_samples = 200000, r.stats.nee_zero = 50000;
  std::string s = render_summary(r, {"a.exr"});
  INFO(s);
  CHECK(has(s, "rendered 4 spp in 2.00 s (1 pass, 1.50 Mrays/s, 0.10 M NEE samples/s)"));
  CHECK(has(s, "; 25.0% of NEE samples contribute nothing"));  // 50000 of 200000
  CHECK(has(s, " -> a.exr"));
  // Several passes; regions: the pairs' mean per region, or a single region's count.
  r.passes = 3;
  r.regions = 4;
  r.pairs = 100;
  s = render_summary(r, {"a.exr"});
  INFO(s);
  CHECK(has(s, " (3 passes, "));
  CHECK(has(s, "; 4 regions, 25.0 clusters or members per region, "));
  r.regions = 1;
  s = render_summary(r, {"a.exr"});
  INFO(s);
  CHECK(has(s, "; 1 region, 100 clusters or members, "));
}
