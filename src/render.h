// render: the pass loop — renders passes of whole samples per pixel in parallel, folds each completed pass
// into the film, lets adaptive samplers learn between passes, and logs error against wall time.
// Invariants: the work of a pass is split into a fixed partition (one chunk per image row) that does not
// depend on the thread count; every pixel's samples are summed in sample order; the film only ever holds
// completed passes; the pass schedule depends only on the pass index, so a --time run equals the --spp run
// of the same sample count. Interruption (SIGINT/SIGTERM) abandons the running pass.
#pragma once

#include "image_io.h"
#include "integrator.h"
#include "light_sampler.h"
#include "metrics.h"
#include "profile_timers.h"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace bl {

struct render_result;

// Options of one render.
struct render_params {
  int width = 640, height = 480;
  int spp = 64;               // target samples per pixel (ignored when time_budget > 0)
  double time_budget = 0;     // seconds; > 0: render passes until this much wall time is spent (fit_pass_to_time)
  int max_depth = 5;
  uint64_t seed = 0;
  int threads = 0;            // 0: all cores
  sampler_params sampler;
  const image_data* reference = nullptr;  // error is measured after every pass when set
  bool progress = false;      // progress bar on stderr
  bool notes = false;         // slow_phase_note lines on stderr (set-up, oracle learning); profile: without the bar
  bool profile = false;       // time the hot path's stages (profile_timers.h) into render_result::profile_cycles
  int frames = 1;             // animation frames (the sun moves from sun.direction to sun.direction_end)
  double frame_decay = 0.5;   // learned statistics are scaled by this at the start of every frame after the first
  // Adaptive samplers (bayes, donikian): the samples of a pass taken after n spp count pass_weight(n, this)
  // times in the image (0: all alike). Fixed in advance, so the weighted mean stays unbiased.
  double pass_weighting = 4;
  int light_samples = 1;      // NEE samples per path vertex (render_inputs::nee_samples)
  int light_points = 1;       // points per NEE draw at the first vertex (render_inputs::light_points); 0: auto
  bool stratify = true;       // stratified light and BSDF samples at the first vertex (integrator.h)
  // A signal arriving during the render's first pass (frame 0, not resumed) lets that pass finish, so that there is an
  // image to write, and the render then stops; a second one, half a second or more later, stops it at once. (The
  // render command; compare, profile and the oracle's learning stop at once.)
  bool finish_first_pass = false;
  // The render's own passes (false: --bayes-oracle's learning): a signal from their start on is no longer one before
  // the first pass (install_interrupt_handlers).
  bool begins_passes = true;
  // Testing: raise SIGINT this many times once the first pass's first row is done (< 0: -N times, 0.6 s apart).
  int signals_in_first_pass = 0;
  int signal_frame = -1;  // testing: raise SIGINT once in this frame's first pass (after its first row; frames > 0)
  std::vector<const image_data*> frame_references;  // per frame (overrides `reference` when not empty)
  // Called after every completed pass (last = false) and once when the render ends (last = true), with the state
  // of the completed passes: what a checkpoint saves.
  std::function<void(const render_result&, const light_sampler&, bool last)> on_pass;
  std::function<void(int spp)> on_samples;  // testing: called as a pass starts its samples (and as a cut one goes on)
  // Called once the sampler is built, before the first pass: restores a checkpointed state (resume).
  std::function<void(render_result&, light_sampler&)> restore;
};

// One completed pass.
struct pass_record {
  int pass = 0;
  int spp = 0;                // total samples per pixel after this pass
  double seconds = 0;         // render wall time since the first pass started
  bool has_error = false;
  error_metrics error;
};

