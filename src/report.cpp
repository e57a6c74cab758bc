// report: CSV and summary formatting (numbers with enough digits to round-trip).
#include "report.h"

#include "obj_io.h"

#include <sys/resource.h>

#include <cmath>
#include <cstdio>

namespace bl {

size_t peak_memory_bytes() {
  rusage u{};
  if (getrusage(RUSAGE_SELF, &u) != 0) return 0;
  return size_t(u.ru_maxrss) * 1024;  // Linux reports kilobytes
}

std::string pass_log_csv(const std::string& sampler, const std::vector<pass_record>& log) {
  std::string s = "sampler,pass,spp,seconds,relmse,mse\n";
  char buf[256];
  for (const pass_record& p : log) {
    if (p.has_error)
      std::snprintf(buf, sizeof buf, "%s,%d,%d,%.6f,%.9g,%.9g\n", sampler.c_str(), p.pass, p.spp, p.seconds,
                    p.error.relmse, p.error.mse);
    else
      std::snprintf(buf, sizeof buf, "%s,%d,%d,%.6f,,\n", sampler.c_str(), p.pass, p.spp, p.seconds);
    s += buf;
  }
  return s;
}

std::string render_summary(const render_result& r, const std::vector<std::string>& outputs) {
  const path_stats& st = r.stats;
  double rays = double(st.camera_rays + st.shadow_rays + st.bounce_rays);
  char buf[512];
  // (The time is the completed passes': "after 0 spp in 0.00 s" read as if the render had not started.)
  if (r.interrupted && r.spp == 0)
    std::snprintf(buf, sizeof buf, "interrupted during the first pass");
  else
    std::snprintf(buf, sizeof buf, "%s %d spp in %.2f s (%d pass%s, %.2f Mrays/s, %.2f M NEE samples/s)",
                  r.interrupted ? "interrupted after" : "rendered", r.spp, r.seconds, r.passes,
                  r.passes == 1 ? "" : "es", r.seconds > 0 ? rays / r.seconds * 1e-6 : 0.0,
                  r.seconds > 0 ? double(st.nee_samples) / r.seconds * 1e-6 : 0.0);
  std::string s = buf;
  if (!r.log.empty() && r.log.back().has_error) {  // --reference: the error of the image written
    std::snprintf(buf, sizeof buf, "; relMSE %.4e against the reference", r.log.back().error.relmse);
    s += buf;
  }
  if (st.nee_samples > 0) {
    std::snprintf(buf, sizeof buf, "; %.1f%% of NEE samples contribute nothing", 100.0 * double(st.nee_zero) / double(st.nee_samples));
    s += buf;
  }
  if (st.first_points > st.first_draws) {  // (--light-points above 1, or auto)
    std::snprintf(buf, sizeof buf, "; %.2f light points per first-vertex NEE sample",
                  double(st.first_points) / double(st.first_draws));
    s += buf;
  }
  if (r.regions > 0) {
    // One region: a cut shared by all (a handful of lights), which the bound sampler reads from the root alone.
    if (r.regions == 1)
      std::snprintf(buf, sizeof buf, "; 1 region, %.0f %s, %.1f MB sampler state", double(r.pairs),
                    r.pairs == 1 ? "cluster" : "clusters or members", double(r.sampler_bytes) / (1 << 20));
    else
      std::snprintf(buf, sizeof buf, "; %d regions, %.1f clusters or members per region, %.1f MB sampler state",
                    r.regions, double(r.pairs) / r.regions, double(r.sampler_bytes) / (1 << 20));
    s += buf;
  }
  if (r.one_light) {
    s += "; one light: nothing to learn, sampled as by power";
  } else if (r.fallback_spp > 0 && r.fallback_earlier) {
    std::snprintf(buf, sizeof buf, "; %s sampling since an earlier frame (after %d spp of it)",
                  r.fallback_bvh ? "bvh" : "power", r.fallback_spp);
    s += buf;
  } else if (r.fallback_spp > 0) {
    std::snprintf(buf, sizeof buf, "; %s sampling after %d spp (learning was estimated to cut relMSE per sample only %.2fx)",
                  r.fallback_bvh ? "bvh" : "power", r.fallback_spp,
                  r.fallback_bvh ? r.fallback_ratio_bvh : r.fallback_ratio);
    s += buf;
  } else if (r.fallback_ratio > 0) {
    // (Against independent samples: power's own are stratified over the render, which can gain it far more where
    // every light is seen alike, a lamp in 450 triangles 60x; README, Fallback.)
    std::snprintf(buf, sizeof buf,
                  "; learning estimated to cut relMSE per sample %.3gx against power sampling", r.fallback_ratio);
    s += buf;
    if (r.fallback_ratio_bvh > 0 && std::isfinite(r.fallback_ratio_bvh)) {
      std::snprintf(buf, sizeof buf, " and %.3gx against bvh", r.fallback_ratio_bvh);
      s += buf;
    }
    s += ", with independent samples";
  }
  if (r.setup_seconds >= 0.01) {
    std::snprintf(buf, sizeof buf, "; set-up %.2f s (light tree, regions)", r.setup_seconds);
    s += buf;
  }
  std::snprintf(buf, sizeof buf, "; peak memory %.0f MB", double(peak_memory_bytes()) / (1 << 20));
  s += buf;
  if (st.bad_samples > 0) s += "; " + std::to_string(st.bad_samples) + " non-finite samples discarded";
  if (r.spp > 0 && !outputs.empty()) {  // (none when every image output failed: their errors follow)
    s += " -> ";
    for (size_t i = 0; i < outputs.size(); i++) s += (i ? ", " : "") + outputs[i];
  } else if (r.spp == 0) {
    s += "; no pass completed, no image written";
  }
  return s;
}

void report_dropped_triangles(const std::string& mesh_path, int dropped, int first_line) {
  if (dropped > 0)
    std::fprintf(stderr, "%s: dropped %d degenerate triangle%s, the first of the face at line %d (%s)\n",
                 mesh_path.c_str(), dropped, dropped == 1 ? "" : "s", first_line, degenerate_reason);
}

}  // namespace bl
