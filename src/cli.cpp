// cli: parses the command line with CLI11, runs the subcommand, and maps failures to exit statuses
// (0 ok, 1 other failure, 2 bad command line, 3 bad input, 128+signal after an interrupted render).
#include "cli.h"

#include "bvh.h"
#include "checkpoint.h"
#include "cli_options.h"
#include "cli_validators.h"
#include "compare.h"
#include "error_image.h"
#include "errors.h"
#include "file_io.h"
#include "image_io.h"
#include "lights.h"
#include "metrics.h"
#include "profile.h"
#include "progress.h"
#include "render.h"
#include "report.h"
#include "scene.h"
#include "scene_checks.h"
#include "scene_desc.h"
#include "version.h"

#include <CLI/CLI.hpp>

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cctype>
#include <chrono>
#include <climits>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <optional>
#include <thread>

namespace bl {

namespace {

namespace fs = std::filesystem;

// Checks that an output path can be written before spending time on a render.
void check_output_path(const std::string& path) {
  fs::path p(path);
  fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
  // One status of the path (links followed): a loop, a directory, or an existing FIFO or device (/dev/stdout,
  // /dev/null), which is written in place, so that its directory need not be writable.
  std::error_code ec;
  const fs::file_status st = fs::status(p, ec);
  // Any failure but a missing file or folder (said below) ends here: a loop, a name too long, a folder that may not be
  // searched (they were found only when the output was written, after the render).
  if (ec && ec != std::errc::no_such_file_or_directory && ec != std::errc::not_a_directory)
    throw output_error("cannot write " + path + ": " + ec.message());
  if (!ec && fs::is_directory(st)) throw output_error("cannot write " + path + ": is a directory");
  if (!ec && fs::exists(st) && !fs::is_regular_file(st)) return;
  if (fs::is_symlink(fs::symlink_status(p, ec))) {
    fs::path target = fs::path(output_target(path)).parent_path();  // where it points
    if (!target.empty()) dir = target;
  }
  if (!fs::is_directory(dir, ec)) {
    // The nearest folder on the way that exists: a file there is the problem, not a missing directory.
    fs::path up = dir;
    while (up.has_parent_path() && up != up.parent_path() && !fs::exists(up, ec)) up = up.parent_path();
    throw output_error("cannot write " + path + ": " +
                       (fs::exists(up, ec) && !fs::is_directory(up, ec) ? up.string() + " is not a directory"
                                                                        : "directory " + dir.string() + " does not exist"));
  }
  if (access(dir.c_str(), W_OK) != 0) throw output_error("cannot write " + path + ": directory " + dir.string() + " is not writable");
}

// What option `name` (of group `group`) applies to, when a render with sampler `kind` and options o does not use
// it; empty when it does.
std::string unused_because(const std::string& name, const std::string& group, sampler_kind kind,
                           const render_options& o) {
  const bool bayes = kind == sampler_kind::bayes, bound = kind == sampler_kind::bound;
  const bool adaptive = bayes || kind == sampler_kind::donikian;
  if (name == "--cut-members" || group == bayes_group) {
    if (!bayes) return "bayes only";
    // Within bayes, the options its other options leave without effect.
    const bool naive = !o.bayes.prior, point = o.bayes_prior == "point", mean = o.bayes_pmf == "mean";
    if (naive && (name == "--bayes-a0" || name == "--bayes-b0" || name == "--bayes-kappa0" ||
                  name == "--bayes-alpha0" || name == "--bayes-c" || name == "--bayes-no-mean-hierarchy" ||
                  name == "--bayes-unseen-cap"))
      return "no prior with --bayes-naive";
    const bool cv_option = name == "--bayes-cv-min-visible" || name == "--bayes-cv-sun-min-visible" ||
                           name == "--bayes-cv-last-only";
    if (point && (name == "--bayes-no-orientation" || name == "--bayes-no-bsdf-factor" || name == "--bayes-no-cv" ||
                  name == "--bayes-cv-last-only" ||
                  name == "--bayes-cv-min-visible" || name == "--bayes-cv-sun-min-visible" ||
                  name == "--bayes-no-mean-hierarchy" || name == "--bayes-unseen-cap"))
      return "region prior only, not with --bayes-prior point";
    if (mean && (name == "--bayes-no-cv" || cv_option))
      return "control variates need --bayes-pmf second-moment";
    if (!o.bayes.control_variate && cv_option) return "no control variates with --bayes-no-cv";
    if (!(o.bayes.hierarchy > 0) && name == "--bayes-no-mean-hierarchy") return "no hierarchy with --bayes-hierarchy 0";
    return "";
  }
  // (donikian's deeper vertices use bound's regions, and its first-hit cut their --max-cut)
  if (group == region_group) return bound || adaptive ? "" : "bound, donikian and bayes only";
  if (name == "--pass-weighting") {
    if (!adaptive) return "bayes and donikian only";
    return bayes && o.bayes.oracle_spp > 0 ? "a frozen --bayes-oracle model does not adapt" : "";
  }
  if (name == "--frame-decay") return o.frames > 1 && adaptive ? "" : "with --frames and bayes or donikian only";
  if (name == "--checkpoint-every") return o.checkpoint.empty() ? "with --checkpoint only" : "";
  return "";
}

// The validated render parameters of a scene and the command line.
render_params resolve_params(const render_options& o, const scene_desc& desc, sampler_kind kind) {
  render_params p;
  p.width = o.width > 0 ? o.width : desc.width;
  p.height = o.height > 0 ? o.height : desc.height;
  if ((long long)p.width * p.height > max_pixels) {
    // Bad input when the scene file gave a side of it (its "image"), else a bad command line.
    std::string why = "image of " + std::to_string(p.width) + "x" + std::to_string(p.height) +
                      " pixels is too large (at most 2^28 pixels)";
    if (o.width > 0 && o.height > 0) throw usage_error(why);
    throw input_error(desc.path, why);
  }
  p.spp = o.spp > 0 ? o.spp : desc.spp;
  p.time_budget = o.time;
  p.max_depth = o.max_depth > 0 ? o.max_depth : desc.max_depth;
  p.seed = o.has_seed ? o.seed : desc.seed;
  p.threads = o.threads;
  p.sampler.kind = kind;
  p.sampler.regions = o.regions;
  p.sampler.bayes = o.bayes;
  p.sampler.bayes.second_moment = o.bayes_pmf == "second-moment";
  p.sampler.bayes.region_prior = o.bayes_prior == "region";
  p.frames = std::max(1, o.frames);
  p.frame_decay = o.frame_decay;
  p.pass_weighting = o.pass_weighting;
  p.stratify = !o.independent;
  p.light_samples = o.light_samples;
  p.light_points = o.light_points;
  p.progress = p.notes = !o.quiet && stderr_is_terminal();
  return p;
}

// Whether a path holds exactly one printf integer directive (%d, %04d, ...) and no other '%' but "%%" (a '%').
bool is_frame_pattern(const std::string& p) {
  int directives = 0;
  for (size_t at = p.find('%'); at != std::string::npos; at = p.find('%', at)) {
    if (at + 1 < p.size() && p[at + 1] == '%') {
      at += 2;
      continue;
    }
    size_t k = at + 1;
    while (k < p.size() && (std::isdigit(static_cast<unsigned char>(p[k])) != 0)) k++;
    // A field width of at most two digits (%04d): a wider one would make names longer than a path may be.
    if (!(k < p.size() && k - at - 1 <= 2 && p[k] == 'd')) return false;
    directives++;
    at = k + 1;
  }
  return directives == 1;
}
// The path of frame `frame` of a frame pattern when --frames was given (animated). Without it the path is taken as
// written, '%' and all: only --frames makes a name a pattern (--frames 1 too).
std::string frame_path(const std::string& pattern, int frame, bool animated) {
  if (!animated || !is_frame_pattern(pattern)) return pattern;
  char buf[4096];
  std::snprintf(buf, sizeof buf, pattern.c_str(), frame);
  return buf;
}
// A name with its '%' written as "%%", for a frame pattern.
static std::string escape_percent(const std::string& s) {
  std::string out;
  for (char c : s) out += c == '%' ? std::string("%%") : std::string(1, c);
  return out;
}

// Reads a reference image of the render's size.
image_data load_reference(const std::string& path, const render_params& params) {
  return read_reference(path, params.width, params.height);
}

// Warns about the options given that no render of `kinds` uses, each with what it applies to.
void warn_unused_options(const render_options& o, const std::vector<sampler_kind>& kinds) {
  std::string unused;
  for (const auto& [name, group] : o.given) {
    std::string why;
    for (sampler_kind k : kinds) {
      why = unused_because(name, group, k, o);
      if (why.empty()) break;
    }
    if (!why.empty()) unused += (unused.empty() ? "" : ", ") + name + " (" + why + ")";
  }
  if (!unused.empty())
    std::fprintf(stderr, "bayeslight: warning: options that change nothing in this run are ignored: %s\n",
                 unused.c_str());
}

// Whether option `name` was given on the command line.
static bool option_given(const render_options& o, const std::string& name) {
  for (const auto& g : o.given)
    if (g.first == name) return true;
  return false;
}

// Regions coarser than the grid asks for, once the mesh's bounds are known (light_sampler.h).
static void warn_coarse_grid(const render_options& o, const render_params& params, const scene_data& scene,
                             const light_data& lights) {
  const std::string w =
      coarse_grid_warning(params.sampler, params.max_depth, int64_t(params.width) * params.height, scene.bounds,
                          lights, option_given(o, "--grid"));
  if (!w.empty()) std::fprintf(stderr, "%s: warning: %s\n", o.scene.c_str(), w.c_str());
}

// What only the scene (its max depth, image size) tells: fine regions at depths the paths never reach, donikian's
// region options at max depth 1, and settings that may take gigabytes (warn_unused_options runs before the scene is
// read). Each option is named once.
void warn_after_scene(const render_options& o, const render_params& params, const std::vector<sampler_kind>& kinds) {
  const int max_depth = params.max_depth;
  const bool donikian = std::find(kinds.begin(), kinds.end(), sampler_kind::donikian) != kinds.end();
  // Whether a sampler of `kinds` reads a region option at this max depth: donikian's regions are bound's, for the
  // vertices past the first; its first hit reads only --max-cut and --cut-coherence (its cut over the scene).
  auto read_now = [&](const std::string& name) {
    for (sampler_kind k : kinds)
      if (unused_because(name, region_group, k, o).empty() &&
          (k != sampler_kind::donikian || max_depth > 1 || name == "--max-cut" || name == "--cut-coherence"))
        return true;
    return false;
  };
  auto given = [&](const std::string& name) { return option_given(o, name); };
  // donikian keeps every pixel's estimate of each cluster of its cut (up to --max-cut and the sun, 4 bytes each): 6.7
  // GB at 4096x4096 in a review, with nothing said before.
  if (donikian) {
    const double bytes = double(params.width) * params.height * (double(o.regions.max_cut) + 2) * 4;
    if (bytes > 4.0 * (1 << 30))
      std::fprintf(stderr,
                   "bayeslight: warning: donikian keeps each pixel's estimate of every cluster of its cut: up to %.0f "
                   "GB at %dx%d with --max-cut %d (a smaller image or --max-cut takes less)\n",
                   bytes / (1 << 30), params.width, params.height, o.regions.max_cut);
  }
  // A budget near its maximum lets a fine grid's regions take tens of GB (a review: 10 GB at 160x120 with --grid
  // 100000 --region-min-samples 1): said before the render, with what it can cost. About 130 bytes per pair (the
  // statistics and weight columns, the cut entries), fine and coarse pairs up to twice the budget.
  constexpr double bytes_per_pair = 130, warn_bytes = 4.0 * (1 << 30);
  const double most = 2.0 * double(o.regions.max_pairs) * bytes_per_pair;
  if (o.regions.max_pairs > 0 && most > warn_bytes && read_now("--region-budget"))
    std::fprintf(stderr,
                 "bayeslight: warning: --region-budget %lld lets the regions and their statistics grow to about %.0f "
                 "GB where the samples reach that many cells (a fine --grid, a small --region-min-samples)\n",
                 (long long)o.regions.max_pairs, most / (1 << 30));
  bool used = false;
  for (sampler_kind k : kinds) used |= unused_because("--fine-depth", region_group, k, o).empty();
  const bool deep_fine = given("--fine-depth") && used && o.regions.fine_depth > max_depth;
  if (deep_fine)
    std::fprintf(stderr, "bayeslight: warning: --fine-depth %d is above the max depth %d: depths past %d change nothing\n",
                 o.regions.fine_depth, max_depth, max_depth);
  // bayes's early draws serve direct illumination only (max depth 1), and only where they take more draws than
  // --light-samples over a span of at least one spp (render.cpp, pass_draws; the checkpoint fingerprint reads them
  // the same way).
  const bool bayes = std::find(kinds.begin(), kinds.end(), sampler_kind::bayes) != kinds.end();
  if (bayes && max_depth > 1) {
    std::string early;
    for (const char* name : {"--bayes-early-draws", "--bayes-early-spp"})
      if (given(name)) early += (early.empty() ? "" : ", ") + std::string(name);
    if (!early.empty())
      std::fprintf(stderr,
                   "bayeslight: warning: options that change nothing in this run are ignored: %s (direct "
                   "illumination only, and the max depth is %d)\n",
                   early.c_str(), max_depth);
  } else if (bayes) {
    if (given("--bayes-cv-last-only") &&
        unused_because("--bayes-cv-last-only", bayes_group, sampler_kind::bayes, o).empty())
      std::fprintf(stderr,
                   "bayeslight: warning: options that change nothing in this run are ignored: --bayes-cv-last-only "
                   "(at max depth 1 every vertex is the last)\n");
    const int per_sample = std::max(1, o.light_samples);
    const bayes_params defaults;
    auto takes_effect = [&](int draws, int spp) { return draws > per_sample && spp > 0; };
    const int draws = o.bayes.early_draws, spp = o.bayes.early_spp;
    // An option is ignored where neither its value nor its default would make the early draws happen, the other
    // option as given. Where each would be so without the other (--bayes-early-draws 1 --bayes-early-spp 0), neither
    // is: both turn the early draws off, and dropping both would bring them back.
    const bool draws_idle = given("--bayes-early-draws") && !takes_effect(draws, spp) &&
                            !takes_effect(defaults.early_draws, spp);
    const bool spp_idle = given("--bayes-early-spp") && !takes_effect(draws, spp) &&
                          !takes_effect(draws, defaults.early_spp);
    if (draws_idle && spp_idle)
      std::fprintf(stderr,
                   "bayeslight: warning: --bayes-early-draws %d and --bayes-early-spp 0 each turn the early draws "
                   "off: one of them is enough\n",
                   draws);
    else if (draws_idle)
      std::fprintf(stderr,
                   "bayeslight: warning: options that change nothing in this run are ignored: --bayes-early-draws (%s)\n",
                   spp == 0 ? "--bayes-early-spp 0 turns the early draws off"
                            : ("every camera sample takes --light-samples " + std::to_string(per_sample) +
                               " draws already").c_str());
    else if (spp_idle)
      std::fprintf(stderr,
                   "bayeslight: warning: options that change nothing in this run are ignored: --bayes-early-spp "
                   "(--bayes-early-draws %d is not above --light-samples %d)\n",
                   draws, per_sample);
  }
  if (!donikian || max_depth > 1) return;
  std::string unused;
  for (const auto& [name, group] : o.given) {
    if (group != region_group || read_now(name) || (name == "--fine-depth" && deep_fine) ||
        !unused_because(name, group, sampler_kind::donikian, o).empty())  // (warned about already)
      continue;
    unused += (unused.empty() ? "" : ", ") + name;
  }
  if (!unused.empty())
    std::fprintf(stderr,
                 "bayeslight: warning: options that change nothing in this run are ignored: %s (donikian's regions "
                 "serve the vertices past the first, and the max depth is 1)\n",
                 unused.c_str());
}

// "frame A was" or "frames A to B were": an animation's frames in a message.
std::string frames_were(int a, int b) {
  return a == b ? "frame " + std::to_string(a) + " was"
                : "frames " + std::to_string(a) + " to " + std::to_string(b) + " were";
}

// The outputs of a render (-o as given, else SCENE.exr or, with --frames, SCENE_%04d.exr), after the checks of
// the names of its files that need no scene: image formats, a log named like an image or scene, frame patterns.
std::vector<std::string> checked_output_names(const render_options& o) {
  const bool animated = o.frames > 0;
  std::vector<std::string> outputs = o.outputs;
  if (outputs.empty()) {
    // SCENE.exr in the working directory ("dir/" names dir: the scene load then says what is wrong with it).
    fs::path scene = fs::path(o.scene).lexically_normal();
    if (!scene.has_filename()) scene = scene.parent_path();
    std::string stem = scene.stem().string();
    if (stem.empty() || stem == "." || stem == "..") stem = "render";
    outputs.push_back(animated ? escape_percent(stem) + "_%04d.exr" : stem + ".exr");
  }
  for (const std::string& out : outputs)
    if (image_format_of(out) == image_format::unknown)
      throw usage_error("output " + out + ": unknown image format (use .exr, .pfm or .png)");
  if (!o.log.empty()) {
    // A log named like an image or a scene is a slip (--log ref.exr for --reference ref.exr replaced the reference
    // with CSV text; a review): refused before anything is written.
    const std::string ext = lower_extension(o.log);
    if (image_format_of(o.log) != image_format::unknown || ext == ".obj" || ext == ".mtl" || ext == ".json")
      throw usage_error("--log " + o.log + ": the per-pass log is CSV text and would replace a file of that kind; "
                        "name it .csv (an error reference is given with --reference)");
  }
  if (animated) {
    // Every per-frame file names its frame with a printf pattern such as out_%04d.exr.
    const std::string how = " (one %d such as out_%04d.exr; a '%' in the name is written %%): ";
    for (const std::string& out : outputs)
      if (!is_frame_pattern(out)) throw usage_error("--frames needs a frame pattern in -o" + how + out);
    if (!o.log.empty() && !is_frame_pattern(o.log))
      throw usage_error("--frames needs a frame pattern in --log" + how + o.log);
    if (!o.reference.empty() && !is_frame_pattern(o.reference))
      throw usage_error("--frames needs a frame pattern in --reference" + how + o.reference);
  } else {
    // A still render writes a name as given: a frame pattern there is likely a forgotten --frames.
    for (const std::string& out : o.outputs)  // (as given: a scene named with one gives its default output one too)
      if (is_frame_pattern(out))
        std::fprintf(stderr, "bayeslight: warning: -o %s is a frame pattern, but without --frames the render is one "
                     "image, written under that name as it stands\n", out.c_str());
  }
  return outputs;
}

// Restores the checkpoint --resume names (its bytes in resume_bytes, released once decoded) into r and s, and says
// what the render continues and adds; refuses a --spp below the saved one.
void resume_render(const render_options& o, const render_params& params, const std::vector<std::string>& outputs,
                   const render_fingerprint_data& fingerprint, const std::vector<uint64_t>& reference_keys,
                   std::string& resume_bytes, render_result& r, light_sampler& s) {
  const bool animated = o.frames > 0;
  uint64_t measured = decode_checkpoint(resume_bytes, o.resume, fingerprint, params, r, s);
  // Decoded: the file's bytes (the size of the sampler's state, 100 MB and more) were held for the whole render
  // (a review: 343 MB against 222 MB resident).
  std::string().swap(resume_bytes);
  const uint64_t reference_key = reference_keys[size_t(r.frame)];
  // Samples cannot be taken back out of a checkpoint: a smaller --spp would silently write the larger image.
  if (params.time_budget <= 0 && r.spp > params.spp)
    throw usage_error((o.spp > 0 ? "--spp " + std::to_string(params.spp)
                                 : "the scene's render.spp (" + std::to_string(params.spp) + ")") +
                      " is below the " + std::to_string(r.spp) + " spp already in " + o.resume + ": give --spp " +
                      std::to_string(r.spp) + " or more, or --time");
  // An animation's checkpoint of frame k: frames 0 to k - 1 were written by the render that saved it (they are not
  // rendered again: frame k needs what they learned, and their state is gone).
  std::string missing;
  int count = 0;
  for (int f = 0; f < r.frame; f++)
    for (const std::string& out : outputs) {
      std::string file = frame_path(out, f, animated);
      if (!fs::exists(file) && count++ == 0) missing = file;
    }
  // What the render continues, and what it adds: its spp, seconds and --time budget count the checkpoint's (an
  // animation's: those of the frame under way).
  const bool budget_spent = params.time_budget > 0 && r.seconds >= params.time_budget;
  if (count > 0 || !o.quiet) {
    const std::string none = animated ? "frame " + std::to_string(r.frame) + " adds no pass" : "no pass is added";
    char at[160], budget[160] = "";
    if (animated)
      std::snprintf(at, sizeof at, "the animation at frame %d of %d, %d spp into it (%d pass%s, %.3g s%s)", r.frame,
                    params.frames, r.spp, r.passes, r.passes == 1 ? "" : "es", r.seconds,
                    r.frame > 0 ? ("; " + frames_were(0, r.frame - 1) + " rendered before").c_str() : "");
    else
      std::snprintf(at, sizeof at, "at %d spp (%d pass%s, %.3g s rendered before)", r.spp, r.passes,
                    r.passes == 1 ? "" : "es", r.seconds);
    if (budget_spent)
      std::snprintf(budget, sizeof budget, "; --time %g counts them and is spent: %s", params.time_budget,
                    none.c_str());
    else if (params.time_budget > 0)
      std::snprintf(budget, sizeof budget, "; --time %g counts them: %.3g s left", params.time_budget,
                    params.time_budget - r.seconds);
    else if (params.spp == r.spp)
      std::snprintf(budget, sizeof budget, "; --spp %d: %s", params.spp, none.c_str());
    std::fprintf(stderr, "%s: resuming %s%s%s\n", o.resume.c_str(), at, budget,
                 count == 0 ? ""
                            : ("; warning: " + missing +
                               (count > 1 ? " and " + std::to_string(count - 1) + " more of those frames' files are"
                                          : " is") +
                               " missing (a frame cannot be rendered alone: render the animation again for it)")
                                  .c_str());
  }
  // The log is one error curve against one reference: rows measured against another one (or none) keep their
  // pass, spp and time but lose their errors (before, the relMSE column jumped at the resumed pass unexplained).
  if (measured != reference_key && !r.log.empty()) {
    for (pass_record& p : r.log) p.has_error = false;
    if (!o.log.empty())  // (said where a log is written)
      std::fprintf(stderr, "%s: warning: its %d passes were %s; their rows of the log have no error values\n",
                   o.resume.c_str(), r.passes,
                   measured == 0        ? "rendered without --reference"
                   : reference_key == 0 ? "measured against a reference, and this render has none"
                                        : "measured against another reference");
  }
  // An adaptive sampler's passes after a truncated one learn from other sample counts (and weigh theirs
  // otherwise) than one render's: still a correct image, but not the bytes the README promises at pass ends.
  // --light-points auto likewise: each pass draws its light points from a set of its own, with counts chosen from
  // the passes before it, so the rest of a truncated pass is a pass of its own. Every pass of the saved render counts
  // (a checkpoint of 10 spp reached through one of 9 is off schedule too).
  int off = 0;
  for (const pass_record& p : r.log)
    if (!ends_scheduled_pass(p.spp, int64_t(r.width) * r.height)) {
      off = p.spp;
      break;
    }
  const bool adapts = sampler_adapts(s) || params.light_points == 0;
  if (adapts && off > 0 && (params.time_budget > 0 ? !budget_spent : params.spp > r.spp))
    std::fprintf(stderr,
                 "%s: warning: its pass ending at %d spp did not end a scheduled pass (as 8 10 12 15 18 22 27 33 "
                 "... do; a --time render cuts its last pass to the time left): the continued image is correct, but not "
                 "bit-identical to one render of the final spp\n",
                 o.resume.c_str(), off);
}

// Says how an interrupted render ended (interrupted: in a pass, else after one; last_frame and last_passes: the last
// frame whose outputs were written, and its passes; checkpoint_ok: no checkpoint failed to be written) and how to
// go on; returns the exit status, 128 + signal.
int report_interruption(const render_options& o, int frames, bool interrupted, int last_frame, int last_passes,
                        bool checkpoint_ok) {
  int sig = interrupt_signal();
  const std::string rest = frames_were(last_frame + 1, frames - 1);  // (the frames after last_frame)
  if (interrupted && frames > 1)  // (in an animation's frame: say what is left, and how to go on)
    std::fprintf(stderr, "bayeslight: the animation stopped in frame %d of %d%s%s\n", last_frame, frames,
                 last_frame + 1 < frames ? ("; " + rest + " not rendered").c_str() : "",
                 o.checkpoint.empty() ? "" : ("; --resume " + o.checkpoint + " continues it").c_str());
  else if (!interrupted && last_frame + 1 < frames)  // (between an animation's frames)
    std::fprintf(stderr, "bayeslight: interrupted (%s) after frame %d; %s not rendered%s\n", signal_name(sig),
                 last_frame, rest.c_str(),
                 o.checkpoint.empty() ? "" : ("; --resume " + o.checkpoint + " renders them").c_str());
  else if (!interrupted)
    std::fprintf(stderr, "bayeslight: interrupted (%s) after the last pass; every output was written\n",
                 signal_name(sig));
  else if (!o.checkpoint.empty() && checkpoint_ok && last_passes > 0)  // (a still render)
    std::fprintf(stderr, "bayeslight: %s holds the render; --resume %s continues it\n", o.checkpoint.c_str(),
                 o.checkpoint.c_str());
  return 128 + (sig != 0 ? sig : SIGINT);
}

int run_render(const render_options& o) {
  // (Held back until the handlers are installed below, in the mode the checkpoint's header decides: none takes the
  // default action, and one that came first is delivered there.)
  block_interrupt_signals();
  // A render saved at --checkpoint that this one does not resume would be replaced by this one's first checkpoint:
  // it is said, and a signal before this render's first pass ends (the user's answer to that) writes nothing.
  std::error_code ec;
  const bool resumes_it = !o.resume.empty() && fs::equivalent(o.resume, o.checkpoint, ec);
  const bool replaces_saved = !o.checkpoint.empty() && !resumes_it && holds_checkpoint(o.checkpoint);
  // A first signal from here on lets the render go on to write the image of a first pass (of the checkpoint's passes
  // when resuming), except where that would replace a saved render, or follow --bayes-oracle's learning cut short
  // (the set-up then ends at once, as before any learning).
  // A resumed checkpoint without a pass of its frame (an animation stopped before that frame's first) has no image to
  // write: a signal in the set-up ends the render at once, as in a later frame of one render (left over at stop 43:
  // the message promised the image of the checkpoint's passes, and nothing came).
  const bool resumes_no_pass = !o.resume.empty() && saved_passes(o.resume, std::max(1, o.frames)) == 0;
  install_interrupt_handlers(!replaces_saved && !resumes_no_pass && (o.bayes.oracle_spp == 0 || !o.resume.empty()),
                             !o.resume.empty());
  sampler_kind kind;
  if (!parse_sampler_kind(o.sampler, kind))
    throw usage_error("unknown sampler \"" + o.sampler + "\" (valid: " + sampler_names() + ")");
  const bool animated = o.frames > 0;  // --frames given: names are frame patterns (even for one frame)
  const std::vector<std::string> outputs = checked_output_names(o);
  warn_unused_options(o, {kind});
  // Every frame's files (a folder that exists for frame 0 only would fail them after their renders).
  for (int f = 0; f < std::max(1, o.frames); f++) {
    for (const std::string& out : outputs) check_output_path(frame_path(out, f, animated));
    if (!o.log.empty()) check_output_path(frame_path(o.log, f, animated));
  }
  if (!o.checkpoint.empty()) check_output_path(o.checkpoint);
  // (A render saved there is lost at this one's first checkpoint: a forgotten --resume, or a second render's slip.)
  if (replaces_saved)
    std::fprintf(stderr, "bayeslight: warning: %s holds a saved render, which this render's first checkpoint "
                         "replaces (--resume %s continues that render instead; interrupted before its first pass "
                         "ends, this render writes nothing)\n", o.checkpoint.c_str(), o.checkpoint.c_str());
  std::string resume_bytes;
  if (!o.resume.empty()) resume_bytes = read_file(o.resume);

  scene_desc desc = load_scene_desc(o.scene);
  render_params params = resolve_params(o, desc, kind);
  params.finish_first_pass = !replaces_saved;  // (an interrupted render has an image to write)
  params.signals_in_first_pass = o.signals_in_first_pass;
  params.signal_frame = o.signal_frame;
  warn_after_scene(o, params, {kind});
  if (o.frames > 1 && !(desc.sun.enabled && desc.sun.animated))
    std::fprintf(stderr, "%s: warning: %s, so the %d frames show the same scene (the sun moves to sun.direction_end)\n",
                 o.scene.c_str(), desc.sun.enabled ? "the sun has no \"direction_end\"" : "the scene has no sun",
                 o.frames);
  std::vector<image_data> references;
  if (!o.reference.empty())
    for (int f = 0; f < params.frames; f++)
      references.push_back(load_reference(frame_path(o.reference, f, animated), params));
  for (const image_data& r : references) params.frame_references.push_back(&r);
  auto t_load = std::chrono::steady_clock::now();
  std::optional<slow_phase_note> loading(std::in_place, params.notes, "loading " + o.scene + " ...");
  scene_data scene = build_scene(desc, float(params.width) / float(params.height));
  report_dropped_triangles(desc.mesh_path, scene.mesh.dropped_degenerate, scene.mesh.first_degenerate_line);
  {
    std::vector<std::pair<std::string, std::string>> outs, ins = {{o.scene, "scene file"}};
    for (int f = 0; f < params.frames; f++) {
      for (const std::string& out : outputs) outs.push_back({frame_path(out, f, animated), "output"});
      if (!o.log.empty()) outs.push_back({frame_path(o.log, f, animated), "log"});
      if (!o.reference.empty()) ins.push_back({frame_path(o.reference, f, animated), "reference"});
    }
    if (!o.checkpoint.empty()) outs.push_back({o.checkpoint, "checkpoint"});
    for (const std::string& src : scene.mesh.source_files) ins.push_back({src, "scene input"});
    if (!o.resume.empty()) ins.push_back({o.resume, resumed_role});
    check_distinct_outputs(outs, ins);
  }
  auto t_bvh = std::chrono::steady_clock::now();
  bvh_data bvh = build_bvh(scene);
  light_data lights = build_lights(scene);
  loading.reset();
  warn_about_lights(o.scene, scene, bvh, lights);
  warn_coarse_grid(o, params, scene, lights);
  if (!o.quiet) {
    auto t_end = std::chrono::steady_clock::now();
    std::fprintf(stderr, "%s: %zu triangles, %d lights%s; loaded in %.2f s, Embree BVH and lights in %.2f s\n",
                 o.scene.c_str(), scene.tri_area.size(), lights.count, lights.sun != invalid_id ? " (sun included)" : "",
                 std::chrono::duration<double>(t_bvh - t_load).count(),
                 std::chrono::duration<double>(t_end - t_bvh).count());
  }

  // (Hashed only for a checkpoint or a resume: every mesh value is hashed twice, for the total and for its part.)
  const render_fingerprint_data fingerprint =
      o.checkpoint.empty() && o.resume.empty() ? render_fingerprint_data{} : render_fingerprint(scene, params);
  // Per frame: the hash of the reference a frame's logged errors are measured against (0: none).
  std::vector<uint64_t> reference_keys;
  for (int f = 0; f < params.frames; f++)
    reference_keys.push_back(reference_hash(references.empty() ? nullptr : &references[size_t(f)]));
  // (testing: the render's set-up calls restore)
  const int setup_signals = o.stop_after_passes == 0 ? 1 : o.signals_in_setup;
  if (setup_signals != 0 || !o.resume.empty())
    params.restore = [&](render_result& r, light_sampler& s) {
      for (int k = 0; k < std::abs(setup_signals); k++) {
        if (k > 0 && setup_signals < 0) std::this_thread::sleep_for(std::chrono::milliseconds(600));
        std::raise(SIGINT);
      }
      if (o.resume.empty()) return;
      resume_render(o, params, outputs, fingerprint, reference_keys, resume_bytes, r, s);
    };
  auto last_write = std::chrono::steady_clock::now();
  // A checkpoint that cannot be written (a full disk) is reported and the render goes on: its image is still
  // written, and the exit status is 1 at the end.
  std::string checkpoint_failure;
  int earlier_passes = 0;  // passes of the frames this run completed before (the testing aids count over frames)
  params.on_pass = [&](const render_result& r, const light_sampler& s, bool last) {
    const int passes = earlier_passes + r.passes;
    if (!last && o.stop_after_passes > 0 && passes == o.stop_after_passes) std::raise(SIGINT);
    if (last && o.signal_after_last_pass) std::raise(SIGINT);
    // A render stopped before its first pass has nothing to save: a checkpoint already there is kept. An animation's
    // later frame stopped so has: the statistics the earlier frames left it (decayed), from which it resumes (the end
    // of the frame before was saved only when due; a review: nothing to resume from after a signal in frame 1).
    if (o.checkpoint.empty() || (r.passes == 0 && !(last && r.frame > 0))) return;
    auto now = std::chrono::steady_clock::now();
    bool due = std::chrono::duration<double>(now - last_write).count() >= o.checkpoint_every;
    // The end of the render is always saved; an animation's other frame ends only when due (100 short frames
    // wrote 100 checkpoints in a few seconds).
    bool end = last && (r.frame == params.frames - 1 || r.interrupted || interrupt_signal() != 0);
    if (!end && !due && passes != o.kill_after_passes) return;
    try {
      write_checkpoint(o.checkpoint, fingerprint, reference_keys[size_t(r.frame)], r, s, params.frames);
    } catch (const output_error& e) {
      if (checkpoint_failure.empty())
        std::fprintf(stderr, "bayeslight: warning: %s; the render %s without it\n", e.what(),
                     interrupt_signal() != 0 ? "stops after this pass" : "goes on");
      checkpoint_failure = e.what();
    }
    last_write = now;
    if (!last && o.kill_after_passes > 0 && passes == o.kill_after_passes) std::raise(SIGKILL);
  };

  if (int status = interrupted_before_render()) return status;
  bool interrupted = false;
  output_failures failures;  // every output is tried (and every frame rendered) whatever failed before it
  failures.say_now = params.frames > 1;
  int last_frame = -1;  // the last frame whose outputs were written
  int last_passes = 0;  // ... and its passes (none: a checkpoint there is an earlier render's)
  render_frames(scene, bvh, lights, params, [&](int frame, const render_result& result) {
    earlier_passes += result.passes;
    last_frame = frame;
    std::vector<std::string> files;
    // (A 4096^2 EXR takes seconds to compress and write after the bar has reached its end.)
    std::optional<slow_phase_note> writing;
    if (!outputs.empty() && result.spp > 0)
      writing.emplace(params.notes, "writing " + frame_path(outputs[0], frame, animated) +
                                        (outputs.size() > 1 ? " and the other outputs ..." : " ..."));
    if (result.spp > 0) {
      image_data img = film_image(result);
      for (const std::string& out : outputs) {
        std::string f = frame_path(out, frame, animated);
        if (failures.attempt([&] { write_image(f, img); })) files.push_back(f);
      }
    }
    writing.reset();
    // (Nor a log without a pass: a file already there is kept, as the image is.)
    if (!o.log.empty() && result.passes > 0)
      failures.attempt(
          [&] { write_file_atomic(frame_path(o.log, frame, animated), pass_log_csv(o.sampler, result.log)); });
    // (--quiet too when a signal came, during the render or while the outputs were written: say what was written)
    if (!o.quiet || result.interrupted || interrupt_signal() != 0) {
      std::string prefix = params.frames > 1 ? "frame " + std::to_string(frame) + ": " : "";
      std::fprintf(stderr, "%s%s\n", prefix.c_str(), render_summary(result, files).c_str());
    }
    interrupted = result.interrupted;
    last_passes = result.passes;
  });
  failures.rethrow();  // (main exits 128 + signal when a signal came, else 1)
  // A signal that came after the last pass (while the outputs were written) still ends the run as interrupted.
  if (interrupted || interrupt_signal() != 0)
    return report_interruption(o, params.frames, interrupted, last_frame, last_passes, checkpoint_failure.empty());
  if (!checkpoint_failure.empty()) throw output_error(checkpoint_failure);  // (the image is written)
  return exit_ok;
}

int run_diff(const diff_options& o) {
  if (!o.error_map.empty() && image_format_of(o.error_map) == image_format::unknown)
    throw usage_error("--error-map " + o.error_map + ": unknown image format (expected .exr, .pfm or .png)");
  image_data a = read_image(o.a), b = read_image(o.b);
  if (a.width != b.width || a.height != b.height)
    throw input_error(o.b, "size " + std::to_string(b.width) + "x" + std::to_string(b.height) + " differs from " +
                               o.a + " (" + std::to_string(a.width) + "x" + std::to_string(a.height) + ")");
  // Bit-equal pixel data are identical whatever they hold (SPEC 4), NaN and infinities included: no error.
  const bool identical = bit_identical(a, b);
  error_metrics e;
  if (!identical) {
    // Otherwise a non-finite pixel has no error: say where it is rather than print nan (exit 3, like a reference's).
    require_finite(a, o.a, "image");
    require_finite(b, o.b, "image");
    e = compute_error(a, b);
  }
  error_spread spread;
  if (o.worst > 0 || !o.error_map.empty()) {
    if (identical) spread.term.assign(size_t(b.width) * size_t(b.height), 0.0);  // (no error, NaN pixels included)
    else spread = spread_of_error(a, b, size_t(o.worst));
  }
  if (!o.error_map.empty()) {
    // .png: compare's false-colour image (error_image.h); .exr/.pfm: each pixel's relMSE term in its three channels.
    if (image_format_of(o.error_map) == image_format::png) {
      write_error_image(o.error_map, a, b, error_image_params{});
    } else {
      image_data map;
      map.width = b.width, map.height = b.height;
      map.pixels.resize(spread.term.size() * 3);
      for (size_t i = 0; i < spread.term.size(); i++)
        map.pixels[3 * i] = map.pixels[3 * i + 1] = map.pixels[3 * i + 2] = float(spread.term[i]);
      write_image(o.error_map, map);
    }
  }
  if (identical) {
    std::printf("relmse=0 mse=0 maxabs=0\nidentical\n");
    return exit_ok;
  }
  std::printf("relmse=%.9g mse=%.9g maxabs=%.9g\n", e.relmse, e.mse, e.maxabs);
  if (o.worst > 0) {
    std::printf("worst pixels:");
    for (int k = 0; k < 3; k++)
      std::printf("%s %g%% (%zu) %s%.1f%%%s", k > 0 ? "," : "", 100 * error_tail_fractions[k], spread.tail_pixels[k],
                  k == 0 ? "hold " : "", 100 * spread.tail_share[k], k == 0 ? " of the relmse" : "");
    std::printf("\n");
    const double total = e.relmse * double(spread.term.size());
    for (size_t i : spread.worst) {
      const float *x = &a.pixels[3 * i], *r = &b.pixels[3 * i];
      std::printf("pixel %zu %zu: %.2f%% of the relmse; value %.6g %.6g %.6g, reference %.6g %.6g %.6g\n",
                  i % size_t(b.width), i / size_t(b.width), total > 0 ? 100 * spread.term[i] / total : 0.0, x[0], x[1],
                  x[2], r[0], r[1], r[2]);
    }
  }
  return exit_ok;
}

// ---- profile: where the time of a render goes ----

int run_profile_command(const render_options& o) {
  install_interrupt_handlers();
  sampler_kind kind;
  if (!parse_sampler_kind(o.sampler, kind))
    throw usage_error("unknown sampler \"" + o.sampler + "\" (valid: " + sampler_names() + ")");
  warn_unused_options(o, {kind});
  scene_desc desc = load_scene_desc(o.scene);
  render_params params = resolve_params(o, desc, kind);
  warn_after_scene(o, params, {kind});
  std::optional<slow_phase_note> loading(std::in_place, params.notes, "loading " + o.scene + " ...");
  params.progress = false;  // (the timed stages must not share the machine with the bar; the notes stay)
  scene_data scene = build_scene(desc, float(params.width) / float(params.height));
  bvh_data bvh = build_bvh(scene);
  light_data lights = build_lights(scene);
  loading.reset();
  warn_coarse_grid(o, params, scene, lights);
  if (int status = interrupted_before_render()) return status;
  std::string report = profile_render(scene, bvh, lights, params, o.scene + " with the " + o.sampler + " sampler");
  std::fputs(report.c_str(), stdout);
  return interrupt_signal() != 0 ? 128 + interrupt_signal() : exit_ok;
}

// ---- compare: equal-time (or equal-spp) comparison of samplers (compare.h does the work) ----

int run_compare_command(const compare_options& o) {
  install_interrupt_handlers();  // (a signal while the scene loads ends the command at once)
  compare_params cp;
  std::vector<std::string> names;
  for (size_t b = 0;;) {
    size_t e = o.samplers.find(',', b);
    // Blanks around a name are dropped ("bound, bayes", as a list is often written).
    std::string name = o.samplers.substr(b, e == std::string::npos ? std::string::npos : e - b);
    const size_t first = name.find_first_not_of(" \t"), last = name.find_last_not_of(" \t");
    names.push_back(first == std::string::npos ? std::string() : name.substr(first, last - first + 1));
    if (e == std::string::npos) break;
    b = e + 1;
  }
  for (const std::string& name : names) {
    if (name.empty()) throw usage_error("--samplers \"" + o.samplers + "\" has an empty name (e.g. bound,bayes)");
    sampler_kind kind;
    if (!parse_sampler_kind(name, kind))
      throw usage_error("unknown sampler \"" + name + "\" (valid: " + sampler_names() + ")");
    if (!sampler_available(kind)) throw usage_error("sampler \"" + name + "\" is not implemented yet in this build");
    if (std::find(cp.samplers.begin(), cp.samplers.end(), kind) != cp.samplers.end())
      throw usage_error("sampler \"" + name + "\" is given twice in --samplers");
    cp.samplers.push_back(kind);
  }
  if (cp.samplers.empty()) throw usage_error("--samplers names no sampler");
  if ((o.render.spp > 0) == (o.render.time > 0)) throw usage_error("compare needs exactly one of --time and --spp");
  if (o.render.frames > 0 || !o.render.checkpoint.empty() || !o.render.resume.empty())
    throw usage_error("--frames, --checkpoint and --resume are options of render, not of compare");
  warn_unused_options(o.render, cp.samplers);
  scene_desc desc = load_scene_desc(o.render.scene);
  cp.render = resolve_params(o.render, desc, cp.samplers[0]);
  warn_after_scene(o.render, cp.render, cp.samplers);
  cp.runs = o.runs;
  cp.scene_path = o.render.scene;
  cp.reference_path = o.render.reference;
  cp.reference_note = o.reference_note;
  cp.out_dir = o.out;
  cp.quiet = o.render.quiet;
  cp.grid_given = option_given(o.render, "--grid");
  return run_compare(desc, cp);
}

}  // namespace

// Prints the help CLI11 was asked for (to std::cout); help that could not be written (a full disk) is a failure.
static int help_exit(CLI::App& app, const CLI::Error& e) {
  int status = app.exit(e);
  std::cout.flush();
  if (!std::cout) {
    std::fprintf(stderr, "bayeslight: error: cannot write standard output\n");
    return exit_failure;
  }
  return status;
}

int run_cli(int argc, char** argv) {
  // A reader that goes away (a pipe into head, a FIFO output's reader) makes writes fail with EPIPE, reported as
  // write failures (stdout, outputs), instead of killing the process between outputs; stderr's messages are lost.
  std::signal(SIGPIPE, SIG_IGN);
  CLI::App app{"bayeslight — deterministic path tracer with Bayesian light selection for NEE"};
  app.require_subcommand(1);
  app.footer(
      "Examples:\n"
      "  bayeslight render scene.json -o out.exr --spp 256\n"
      "  bayeslight render scene.json --time 10 --reference ref.exr --log log.csv -o out.png\n"
      "  bayeslight compare scene.json --reference ref.exr --time 10 --samplers bound,bayes --out cmp\n"
      "  bayeslight profile scene.json --sampler bayes --time 10\n"
      "  bayeslight diff out.exr ref.exr\n"
      "Each command's options: bayeslight COMMAND --help. The version and build: bayeslight --version.\n"
      "Exit status: 0 success; 1 other failure (e.g. an output that cannot be written); 2 bad command line; 3 bad "
      "input (the message names the file and line); 130/143/129 interrupted (SIGINT/SIGTERM/SIGHUP): an interrupted "
      "render or compare first writes the image of the passes completed.");
  render_options ro;
  diff_options dopt;
  compare_options copt;
  add_render_command(app, ro);
  add_compare_command(app, copt);
  render_options popt;
  add_profile_command(app, popt);
  CLI::App* diff = app.add_subcommand("diff", "Compare two images: relmse, mse, maxabs; 'identical' if bit-equal");
  diff->add_option("A", dopt.a, "Image (.exr/.pfm)")->required()->type_name("FILE");
  diff->add_option("B", dopt.b, "Image (.exr/.pfm), the reference")->required()->type_name("FILE");
  diff->add_option("--worst", dopt.worst,
                   "Also print the share of the relmse the worst 0.1 %, 1 % and 5 % of the pixels hold, and the N worst "
                   "pixels (x y from the top left, their share, both values): fireflies or noise spread over the image")
      ->check(CLI::Range(0, 1000000))
      ->type_name("N");
  diff->add_option("--error-map", dopt.error_map,
                   "Write where the error lies to FILE: .exr/.pfm each pixel's relmse term (the mean of its channels' "
                   "(a - b)^2 / (b^2 + 0.01); the image's mean is the relmse) in all three channels; .png compare's "
                   "false-colour relative error |a - b| / (|b| + 0.1) (viridis, log scale from 1e-3 to 1)")
      ->type_name("FILE");
  std::string first = argc >= 2 ? argv[1] : "";
  if (argc == 2 && (first == "--version" || first == "-V")) {
    print_version();
    // (stdout full or closed: a failure, as for diff's output)
    if (std::fflush(stdout) != 0 || std::ferror(stdout)) {
      std::fprintf(stderr, "bayeslight: error: cannot write to standard output\n");
      return exit_failure;
    }
    return exit_ok;
  }
  if (!first.empty() && first[0] != '-' && first != "render" && first != "diff" && first != "compare" &&
      first != "profile") {
    std::fprintf(stderr, "bayeslight: error: unknown command \"%s\" (commands: render, compare, profile, diff)\n"
                         "Run with --help for more information.\n", first.c_str());
    return exit_usage;
  }
  for (CLI::App* command : app.get_subcommands({}))
    for (CLI::Option* opt : command->get_options())
      if (opt->get_type_name().rfind("INT", 0) == 0) opt->transform(decimal_integer);
      else if (opt->get_type_name().rfind("FLOAT", 0) == 0) opt->transform(decimal_number);
  try {
    app.parse(argc, argv);
    // The options given, with their help groups (what they apply to), for warn_unused_options.
    for (auto [command, opts] : {std::pair{"render", &ro}, std::pair{"compare", &copt.render}, std::pair{"profile", &popt}})
      if (app.got_subcommand(command))
        for (CLI::Option* opt : app.get_subcommand(command)->get_options())
          if (opt->count() > 0 && !opt->get_lnames().empty())
            opts->given.emplace_back("--" + opt->get_lnames()[0], opt->get_group());
  } catch (const CLI::CallForHelp& e) {
    return help_exit(app, e);
  } catch (const CLI::CallForAllHelp& e) {
    return help_exit(app, e);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);
    // The parser's own messages (an unknown option, a value out of range) carry the prefix every other error has.
    std::fprintf(stderr, "bayeslight: error: %s\nRun with --help for more information.\n", e.what());
    return exit_usage;
  }
  try {
    int status = exit_usage;
    if (app.got_subcommand("render")) status = run_render(ro);
    else if (app.got_subcommand("diff")) status = run_diff(dopt);
    else if (app.got_subcommand("compare")) status = run_compare_command(copt);
    else if (app.got_subcommand("profile")) status = run_profile_command(popt);
    // What diff and profile print is their output: a full disk or a closed stdout is a write failure, not exit 0.
    errno = 0;
    if ((std::fflush(stdout) != 0 || std::ferror(stdout)) && status == exit_ok)
      throw output_error(std::string("cannot write standard output: ") + std::strerror(errno ? errno : EIO));
    return status;
  } catch (const usage_error& e) {
    std::fprintf(stderr, "bayeslight: error: %s\nRun with --help for more information.\n", e.what());
    return exit_usage;
  } catch (const input_error& e) {
    std::fprintf(stderr, "bayeslight: error: %s\n", e.what());
    return exit_bad_input;
  } catch (const output_error& e) {
    std::fprintf(stderr, "bayeslight: error: %s\n", e.what());
    // An output that failed in a run a signal interrupted (a signal that ended a FIFO's wait for its reader, or a
    // write failing while an interrupted render wrote its passes): the interrupted run's status, 128 + signal.
    return interrupt_signal() != 0 ? 128 + interrupt_signal() : exit_failure;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "bayeslight: error: out of memory\n");
    return exit_failure;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bayeslight: error: %s\n", e.what());
    return exit_failure;
  }
  return exit_usage;
}

}  // namespace bl
