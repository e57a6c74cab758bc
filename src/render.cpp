// render: pass schedule, parallel pass execution over image rows, film folding, learning, error log.
#include "render.h"

#include "file_io.h"
#include "light_points.h"
#include "progress.h"

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <climits>
#include <cmath>
#include <csignal>
#include <ctime>
#include <pthread.h>
#include <thread>
#include <optional>
#include <type_traits>
#include <unistd.h>

namespace bl {

namespace {

// Mixed into the seed for the keys of --light-points auto's per-pass point sets (apart from the light sets' keys).
constexpr uint64_t point_set_seed = 0x3c6ef372fe94f82bull;

std::atomic<int> g_signal{0};
std::atomic<int> g_signal_count{0};  // signals received (an output's wait ends on a new one)
std::atomic<bool> g_first_pass{false};  // a render's first pass that a first signal lets finish is running
// `render` (install_interrupt_handlers(true)): a first signal before the render's first pass begins lets the command
// go on to render that pass and write its image (g_early_signal notes one); a second one ends it at once.
std::atomic<bool> g_finish_early{false};
std::atomic<bool> g_early_signal{false};
std::atomic<bool> g_resuming{false};      // ... and when it resumes a checkpoint, to write the image of its passes
std::atomic<bool> g_passes_begun{false};  // the render's passes have begun (not an oracle's learning)
std::atomic<bool> g_no_first_pass{false};  // --bayes-oracle's learning was cut short: no first pass may follow
// Where the command stands, for a signal: while setting up (loading the scene, phase_setup; then, in the first
// render_frames, the light tree, the sampler's regions and a checkpoint's state, phase_render_setup) nothing has been
// written yet, and a loader deep in a large file would notice a request only once it is done, so the handler ends
// the process at once (`render`: at a second signal; the first lets it go on to its first pass); afterwards it asks
// the render to stop after its pass.
enum phase : int { phase_none, phase_setup, phase_before_render, phase_render_setup, phase_render };
std::atomic<int> g_phase{phase_none};

// Monotonic nanoseconds (clock_gettime is async-signal-safe).
int64_t monotonic_ns() {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return int64_t(t.tv_sec) * 1000000000 + t.tv_nsec;
}
std::atomic<int64_t> g_first_signal_ns{0}, g_last_signal_ns{0};

// Writes a whole line to stderr from a signal handler: write(2) only, one write (a line another thread prints
// stays whole). The line is the pieces joined (at most 511 characters).
void signal_safe_line(std::initializer_list<const char*> pieces) {
  char line[512];
  size_t len = 0;
  for (const char* p : pieces)
    for (; *p && len < sizeof line; p++) line[len++] = *p;
  ssize_t ignored = write(2, line, len);
  (void)ignored;
}

// Whether a second signal came, at least half a second after the first. (GNU timeout sends its signal twice, to the
// process and to its group: two deliveries microseconds apart are one request.)
bool second_request() {
  return g_signal_count.load() >= 2 && g_last_signal_ns.load() - g_first_signal_ns.load() >= 500000000;
}

extern "C" void on_interrupt(int sig) {
  // The handler's write(2) fails with stderr closed or full, and would leave its errno to the interrupted thread, which
  // may be between a failed call of its own and reading errno (a TSan review: "signal handler spoils errno").
  struct keep_errno {
    int saved = errno;
    ~keep_errno() { errno = saved; }
  } keep;
  static const char* const names[3] = {"SIGINT", "SIGTERM", "SIGHUP"};
  const char* name = names[sig == SIGTERM ? 1 : sig == SIGHUP ? 2 : 0];
  const int phase = g_phase.load();
  const bool setting_up = phase == phase_setup || phase == phase_render_setup;
  const char* where = phase == phase_setup          ? "while loading the scene"
                      : phase == phase_render_setup ? "while setting up the render"
                                                    : "before the first pass";
  if (setting_up && !g_finish_early.load()) {
    // Async-signal-safe: write(2) and _exit(2) only. The message names the phase: loading the scene, or the render's
    // set-up (light tree, regions, a checkpoint's state), which takes seconds in a scene of many emitters.
    signal_safe_line({"bayeslight: interrupted (", name, ") ", where, "; nothing written\n"});
    _exit(128 + sig);
  }
  const int64_t now = monotonic_ns();
  int64_t unset = 0;  // (lock-free read-modify-writes: a handler interrupted by another keeps the earliest and latest)
  g_first_signal_ns.compare_exchange_strong(unset, now);
  for (int64_t last = g_last_signal_ns.load(); last < now && !g_last_signal_ns.compare_exchange_weak(last, now);) {
  }
  // (The count and the early flag before the signal itself: a thread that sees the signal sees them. The first
  // signal's number is kept: the exit status is that of the request the render acts on.)
  const bool first_signal = g_signal_count.fetch_add(1) == 0;
  const bool early = g_finish_early.load() && !g_passes_begun.load();
  if (early && first_signal) g_early_signal.store(true);
  int none = 0;
  g_signal.compare_exchange_strong(none, sig);
  if (early) {
    // `render` before its first pass: the first signal lets it go on to that pass; a second one, while nothing can
    // see it (loading, set-up, the time between), ends it here.
    if (first_signal) {
      signal_safe_line({"bayeslight: interrupted (", name, ") ", where,
                        g_resuming.load() ? ": going on to write the image of the checkpoint's passes"
                                          : ": going on to render a first pass and write its image",
                        " (interrupt again, half a second or more later, to stop now, with none)\n"});
    } else if (phase != phase_render && second_request()) {
      signal_safe_line({"bayeslight: interrupted again (", name, ") ", where, "; nothing written\n"});
      _exit(128 + sig);
    }
    return;
  }
  if (first_signal && g_first_pass.load())
    signal_safe_line({"bayeslight: interrupted (", name,
                      ") in the first pass: finishing it to write an image (interrupt again, half a second or more "
                      "later, to stop now, with none)\n"});
}

// Whether a pass must stop: on a signal; in a first pass that may finish (g_first_pass), on a second request.
bool stop_requested() {
  if (g_signal.load(std::memory_order_relaxed) == 0) return false;
  if (!g_first_pass.load(std::memory_order_relaxed)) return true;
  return second_request();
}

using clock_type = std::chrono::steady_clock;
double seconds_since(clock_type::time_point t) {
  return std::chrono::duration<double>(clock_type::now() - t).count();
}

// Per-row outputs of one pass: the row's sample sums go straight to the pass buffer; a learning sampler's
// row states and the counters are kept per row so that folding them in row order is independent of which
// thread ran which row.
template <class Sampler>
struct pass_rows {
  std::vector<path_stats> stats;
  std::vector<cycle_timers> timers;  // profile renders only
  std::vector<typename Sampler::row_state> records;
};
struct pass_rows_none {
  std::vector<path_stats> stats;
  std::vector<cycle_timers> timers;
};

// Hands a learning sampler's NEE events to its state of one row.
template <class Sampler>
struct row_sink {
  const Sampler* sampler;
  typename Sampler::row_state* row;
  template <class Event>
  void record(const Event& e) {
    sampler->record(*row, e);
  }
  void sample_done(int pixel, vec3f l) { sampler->sample_done(*row, pixel, l); }
};
// A sink that drops everything (samplers that do not learn).
struct null_row_sink : null_sink {
  void sample_done(int, vec3f) {}
};

// Image rows per work item (and per row state of a learning sampler).
template <class Sampler>
constexpr int rows_per_band() {
  if constexpr (Sampler::learns) return Sampler::rows_per_state;
  else return 1;
}

// --light-points auto (light_points.h): what a pass gathers for the choice of point counts. The film before the
// pass gives each pixel's mean; each image row sums its pixels' statistics, in pixel order, into its own slots (one
// per tile of the row), which render_with folds in row order after the pass.
struct point_gather {
  const std::vector<double>* film = nullptr;
  double film_weight = 0;
  double mean_samples = 0;   // samples per pixel before the pass
  std::vector<double> rows;  // height * point_tile_cols * point_stat_fields
  int cols = 0;
};

// Renders samples [s0, s1) of every pixel into pass_sum; false when interrupted (the pass is then void). With
// Profile, each row's stages are timed into rows.timers. extend: the samples go on from a run of the same pass
// that ended at s0 (its sums, counters, timers and records are added to, not restarted).
template <bool Profile, class Sampler, class Rows>
bool run_pass(const render_inputs& in, const Sampler& sampler, int s0, int s1, std::vector<double>& pass_sum,
              Rows& rows, tbb::task_arena& arena, progress_counters& progress, int raise_signals = 0,
              bool extend = false, point_gather* points = nullptr) {
  int w = in.camera.width, h = in.camera.height;
  std::atomic<bool> stopped{false};
  // Work items are bands of rows (one row for samplers without a row state shared by several rows): a band's rows
  // are rendered in order into its state, so what a state holds never depends on the thread that ran it.
  constexpr int band = rows_per_band<Sampler>();
  const int bands = (h + band - 1) / band;
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, bands, 1), [&](const tbb::blocked_range<int>& range) {
      for (int b = range.begin(); b < range.end(); b++) {
        auto render_band = [&](auto& sink) {
          for (int y = b * band; y < std::min(h, (b + 1) * band); y++) {
            if (stop_requested()) {
              stopped = true;
              return;
            }
            path_stats& st = rows.stats[size_t(y)];
            if (!extend) st = {};
            if (points && !extend) {
              const size_t row = size_t(y) * size_t(points->cols) * point_stat_fields;
              std::fill(points->rows.begin() + ptrdiff_t(row),
                        points->rows.begin() + ptrdiff_t(row + size_t(points->cols) * point_stat_fields), 0.0);
            }
            typename Sampler::context ctxs[2];
            std::conditional_t<Profile, cycle_timers, no_timers> tm;
            light_point_sets light_sets;
            for (int x = 0; x < w; x++) {
              double* out = &pass_sum[3 * (size_t(y) * w + x)];
              // (Extended: the sums go on from the pass's earlier samples, added in the order one pass adds them.)
              double sum[3] = {extend ? out[0] : 0.0, extend ? out[1] : 0.0, extend ? out[2] : 0.0};
              const pixel_streams ps = pixel_streams_of(in.seed, in.stratum_key, uint64_t(y * w + x), in.point_key);
              if (!points) {
                for (int s = s0; s < s1; s++) {
                  vec3f l = trace_path_timed(in, sampler, x, y, ps, uint64_t(s), st, sink, ctxs, tm);
                  sink.sample_done(y * w + x, l);
                  sum[0] += l.x, sum[1] += l.y, sum[2] += l.z;
                }
              } else {
                double* slot = &points->rows[(size_t(y) * size_t(points->cols) + size_t(x / point_tile_size)) *
                                             point_stat_fields];
                const bool has_mean = points->film_weight > 0;
                double m = 0, g = 0, mean_noise = 1;
                if (has_mean) {
                  const double* f = &(*points->film)[3 * (size_t(y) * w + x)];
                  m = luminance(f[0], f[1], f[2]) / points->film_weight;
                  // (A mean of n earlier samples adds V / n to E (y - m)^2: n / (n + 1) takes it out.)
                  g = 1.0 / (m * m + 0.01);
                  mean_noise = points->mean_samples / (points->mean_samples + 1);
                }
                double block[point_block] = {};
                light_sets.reset(ps.point, uint64_t(s0));
                for (int s = s0; s < s1; s++) {
                  const uint64_t vertices = st.camera_rays + st.bounce_rays;
                  sample_info info;
                  info.light_sets = &light_sets;
                  vec3f l = trace_path_timed(in, sampler, x, y, ps, uint64_t(s), st, sink, ctxs, tm, &info);
                  sink.sample_done(y * w + x, l);
                  sum[0] += l.x, sum[1] += l.y, sum[2] += l.z;
                  slot[ps_samples] += 1;
                  slot[ps_vertices] += double(st.camera_rays + st.bounce_rays - vertices);
                  if (has_mean) {
                    const double y_lum = luminance(l.x, l.y, l.z), d = y_lum - m;
                    slot[ps_mean_samples] += 1;
                    slot[ps_sq_dev] += g * mean_noise * d * d;
                    slot[ps_inv_points] += 1.0 / info.points;
                    if (info.points > 1) slot[ps_within] += g * info.within, slot[ps_within_samples] += 1;
                    // (Blocks of the light set, which starts at stratum_base: an adaptive sampler's restarts
                    // whenever its model changes, and after bayes's fallback at the fallback.)
                    const uint64_t b = uint64_t(s) - in.stratum_base;
                    block[b % point_block] = y_lum;
                    if (b % point_block == point_block - 1 && s - (point_block - 1) >= s0)
                      add_point_block(slot, block, m, g);
                  }
                }
              }
              out[0] = sum[0], out[1] = sum[1], out[2] = sum[2];
            }
            if constexpr (Profile) {
              if (!extend) rows.timers[size_t(y)] = {};
              for (int c = 0; c < prof_count; c++) rows.timers[size_t(y)].cycles[c] += tm.cycles[c];
            }
            if (progress.rows_done.fetch_add(1, std::memory_order_relaxed) == 0)  // (testing)
              for (int k = 0; k < std::abs(raise_signals); k++) {
                if (k > 0 && raise_signals < 0) std::this_thread::sleep_for(std::chrono::milliseconds(600));
                std::raise(SIGINT);
              }
          }
        };
        if constexpr (Sampler::learns) {
          auto& state = rows.records[size_t(b)];
          if (!extend) state.clear();
          row_sink<Sampler> sink{&sampler, &state};
          render_band(sink);
        } else {
          null_row_sink sink;
          render_band(sink);
        }
        if (stopped) return;
      }
    });
  });
  return !stopped;
}