// The outcome of a render.
struct render_result {
  int width = 0, height = 0;
  int frame = 0;              // the animation frame (render_frames; a checkpoint of frame k resumes there)
  std::vector<double> film;   // per pixel RGB sums over all completed samples, each pass's times its weight
  double film_weight = 0;     // the sum of the weights of one pixel's samples (= spp when all weigh 1)
  // bayes's staged pass weights (staged_pass_weight, direct renders): where its fallback check had found learning to
  // pay by the end of its first staged_spp spp, the film's sums of those passes (F_e) and their weight W_e, kept
  // apart; the later passes' share of the image is that of the plain schedule, late_ref_weight their weight under it
  // (film_image). Likewise after bayes's fallback (late_fallback): the passes before it kept apart,
  // the later ones weighing alike among themselves, with the share the plain schedule (their weights by their own
  // starts) gives them. Empty, 0 and false otherwise: the film alone is the image's sums.
  std::vector<double> early_film;
  double early_weight = 0;
  double late_ref_weight = 0;
  bool late_learns = false;
  bool late_fallback = false;
  // --light-points auto: the tiles' statistics of the completed passes (light_points.h; empty otherwise).
  std::vector<double> point_stats;
  int spp = 0;                // samples per pixel in the film
  int passes = 0;
  int stratum_base = 0;       // first sample of the stratified light set (integrator.h): the last change of model
  bool interrupted = false;
  double seconds = 0;         // render wall time (passes and learning, not error computation)
  double setup_seconds = 0;   // light tree, regions (before the first pass; not in `seconds`)
  size_t sampler_bytes = 0;   // memory of the sampler's regions, cuts and statistics
  double learn_seconds = 0;   // of `seconds`: learning between passes (the reduction and PMF rebuild)
  learn_timing learn_parts;   // learn_seconds by part, where the sampler reports them (bayes)
  uint64_t profile_cycles[prof_count] = {};  // time-stamp counter cycles per stage (profile renders only)
  int regions = 0;            // regions of a region-based sampler
  int64_t pairs = 0;          // (region, cluster) pairs
  int fallback_spp = 0;       // bayes: spp after which it fell back to power (or bvh) sampling (0: it did not)
  bool fallback_bvh = false;  // ... to the bvh sampler
  bool fallback_earlier = false;  // ... in an earlier frame of the animation (fallback_spp counts that frame's spp)
  bool one_light = false;      // bayes: the scene has one light, sampled as by power (bayes_sampler::one_light)
  double fallback_ratio = 0;  // bayes: the last checked estimate of power's relMSE over the learned sampler's (0: none)
  double fallback_ratio_bvh = 0;  // ... and of bvh's (0: none)
  path_stats stats;
  std::vector<pass_record> log;
};

// Samples per pixel of pass `pass` given `done` samples before it (before truncation to the target), for an image
// of `pixels` pixels.
int pass_size(int pass, int done, int64_t pixels);
// Whether `spp` ends a pass of the untruncated schedule (pass_size from 0): a render stopped there and continued
// takes the same passes as one render of more spp.
bool ends_scheduled_pass(int spp, int64_t pixels);
// Samples per pixel of the next pass of a --time render with `left` seconds of its budget left: `count` (its
// scheduled size), or fewer where the last pass's `seconds_per_spp` (its learning included) says fewer fill the time
// left (a quarter more, rounded up, so that the pass ends past the budget unless the machine speeds up by more than
// that; at least 1). Without a speed (0: no pass timed yet): `count`. A cut pass is the render's last; where it ends
// short of the budget, it goes on with more of its samples (the same model and sums), sized alike from its own speed,
// up to its scheduled size less one spp.
int fit_pass_to_time(int count, double left, double seconds_per_spp);
// The seconds per spp to expect of a pass of `draws` NEE draws per vertex, from a pass of `measured_draws` that took
// `seconds_per_spp`: scaled by (2 + draws) / (2 + measured_draws), as if a camera sample cost two draws besides its
// draws (bayes's early draws, direct, 320x240: 4 draws to 1 halved the time per spp, 0.056 to 0.0275 s in the living
// room, 0.083 to 0.041 s in the hall). Unscaled where the counts agree or one is unknown (0).
double seconds_per_spp_at(double seconds_per_spp, int measured_draws, int draws);
// Weight of the samples of a pass that starts after `done` spp: (done + 1) / (done + 1 + s), 1 for s = 0.
double pass_weight(int done, double s);
// bayes's passes in a direct render (stages_passes: s > 0, max_depth 1): its first staged_spp spp weigh
// pass_weight(done, staged_early * s); the later ones pass_weight(done, s), or pass_weight(done, staged_late * s)
// among themselves where `late_learns` (its fallback check found learning to pay within those first spp), their share
// of the image then still that of pass_weight(done, s) (render_result::early_film). Every weight and share is fixed
// before the pass's samples are drawn. Path-traced renders weigh pass_weight(done, s) throughout.
constexpr int staged_spp = 8;
constexpr double staged_early = 4, staged_late = 16;
bool stages_passes(const render_params& params, double weighting);
double staged_pass_weight(int done, double s, bool late_learns);
// A pass's weight by its own start (the plain schedule): the share of the passes after bayes's fallback.
inline double plain_pass_weight(int done, double s, bool staged) {
  return staged ? staged_pass_weight(done, s, false) : pass_weight(done, s);
}
// Whether the sampler's passes are weighted by pass_weight (an adaptive sampler that still learns).
bool sampler_adapts(const light_sampler& s);

