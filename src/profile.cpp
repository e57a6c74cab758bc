// profile: the two renders, the time-stamp counter calibration, the raw occlusion benchmark and the table.
#include "profile.h"

#include "camera.h"
#include "rng.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <thread>

namespace bl {

namespace {

using clock_type = std::chrono::steady_clock;

// Time-stamp counter ticks per second (measured against the steady clock over ~50 ms).
double tsc_hz() {
  auto t0 = clock_type::now();
  uint64_t c0 = __rdtsc();
  while (std::chrono::duration<double>(clock_type::now() - t0).count() < 0.05) {
  }
  double dt = std::chrono::duration<double>(clock_type::now() - t0).count();
  return double(__rdtsc() - c0) / dt;
}

// Shadow rays distributed like the renderer's: from camera first hits to points sampled on uniformly chosen
// lights (each moved off its surface as integrator.h's unoccluded() does).
struct ray_set {
  std::vector<vec3f> org, dir;
  std::vector<float> tmax;
};

ray_set make_shadow_rays(const scene_data& scene, const bvh_data& bvh, const light_data& lights, int width,
                         int height, size_t count) {
  ray_set rays;
  if (lights.count == 0) return rays;
  camera_data cam = make_camera(scene.camera, width, height);
  for (uint64_t s = 0; rays.org.size() < count && s < 64; s++)
    for (int y = 0; y < height && rays.org.size() < count; y++)
      for (int x = 0; x < width && rays.org.size() < count; x++) {
        uint64_t key = sample_key(0x70726f66ull, uint64_t(y) * uint64_t(width) + uint64_t(x), s);
        vertex_randoms c = draw_vertex(key, 0), v = draw_vertex(key, 1);
        vec3f d = camera_ray_dir(cam, float(x) + c.u[0], float(y) + c.u[1]);
        hit_info h = intersect(bvh, cam.eye, d);
        if (h.tri == invalid_id) continue;
        surface_point sp = eval_surface(scene, h.tri, h.b1, h.b2, h.p, d);
        int light = std::min(int(v.u[0] * float(lights.count)), lights.count - 1);
        light_sample ls = sample_light_point(lights, scene, light, sp.p, v.u[2], v.u[3]);
        if (!(ls.pdf > 0)) continue;
        shadow_ray r = shadow_ray_of(scene, sp, ls);
        if (!(r.tmax > 0)) continue;
        rays.org.push_back(r.org), rays.dir.push_back(r.dir), rays.tmax.push_back(r.tmax);
      }
  return rays;
}

// Rays per second of rtcOccluded1 over the set on `threads` threads (best of three rounds).
double occlusion_rate(const bvh_data& bvh, const ray_set& rays, int threads) {
  if (rays.org.empty()) return 0;
  tbb::task_arena arena(threads);
  double best = 0;
  for (int round = 0; round < 3; round++) {
    auto t0 = clock_type::now();
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.org.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
        int blocked = 0;
        for (size_t i = r.begin(); i < r.end(); i++) blocked += occluded(bvh, rays.org[i], rays.dir[i], rays.tmax[i]);
        volatile int sink = blocked;
        (void)sink;
      });
    });
    double dt = std::chrono::duration<double>(clock_type::now() - t0).count();
    best = std::max(best, double(rays.org.size()) / dt);
  }
  return best;
}

const char* stage_name(int c) {
  switch (c) {
    case prof_camera: return "camera rays (generation + closest hit)";
    case prof_bounce: return "closest hit of bounce rays";
    case prof_shading: return "shading set-up (surface, BSDF, emission)";
    case prof_region: return "region lookup";
    case prof_pmf: return "PMF build at the point";
    case prof_select: return "cluster / light choice";
    case prof_point: return "point on the light + BSDF eval";
    case prof_shadow: return "shadow rays";
    case prof_record: return "observation recording";
    case prof_continue: return "BSDF sampling + roulette";
  }
  return "?";
}

}  // namespace

