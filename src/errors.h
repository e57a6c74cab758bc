// errors: the two failure kinds users see, each with its exit status (SPEC.md section 4).
// input_error (exit 3): a missing, unreadable or malformed scene, OBJ, MTL or image; names file and line.
// usage_error (exit 2): a bad command line. output_error and anything else escaping main is exit 1.
#pragma once

#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <string>

namespace bl {

constexpr int exit_ok = 0;
constexpr int exit_failure = 1;
constexpr int exit_usage = 2;
constexpr int exit_bad_input = 3;

// Bad input file: the message reads "FILE:LINE: what" (or "FILE: what" when there is no line).
// A file name as a message shows it: one longer than any path the system takes (4096 bytes) by its two ends (a
// scene's 10 MB "mesh" name was echoed whole; a review).
inline std::string shown_file_name(const std::string& f) {
  if (f.size() <= 4096) return f;
  return f.substr(0, 200) + "...(" + std::to_string(f.size()) + " characters)..." + f.substr(f.size() - 100);
}
struct input_error : std::runtime_error {
  std::string file;
  int line = 0;
  input_error(const std::string& file_, int line_, const std::string& what)
      : std::runtime_error(shown_file_name(file_) + (line_ > 0 ? ":" + std::to_string(line_) : std::string()) +
                           ": " + what),
        file(file_),
        line(line_) {}
  input_error(const std::string& file_, const std::string& what) : input_error(file_, 0, what) {}
};

// Output could not be written (unwritable path, full disk): exit 1.
struct output_error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The failures of a set of outputs written one after another: each is tried and a failure kept, so that one
// output that cannot be written (a full disk, a FIFO's reader gone) does not lose the outputs after it.
struct output_failures {
  std::string messages;  // one per line
  // An animation says each failure when it happens (a frame's unwritable output was named only after the last
  // frame: a review), and at the end how many there were.
  bool say_now = false;
  int count = 0;
  // Runs write(); an output_error it throws is kept (false) instead of ending the caller.
  template <class F>
  bool attempt(F&& write) {
    try {
      write();
      return true;
    } catch (const output_error& e) {
      count++;
      if (say_now) std::fprintf(stderr, "bayeslight: error: %s\n", e.what());
      messages += (messages.empty() ? "" : "\nbayeslight: error: ") + std::string(e.what());
      return false;
    }
  }
  // Throws one output_error naming every failure (each on its own line, as main prints errors), if any; once said,
  // their count.
  void rethrow() const {
    if (count == 0) return;
    if (say_now)
      throw output_error(std::to_string(count) + " output" + (count > 1 ? "s" : "") +
                         " could not be written (each named above)");
    throw output_error(messages);
  }
};

// A warning (or any text for stderr) assembled with << and written with one fwrite when it goes out of scope (a
// temporary: at the end of its statement), so that a line another thread prints meanwhile (slow_phase_note) cannot
// land inside it as it could between the pieces std::cerr writes one by one.
struct stderr_text : std::ostringstream {
  stderr_text() = default;
  stderr_text(const stderr_text&) = delete;
  stderr_text& operator=(const stderr_text&) = delete;
  ~stderr_text() override {
    const std::string s = str();
    std::fwrite(s.data(), 1, s.size(), stderr);
  }
};

// Bad command line (unknown flag, value out of range, unknown sampler name).
struct usage_error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace bl