// Whether a sampler's pmf improves with what it learns during the render (its first passes are its worst).
template <class Sampler>
bool adapts(const Sampler& s) {
  if constexpr (std::is_same_v<Sampler, bayes_sampler>) return !s.frozen && !s.one_light;
  else return std::is_same_v<Sampler, donikian_sampler>;
}

// Whether the sampler's model would change if it learned from the pass just rendered (bayes: unless frozen or
// fallen back to power sampling).
template <class Sampler>
bool model_moves(const Sampler& s) {
  if constexpr (std::is_same_v<Sampler, bayes_sampler>) return !s.frozen && !s.fallback;
  else return std::is_same_v<Sampler, donikian_sampler>;
}

// NEE draws per path vertex in the pass that starts after `done` spp: bayes, in a direct render, takes
// early_draws in its first early_spp spp while it learns (unless its check fell back, or its model is frozen):
// those passes weigh little in the image (staged_pass_weight) but decide the model every later pass samples from,
// and a draw costs less than the camera ray and shading it shares with the others. Living room, direct, 400 spp,
// seeds 11-13: relMSE 0.78-0.88x of one draw throughout (README, "Choosing the defaults"). A function of the spp
// done and of the model's state, which a checkpoint keeps: a --time or resumed render stays the --spp render of its
// samples.
template <class Sampler>
int pass_draws(const Sampler& s, const render_params& params, int done, int draws) {
  if constexpr (std::is_same_v<Sampler, bayes_sampler>) {
    if (params.max_depth == 1 && !s.frozen && !s.fallback && done < s.params.early_spp)
      return std::max(draws, s.params.early_draws);
  }
  return draws;
}

