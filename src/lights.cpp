// lights: emitter collection, power, and point sampling (area-uniform on triangles, uniform in the sun's cone).
#include "lights.h"

#include "sampling.h"

namespace bl {

light_data build_lights(const scene_data& scene) {
  light_data l;
  const mesh_data& m = scene.mesh;
  int n = triangle_count(m);
  l.two_sided = scene.two_sided_emitters;
  l.light_of_tri.assign(n, invalid_id);
  for (int t = 0; t < n; t++) {
    if (!scene.material_emissive[m.tri_materials[t]]) continue;
    // A face with a reversed twin is one side of a sheet: it emits from its front only, also with two_sided (the
    // other side is its twin's, which a ray from there meets).
    bool sheets = l.two_sided && !scene.tri_twin.empty();
    bool front_only = sheets && scene.tri_twin[size_t(t)] != invalid_id;
    if (sheets) l.front_only.push_back(front_only);
    l.light_of_tri[t] = int(l.tri.size());
    l.tri.push_back(t);
    vec3f le = m.materials[m.tri_materials[t]].ke;
    l.radiance.push_back(le);
    l.power.push_back(luminance(le) * scene.tri_area[t] * pi_f * (l.two_sided && !front_only ? 2.0f : 1.0f));
  }
  l.tri_count = int(l.tri.size());
  l.count = l.tri_count;
  if (scene.sun.enabled && max_component(scene.sun.irradiance) > 0) {
    l.sun = l.count++;
    l.sun_dir = normalize(scene.sun.direction);
    l.sun_frame = make_frame(l.sun_dir);
    l.sun_one_minus_cos = sun_one_minus_cos(scene.sun.angular_diameter_deg);
    float sin2 = l.sun_one_minus_cos * (2 - l.sun_one_minus_cos);
    l.sun_irradiance = scene.sun.irradiance;
    l.sun_radiance = scene.sun.irradiance / (pi_f * sin2);
    // Power of a distant light: its irradiance over the disk that bounds the scene (as pbrt does).
    float r = 0.5f * diagonal(scene.bounds);
    // (At most 1e30, the emitters' limit (obj_io.cpp): an infinite power would leave nothing else sampled.)
    l.power.push_back(std::min(luminance(scene.sun.irradiance) * pi_f * r * r, 1e30f));
  }
  return l;
}

void set_sun_direction(light_data& l, vec3f direction) {
  if (l.sun == invalid_id) return;
  l.sun_dir = normalize(normalize(direction));  // scene_desc's normalisation, then build_lights'
  l.sun_frame = make_frame(l.sun_dir);
}

light_sample sample_light_point(const light_data& l, const scene_data& scene, int light, vec3f x, float u,
                                float v) {
  light_sample s;
  if (light == l.sun) {
    s.wi = normalize(to_world(l.sun_frame, sample_cone(u, v, l.sun_one_minus_cos)));
    s.dist = inf_f;
    s.le = l.sun_radiance;
    s.pdf = cone_pdf(l.sun_one_minus_cos);
    return s;
  }
  int t = l.tri[light];
  vec2f b = sample_triangle(u, v);
  s.p = scene.tri_p0[t] + scene.tri_e1[t] * b.x + scene.tri_e2[t] * b.y;
  s.tri = t;
  s.n = scene.tri_ng[t];
  // A hole of the emitter's own cut-out emits nothing (rays pass through it; pdf 0: no contribution).
  if (scene.has_alpha && alpha_hole(scene, t, b.x, b.y)) return s;
  vec3f d = s.p - x;
  float dist2 = length_sq(d);
  if (!(dist2 > 0)) return s;
  s.dist = std::sqrt(dist2);
  s.wi = d / s.dist;
  float cos_l = -dot(s.n, s.wi);
  if (cos_l < 0 && emits_both_sides(l, light)) cos_l = -cos_l;
  if (!(cos_l > 0)) return s;
  s.le = l.radiance[light];
  s.pdf = triangle_light_pdf(scene, l, light, s.dist, cos_l);
  return s;
}

}  // namespace bl
