// material: Lambertian + normalized Phong. The Phong lobe is f = ks (n + 2) / (2 pi) cos^n(alpha), alpha the
// angle between wi and the mirror direction of wo about the shading normal; its albedo never exceeds ks.
#include "material.h"

#include "sampling.h"
#include "texture.h"

#include <algorithm>

namespace bl {

bsdf_data make_bsdf(const scene_data& scene, const surface_point& sp) {
  const material_data& m = scene.mesh.materials[sp.material];
  bsdf_data b;
  b.kd = m.kd;
  if (m.kd_texture != invalid_id) {
    // A colour image that is also the cut-out (material_data::kd_is_cutout): blended over its solid texels only.
    b.kd = b.kd * eval_texture_rgb(scene.mesh.textures[m.kd_texture], transform_uv(m.kd_map, sp.uv), m.kd_map.clamp,
                                   m.kd_is_cutout ? &m.alpha_map.channel : nullptr);
  }
  b.ks = m.ks;
  b.ns = std::min(std::max(m.ns, 0.0f), max_phong_exponent);
  float total = max_component(b.kd + b.ks);
  if (total > 1) {
    b.kd = b.kd / total;
    b.ks = b.ks / total;
  }
  float ld = luminance(b.kd), ls = luminance(b.ks);
  b.spec_prob = ld + ls > 0 ? ls / (ld + ls) : 0;
  b.frame = make_frame(sp.ns);
  b.ng = sp.ng;
  return b;
}

vec3f eval_bsdf_cos(const bsdf_data& b, vec3f wo, vec3f wi) {
  if (dot(wi, b.ng) <= 0) return {0, 0, 0};
  float cos_i = dot(wi, b.frame.n);
  if (cos_i <= 0) return {0, 0, 0};
  vec3f f = b.kd * inv_pi_f;
  if (b.spec_prob > 0) {
    float cos_a = dot(wi, reflect(wo, b.frame.n));
    if (cos_a > 0) f += b.ks * ((b.ns + 2) * (0.5f * inv_pi_f) * std::pow(cos_a, b.ns));
  }
  return f * cos_i;
}

float bsdf_pdf(const bsdf_data& b, vec3f wo, vec3f wi) {
  if (dot(wi, b.ng) <= 0) return 0;
  float cos_i = dot(wi, b.frame.n);
  float pdf = (1 - b.spec_prob) * cosine_hemisphere_pdf(cos_i);
  if (b.spec_prob > 0) pdf += b.spec_prob * phong_lobe_pdf(dot(wi, reflect(wo, b.frame.n)), b.ns);
  return pdf;
}

bsdf_sample sample_bsdf(const bsdf_data& b, vec3f wo, float u, float v) {
  bsdf_sample s;
  const bool glossy = u < b.spec_prob;
  if (b.spec_prob > 0 && b.spec_prob < 1)
    u = std::min(glossy ? u / b.spec_prob : (u - b.spec_prob) / (1 - b.spec_prob), 0x1.fffffep-1f);
  if (glossy) {
    vec3f r = reflect(wo, b.frame.n);
    s.wi = to_world(make_frame(r), sample_phong_lobe(u, v, b.ns));
  } else {
    s.wi = to_world(b.frame, sample_cosine_hemisphere(u, v));
  }
  s.wi = normalize(s.wi);
  if (dot(s.wi, b.ng) <= 0) return {s.wi, 0};
  s.pdf = bsdf_pdf(b, wo, s.wi);
  return s;
}

}  // namespace bl
