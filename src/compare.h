// compare: the `compare` command — renders several light samplers for the same time (or spp) against a
// reference, K runs each with seeds base, base+1, ..., and writes DIR/curves.csv, DIR/error_vs_time.svg,
// DIR/summary.md, DIR/<sampler>.exr and DIR/<sampler>_error.png.
// Invariants: the scene, BVH and lights are built once; renders never overlap in time (round r renders every
// sampler in the given order, then round r+1), so their timings compare; every output is written atomically;
// summary.md's numbers are computed from exactly the pass records curves.csv lists.
#pragma once

#include "bvh.h"
#include "error_image.h"
#include "lights.h"
#include "render.h"
#include "scene.h"
#include "scene_desc.h"

#include <string>
#include <vector>

namespace bl {

// What a comparison renders and where it writes.
struct compare_params {
  std::vector<sampler_kind> samplers;  // in the order given; the first is the baseline of speed-ups
  int runs = 1;                        // run r (1-based) uses seed render.seed + r - 1
  render_params render;                // shared options: size, spp or time budget, depth, threads, sampler options
  std::string scene_path;              // for the summary's title
  std::string reference_path;
  std::string reference_note;          // summary line about the reference (empty: "reference: FILE")
  std::string out_dir;                 // created (one level) when missing
  error_image_params error_image;
  bool quiet = false;                  // no per-render lines on stderr
  bool grid_given = false;             // --grid was given (for the warning about coarse regions)
};

// One render of one sampler.
struct compare_run {
  int run = 1;  // 1-based
  uint64_t seed = 0;
  int spp = 0;
  double seconds = 0, setup_seconds = 0;
  bool interrupted = false;
  std::vector<pass_record> log;  // every pass, with its error against the reference
};

// Every run of one sampler, and the render of its first run (written as DIR/<sampler>.exr).
struct compare_sampler {
  sampler_kind kind = sampler_kind::bayes;
  std::vector<compare_run> runs;
  image_data image;  // empty when the first run completed no pass
};

// The renders of a comparison.
struct compare_data {
  std::vector<compare_sampler> samplers;  // in the order given
  bool equal_time = false;                // --time budget (else equal spp)
  double time_budget = 0;                 // that budget, seconds
  int signal = 0;                         // the SIGINT/SIGTERM that cut it short (0: complete)
};

// What summary.md and the plot report for one sampler (error and time of runs that completed a pass).
struct compare_stats {
  // Mean curve over runs: at equal spp point i averages pass i of every run (a run cut short contributes its final
  // pass); at equal time the runs' relMSE at common times (their pass times within the span all runs cover).
  std::vector<double> curve_seconds, curve_relmse;
  double image_relmse = -1;          // run 1's final pass: the error of the image written (-1: run 1 has no pass)
  int runs = 0;                      // runs with at least one pass
  int spp_min = 0, spp_max = 0;      // final spp over runs
  double seconds = 0;                // mean final render time
  double relmse = 0, relmse_sd = 0;  // mean and sample standard deviation over runs of the relMSE at the end: at
                                     // exactly comparison_time (relmse_at_time) at equal time, else the final one
  double setup_seconds = 0;          // mean setup time (light tree, regions; not in `seconds`)
  double speedup = 0;                // against the first sampler (NaN when undefined)
  bool before_first_pass = false;    // equal time: a run's first pass ended after the comparison time, so its relmse
                                     // is that pass's, not the error at that time (no speed-up then)
  double time_to_target = -1;        // seconds until it stays at or below the first sampler's relmse
};

// A run's relMSE at exactly time t: log-log interpolation between the last pass before t and the first at or after
// it (a --time run ends with the first whole pass past t); the first pass's when it already ends past t, the last
// pass's when the run ended sooner (interrupted).
double relmse_at_time(const std::vector<pass_record>& log, double t);

// Renders every (run, sampler) one at a time; stops early on SIGINT/SIGTERM (data.signal).
compare_data run_comparison(const scene_data& scene, const bvh_data& bvh, const light_data& lights,
                            const image_data& reference, const compare_params& params);
// The time at which an equal-time comparison compares the samplers: the budget, or where a signal cut the renders
// short, the end of the shortest run (every run's error exists there; the budget is 0 at equal spp).
double comparison_time(const compare_data& data);
// Statistics of every sampler. Speed-up: equal time: relMSE_first / relMSE; equal spp: the efficiency ratio
// (relMSE x seconds)_first / (relMSE x seconds).
std::vector<compare_stats> comparison_stats(const compare_data& data);
// The time from which a curve stays at or below `target`: log-log interpolation between the last point above
// it and the next (the first point's time when every point is at or below); -1 when the last point is above.
double time_to_reach(const std::vector<double>& seconds, const std::vector<double>& relmse, double target);

// curves.csv: header `sampler,pass,spp,seconds,relmse,mse,run,seed` (a --log's columns first), one row per pass of
// every run.
std::string comparison_csv(const compare_data& data);
// summary.md: the table of SPEC.md's compare command and notes saying how each column is computed.
std::string comparison_summary(const compare_data& data, const compare_params& params);
// error_vs_time.svg: relMSE against seconds on log-log axes, the mean curve of each sampler.
std::string comparison_svg(const compare_data& data, const compare_params& params);
// Writes every output into params.out_dir (which must exist), each atomically.
void write_comparison(const compare_data& data, const compare_params& params, const image_data& reference);

// The whole command: reads and checks the reference (input_error), builds the scene once, creates the output
// directory, renders, writes; returns the exit status (0, or 128 + signal when interrupted).
int run_compare(const scene_desc& desc, const compare_params& params);

}  // namespace bl
