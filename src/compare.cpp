// compare: render rounds, per-sampler statistics (mean curves, equal-time error, speed-ups, time to a target
// error) and the text of curves.csv, summary.md and error_vs_time.svg.
// Numbers in summary.md are derived from the same pass records curves.csv prints, in run order, so the
// summary can be checked against the CSV.
#include "compare.h"

#include "errors.h"
#include "file_io.h"
#include "progress.h"
#include "report.h"
#include "svg_plot.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <optional>

namespace bl {

namespace fs = std::filesystem;

// printf into a std::string.
template <class... Args>
static std::string format(const char* fmt, Args... args) {
  char buf[512];
  std::snprintf(buf, sizeof buf, fmt, args...);
  return buf;
}

// Path of a file in the output directory.
static std::string out_path(const compare_params& p, const std::string& name) {
  return (fs::path(p.out_dir) / name).string();
}

compare_data run_comparison(const scene_data& scene, const bvh_data& bvh, const light_data& lights,
                            const image_data& reference, const compare_params& params) {
  compare_data data;
  data.equal_time = params.render.time_budget > 0;
  data.time_budget = params.render.time_budget;
  for (sampler_kind k : params.samplers) data.samplers.push_back({k, {}, {}});
  // Rounds: every sampler once per round, so slow drifts of the machine (clock, heat) affect all alike.
  for (int run = 1; run <= params.runs && data.signal == 0; run++) {
    for (compare_sampler& s : data.samplers) {
      render_params rp = params.render;
      rp.sampler.kind = s.kind;
      rp.seed = params.render.seed + uint64_t(run - 1);
      rp.reference = &reference;
      render_result r = render(scene, bvh, lights, rp);
      compare_run cr;
      cr.run = run;
      cr.seed = rp.seed;
      cr.spp = r.spp;
      cr.seconds = r.seconds;
      cr.setup_seconds = r.setup_seconds;
      cr.interrupted = r.interrupted;
      cr.log = r.log;
      if (run == 1 && r.spp > 0) s.image = film_image(r);
      if (!params.quiet && !r.log.empty())
        std::fprintf(stderr, "compare: %s run %d/%d (seed %llu): %d spp in %.3f s, relMSE %.4e\n",
                     sampler_name(s.kind), run, params.runs, (unsigned long long)cr.seed, r.spp, r.seconds,
                     r.log.back().error.relmse);
      s.runs.push_back(std::move(cr));
      if (r.interrupted || interrupt_signal() != 0) {
        data.signal = interrupt_signal() != 0 ? interrupt_signal() : SIGINT;
        break;
      }
    }
  }
  return data;
}

double time_to_reach(const std::vector<double>& seconds, const std::vector<double>& relmse, double target) {
  size_t n = std::min(seconds.size(), relmse.size());
  // The curve stays at or below the target from point i on; a dip of a noisy curve that rises again does not
  // count as reaching it.
  size_t i = n;
  while (i > 0 && relmse[i - 1] <= target) i--;
  if (i == n) return -1;
  if (i == 0) return seconds[0];
  double t0 = seconds[i - 1], t1 = seconds[i], e0 = relmse[i - 1], e1 = relmse[i];
  if (!(t0 > 0 && t1 > t0 && e1 > 0 && target > 0 && std::isfinite(e0))) return t1;
  // Straight line between the two passes on log-log axes: log t = log t0 + (log target - log e0) * slope.
  double slope = (std::log(t1) - std::log(t0)) / (std::log(e1) - std::log(e0));
  return std::exp(std::log(t0) + (std::log(target) - std::log(e0)) * slope);
}

double relmse_at_time(const std::vector<pass_record>& log, double t) {
  if (log.empty()) return NAN;
  size_t i = 0;
  while (i < log.size() && log[i].seconds < t) i++;
  if (i == log.size()) return log.back().error.relmse;
  if (i == 0) return log[0].error.relmse;
  double t0 = log[i - 1].seconds, t1 = log[i].seconds, e0 = log[i - 1].error.relmse, e1 = log[i].error.relmse;
  if (!(t0 > 0 && t1 > t0)) return e1;
  if (!(e0 > 0 && e1 > 0)) return e0 + (e1 - e0) * (t - t0) / (t1 - t0);  // (an exact pass: no logarithm)
  double f = (std::log(t) - std::log(t0)) / (std::log(t1) - std::log(t0));
  return std::exp(std::log(e0) + f * (std::log(e1) - std::log(e0)));
}

double comparison_time(const compare_data& data) {
  double t = data.time_budget;
  if (data.equal_time && data.signal != 0)
    for (const compare_sampler& s : data.samplers)
      for (const compare_run& r : s.runs)
        if (!r.log.empty()) t = std::min(t, r.log.back().seconds);
  return t;
}

std::vector<compare_stats> comparison_stats(const compare_data& data) {
  const double t_cmp = comparison_time(data);
  std::vector<compare_stats> all;
  for (const compare_sampler& s : data.samplers) {
    compare_stats st;
    std::vector<const compare_run*> runs;
    size_t passes = 0;
    for (const compare_run& r : s.runs)
      if (!r.log.empty()) runs.push_back(&r), passes = std::max(passes, r.log.size());
    st.runs = int(runs.size());
    if (runs.empty()) {
      all.push_back(st);
      continue;
    }
    double k = double(runs.size());
    std::vector<double> times;  // equal time, several runs: the common times of the mean curve
    if (data.equal_time && runs.size() > 1) {
      // Runs end at different passes and times: the mean curve averages them at common times (every run's pass
      // times from the latest first pass to the earliest last one, each run interpolated there as the table's
      // relMSE is). Averaged by pass index, a pass of a fast run was averaged with one of a slow run 0.5 s later,
      // and a run that had ended was held at its last value (a review).
      double from = 0, to = INFINITY;
      for (const compare_run* r : runs) from = std::max(from, r->log.front().seconds);
      for (const compare_run* r : runs) to = std::min(to, r->log.back().seconds);
      for (const compare_run* r : runs)
        for (const pass_record& p : r->log)
          if (p.seconds >= from && p.seconds <= to) times.push_back(p.seconds);
      std::sort(times.begin(), times.end());
      times.erase(std::unique(times.begin(), times.end()), times.end());
    }
    for (double t : times) {
      double e = 0;
      for (const compare_run* r : runs) e += relmse_at_time(r->log, t);
      st.curve_seconds.push_back(t);
      st.curve_relmse.push_back(e / k);
    }
    if (times.empty()) {
      // Equal spp: every run has the same passes (the same spp); a run cut short by a signal keeps its last one.
      // (Also runs that share no time: one's first pass ended after another's last, when a signal cut them short.)
      for (size_t i = 0; i < passes; i++) {
        double t = 0, e = 0;
        for (const compare_run* r : runs) {
          const pass_record& p = r->log[std::min(i, r->log.size() - 1)];
          t += p.seconds;
          e += p.error.relmse;
        }
        st.curve_seconds.push_back(t / k);
        st.curve_relmse.push_back(e / k);
      }
    }
    st.seconds = 0;
    for (const compare_run* r : runs) st.seconds += r->log.back().seconds / k;
    for (const compare_run* r : runs)
      if (r->run == 1) st.image_relmse = r->log.back().error.relmse;
    // Each run's relMSE at the end: at exactly the comparison time at equal time (runs stop at different passes near
    // it), which may lie before a run's first pass when the budget is that short.
    auto end_relmse = [&](const compare_run* r) {
      return data.equal_time ? relmse_at_time(r->log, t_cmp) : r->log.back().error.relmse;
    };
    for (const compare_run* r : runs)
      if (data.equal_time && r->log[0].seconds > t_cmp) st.before_first_pass = true;
    st.relmse = 0;
    for (const compare_run* r : runs) st.relmse += end_relmse(r) / k;
    st.spp_min = st.spp_max = runs[0]->spp;
    double var = 0;
    for (const compare_run* r : runs) {
      st.spp_min = std::min(st.spp_min, r->spp);
      st.spp_max = std::max(st.spp_max, r->spp);
      double d = end_relmse(r) - st.relmse;
      var += d * d;
      st.setup_seconds += r->setup_seconds / k;
    }
    st.relmse_sd = runs.size() > 1 ? std::sqrt(var / (k - 1)) : 0;
    all.push_back(st);
  }
  if (all.empty() || all[0].runs == 0) return all;
  const compare_stats& base = all[0];
  for (compare_stats& st : all) {
    if (st.runs == 0) {
      st.speedup = NAN;
      continue;
    }
    double num = data.equal_time ? base.relmse : base.relmse * base.seconds;
    double den = data.equal_time ? st.relmse : st.relmse * st.seconds;
    const bool comparable = !st.before_first_pass && !base.before_first_pass;  // (both errors at the same time)
    st.speedup = comparable && den > 0 && std::isfinite(num) && std::isfinite(den) ? num / den : NAN;
    // The first sampler reaches its own relMSE at its end by definition: at the budget at equal time (its curve can
    // rise again in the pass after it, heavy-tailed as relMSE is), which is at the shortest run's last pass when a
    // signal stopped them sooner; at its mean time at equal spp (where its curve's last point, the mean of sums, can
    // differ from the sum of means in the last bit and miss it).
    // (A first pass that ended after the comparison time: at that pass, when its error was measured.)
    if (&st == &all[0])
      st.time_to_target = !data.equal_time    ? st.seconds
                          : st.before_first_pass ? st.curve_seconds[0]
                                                 : std::min(t_cmp, st.seconds);
    else st.time_to_target = time_to_reach(st.curve_seconds, st.curve_relmse, base.relmse);
  }
  return all;
}

std::string comparison_csv(const compare_data& data) {
  // The columns of a render's --log first (a reader of those reads these alike), then the run and its seed.
  std::string s = "sampler,pass,spp,seconds,relmse,mse,run,seed\n";
  for (const compare_sampler& cs : data.samplers)
    for (const compare_run& r : cs.runs)
      for (const pass_record& p : r.log)
        s += format("%s,%d,%d,%.6f,%.9g,%.9g,%d,%llu\n", sampler_name(cs.kind), p.pass, p.spp, p.seconds,
                    p.error.relmse, p.error.mse, r.run, (unsigned long long)r.seed);
  return s;
}

// "—" (U+2014), the table's mark for a value that does not exist.
static const char* const dash = "\xe2\x80\x94";

std::string comparison_summary(const compare_data& data, const compare_params& p) {
  std::vector<compare_stats> stats = comparison_stats(data);
  const render_params& rp = p.render;
  std::string base = p.samplers.empty() ? "" : sampler_name(p.samplers[0]);
  std::string s = "# Sampler comparison: " + p.scene_path + "\n\n";
  s += data.equal_time ? format("Equal time: %g s of rendering per sampler and run", rp.time_budget)
                       : format("Equal samples: %d spp per sampler and run", rp.spp);
  s += format(" | %dx%d pixels | max depth %d | ", rp.width, rp.height, rp.max_depth);
  if (rp.light_samples > 1) s += format("%d light samples per vertex | ", rp.light_samples);
  if (rp.light_points > 0) s += format("%d light point%s per first-vertex NEE draw | ", rp.light_points,
                                       rp.light_points == 1 ? "" : "s");
  const uint64_t last_seed = rp.seed + uint64_t(p.runs - 1);  // (consecutive seeds wrap past 2^64 - 1 to 0)
  s += p.runs == 1 ? format("1 run (seed %llu)", (unsigned long long)rp.seed)
                   : format("%d runs (seeds %llu to %llu%s)", p.runs, (unsigned long long)rp.seed,
                            (unsigned long long)last_seed, last_seed < rp.seed ? ", wrapping past 2^64 - 1 to 0" : "");
  s += rp.threads > 0 ? format(" | %d thread%s\n\n", rp.threads, rp.threads == 1 ? "" : "s")
                      : std::string(" | threads: all cores\n\n");
  s += (p.reference_note.empty() ? "reference: " + p.reference_path : p.reference_note) + "\n\n";
  const double t_cmp = comparison_time(data);
  if (data.signal != 0) {
    s += format("**Interrupted** by signal %d: the table covers the passes completed before it", data.signal);
    s += data.equal_time && t_cmp < data.time_budget
             ? format(", and compares the samplers at %.4g s, where the shortest run ended.\n\n", t_cmp)
             : std::string(".\n\n");
  }
  std::string early;
  for (size_t i = 0; i < stats.size(); i++)
    if (stats[i].before_first_pass) early += std::string(early.empty() ? "" : ", ") + sampler_name(data.samplers[i].kind);
  if (!early.empty())
    s += format("**The comparison time, %.4g s, ends before the first pass of %s**: the relMSE given is that pass's, "
                "at a later time than the others', so there is no speed-up against it (a longer --time compares "
                "them).\n\n", t_cmp, early.c_str());

  std::string target = stats.empty() || stats[0].runs == 0 ? std::string("?") : format("%.4e", stats[0].relmse);
  s += "| sampler | spp | seconds | relMSE | speed-up vs " + base +
       (data.equal_time ? " (equal time)" : " (efficiency)") +
       " | time to relMSE " + target + " (s) | setup (s) |" + (data.equal_time ? " image relMSE |\n" : "\n");
  s += std::string("|:--|--:|--:|--:|--:|--:|--:|") + (data.equal_time ? "--:|\n" : "\n");
  for (size_t i = 0; i < stats.size(); i++) {
    const compare_stats& st = stats[i];
    s += std::string("| ") + sampler_name(data.samplers[i].kind) + " | ";
    if (st.runs == 0) {
      s += std::string(dash) + " | " + dash + " | " + dash + " | " + dash + " | " + dash + " | " + dash + " |";
      s += data.equal_time ? std::string(" ") + dash + " |\n" : std::string("\n");
      continue;
    }
    s += st.spp_min == st.spp_max ? format("%d", st.spp_max) : format("%d\xe2\x80\x93%d", st.spp_min, st.spp_max);
    s += format(" | %.4g | %.4e", st.seconds, st.relmse);
    if (st.runs > 1) s += format(" \xc2\xb1 %.2e", st.relmse_sd);
    s += std::isfinite(st.speedup) ? format(" | %.2f", st.speedup) : std::string(" | ") + dash;
    s += st.time_to_target >= 0 ? format(" | %.4g", st.time_to_target) : std::string(" | ") + dash;
    s += format(" | %.3g |", st.setup_seconds);
    if (data.equal_time)
      s += st.image_relmse >= 0 ? format(" %.4e |\n", st.image_relmse) : std::string(" ") + dash + " |\n";
    else
      s += "\n";
  }

  s += "\n- **relMSE**: mean over pixels and RGB channels of (x \xe2\x88\x92 r)\xc2\xb2 / (r\xc2\xb2 + 0.01) ";
  s += data.equal_time ? "at exactly the comparison time (log-log between the last pass before it and the first at or "
                         "after it; spp and seconds are the final pass's)"
                       : "after the final pass";
  s += p.runs > 1 ? format("; mean \xc2\xb1 standard deviation over the %d runs.\n", p.runs) : std::string(".\n");
  if (data.equal_time)
    s += "- **image relMSE**: the error of `<sampler>.exr`, run 1's render after its last pass (cut to end just past "
         "the budget).\n";
  if (data.equal_time)
    s += "- **speed-up** at equal time: relMSE of " + base + " / relMSE of the sampler, both at the time budget "
         "(each render's last pass is cut to the time left, to end just past it; its error at the budget is "
         "interpolated), or where a signal cut the renders short, at the end of the shortest run.\n";
  else
    s += "- **speed-up** at equal spp: the efficiency ratio (relMSE \xc3\x97 seconds of " + base +
         ") / (relMSE \xc3\x97 seconds of the sampler), which is the equal-time speed-up when relMSE falls as "
         "1/time; the time-to-target column measures it without that assumption.\n";
  s += "- **time to relMSE**: the time from which the sampler's mean curve stays at or below " + base +
       "'s relMSE in the table, interpolated log-log between passes; " + dash + ": not reached.\n";
  if (p.runs > 1)
    s += data.equal_time ? "- **mean curve**: the runs' relMSE averaged at common times (each run's pass times, from "
                           "the latest first pass to the earliest last one; each run interpolated log-log there; runs "
                           "that share no time, pass by pass).\n"
                         : "- **mean curve**: the runs' relMSE and seconds averaged pass by pass.\n";
  s += "- **seconds**: render wall time (passes and learning), mean over runs; it excludes the setup column (light "
       "tree, regions) and error computation. Every pass is in curves.csv; error_vs_time.svg plots the mean curves.\n";
  s += format("- **images**: `<sampler>.exr` is the render of run 1 (seed %llu), `<sampler>.png` the same as 8-bit "
              "sRGB (clamped); `<sampler>_error.png` shows its per-pixel relative error |x \xe2\x88\x92 r| / (|r| + 0.1), averaged over RGB, on the viridis ramp with "
              "the fixed logarithmic range %g (dark purple, and below) to %g (yellow, and above).\n",
              (unsigned long long)rp.seed, double(p.error_image.min_error), double(p.error_image.max_error));
  return s;
}

std::string comparison_svg(const compare_data& data, const compare_params& p) {
  std::vector<compare_stats> stats = comparison_stats(data);
  std::vector<plot_series> series;
  for (size_t i = 0; i < stats.size(); i++)
    series.push_back({sampler_name(data.samplers[i].kind), stats[i].curve_seconds, stats[i].curve_relmse});
  loglog_plot_params pp;
  pp.title = "relMSE against time: " + fs::path(p.scene_path).filename().string() +
             (p.runs > 1 ? format(" (mean of %d runs)", p.runs) : std::string());
  pp.x_label = "render time (s)";
  pp.y_label = "relMSE";
  pp.guide_label = "slope \xe2\x88\x92" "1 (1/t)";
  return loglog_plot_svg(series, pp);
}

// The files compare writes into the output directory: per sampler its image and error image, then the reports.
static std::string image_file(const compare_params& p, sampler_kind k) {
  return out_path(p, std::string(sampler_name(k)) + ".exr");
}
static std::string png_file(const compare_params& p, sampler_kind k) {
  return out_path(p, std::string(sampler_name(k)) + ".png");
}
static std::string error_file(const compare_params& p, sampler_kind k) {
  return out_path(p, std::string(sampler_name(k)) + "_error.png");
}
static constexpr const char* curves_file = "curves.csv";
static constexpr const char* plot_file = "error_vs_time.svg";
static constexpr const char* summary_file = "summary.md";

void write_comparison(const compare_data& data, const compare_params& p, const image_data& reference) {
  output_failures failures;  // every file is tried, whatever failed before it
  for (const compare_sampler& s : data.samplers) {
    if (s.image.pixels.empty()) {
      // Interrupted before this sampler's first pass: images an earlier comparison left here would sit beside a
      // summary that lists none for it.
      std::error_code ec;
      for (const std::string& f : {image_file(p, s.kind), png_file(p, s.kind), error_file(p, s.kind)})
        fs::remove(f, ec);
      continue;
    }
    failures.attempt([&] { write_image(image_file(p, s.kind), s.image); });
    failures.attempt([&] { write_image(png_file(p, s.kind), s.image); });
    failures.attempt([&] { write_error_image(error_file(p, s.kind), s.image, reference, p.error_image); });
  }
  failures.attempt([&] { write_file_atomic(out_path(p, curves_file), comparison_csv(data)); });
  failures.attempt([&] { write_file_atomic(out_path(p, plot_file), comparison_svg(data, p)); });
  failures.attempt([&] { write_file_atomic(out_path(p, summary_file), comparison_summary(data, p)); });
  // Images of samplers this comparison did not run, left by an earlier one in the same folder, look like its results
  // (a review): named, not removed (they may be wanted).
  std::string stale;
  for (sampler_kind k : all_sampler_kinds) {
    if (std::find(p.samplers.begin(), p.samplers.end(), k) != p.samplers.end()) continue;
    std::error_code ec;
    for (const std::string& f : {image_file(p, k), png_file(p, k), error_file(p, k)})
      if (fs::exists(f, ec)) stale += (stale.empty() ? "" : ", ") + fs::path(f).filename().string();
  }
  if (!stale.empty())
    std::fprintf(stderr, "compare: warning: %s also holds %s from an earlier comparison (not part of this one)\n",
                 p.out_dir.c_str(), stale.c_str());
  failures.rethrow();
}

// Creates the output directory when missing, with any missing parents (as mkdir -p); throws output_error when it
// cannot be used. Returns the folders it created, the deepest first.
static std::vector<fs::path> make_output_dir(const std::string& dir) {
  std::error_code ec;
  std::vector<fs::path> created;
  for (fs::path p = fs::path(dir).lexically_normal(); !p.empty() && !fs::exists(p, ec); p = p.parent_path()) {
    created.push_back(p);
    if (p == p.parent_path()) break;
  }
  if (!created.empty() && !fs::create_directories(dir, ec) && !fs::is_directory(dir))
    throw output_error("cannot create directory " + dir + ": " + ec.message());
  if (!fs::is_directory(dir, ec)) throw output_error("cannot write into " + dir + ": not a directory");
  if (access(dir.c_str(), W_OK) != 0) throw output_error("cannot write into " + dir + ": directory is not writable");
  return created;
}

int run_compare(const scene_desc& desc, const compare_params& params) {
  const render_params& rp = params.render;
  image_data reference = read_reference(params.reference_path, rp.width, rp.height);
  std::optional<slow_phase_note> loading(std::in_place, rp.notes, "loading " + desc.path + " ...");
  scene_data scene = build_scene(desc, float(rp.width) / float(rp.height));
  report_dropped_triangles(desc.mesh_path, scene.mesh.dropped_degenerate, scene.mesh.first_degenerate_line);
  {
    // The files written into --out must not be inputs (e.g. a reference kept there as <sampler>.exr).
    std::vector<std::pair<std::string, std::string>> outs, ins = {{params.scene_path, "scene file"},
                                                                  {params.reference_path, "reference"}};
    for (const std::string& src : scene.mesh.source_files) ins.push_back({src, "scene input"});
    for (sampler_kind k : params.samplers) {
      outs.push_back({image_file(params, k), "output"});
      outs.push_back({png_file(params, k), "output"});
      outs.push_back({error_file(params, k), "output"});
    }
    for (const char* f : {curves_file, plot_file, summary_file}) outs.push_back({out_path(params, f), "output"});
    check_distinct_outputs(outs, ins);
    // An output name taken by a directory would only fail after every render: refused before the first.
    std::error_code ec;
    for (const auto& o : outs)
      if (fs::is_directory(o.first, ec)) throw output_error("cannot write " + o.first + ": is a directory");
  }
  bvh_data bvh = build_bvh(scene);
  light_data lights = build_lights(scene);
  loading.reset();
  if (lights.count == 0)
    std::fprintf(stderr, "%s: warning: the scene has no emitters (the image is black)\n", params.scene_path.c_str());
  for (sampler_kind k : params.samplers) {  // (the first sampler the regions of which come out coarse: one line)
    sampler_params sp = rp.sampler;
    sp.kind = k;
    const std::string w =
        coarse_grid_warning(sp, rp.max_depth, int64_t(rp.width) * rp.height, scene.bounds, lights, params.grid_given);
    if (w.empty()) continue;
    std::fprintf(stderr, "%s: warning: %s\n", params.scene_path.c_str(), w.c_str());
    break;
  }
  const std::vector<fs::path> created = make_output_dir(params.out_dir);
  // Interrupted with nothing to report (as render, which then keeps the files already there): the folders this run
  // created are removed again, since they stay empty.
  auto nothing_written = [&](int status) {
    std::error_code ec;
    for (const fs::path& p : created) fs::remove(p, ec);  // (only if still empty; the deepest first)
    return status;
  };
  if (int status = interrupted_before_render()) return nothing_written(status);
  compare_data data = run_comparison(scene, bvh, lights, reference, params);
  bool any_pass = false;
  for (const compare_sampler& s : data.samplers)
    for (const compare_run& r : s.runs) any_pass = any_pass || !r.log.empty();
  if (!any_pass && data.signal != 0) {
    std::fprintf(stderr, "compare: interrupted before the first pass; nothing written\n");
    return nothing_written(128 + data.signal);
  }
  write_comparison(data, params, reference);
  // (A signal that came after the last render, while the files were written, ends the command as interrupted.)
  const int sig = data.signal != 0 ? data.signal : interrupt_signal();
  if (!params.quiet || sig != 0)
    std::fprintf(stderr, "compare: %s -> %s (summary.md, curves.csv, error_vs_time.svg, <sampler>.exr, "
                         "<sampler>.png, <sampler>_error.png)\n",
                 data.signal != 0 ? "interrupted; wrote the passes completed so far"
                 : sig != 0       ? "interrupted after the last render; wrote everything"
                                  : "done",
                 params.out_dir.c_str());
  return sig != 0 ? 128 + sig : exit_ok;
}

}  // namespace bl
