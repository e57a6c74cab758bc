// cli_options: the options of the commands render, profile, compare and diff as CLI11 parses them into plain structs,
// with their help texts, ranges and groups; cli.cpp resolves them against the scene file and runs the command.
#pragma once

#include "bayes_stats.h"
#include "region_grid.h"

#include <CLI/CLI.hpp>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace bl {

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
  region_params regions = [] {
    region_params r;
    r.max_pairs = -1;  // auto (region_params::auto_pairs_per_pixel) unless --region-budget is given
    r.grid = -1;       // auto (region_params::auto_grid, by the image's pixel count) unless --grid is given
    return r;
  }();
  bayes_params bayes;
  std::string bayes_pmf = "second-moment";
  std::string bayes_prior = "region";
  int frames = 0;  // --frames N (0: not given: no animation, names are literal)
  double frame_decay = 0.5;
  double pass_weighting = 4;
  bool independent = false;
  int light_samples = 1;
  int light_points = 0;  // --light-points (0: auto, the default)
  std::string checkpoint;
  double checkpoint_every = 30;
  std::string resume;
  int stop_after_passes = -1;  // testing aid: raise SIGINT after this many passes (0: while the render sets up)
  bool signal_after_last_pass = false;  // testing aid: raise SIGINT once the last pass is done, before the outputs
  int kill_after_passes = 0;  // testing aid: raise SIGKILL right after the checkpoint of this pass
  int signals_in_first_pass = 0;  // testing aid: raise SIGINT this many times once the first pass's first row is done
  int signals_in_setup = 0;       // testing aid: raise SIGINT this many times in the render's set-up (-N: 0.6 s apart)
  int signal_frame = -1;          // testing aid: raise SIGINT once during this frame's first pass (frames > 0)
  std::vector<std::pair<std::string, std::string>> given;  // options given on the command line: (name, help group)
};

// Options of `diff`.
struct diff_options {
  std::string a, b;
  int worst = 0;          // --worst: the shares of the worst pixels and the N worst, after the metrics (0: off)
  std::string error_map;  // --error-map: each pixel's relMSE term (.exr/.pfm), or compare's false-colour image (.png)
};

// Options of `compare` (render.sampler, render.outputs and render.log are unused).
struct compare_options {
  render_options render;
  std::string samplers;  // comma-separated
  std::string out;
  int runs = 1;
  std::string reference_note;
};

// Largest image a command line may ask for (same limits as scene files).
constexpr long long max_side = 65536;
constexpr long long max_pixels = 1ll << 28;

// Help groups of the options that only some samplers use (cli.cpp names them in a warning where they cannot apply).
inline constexpr const char* region_group = "Regions and light cuts (bound, donikian, bayes)";
inline constexpr const char* bayes_group = "Bayesian sampler (bayes): prior strengths and ablations";

// Adds the subcommand render, with every option it takes, writing into o.
void add_render_command(CLI::App& app, render_options& o);
// Adds the subcommand profile (the options of render, without outputs), writing into o.
void add_profile_command(CLI::App& app, render_options& o);
// Adds the subcommand compare, writing into o.
void add_compare_command(CLI::App& app, compare_options& o);

}  // namespace bl
