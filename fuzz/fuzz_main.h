// fuzz_main: the libFuzzer glue shared by the fuzz_<target> binaries (built only with -DBAYESLIGHT_FUZZ=ON).
// An input_error is the parser's correct answer to a bad file; any other exception aborts with its type and
// message, so libFuzzer saves the input as a crash. Warnings the parsers print on std::cerr are dropped (they
// would flood the fuzzer's log) unless BAYESLIGHT_FUZZ_VERBOSE is set (then each input_error is printed too, to
// check what a seed reaches); sanitizer reports go to fd 2 as usual.
#pragma once

#include "fuzz_entry.h"

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <typeinfo>

namespace bl::fuzz {

// Runs one input through target t in this process's scratch folder.
inline int run_one(target t, const uint8_t* data, size_t size) {
  static scratch_dir dir;  // one per process, removed at exit
  try {
    feed(t, dir, data, size);
  } catch (const input_error& e) {
    // A clean rejection naming the file: the expected outcome for malformed input.
    if (std::getenv("BAYESLIGHT_FUZZ_VERBOSE")) std::fprintf(stderr, "input_error: %s\n", e.what());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz_%s: escaped exception %s: %s\n", target_name(t), typeid(e).name(), e.what());
    std::abort();
  } catch (...) {
    std::fprintf(stderr, "fuzz_%s: escaped non-standard exception\n", target_name(t));
    std::abort();
  }
  return 0;
}

}  // namespace bl::fuzz

// libFuzzer start-up hook: silence std::cerr (see the header comment).
extern "C" int LLVMFuzzerInitialize(int*, char***) {
  if (!std::getenv("BAYESLIGHT_FUZZ_VERBOSE")) std::cerr.rdbuf(nullptr);
  return 0;
}
