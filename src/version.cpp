// version: bayeslight --version (version.h). BAYESLIGHT_VERSION and BAYESLIGHT_BUILD_TYPE come from CMake.
#include "version.h"

#include "checkpoint.h"

#include <embree3/rtcore_config.h>
#include <oneapi/tbb/version.h>

#include <cstdio>
#include <string>

namespace bl {

void print_version() {
#ifndef BAYESLIGHT_VERSION
#define BAYESLIGHT_VERSION "unknown"
#define BAYESLIGHT_BUILD_TYPE "unknown"
#endif
#if defined(__clang__)
  const std::string compiler = "clang " __clang_version__;
#elif defined(__GNUC__)
  const std::string compiler = "GCC " __VERSION__;
#else
  const std::string compiler = "an unknown compiler";
#endif
#if defined(__SANITIZE_ADDRESS__)
  const char* sanitizers = ", AddressSanitizer";
#elif defined(__SANITIZE_THREAD__)
  const char* sanitizers = ", ThreadSanitizer";
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
  const char* sanitizers = ", AddressSanitizer";
#elif __has_feature(thread_sanitizer)
  const char* sanitizers = ", ThreadSanitizer";
#else
  const char* sanitizers = "";
#endif
#else
  const char* sanitizers = "";
#endif
  std::printf("bayeslight %s\ncheckpoint format %u\nbuilt with %s (%s%s; -ffp-contract=off, no fast-math, no host-specific "
              "instructions), Embree %s, oneTBB %s\n",
              BAYESLIGHT_VERSION, unsigned(checkpoint_format_version()), compiler.c_str(), BAYESLIGHT_BUILD_TYPE,
              sanitizers, RTC_VERSION_STRING, TBB_VERSION_STRING);
}

}  // namespace bl
