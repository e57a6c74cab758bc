// progress: the stderr progress bar (passes, spp, elapsed, estimated remaining time).
#include "progress.h"

#include <unistd.h>

#include <cstdio>
#include <string>
#include <utility>

namespace bl {

bool stderr_is_terminal() { return isatty(STDERR_FILENO) == 1; }

namespace {
std::string format_seconds(double s) {
  if (!(s >= 0) || s > 1e7) return "--:--";
  int t = int(s + 0.5);
  char buf[32];
  if (t >= 3600) std::snprintf(buf, sizeof buf, "%d:%02d:%02d", t / 3600, t / 60 % 60, t % 60);
  else std::snprintf(buf, sizeof buf, "%d:%02d", t / 60, t % 60);
  return buf;
}
}  // namespace

progress_bar::progress_bar(progress_counters& counters, bool enabled)
    : counters_(counters), enabled_(enabled), start_(std::chrono::steady_clock::now()) {
  if (enabled_) thread_ = std::thread([this] { run(); });
}

progress_bar::~progress_bar() {
  if (!enabled_) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.join();
  draw(true);
}

void progress_bar::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stop_) {
    draw(false);
    wake_.wait_for(lock, std::chrono::milliseconds(250));
  }
}

void progress_bar::draw(bool final_line) {
  double elapsed = counters_.seconds_before.load() +
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  int done = counters_.spp_done.load(), target = counters_.spp_target.load();
  double budget = counters_.time_budget.load();
  int rows = std::max(1, counters_.rows.load());
  // Fraction done, counting the running pass by its finished rows.
  double running = double(counters_.pass_spp.load()) * counters_.rows_done.load() / rows;
  double fraction = target > 0 ? (done + running) / target : (budget > 0 ? elapsed / budget : 0);
  fraction = std::min(std::max(fraction, 0.0), 1.0);
  double remaining = fraction > 0 ? elapsed * (1 - fraction) / fraction : -1;
  if (target == 0 && budget > 0) {
    // The budget's end, or the end of the running pass where that comes later (a pass started before the budget runs
    // to its end: the bar read "0:00 left" for the whole of a last pass of 28 s; a review), from its rows done.
    remaining = std::max(0.0, budget - elapsed);
    const int rows_done = counters_.rows_done.load();
    const int64_t started = counters_.pass_start_ns.load();
    if (counters_.pass_spp.load() > 0 && rows_done > 0 && started > 0) {
      const double in_pass =
          1e-9 * double(std::chrono::duration_cast<std::chrono::nanoseconds>(
                            std::chrono::steady_clock::now().time_since_epoch()).count() - started);
      const double pass_fraction = double(rows_done) / rows;
      remaining = std::max(remaining, in_pass * (1 - pass_fraction) / pass_fraction);
    }
    fraction = elapsed + remaining > 0 ? elapsed / (elapsed + remaining) : 0;
  }
  const int width = 30;
  int fill = int(fraction * width);
  std::string bar(size_t(fill), '=');
  if (fill < width) bar += '>' + std::string(size_t(width - fill - 1), ' ');
  std::string spp = target > 0 ? std::to_string(done) + "/" + std::to_string(target) : std::to_string(done);
  std::fprintf(stderr, "\r[%s] pass %d  spp %s  %s elapsed  %s left   ", bar.c_str(), counters_.pass.load(),
               spp.c_str(), format_seconds(elapsed).c_str(), format_seconds(remaining).c_str());
  if (final_line) std::fprintf(stderr, "\n");
  std::fflush(stderr);
}

slow_phase_note::slow_phase_note(bool enabled, std::string text, std::chrono::milliseconds after)
    : text_(std::move(text)) {
  if (!enabled) return;
  thread_ = std::thread([this, after] {
    std::unique_lock<std::mutex> lock(mutex_);
    // (A whole line: warnings the phase prints cannot land in the middle of it.)
    if (!wake_.wait_for(lock, after, [this] { return done_; })) std::fprintf(stderr, "%s\n", text_.c_str());
  });
}

slow_phase_note::~slow_phase_note() {
  if (!thread_.joinable()) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    done_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

}  // namespace bl