// The pass loop for one sampler type; continues from the passes already in `result` (a resumed render).
// after_pass is called after every completed pass.
template <class Sampler>
void render_with(const render_inputs& in, Sampler& sampler, const render_params& params, render_result& result,
                 const std::function<void()>& after_pass = {}) {
  int w = params.width, h = params.height;
  size_t n = size_t(w) * size_t(h) * 3;
  // (Large images: zeroing the film and per-row buffers touches hundreds of MB, seconds before the bar appears.)
  std::optional<slow_phase_note> preparing(std::in_place, params.notes, "preparing the image's buffers ...");
  if (result.film.size() != n) {
    result.film.assign(n, 0.0);
    result.film_weight = 0;
    result.early_film.clear();
    result.early_weight = result.late_ref_weight = 0;
    result.late_learns = result.late_fallback = false;
    result.point_stats.clear();
    result.spp = result.passes = 0;
  }
  const double weighting = adapts(sampler) ? params.pass_weighting : 0.0;
  const bool staged = std::is_same_v<Sampler, bayes_sampler> && stages_passes(params, weighting);
  if constexpr (std::is_same_v<Sampler, bayes_sampler>) {
    // The fallback check starts afresh with each frame (its first pass is not checked).
    if (result.spp == 0) sampler.restart_check();
  }
  std::vector<double> pass_sum(n, 0.0);
  // --light-points auto: the tiles' statistics (kept with the film), this pass's rows of them, the tiles' counts.
  const bool auto_points = params.light_points == 0;
  const int tile_cols = point_tile_cols(w);
  point_gather gather;
  std::vector<uint8_t> tile_points;
  if (auto_points) {
    if (result.point_stats.size() != point_stats_size(w, h)) result.point_stats.assign(point_stats_size(w, h), 0.0);
    gather.rows.assign(size_t(h) * size_t(tile_cols) * point_stat_fields, 0.0);
    gather.cols = tile_cols;
    gather.film = &result.film;
  } else {
    result.point_stats.clear();
  }
  using rows_type = std::conditional_t<Sampler::learns, pass_rows<Sampler>, pass_rows_none>;
  rows_type rows;
  rows.stats.resize(size_t(h));
  if (params.profile) rows.timers.resize(size_t(h));
  if constexpr (Sampler::learns) rows.records.resize(size_t((h + rows_per_band<Sampler>() - 1) / rows_per_band<Sampler>()));

  int threads = params.threads > 0 ? params.threads : int(std::max(1u, std::thread::hardware_concurrency()));
  // More threads than cores are allowed when asked for (TBB's default limit would warn and ignore them).
  tbb::global_control allow(tbb::global_control::max_allowed_parallelism, size_t(threads));
  tbb::task_arena arena(threads);
  progress_counters progress;
  progress.spp_target = params.time_budget > 0 ? 0 : params.spp;
  progress.time_budget = params.time_budget;
  progress.seconds_before = result.seconds;
  progress.rows = h;
  preparing.reset();
  progress_bar bar(progress, params.progress);
  // From here a signal is one in (or after) the render's passes; the first pass of frame 0 may finish for it.
  if (params.begins_passes) {
    g_first_pass.store(params.finish_first_pass && result.passes == 0 && result.spp == 0);
    g_passes_begun.store(true);
  }

  const int target = params.time_budget > 0 ? INT_MAX : params.spp;
  int done = result.spp;
  double seconds_per_spp = 0;  // of the last pass, with its learning (0: none yet)
  int measured_draws = 0;      // ... whose NEE draws per vertex were these (0: unknown)
  if (!result.log.empty()) {  // (a resumed render: its checkpoint's last pass)
    const size_t n = result.log.size();
    const double t0 = n > 1 ? result.log[n - 2].seconds : 0.0;
    const int s0 = n > 1 ? result.log[n - 2].spp : 0;
    if (result.log[n - 1].spp > s0) seconds_per_spp = (result.log[n - 1].seconds - t0) / (result.log[n - 1].spp - s0);
    measured_draws = pass_draws(sampler, params, s0, in.nee_samples);
  }
  progress.spp_done = done;
  for (int pass = result.passes; done < target; pass++) {
    if (params.time_budget > 0 && result.seconds >= params.time_budget) break;
    // A first pass that a signal lets finish (render_params::finish_first_pass): one arriving during it, or before it
    // (as the scene loaded, the render set up, the buffers were prepared: install_interrupt_handlers), unless a second
    // request came or the signal cut --bayes-oracle's learning short; otherwise a signal stops the render here, as it
    // stops later passes.
    const bool first = params.finish_first_pass && pass == 0 && done == 0;
    if (g_signal.load() != 0 && !(first && !g_no_first_pass.load() && !second_request())) {
      g_first_pass.store(false);
      result.interrupted = true;
      break;
    }
    g_first_pass.store(first);
    int count = std::min(pass_size(pass, done, int64_t(in.camera.width) * in.camera.height), target - done);
    // The last pass of a --time render takes only what fits the time left: passes grow by a quarter of the spp so
    // far, and a whole one started just before the budget ran a render up to a quarter past it. A cut pass is the
    // render's last: a --spp render of the same total cuts its last pass at the same place, and only there, so the
    // two stay the same image. (Where it ends before the budget, it goes on below with more of its samples.)
    // (The first pass after bayes's early draws takes fewer draws, and less time per spp, than the pass timed.)
    const int scheduled = count;
    const int draws = pass_draws(sampler, params, done, in.nee_samples);
    if (params.time_budget > 0)
      count = fit_pass_to_time(count, params.time_budget - result.seconds,
                               seconds_per_spp_at(seconds_per_spp, measured_draws, draws));
    const double cycle_start = result.seconds;
    progress.pass = pass + 1;
    // The bar's running pass (or piece of one): its spp and rows, timed from now.
    auto bar_runs = [&](int spp) {
      progress.pass_spp = spp;
      progress.rows_done = 0;
      progress.pass_start_ns =
          std::chrono::duration_cast<std::chrono::nanoseconds>(clock_type::now().time_since_epoch()).count();
    };
    bar_runs(count);
    auto t0 = clock_type::now();
    // Stratified light sets (integrator.h): a set starts with the render and after every change of the sampler's
    // model, so no light sample of a set depends on samples its model learned from; a model that stays keeps its set.
    // (The BSDF direction's set is the render's, whatever the model.)
    render_inputs pin = in;
    pin.stratum_base = uint64_t(result.stratum_base);
    pin.stratum_key = stratum_key_of(in.seed, pin.stratum_base);
    pin.nee_samples = draws;
    // (Not after a fallback, which ends the checks: a resumed render, which cannot tell the draws of the pass before
    // its checkpoint from the sampler's state after it, keeps the same check state then.)
    if constexpr (std::is_same_v<Sampler, bayes_sampler>)
      if (measured_draws > 0 && draws != measured_draws && !sampler.fallback) sampler.unpair();
    if (auto_points) {
      choose_tile_points(result.point_stats, done, pass, pin.nee_samples, tile_points);
      pin.point_tiles = tile_points.data();
      // (The pass's light-point sets: integrator.h, light_pass_point_uv and pass_point_uv.)
      pin.point_base = uint64_t(done);
      pin.point_key = stratum_key_of(in.seed ^ point_set_seed, uint64_t(done));
      pin.point_tile_cols = tile_cols;
      gather.film_weight = result.film_weight;
      gather.mean_samples = done;
    }
    point_gather* gathering = auto_points ? &gather : nullptr;
    int raise = pass == 0 && done == 0 ? params.signals_in_first_pass : 0;
    auto run_samples = [&](int s0, int s1, bool extend) {
      if (params.on_samples) params.on_samples(s1 - s0);
      auto run = [&](const auto& s) {
        return params.profile
                   ? run_pass<true>(pin, s, s0, s1, pass_sum, rows, arena, progress, raise, extend, gathering)
                   : run_pass<false>(pin, s, s0, s1, pass_sum, rows, arena, progress, raise, extend, gathering);
      };
      // A bayes sampler that fell back runs its passes as the power (or bvh) sampler itself: the hot path has none of
      // its code.
      if constexpr (std::is_same_v<Sampler, bayes_sampler>)
        return !sampler.fallback ? run(sampler) : sampler.fallback_bvh ? run(sampler.bvh) : run(sampler.power);
      else return run(sampler);
    };
    bool complete = run_samples(done, done + count, false);
    // A cut pass that ends before the budget (the machine sped up) goes on with more of its samples, from the same
    // model and sums: still one pass, the --spp render's of its total, and still shorter than the scheduled one. So
    // it is the render's last whatever happens: what bayes learns from a pass in pieces differs in the last bits from
    // what it learns from one run of it (its accumulators add the samples in another order), and no later pass may
    // use that. Where even the scheduled size less one spp ends short of the budget (the machine sped up by more than
    // the quarter fit_pass_to_time adds), the render ends there, a little early.
    raise = 0;
    while (complete && count < scheduled - 1 && result.seconds + seconds_since(t0) < params.time_budget) {
      const double elapsed = seconds_since(t0);
      const int more =
          fit_pass_to_time(scheduled - 1 - count, params.time_budget - result.seconds - elapsed, elapsed / count);
      progress.spp_done = done + count;  // (the bar's running pass: this piece, from its start)
      bar_runs(more);
      complete = run_samples(done + count, done + count + more, true);
      count += more;
    }
    const bool cut = count < scheduled;
    g_first_pass.store(false);
    // A signal the first pass finished for ends the render after it, even where that pass was the last (an animation
    // then stops after this frame; before, it went on to the next frame's first pass).
    if (first && g_signal.load() != 0) result.interrupted = true;
    if (!complete) {
      result.interrupted = true;
      break;
    }
    // Weighted passes: the film holds sum_k w_k S_k and the weight sum_k w_k n_k (w = 1 is exact: S_k itself).
    // A pass weighs as the first pass of its stratified light set (integrator.h), whose samples must weigh alike:
    // unequal weights undo the set's stratification. While a sampler learns, every pass starts a set and weighs by
    // its own start; after bayes's fallback every later pass weighs as the first one after it. (By each pass's own
    // start, the Cornell box, direct, 640x480, falling back after 5 spp, had 1.9-2.0x power's relMSE at 32 spp, seeds
    // 13-15; 1.4x by the set's, whose 27 samples stand against power's one set of 32.) The passes before the fallback
    // are then kept apart (late_fallback), and the share of the image of those after it is what the plain schedule
    // gives them: a share that followed the fallback's spp, which the check drew from the samples it weighs, biased
    // the image.
    const int set_start = result.stratum_base;
    const double wk =
        staged ? staged_pass_weight(set_start, weighting, result.late_learns) : pass_weight(set_start, weighting);
    for (size_t i = 0; i < n; i++) result.film[i] += wk * pass_sum[i];
    result.film_weight += wk * count;
    if (result.late_learns) result.late_ref_weight += pass_weight(set_start, weighting) * count;
    if (result.late_fallback) result.late_ref_weight += plain_pass_weight(done, weighting, staged) * count;
    if (auto_points) {  // (in row order: a tile's rows one after another)
      for (double& x : result.point_stats) x *= point_stats_decay;
      for (int y = 0; y < h; y++)
        for (int tx = 0; tx < tile_cols; tx++) {
          double* to = &result.point_stats[point_tile_of(tx * point_tile_size, y, tile_cols) * point_stat_fields];
          const double* from = &gather.rows[(size_t(y) * size_t(tile_cols) + size_t(tx)) * point_stat_fields];
          for (int f = 0; f < point_stat_fields; f++) to[f] += from[f];
        }
    }
    for (const path_stats& st : rows.stats) add_stats(result.stats, st);
    for (const cycle_timers& t : rows.timers)
      for (int c = 0; c < prof_count; c++) result.profile_cycles[c] += t.cycles[c];
    auto tl = clock_type::now();
    bool changed = false;  // the model of the next pass differs from this one's
    if constexpr (std::is_same_v<Sampler, bayes_sampler>) {
      bool was = sampler.fallback;
      sampler.check_fallback(rows.records, result.film, result.film_weight, count, done + count);
      changed = sampler.fallback != was;
      // The end of the first staged_spp spp: where the check has found learning to pay, the later passes weigh by the
      // learner's schedule among themselves, and the passes so far keep their share (staged_pass_weight).
      if (staged && done < staged_spp && done + count >= staged_spp && sampler.check_done && !sampler.fallback) {
        result.early_film = result.film;
        result.early_weight = result.film_weight;
        result.late_learns = true;
      }
      // The fallback: the passes so far keep their share of the image by the plain schedule, the later ones (one
      // stratified set) weigh alike among themselves.
      if (changed && weighting > 0) {
        result.early_film = result.film;
        result.early_weight = result.film_weight;
        result.late_fallback = true;
      }
    }
    if constexpr (Sampler::learns) {
      changed = changed || model_moves(sampler);
      sampler.learn(rows.records);
    } else {
      sampler.end_pass();
    }
    if (changed) result.stratum_base = done + count;
    result.learn_seconds += seconds_since(tl);
    if constexpr (std::is_same_v<Sampler, bayes_sampler>) result.learn_parts = sampler.timing;
    result.seconds += seconds_since(t0);
    // (Not the checkpoint after it: a cut pass, the last, has none.)
    seconds_per_spp = (result.seconds - cycle_start) / count;
    measured_draws = draws;
    done += count;
    result.spp = done;
    result.passes = pass + 1;
    progress.spp_done = done;
    progress.pass_spp = 0;

    pass_record rec;
    rec.pass = pass + 1;
    rec.spp = done;
    rec.seconds = result.seconds;
    if (params.reference) {
      rec.has_error = true;
      image_data mean = film_image(result);
      rec.error = compute_error(mean.pixels.data(), params.reference->pixels.data(), mean.pixels.size());
    }
    result.log.push_back(rec);
    // Not after the last pass (the render's end, where the caller writes its final checkpoint anyway: a second
    // copy of it, counted in the render's seconds, made the summary disagree with the log's last row; a review).
    const bool last_pass = done >= target || (params.time_budget > 0 && result.seconds >= params.time_budget) || cut;
    if (after_pass && !last_pass) {
      // What the caller does between passes (a checkpoint: seconds for a large render) is render time too: the next
      // pass's seconds, the --time budget and the summary count it (the error computation above they do not).
      auto ta = clock_type::now();
      after_pass();
      result.seconds += seconds_since(ta);
    }
    if (cut) break;
  }
}

}  // namespace

