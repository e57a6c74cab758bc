// cli: parses the command line with CLI11, runs the subcommand, and maps failures to exit statuses
// (0 ok, 1 other failure, 2 bad command line, 3 bad input, 128+signal after an interrupted render).
#include "cli.h"

#include "bvh.h"
#include "errors.h"
#include "file_io.h"
#include "image_io.h"
#include "lights.h"
#include "metrics.h"
#include "progress.h"
#include "render.h"
#include "report.h"
#include "scene.h"
#include "scene_desc.h"

#include <CLI/CLI.hpp>

#include <unistd.h>

#include <climits>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <iostream>

namespace bl {

namespace {

namespace fs = std::filesystem;

// Options of `render` as given on the command line (unset ones fall back to the scene file).
struct render_options {
  std::string scene;
  std::string sampler = "bayes";
  int spp = 0;
  double time = 0;
  int max_depth = 0;
  int threads = 0;
  uint64_t seed = 0;
  bool has_seed = false;
  int width = 0, height = 0;
  std::vector<std::string> outputs;
  std::string reference;
  std::string log;
  bool quiet = false;
  region_params regions;
  bayes_params bayes;
  std::string bayes_pmf = "second-moment";
};

// Options of `diff`.
struct diff_options {
  std::string a, b;
};

// Largest image a command line may ask for (same limits as scene files).
constexpr long long max_side = 65536;
constexpr long long max_pixels = 1ll << 28;

// Checks that an output path can be written before spending time on a render.
void check_output_path(const std::string& path) {
  fs::path p(path);
  fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
  std::error_code ec;
  if (fs::is_directory(p, ec)) throw output_error("cannot write " + path + ": is a directory");
  if (!fs::is_directory(dir, ec)) throw output_error("cannot write " + path + ": directory " + dir.string() + " does not exist");
  if (access(dir.c_str(), W_OK) != 0) throw output_error("cannot write " + path + ": directory " + dir.string() + " is not writable");
}

// The validated render parameters of a scene and the command line.
render_params resolve_params(const render_options& o, const scene_desc& desc, sampler_kind kind) {
  render_params p;
  p.width = o.width > 0 ? o.width : desc.width;
  p.height = o.height > 0 ? o.height : desc.height;
  if ((long long)p.width * p.height > max_pixels)
    throw usage_error("image of " + std::to_string(p.width) + "x" + std::to_string(p.height) +
                      " pixels is too large (at most 2^28 pixels)");
  p.spp = o.spp > 0 ? o.spp : desc.spp;
  p.time_budget = o.time;
  p.max_depth = o.max_depth > 0 ? o.max_depth : desc.max_depth;
  p.seed = o.has_seed ? o.seed : desc.seed;
  p.threads = o.threads;
  p.sampler.kind = kind;
  p.sampler.regions = o.regions;
  p.sampler.bayes = o.bayes;
  p.sampler.bayes.second_moment = o.bayes_pmf == "second-moment";
  p.progress = !o.quiet && stderr_is_terminal();
  return p;
}

int run_render(const render_options& o) {
  sampler_kind kind;
  if (!parse_sampler_kind(o.sampler, kind))
    throw usage_error("unknown sampler \"" + o.sampler + "\" (valid: " + sampler_names() + ")");
  if (!sampler_available(kind))
    throw usage_error("sampler \"" + o.sampler + "\" is not implemented yet in this build");
  std::vector<std::string> outputs = o.outputs;
  if (outputs.empty()) outputs.push_back(fs::path(o.scene).stem().string() + ".exr");
  for (const std::string& out : outputs)
    if (image_format_of(out) == image_format::unknown)
      throw usage_error("output " + out + ": unknown image format (use .exr, .pfm or .png)");
  for (const std::string& out : outputs) check_output_path(out);
  if (!o.log.empty()) check_output_path(o.log);

  scene_desc desc = load_scene_desc(o.scene);
  render_params params = resolve_params(o, desc, kind);
  image_data reference;
  if (!o.reference.empty()) {
    reference = read_image(o.reference);
    if (reference.width != params.width || reference.height != params.height)
      throw input_error(o.reference, "reference is " + std::to_string(reference.width) + "x" +
                                         std::to_string(reference.height) + " but the render is " +
                                         std::to_string(params.width) + "x" + std::to_string(params.height));
    params.reference = &reference;
  }
  scene_data scene = build_scene(desc, float(params.width) / float(params.height));
  if (scene.mesh.dropped_degenerate > 0)
    std::fprintf(stderr, "%s: dropped %d degenerate (zero-area) triangles\n", desc.mesh_path.c_str(),
                 scene.mesh.dropped_degenerate);
  bvh_data bvh = build_bvh(scene);
  light_data lights = build_lights(scene);
  if (lights.count == 0) std::fprintf(stderr, "%s: warning: the scene has no emitters (the image is black)\n",
                                      o.scene.c_str());

  install_interrupt_handlers();
  render_result result = render(scene, bvh, lights, params);
  int sig = interrupt_signal();

  if (result.spp > 0) {
    image_data img = film_image(result);
    for (const std::string& out : outputs) write_image(out, img);
  }
  if (!o.log.empty()) write_file_atomic(o.log, pass_log_csv(o.sampler, result.log));
  if (!o.quiet || result.interrupted) std::fprintf(stderr, "%s\n", render_summary(result, outputs).c_str());
  if (result.interrupted) return 128 + (sig != 0 ? sig : SIGINT);
  return exit_ok;
}

int run_diff(const diff_options& o) {
  image_data a = read_image(o.a), b = read_image(o.b);
  if (a.width != b.width || a.height != b.height)
    throw input_error(o.b, "size " + std::to_string(b.width) + "x" + std::to_string(b.height) + " differs from " +
                               o.a + " (" + std::to_string(a.width) + "x" + std::to_string(a.height) + ")");
  error_metrics e = compute_error(a, b);
  std::printf("relmse=%.9g mse=%.9g maxabs=%.9g\n", e.relmse, e.mse, e.maxabs);
  if (bit_identical(a, b)) std::printf("identical\n");
  return exit_ok;
}

void add_render_command(CLI::App& app, render_options& o) {
  CLI::App* r = app.add_subcommand("render", "Render a scene (.json scene file or bare .obj)");
  r->add_option("SCENE", o.scene, "Scene file (.json) or mesh (.obj)")->required();
  r->add_option("--sampler", o.sampler, "Light selection for NEE: " + sampler_names() + " (default bayes)");
  auto* spp = r->add_option("--spp", o.spp, "Samples per pixel (default: the scene's render.spp)")
                  ->check(CLI::Range(1, INT_MAX));
  auto* time = r->add_option("--time", o.time, "Render whole passes until this many seconds are spent")
                   ->check(CLI::Range(1e-6, 1e9));
  spp->excludes(time);
  r->add_option("--max-depth", o.max_depth, "Path length in bounces; 1 = direct illumination only")
      ->check(CLI::Range(1, 1000));
  r->add_option("--threads", o.threads, "Worker threads (default: all cores); never changes the image")
      ->check(CLI::Range(1, 4096));
  r->add_option_function<uint64_t>("--seed", [&o](const uint64_t& s) { o.seed = s, o.has_seed = true; },
                                   "Random seed (default: the scene's render.seed)");
  r->add_option("--width", o.width, "Image width in pixels")->check(CLI::Range(1ll, max_side));
  r->add_option("--height", o.height, "Image height in pixels")->check(CLI::Range(1ll, max_side));
  r->add_option("-o,--output", o.outputs, ".exr/.pfm (linear float RGB) or .png (8-bit sRGB); repeatable");
  r->add_option("--reference", o.reference, "Reference .exr/.pfm of the same size: error after every pass");
  r->add_option("--log", o.log, "Per-pass CSV: sampler,pass,spp,seconds,relmse,mse");
  r->add_flag("--quiet", o.quiet, "No progress bar or summary");
  // Regions, cuts and the ablation switches of the adaptive samplers.
  const char* grp = "Regions and light cuts (bound, bayes)";
  r->add_option("--grid", o.regions.grid, "Region cells along the shortest axis of the scene bounds (default 64)")
      ->check(CLI::Range(1, 100000))->group(grp);
  r->add_option("--max-cut", o.regions.max_cut, "Light clusters per region (default 64, at most 1024)")
      ->check(CLI::Range(1, 1024))->group(grp);
  r->add_option("--cut-coherence", o.regions.coherence,
                "Keep a light cluster whole when its radius / gap to the region <= this (default 0.25; 0 = off)")
      ->check(CLI::Range(0.0, 100.0))->group(grp);
  r->add_option("--region-min-samples", o.regions.min_samples,
                "NEE samples a fine cell asks for before it gets its own region (default 16)")
      ->check(CLI::Range(1, 1 << 30))->group(grp);
  r->add_option("--region-budget", o.regions.max_pairs,
                "Most (region, cluster) pairs before coarser regions serve (default 1048576)")
      ->check(CLI::Range(int64_t(1), int64_t(1) << 40))->group(grp);
  const char* bg = "Bayesian sampler (bayes): prior strengths and ablations";
  r->add_option("--bayes-pmf", o.bayes_pmf, "second-moment (the paper) or mean (ablation: PMF from the mean only)")
      ->check(CLI::IsMember({"second-moment", "mean"}))->group(bg);
  r->add_flag_callback("--bayes-no-regression", [&o] { o.bayes.distance_regression = false; },
                       "Ablation: no 1/d^2 distance regression (z = Y)")->group(bg);
  r->add_flag_callback("--bayes-naive", [&o] { o.bayes.prior = false; },
                       "Ablation: no Bayesian prior, plug-in sample moments (the naive adaptive method)")->group(bg);
  r->add_option("--bayes-epsilon", o.bayes.epsilon, "Defensive mixing with the bound PMF, in [0, 1]")
      ->check(CLI::Range(0.0, 1.0))->group(bg);
  r->add_option("--bayes-a0", o.bayes.a0, "Beta prior of p0: pseudo-count of zero samples (> 0)")
      ->check(CLI::PositiveNumber)->group(bg);
  r->add_option("--bayes-b0", o.bayes.b0, "Beta prior of p0: pseudo-count of non-zero samples (> 0)")
      ->check(CLI::PositiveNumber)->group(bg);
  r->add_option("--bayes-kappa0", o.bayes.kappa0, "Prior pseudo-count of the mean k (> 0)")
      ->check(CLI::PositiveNumber)->group(bg);
  r->add_option("--bayes-alpha0", o.bayes.alpha0, "Inverse-gamma shape of the variance h (> 1)")
      ->check(CLI::Range(1.000001, 1e9))->group(bg);
  r->add_option("--bayes-hierarchy", o.bayes.hierarchy,
                "Concentration of a fine region's Beta prior on p0, centred on its coarse parent's posterior (0 = off)")
      ->check(CLI::Range(0.0, 1e9))->group(bg);
  r->add_option("--bayes-c", o.bayes.c, "Prior squared coefficient of variation: beta0 = c mu0^2 (alpha0 - 1) (> 0)")
      ->check(CLI::PositiveNumber)->group(bg);
}

}  // namespace

int run_cli(int argc, char** argv) {
  CLI::App app{"bayeslight — deterministic path tracer with Bayesian light selection for NEE"};
  app.require_subcommand(1);
  render_options ro;
  diff_options dopt;
  add_render_command(app, ro);
  CLI::App* diff = app.add_subcommand("diff", "Compare two images: relmse, mse, maxabs; 'identical' if bit-equal");
  diff->add_option("A", dopt.a, "Image (.exr/.pfm)")->required();
  diff->add_option("B", dopt.b, "Image (.exr/.pfm), the reference")->required();
  std::string first = argc >= 2 ? argv[1] : "";
  if (!first.empty() && first[0] != '-' && first != "render" && first != "diff") {
    std::fprintf(stderr, "bayeslight: error: unknown command \"%s\" (commands: render, diff)\n"
                         "Run with --help for more information.\n", first.c_str());
    return exit_usage;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return exit_usage;
  }
  try {
    if (app.got_subcommand("render")) return run_render(ro);
    if (app.got_subcommand("diff")) return run_diff(dopt);
  } catch (const usage_error& e) {
    std::fprintf(stderr, "bayeslight: error: %s\nRun with --help for more information.\n", e.what());
    return exit_usage;
  } catch (const input_error& e) {
    std::fprintf(stderr, "bayeslight: error: %s\n", e.what());
    return exit_bad_input;
  } catch (const output_error& e) {
    std::fprintf(stderr, "bayeslight: error: %s\n", e.what());
    return exit_failure;
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
