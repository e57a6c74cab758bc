// material: the BSDF of a surface point — Lambertian diffuse (Kd, map_Kd) plus a normalized Phong lobe
// (Ks, Ns), reflecting on the side the light arrives from; evaluation, sampling and pdf side by side.
// Invariants: directions are world-space unit vectors pointing away from the surface; wo is on the side
// of sp.ng; no transmission (wi below the geometric normal gives 0); kd + ks <= 1 per channel (scaled
// down otherwise) so no material creates energy.
#pragma once

#include "light_sampler_types.h"
#include "math.h"
#include "scene.h"

namespace bl {

// Largest Phong exponent a BSDF uses (a lobe about 1 mrad wide): sharper ones are clamped to it, since in float the
// lobe cos^n of a larger exponent is exactly 1 over a cone of ~3e-4 rad and its normalisation (n + 2) / 2 pi
// overflows the pdfs (non-finite samples) long before it reaches a mirror.
constexpr float max_phong_exponent = 1e6f;

// The BSDF at one surface point, resolved from material and textures.
struct bsdf_data {
  vec3f kd, ks;       // albedos after energy scaling
  float ns = 1;       // Phong exponent
  float spec_prob = 0;  // probability of sampling the Phong lobe
  frame3f frame;      // shading frame about sp.ns
  vec3f ng;           // geometric normal on the wo side
};

// wo mirrored about n (the Phong lobe's axis).
inline vec3f reflect(vec3f wo, vec3f n) { return n * (2 * dot(wo, n)) - wo; }

// What a light sampler sees of a shading point with BSDF b and outgoing direction wo: position, geometric normal, the
// albedo scale, and for a Phong lobe its mirror direction and shares (shade_point).
inline shade_point make_shade_point(vec3f p, const bsdf_data& b, vec3f wo, int pixel, int depth, bool last) {
  float lum_kd = luminance(b.kd), lum_ks = luminance(b.ks);
  shade_point s{p, b.ng, lum_kd + lum_ks, pixel, depth, last};
  if (b.spec_prob > 0 && lum_ks > 0) {
    s.refl = reflect(wo, b.frame.n);
    s.ns = b.ns;
    s.gloss_base = lum_kd / s.albedo;
    s.gloss_peak = lum_ks * (b.ns + 2) * 0.5f / s.albedo;
  }
  return s;
}

// The BSDF at sp.
bsdf_data make_bsdf(const scene_data& scene, const surface_point& sp);
// Whether the BSDF reflects anything (a black surface ends the path).
inline bool is_black_bsdf(const bsdf_data& b) { return is_black(b.kd) && is_black(b.ks); }

// f(wo, wi) * |cos(wi, ns)| (zero below the geometric surface).
vec3f eval_bsdf_cos(const bsdf_data& b, vec3f wo, vec3f wi);
// Solid-angle pdf of sample_bsdf producing wi.
float bsdf_pdf(const bsdf_data& b, vec3f wo, vec3f wi);

// A sampled direction with its pdf; pdf == 0 means the sample failed (below the surface).
struct bsdf_sample {
  vec3f wi;
  float pdf = 0;
};
// Samples wi from the lobe mixture with uniforms (u, v): the glossy lobe where u < spec_prob, else the diffuse one,
// u's place inside its lobe's share (rescaled to [0, 1)) then with v choosing the direction, so (u, v) stratified
// over a pixel's samples (the first vertex's) stay stratified inside each lobe.
bsdf_sample sample_bsdf(const bsdf_data& b, vec3f wo, float u, float v);

}  // namespace bl