// Renders the scene.
render_result render(const scene_data& scene, const bvh_data& bvh, const light_data& lights,
                     const render_params& params);
// Renders params.frames frames of an animation in which the sun moves along the great circle from
// sun.direction to sun.direction_end; the light sampler (and what it learned) carries over from frame to
// frame, its statistics scaled by params.frame_decay at each frame start. Frame k draws the streams of
// frame_seed(seed, k) with the same pass schedule, so frame k of a non-learning sampler equals a single render
// with that frame's sun and that seed (a learning sampler must not draw again the samples it learned from). Calls
// on_frame(k, result) after each frame; stops after an interrupted frame (its result says so). A restored state
// (params.restore, a checkpoint) of frame k starts there: frames before k are not rendered again. A signal that
// comes while on_frame runs ends the animation after that frame (on_pass is then called once more, last = true).
void render_frames(const scene_data& scene, const bvh_data& bvh, light_data& lights, const render_params& params,
                   const std::function<void(int, const render_result&)>& on_frame);
// The film's weighted mean image, values below zero kept (bayes's control variates; README), zero when no sample
// completed.
image_data film_image(const render_result& r);

// Installs SIGINT/SIGTERM handlers. Until interrupted_before_render is called (setting up: nothing written yet) a
// signal ends the process at once with "interrupted (SIG...) while loading the scene; nothing written" and 128 +
// signal; so it does again while the command's first render_frames sets up (light tree, regions, a checkpoint's
// state), saying "while setting up the render"; otherwise a signal requests the render to stop after the current pass.
// finish_first_pass (`render`, whose first pass finishes for a signal): a first signal before that pass lets the
// command go on to render it and write its image (resuming: to write the image of the checkpoint's passes); a second
// one, half a second or more later, ends it at once.
void install_interrupt_handlers(bool finish_first_pass = false, bool resuming = false);
// Blocks SIGINT, SIGTERM and SIGHUP until install_interrupt_handlers unblocks them (a signal meanwhile waits there).
void block_interrupt_signals();
int interrupt_signal();
// How many SIGINT/SIGTERM the handlers have received so far.
int interrupt_count();
// "SIGINT", "SIGTERM", "SIGHUP" (or "signal") for messages.
const char* signal_name(int sig);
// Clears a pending interrupt request (tests).
void reset_interrupt();
// Ends the set-up phase (see install_interrupt_handlers). A signal noted before it (not while setting up, which
// exits at once) is reported as one during loading: the exit status 128 + signal; else (or when the render goes on
// to its first pass) 0.
int interrupted_before_render();

}  // namespace bl
