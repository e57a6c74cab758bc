// profile_timers: cycle counters of the NEE hot path for `bayeslight profile`. The integrator takes a timer
// type as a template argument: no_timers (every call compiles to nothing) for renders, cycle_timers for the
// profile. Invariant: timers only read the CPU's time-stamp counter and add to per-row counters; they never
// change what is rendered.
#pragma once

#include <x86intrin.h>

#include <cstdint>

namespace bl {

// The categories of a profile, in table order.
enum profile_category : int {
  prof_camera,         // camera ray generation and its closest hit
  prof_bounce,         // closest hit of BSDF-sampled rays
  prof_shading,        // surface point and BSDF set-up, emission seen
  prof_region,         // region lookup (region-based samplers)
  prof_pmf,            // light selection set-up at the point (PMF build)
  prof_select,         // cluster / light choice
  prof_point,          // point on the light and BSDF evaluation
  prof_shadow,         // shadow rays
  prof_record,         // observation recording (learning samplers)
  prof_continue,       // BSDF sampling and Russian roulette
  prof_count
};

// Timers that do nothing (renders).
struct no_timers {
  static constexpr bool enabled = false;
  uint64_t start() const { return 0; }
  void stop(profile_category, uint64_t) {}
};

// Cycle counters per category (one per image row, summed afterwards).
struct cycle_timers {
  static constexpr bool enabled = true;
  uint64_t cycles[prof_count] = {};
  uint64_t start() const { return __rdtsc(); }
  void stop(profile_category c, uint64_t t0) { cycles[c] += __rdtsc() - t0; }
};

}  // namespace bl
