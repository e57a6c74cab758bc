// light_sampler_types: the vocabulary every light sampler shares — sampler kinds and their names, what a
// sampler sees of a shading point, and what it returns.
// The contract of a sampler type S (dispatched once per pass by std::visit, never per sample):
//   S::context                               per-vertex scratch, filled by prepare (no allocation)
//   void locate(context&, const shade_point&) const   the region lookup part of prepare (profiles time it apart)
//   void prepare(context&, const shade_point&) const
//   light_choice sample(const context&, double u_select, double u_inner) const   (53-bit uniforms)
//   float pmf(const context&, int light) const      exactly the probability sample() gives `light`
//   void end_pass()                                  between passes (non-learning samplers)
//   void begin_frame(double decay)                   animations: scale learned statistics by `decay` (else no-op)
//   static constexpr bool learns; learners also have S::row_state, record(row_state&, const nee_event&)
//   and learn(std::vector<row_state>&) called between passes with the rows in image order; S::rows_per_state
//   consecutive image rows (a band) share one row_state, filled in pixel order.
//   Learners also have sample_done(row_state&, int pixel, vec3f radiance), called after each path sample.
//   Learners may have `learn_timing timing` (seconds per part of learn, summed over passes) for profiles.
// Invariant (unbiasedness): every light that can contribute at a point has pmf > 0 there.
#pragma once

#include "math.h"

#include <string>

namespace bl {

// The sampler names of the command line, in the order of SPEC.md section 7.
enum class sampler_kind { uniform, power, bvh, bound, donikian, bayes };
inline constexpr sampler_kind all_sampler_kinds[] = {sampler_kind::uniform, sampler_kind::power,
                                                     sampler_kind::bvh,     sampler_kind::bound,
                                                     sampler_kind::donikian, sampler_kind::bayes};
// Name of a sampler kind.
const char* sampler_name(sampler_kind kind);
// Parses a sampler name; false when unknown.
bool parse_sampler_kind(const std::string& name, sampler_kind& kind);
// "uniform | power | ..." for messages.
std::string sampler_names();
// Whether a sampler kind is implemented in this build.
bool sampler_available(sampler_kind kind);

// Wall seconds of the parts of learning between passes, summed over passes.
struct learn_timing {
  double reduce = 0;   // folding the passes' observation records into the statistics (and their coefficients)
  double regions = 0;  // creating requested regions, their cuts and prior means
  double refold = 0;   // folding the posterior into the sampling weights of the pairs that changed
  double records = 0;  // observation records folded (one per pair per row state per pass)
  double refolds = 0;  // sampling weights refolded
};

// What light selection sees of a shading point.
struct shade_point {
  vec3f p;           // position
  vec3f n;           // unit geometric normal on the side the path arrives from
  float albedo = 0;  // luminance of the BSDF's albedos (kd + ks), scale of the expected contribution
  int pixel = 0;     // image pixel of the path
  int depth = 1;     // 1 = first hit
  bool last = false; // the path ends here: NEE is unweighted (no MIS; --bayes-cv-last-only: control variates here only)
  // A glossy point (Phong lobe; bayes's point factor): wo mirrored about the shading normal, the exponent, and the
  // BSDF over the albedo scale (kd + ks) / pi as gloss_base + gloss_peak cos^ns, cos toward refl (gloss_peak 0: none).
  vec3f refl = {0, 0, 1};
  float ns = 1, gloss_base = 1, gloss_peak = 0;
  // A first hit: the side of its pixel's footprint on the surface (pixel_footprint), by which bayes may choose the
  // coarse region (region_params::min_pixels); 0 at deeper vertices.
  float footprint = 0;
};

// A chosen light with its selection probability; cluster is the sampler's own bookkeeping (or -1).
struct light_choice {
  int light = invalid_id;
  float prob = 0;
  int cluster = invalid_id;
  float prob_in_cluster = 1;  // P(light | cluster); prob = P(cluster) * prob_in_cluster (both rounded from double)
  double cluster_prob = 0;    // P(cluster), where `cluster` is set
};

// One NEE event as a learning sampler sees it: its own context, the choice, and the sample's luminance
// Y = f cos Le G V / (P(light | cluster) pdf) (zero when occluded or facing away); with the pixel and the luminance
// of what the event added to the path's radiance (path throughput and MIS weight included): `added` by the light
// sample alone, `added_total` with the control variate's terms; `first_vertex`: the event is the path's first
// vertex's (the one a render stratifies).
template <class Context>
struct nee_event {
  const Context* context;
  light_choice choice;
  float value;
  int pixel = 0;
  float added = 0, added_total = 0;
  bool first_vertex = true;
};

}  // namespace bl