int pass_size(int pass, int done, int64_t pixels) {
  // 1 spp per pass while learning matters most, then passes of 1/4 of the samples so far (the error log gets
  // log-spaced points; learning costs a few per cent of the render: 15 passes for 32 spp, 19 for 64), at most
  // 64 spp. Passes of 1/8 (23 passes for 32 spp) learned no better: fixed-spp relMSE within 0.5 % on the living
  // room, plant room and hall (32 and 128 spp, two seeds), at about 1.5x the learning time.
  // Images under 1024 pixels may grow passes to 65536 samples: every pass keeps a record (the log, checkpoints),
  // and a 1-pixel render of 2^31 spp in 64-spp passes held 3 GB of them.
  if (pass < 8) return 1;
  int cap = int(std::max<int64_t>(64, (int64_t(1) << 16) / std::max<int64_t>(pixels, 1)));
  return std::min(cap, std::max(1, done / 4));
}

bool ends_scheduled_pass(int spp, int64_t pixels) {
  int64_t done = 0;
  for (int pass = 0; done < spp; pass++) done += pass_size(pass, int(done), pixels);
  return done == spp;
}

double seconds_per_spp_at(double seconds_per_spp, int measured_draws, int draws) {
  if (measured_draws <= 0 || draws <= 0 || measured_draws == draws) return seconds_per_spp;
  return seconds_per_spp * (2.0 + draws) / (2.0 + measured_draws);
}

