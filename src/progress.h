// progress: a progress bar on stderr (only when stderr is a terminal), redrawn by its own thread from
// atomic counters the render loop updates; it never touches render data, so it cannot change an image.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>

namespace bl {

// Counters shown by the bar; written by the render loop, read by the bar's thread.
struct progress_counters {
  std::atomic<int> pass{0};
  std::atomic<int> spp_done{0};
  std::atomic<int> spp_target{0};       // 0 when rendering against a time budget
  std::atomic<double> time_budget{0};
  std::atomic<double> seconds_before{0}; // render time already spent (a resumed render's), counted as elapsed
  std::atomic<int> rows_done{0};        // rows of the running pass
  std::atomic<int> rows{1};
  std::atomic<int> pass_spp{0};         // samples per pixel of the running pass
  std::atomic<int64_t> pass_start_ns{0}; // when the running pass began (steady_clock nanoseconds)
};

// A running progress bar; stops and clears its line when destroyed.
class progress_bar {
 public:
  progress_bar(progress_counters& counters, bool enabled);
  ~progress_bar();
  progress_bar(const progress_bar&) = delete;
  progress_bar& operator=(const progress_bar&) = delete;

 private:
  void run();
  void draw(bool final_line);
  progress_counters& counters_;
  bool enabled_;
  std::chrono::steady_clock::time_point start_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::thread thread_;
};

// A note on stderr for a phase that has no progress bar (loading the scene, the light sampler's set-up): `text` as a
// line of its own once `after` has passed with the phase still running; nothing for a quick phase. Only when enabled
// (the progress bar's condition: stderr a terminal, no --quiet). The phase ends when the note is destroyed.
class slow_phase_note {
 public:
  slow_phase_note(bool enabled, std::string text, std::chrono::milliseconds after = std::chrono::milliseconds(1000));
  ~slow_phase_note();
  slow_phase_note(const slow_phase_note&) = delete;
  slow_phase_note& operator=(const slow_phase_note&) = delete;

 private:
  std::string text_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool done_ = false;
  std::thread thread_;
};

// Whether stderr is a terminal.
bool stderr_is_terminal();

}  // namespace bl