std::string profile_render(const scene_data& scene, const bvh_data& bvh, const light_data& lights,
                           const render_params& params, const std::string& title) {
  int threads = params.threads > 0 ? params.threads : int(std::max(1u, std::thread::hardware_concurrency()));
  render_params plain = params;
  plain.profile = false;
  plain.progress = false;
  render_result a = render(scene, bvh, lights, plain);
  auto cut_short = [&](const char* which, const render_result& r) {
    return "profile of " + title + ": interrupted during the " + which + " render (at " + std::to_string(r.spp) +
           " spp); no report\n";
  };
  if (a.interrupted) return cut_short("plain", a);
  // The timed render takes the plain one's samples (with --time the plain render's budget fixed their number), so
  // both do the same work: the stage times are per NEE sample of that work, and the timers' cost is a fair ratio.
  render_params timed = plain;
  timed.profile = true;
  timed.time_budget = 0;
  timed.spp = std::max(a.spp, 1);
  render_result b = render(scene, bvh, lights, timed);
  if (b.interrupted) return cut_short("timed", b);
  double hz = tsc_hz();
  const path_stats& st = a.stats;
  double nee = double(std::max<uint64_t>(st.nee_samples, 1));
  // Without a single NEE sample (no emitters, or none that any shaded point can sample) the stages are per camera
  // ray instead: per NEE sample they would be divided by a count of 0.
  const bool per_ray = b.stats.nee_samples == 0;
  double nee_b = double(std::max<uint64_t>(per_ray ? b.stats.camera_rays : b.stats.nee_samples, 1));
  const char* unit = per_ray ? "camera ray" : "NEE sample";
  ray_set rays = make_shadow_rays(scene, bvh, lights, params.width, params.height,
                                  std::min<size_t>(std::max<uint64_t>(st.shadow_rays, 1), size_t(4) << 20));
  double limit = occlusion_rate(bvh, rays, threads);

  std::string out;
  char buf[512];
  auto line = [&](const char* fmt, auto... args) {
    std::snprintf(buf, sizeof buf, fmt, args...);
    out += buf;
  };
  line("profile of %s\n", title.c_str());
  line("  %dx%d, %d spp, max depth %d, %d thread%s", params.width, params.height, a.spp, params.max_depth, threads,
       threads == 1 ? "" : "s");
  if (params.light_samples > 1) line(", %d light samples per vertex", params.light_samples);
  if (params.light_points > 0)
    line(", %d light point%s per first-vertex NEE draw", params.light_points, params.light_points == 1 ? "" : "s");
  line("\n");
  double rays_total = double(st.camera_rays + st.shadow_rays + st.bounce_rays);
  line("  plain render: %.3f s in %d passes; %.3f M NEE samples (%.2f M/s); %.2f M rays/s (camera %.2f M, shadow "
       "%.2f M, bounce %.2f M)\n",
       a.seconds, a.passes, nee * 1e-6, nee / a.seconds * 1e-6, rays_total / a.seconds * 1e-6,
       double(st.camera_rays) * 1e-6, double(st.shadow_rays) * 1e-6, double(st.bounce_rays) * 1e-6);
  line("  timed render: the same %d spp, %.3f s; stages below per %s of it%s\n", b.spp, b.seconds, unit,
       per_ray ? " (the render took no NEE sample)" : "");
  // bayes's passes after a fallback choose lights by power or bvh (no region, no learning): the stages mix both.
  if (b.fallback_spp > 0) {
    const char* to = b.fallback_bvh ? "bvh" : "power";
    line("  bayes fell back to %s sampling after %d spp (learning was estimated to cut relMSE per sample only "
         "%.2fx): the stages below mix %d spp of bayes with %d of %s sampling\n",
         to, b.fallback_spp, b.fallback_bvh ? b.fallback_ratio_bvh : b.fallback_ratio, b.fallback_spp,
         b.spp - b.fallback_spp, to);
  }
  // Stage times are per-thread cycles; in wall time per NEE sample they are divided by the thread count.
  double pass_wall = b.seconds - b.learn_seconds;
  double staged = 0;
  for (int c = 0; c < prof_count; c++) staged += double(b.profile_cycles[c]) / hz / threads;
  line("\n  %-44s %10s %8s\n", "stage (timed render)", per_ray ? "ns/ray" : "ns/NEE", "share");
  for (int c = 0; c < prof_count; c++) {
    double wall = double(b.profile_cycles[c]) / hz / threads;
    line("  %-44s %10.1f %7.1f%%\n", stage_name(c), wall / nee_b * 1e9, 100 * wall / b.seconds);
  }
  double rest = std::max(0.0, pass_wall - staged);
  line("  %-44s %10.1f %7.1f%%\n", "film, scheduling and timer overhead", rest / nee_b * 1e9, 100 * rest / b.seconds);
  line("  %-44s %10.1f %7.1f%%\n", "between passes: reduction + PMF rebuild", b.learn_seconds / nee_b * 1e9,
       100 * b.learn_seconds / b.seconds);
  const learn_timing& lp = b.learn_parts;
  if (lp.reduce + lp.regions + lp.refold > 0) {
    line("  %-44s %10.1f %7.1f%%\n", "  of which: fold of observation records", lp.reduce / nee_b * 1e9,
         100 * lp.reduce / b.seconds);
    line("  %-44s %10.1f %7.1f%%\n", "  of which: new regions (cuts, prior means)", lp.regions / nee_b * 1e9,
         100 * lp.regions / b.seconds);
    line("  %-44s %10.1f %7.1f%%\n", "  of which: refold of changed weights", lp.refold / nee_b * 1e9,
         100 * lp.refold / b.seconds);
    if (lp.records + lp.refolds > 0)
      line("  %-44s %10.2f records, %.2f refolds per %s (%.1f, %.1f ns each)\n", "  learning work:",
           lp.records / nee_b, lp.refolds / nee_b, unit, lp.reduce / std::max(lp.records, 1.0) * 1e9,
           lp.refold / std::max(lp.refolds, 1.0) * 1e9);
  }
  line("  %-44s %10.1f %7.1f%%\n", "total", b.seconds / nee_b * 1e9, 100.0);
  line("\n  raw Embree rtcOccluded1 on this scene: %.2f M rays/s (%zu rays, %d thread%s)\n", limit * 1e-6,
       rays.org.size(), threads, threads == 1 ? "" : "s");
  if (limit > 0) {
    line("  render NEE samples/s as a fraction of the raw shadow-ray limit: %.3f\n", nee / a.seconds / limit);
    // Why the fraction is below 1: what else a NEE sample pays for, from the timed render's stages.
    auto stage_wall = [&](int c) { return double(b.profile_cycles[c]) / hz / threads; };
    std::vector<std::pair<double, std::string>> others;
    for (int c = 0; c < prof_count; c++)
      if (c != prof_shadow) others.push_back({stage_wall(c), stage_name(c)});
    others.push_back({rest, "film, scheduling and timer overhead"});
    others.push_back({b.learn_seconds, "between passes (learning, new regions)"});
    std::sort(others.begin(), others.end(), [](const auto& x, const auto& y) { return x.first > y.first; });
    line("  why: shadow rays are %.1f%% of the timed render; the largest other parts:", 100 * stage_wall(prof_shadow) / b.seconds);
    for (size_t k = 0; k < 3 && k < others.size(); k++)
      line("%s %s %.1f%%", k ? "," : "", others[k].second.c_str(), 100 * others[k].first / b.seconds);
    line("\n");
    // A direct-only render pays camera_rays / nee_samples camera rays per NEE sample (one where every camera ray
    // hits a surface that samples a light; more where rays miss or hit emitters): even if everything else were
    // free, the fraction cannot exceed t_raw / (t_raw + that many camera rays' time).
    double t_raw = 1 / limit, t_cam_nee = stage_wall(prof_camera) / nee_b;
    double per_nee = double(b.stats.camera_rays) / nee_b;
    if (params.max_depth == 1 && t_cam_nee > 0 && !per_ray && b.stats.camera_rays > 0)
      line("  with its camera rays the fraction is at most %.3g (%.2f camera rays per NEE sample, each costing %.2f raw "
           "shadow rays here)\n", t_raw / (t_raw + t_cam_nee), per_nee, t_cam_nee / per_nee / t_raw);
  }
  line("  between-pass learning: %.2f%% of the plain render's time\n", 100 * a.learn_seconds / std::max(a.seconds, 1e-9));
  double extra = 100 * (b.seconds / a.seconds - 1);
  if (extra >= 0) line("  timers cost: the timed render took %.1f%% longer than the plain one\n", extra);
  else  // the timers' cost is below the machine's noise on a render this short
    line("  timers cost: the timed render took %.1f%% less time than the plain one (noise)\n", -extra);
  if (a.regions > 0)
    line("  sampler state: %.2f MB; %d region%s, %lld (region, cluster) pair%s, %.1f bytes per pair\n",
         double(a.sampler_bytes) / (1 << 20), a.regions, a.regions == 1 ? "" : "s", (long long)a.pairs,
         a.pairs == 1 ? "" : "s",
         a.pairs > 0 ? double(a.sampler_bytes) / double(a.pairs) : 0.0);
  return out;
}

}  // namespace bl