int fit_pass_to_time(int count, double left, double seconds_per_spp) {
  if (count <= 1 || !(seconds_per_spp > 0) || !(left > 0)) return count;
  // (A quarter more than the last pass's speed says: a pass that ends short of the budget goes on, but only up to
  // its scheduled size less one spp.)
  const double fits = std::ceil(1.25 * left / seconds_per_spp);
  return fits < double(count) ? std::max(1, int(fits)) : count;
}

bool sampler_adapts(const light_sampler& s) {
  return std::visit([](const auto& x) { return adapts(x); }, s);
}

double pass_weight(int done, double s) {
  // An adaptive sampler's first passes use the prior alone or models learned from a few samples: in the living
  // room (bayes, direct) the first 2 spp have ~50x the per-sample relMSE of later ones and make up a third of
  // the error of a 357-spp image. Down-weighting them by a schedule fixed in advance keeps every pass's weight
  // independent of its samples (the weighted mean stays unbiased). s = 4 took the living room's error at 357 spp
  // from 7.59e-4 to 5.09e-4 (inverse-variance weights measured against the reference: 4.87e-4) and costs a
  // sampler with nothing to learn 3 % of its samples' worth at 64 spp, 0.8 % at 357.
  if (!(s > 0)) return 1.0;
  return (done + 1.0) / (done + 1.0 + s);
}

