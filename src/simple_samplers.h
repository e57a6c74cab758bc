// simple_samplers: the textbook light selections — uniform over emitters, and proportional to power.
#pragma once

#include "light_sampler_types.h"
#include "sampling.h"

namespace bl {

// Every light equally likely.
struct uniform_sampler {
  static constexpr bool learns = false;
  struct context {};
  int count = 0;
  void locate(context&, const shade_point&) const {}
  void prepare(context&, const shade_point&) const {}
  light_choice sample(const context&, double u, double) const {
    if (count == 0) return {};
    int i = std::min(int(u * double(count)), count - 1);
    return {i, 1.0f / float(count)};
  }
  float pmf(const context&, int) const { return count > 0 ? 1.0f / float(count) : 0.0f; }
  void end_pass() {}
  void begin_frame(double) {}
};

// Lights proportional to emitted power.
struct power_sampler {
  static constexpr bool learns = false;
  struct context {};
  discrete_data dist;
  void locate(context&, const shade_point&) const {}
  void prepare(context&, const shade_point&) const {}
  light_choice sample(const context&, double u, double) const {
    int i = sample_discrete(dist, u);
    if (i < 0) return {};
    return {i, float(discrete_pmf(dist, i))};
  }
  float pmf(const context&, int light) const { return float(discrete_pmf(dist, light)); }
  void end_pass() {}
  void begin_frame(double) {}
};

}  // namespace bl