bool stages_passes(const render_params& params, double weighting) {
  return weighting > 0 && params.max_depth == 1;
}

double staged_pass_weight(int done, double s, bool late_learns) {
  // bayes's first passes are sampled from the prior (the bound sampler's choice) or from a model of a few samples:
  // in the living room (direct, 320 x 240) the first pass has several hundred times the per-sample relMSE of a
  // learned one, and passes up to about 32 spp still weigh on the image. In a direct render (stages_passes) those
  // first 8 spp weigh pass_weight(n, 4s); where the fallback check has found learning to pay by their end, the later
  // passes weigh pass_weight(n, 16s) among themselves, their share of the image still the plain schedule's
  // (film_image), so that no weight or share depends on the samples it weighs: the image stays unbiased. Elsewhere
  // (bayes fell back or its check has not decided) the later passes weigh pass_weight(n, s), as before. Measured at
  // 400 spp, seeds 11 / 12, in the living room, direct: relMSE 5.70 / 5.84e-5 with pass_weight(n, s) throughout,
  // 3.78 / 3.90e-5 staged. Path traced, the bounces' noise, which learning leaves, is most of a learned pass's
  // variance and the passes differ less: staged later passes lost 1.06-1.10x in the living room (128 spp), the staged
  // first 8 spp alone 1.025x in the plant room (116 spp), so path-traced renders keep pass_weight(n, s) throughout.
  if (done < staged_spp) return pass_weight(done, staged_early * s);
  return pass_weight(done, late_learns ? staged_late * s : s);
}

render_result render(const scene_data& scene, const bvh_data& bvh, const light_data& lights,
                     const render_params& params) {
  render_result result;
  render_params one = params;
  one.frames = 1;
  light_data copy = lights;
  render_frames(scene, bvh, copy, one, [&](int, const render_result& r) { result = r; });
  return result;
}

void render_frames(const scene_data& scene, const bvh_data& bvh, light_data& lights, const render_params& params,
                   const std::function<void(int, const render_result&)>& on_frame) {
  render_inputs in;
  in.scene = &scene;
  in.bvh = &bvh;
  in.lights = &lights;
  in.camera = make_camera(scene.camera, params.width, params.height);
  in.max_depth = params.max_depth;
  in.seed = params.seed;
  in.stratify = params.stratify;
  in.nee_samples = std::max(1, params.light_samples);
  in.light_points = std::max(1, params.light_points);
  int frames = std::max(1, params.frames);
  // The set-up (light tree, the regions of the first hits) runs on at most --threads threads too.
  int threads = params.threads > 0 ? params.threads : int(std::max(1u, std::thread::hardware_concurrency()));
  tbb::global_control allow(tbb::global_control::max_allowed_parallelism, size_t(threads));
  auto t0 = clock_type::now();
  // The first render of a command that installed the handlers sets up as the loader does: a signal ends it at once
  // (before, the signal waited for the light tree and regions, seconds in a large scene, and the render that
  // followed stopped before its first pass and wrote an empty checkpoint over the one given). Later renders of the
  // same command (compare's next sampler, profile's timed render) keep what the earlier ones wrote: they stop after
  // their pass.
  struct setup_scope {
    bool active = false;
    setup_scope() {
      int expected = phase_before_render;
      active = (g_signal.load() == 0 || g_early_signal.load()) &&
               g_phase.compare_exchange_strong(expected, phase_render_setup);
    }
    ~setup_scope() {
      if (active) g_phase.store(phase_render);
    }
  };
  std::optional<setup_scope> in_setup;
  in_setup.emplace();
  std::optional<slow_phase_note> note(std::in_place, params.notes,
                                      "setting up the light sampler (light tree, regions of the first hits) ...");
  light_tree_data tree;
  if (needs_light_tree(params.sampler.kind))
    tree = build_light_tree(lights, scene, params.sampler.kind == sampler_kind::bayes);  // (colours: bayes only)
  light_sampler sampler = make_light_sampler(params.sampler, in, tree);
  render_result restored;
  restored.width = params.width;
  restored.height = params.height;
  if (params.restore) params.restore(restored, sampler);
  note.reset();
  in_setup.reset();
  bool resuming = !restored.film.empty();
  // (A resumed render's model was frozen by its oracle unless the oracle itself was interrupted: see below.)
  if (auto* b = std::get_if<bayes_sampler>(&sampler); b && params.sampler.bayes.oracle_spp > 0 && !b->frozen) {
    // Oracle mode: learn for oracle_spp spp on random streams independent of the render's (its own seed),
    // then freeze. Using the render's own streams would let a sample's pmf depend on its own outcome.
    render_inputs learn_in = in;
    learn_in.seed = mix64(params.seed ^ 0x6f7261636c65ull);
    render_params lp = params;
    lp.spp = params.sampler.bayes.oracle_spp;
    lp.time_budget = 0;
    lp.reference = nullptr;
    lp.progress = false;
    lp.notes = false;  // (its own note below says what it does)
    lp.finish_first_pass = false;  // (a signal ends the learning at once, and the render before its first pass)
    lp.begins_passes = false;
    lp.signals_in_first_pass = 0;
    render_result scratch;
    note.emplace(params.notes, "learning the model of --bayes-oracle " + std::to_string(lp.spp) + " spp ...");
    const bool finish_early = g_finish_early.exchange(false);  // (a signal while it learns stops the render too)
    render_with(learn_in, *b, lp, scratch);
    g_finish_early.store(finish_early);
    note.reset();
    if (scratch.interrupted) {
      // Cut short: nothing of it is kept, so a checkpoint saves an empty model and a resumed render learns it anew.
      // Nor does a first pass follow (its half-learned or empty model would differ from one render's).
      sampler = make_light_sampler(params.sampler, in, tree);
      g_no_first_pass.store(true);
    }
    else
      b->frozen = true;
  }
  double setup = seconds_since(t0);
  // A checkpoint of frame k (an animation's) holds the sampler as frame k had it: its decay is in the statistics.
  const int first = resuming ? restored.frame : 0;
  for (int frame = first; frame < frames; frame++) {
    render_result result = frame == first && resuming ? restored : render_result{};
    result.width = params.width;
    result.height = params.height;
    result.frame = frame;
    result.setup_seconds = frame == first ? setup : 0.0;
    render_params fp = params;
    fp.finish_first_pass = params.finish_first_pass && frame == 0;  // (a later frame stops at once: earlier ones exist)
    fp.signals_in_first_pass = frame == params.signal_frame && frame > 0 ? 1 : frame == 0 ? params.signals_in_first_pass : 0;
    if (!params.frame_references.empty()) fp.reference = params.frame_references[size_t(frame)];
    if (frame > 0) set_sun_direction(lights, animated_sun_direction(scene.sun, frame, frames));
    if (frame > first) std::visit([&](auto& s) { s.begin_frame(params.frame_decay); }, sampler);
    if (auto* b = std::get_if<bayes_sampler>(&sampler); b && frame > first) result.fallback_earlier = b->fallback;
    std::function<void()> after_pass;
    if (params.on_pass) after_pass = [&] { params.on_pass(result, sampler, false); };
    // Each frame has its own random streams (frame 0 the render's seed): with the same streams in every frame, a
    // learning sampler began frame k with statistics learned from the very samples it was about to draw again, so
    // its light choices depended on their own outcomes (bayes 1 % dark from frame 1 on with a still sun, z -22).
    render_inputs frame_in = in;
    frame_in.seed = frame_seed(params.seed, frame);
    std::visit([&](auto& s) { render_with(frame_in, s, fp, result, after_pass); }, sampler);
    if (params.on_pass) params.on_pass(result, sampler, true);
    result.sampler_bytes = sampler_memory_bytes(sampler);
    if (auto* b = std::get_if<bound_sampler>(&sampler)) result.regions = int(b->regions.key.size()), result.pairs = b->regions.pairs;
    if (auto* b = std::get_if<bayes_sampler>(&sampler)) {
      result.regions = int(b->regions.key.size());
      result.pairs = b->regions.pairs;
      result.fallback_spp = b->fallback_spp;
      result.fallback_ratio = b->check_ratio;
      result.fallback_bvh = b->fallback_bvh;
      result.fallback_ratio_bvh = b->check_ratio_bvh;
      result.one_light = b->one_light;
    }
    on_frame(frame, result);
    if (result.interrupted) return;
    // A signal while this frame's outputs were written stops the animation here, and its end is saved (on_pass's
    // last call again): frame k + 1 would stop before its first pass, leaving nothing to resume from.
    if (frame + 1 < frames && interrupt_signal() != 0) {
      if (params.on_pass) params.on_pass(result, sampler, true);
      return;
    }
  }
}

image_data film_image(const render_result& r) {
  image_data img;
  img.width = r.width;
  img.height = r.height;
  img.pixels.assign(r.film.size(), 0.0f);
  // The mean as it is, values below zero included (bayes's control variates make a pixel's unbiased mean noisy
  // around a true zero): writing them as zero biased the image upward wherever many pixels' means fall below zero
  // (a reviewer's lamp facing a ceiling 1 mm away: the image's mean 26x too high at 64 spp). PNG clamps for display.
  // Staged weights (render_result::early_film): the first passes' mean and the later passes' mean, in shares fixed in
  // advance, so that the later passes' own weights may depend on what the first ones found.
  const bool staged = !r.early_film.empty() && r.film_weight > r.early_weight;
  const double share = staged ? r.early_weight / (r.early_weight + r.late_ref_weight) : 0.0;
  const double late_weight = r.film_weight - r.early_weight;
  if (r.spp > 0 && r.film_weight > 0)
    for (size_t i = 0; i < r.film.size(); i++) {
      float v = staged ? float(share * (r.early_film[i] / r.early_weight) +
                               (1 - share) * ((r.film[i] - r.early_film[i]) / late_weight))
                       : float(r.film[i] / r.film_weight);
      img.pixels[i] = v == 0 ? 0.0f : v;  // (-0 as 0; NaN stays NaN: the film never holds one, tests check it does not)
    }
  return img;
}

// Blocks or unblocks (how: SIG_BLOCK, SIG_UNBLOCK) SIGINT, SIGTERM and SIGHUP for the calling thread.
static void mask_interrupt_signals(int how) {
  sigset_t s;
  sigemptyset(&s);
  sigaddset(&s, SIGINT);
  sigaddset(&s, SIGTERM);
  sigaddset(&s, SIGHUP);
  pthread_sigmask(how, &s, nullptr);
}

void install_interrupt_handlers(bool finish_first_pass, bool resuming) {
  g_finish_early.store(finish_first_pass);
  g_resuming.store(resuming);
  g_phase.store(phase_setup);
  std::signal(SIGINT, on_interrupt);
  std::signal(SIGTERM, on_interrupt);
  // A closed terminal (SIGHUP) stops the render as SIGTERM does (image of the passes done, exit 129), unless the
  // process was started to ignore it (nohup): that choice is kept.
  if (std::signal(SIGHUP, SIG_IGN) != SIG_IGN) std::signal(SIGHUP, on_interrupt);
  set_fifo_wait_check(interrupt_count);  // an output FIFO's wait for its reader ends on a signal that arrives in it
  // A process started with them blocked (a launcher's mask is inherited) could not be interrupted at all; one that
  // arrived meanwhile is delivered now.
  mask_interrupt_signals(SIG_UNBLOCK);
}
void block_interrupt_signals() { mask_interrupt_signals(SIG_BLOCK); }
int interrupt_signal() { return g_signal.load(); }
const char* signal_name(int sig) {
  return sig == SIGTERM ? "SIGTERM" : sig == SIGINT ? "SIGINT" : sig == SIGHUP ? "SIGHUP" : "signal";
}
int interrupt_count() { return g_signal_count.load(); }
void reset_interrupt() {
  g_signal.store(0);
  g_signal_count.store(0);
  g_first_signal_ns.store(0);
  g_last_signal_ns.store(0);
  g_early_signal.store(false);
  g_passes_begun.store(false);
  g_no_first_pass.store(false);
}
int interrupted_before_render() {
  g_phase.store(phase_before_render);  // until the first render sets up, a signal asks it to stop after its pass
  int sig = g_signal.load();
  if (sig == 0 || g_early_signal.load()) return 0;  // (`render` goes on to its first pass)
  std::fprintf(stderr, "bayeslight: interrupted (%s) while loading the scene; nothing written\n", signal_name(sig));
  return 128 + sig;
}

}  // namespace bl
