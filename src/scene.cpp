// scene: derives the per-triangle columns from a loaded mesh and resolves the camera.
#include "scene.h"

#include "errors.h"
#include "texture.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace bl {

scene_data build_scene(mesh_data mesh, const camera_params& camera, const sun_params& sun, bool two_sided,
                       float aspect) {
  scene_data s;
  s.mesh = std::move(mesh);
  const mesh_data& m = s.mesh;
  int n = triangle_count(m);
  s.tri_p0.resize(n);
  s.tri_e1.resize(n);
  s.tri_e2.resize(n);
  s.tri_ng.resize(n);
  s.tri_area.resize(n);
  s.tri_extent.resize(n);
  for (int t = 0; t < n; t++) {
    vec3f p0 = m.positions[m.tri_positions[3 * t + 0]];
    vec3f p1 = m.positions[m.tri_positions[3 * t + 1]];
    vec3f p2 = m.positions[m.tri_positions[3 * t + 2]];
    vec3f e1 = p1 - p0, e2 = p2 - p0;
    vec3f c = cross(e1, e2);
    float len = length(c);
    s.tri_p0[t] = p0;
    s.tri_e1[t] = e1;
    s.tri_e2[t] = e2;
    s.tri_ng[t] = len > 0 ? c / len : vec3f{0, 0, 1};
    s.tri_area[t] = 0.5f * len;
    // How far the corners' rounding can move an interpolated point off the plane: only the coordinates along the
    // normal count (a point on a huge floor at y = 0 has an exact y however far its corners lie in x and z).
    vec3f big = {std::max({std::fabs(p0.x), std::fabs(p1.x), std::fabs(p2.x)}),
                 std::max({std::fabs(p0.y), std::fabs(p1.y), std::fabs(p2.y)}),
                 std::max({std::fabs(p0.z), std::fabs(p1.z), std::fabs(p2.z)})};
    // (That sum is at most sqrt(3) times the largest corner coordinate, which bounds the rounding too: the smaller.)
    vec3f ng = s.tri_ng[t];
    s.tri_extent[t] = std::min(std::fabs(ng.x) * big.x + std::fabs(ng.y) * big.y + std::fabs(ng.z) * big.z,
                               std::max({big.x, big.y, big.z}));
    s.bounds = merge(merge(merge(s.bounds, p0), p1), p2);
  }
  // Reversed twins: of the triangles with the same three corners (grouped by a hash of the corner set, independent
  // of their order), the lowest-numbered one whose key is this one's reversed key.
  std::vector<std::pair<uint64_t, int>> groups(static_cast<size_t>(n));
  for (int t = 0; t < n; t++) groups[size_t(t)] = {corner_set_hash(m.positions, &m.tri_positions[3 * size_t(t)]), t};
  std::sort(groups.begin(), groups.end());
  std::vector<std::pair<corner_key, int>> keys;
  for (size_t g = 0, e; g < groups.size(); g = e) {
    for (e = g + 1; e < groups.size() && groups[e].first == groups[g].first;) e++;
    if (e - g < 2) continue;
    keys.clear();
    for (size_t k = g; k < e; k++) {
      int t = groups[k].second;
      keys.push_back({triangle_corner_key(m.positions, &m.tri_positions[3 * size_t(t)]), t});
    }
    std::sort(keys.begin(), keys.end());
    for (size_t k = g; k < e; k++) {
      int t = groups[k].second;
      std::pair<corner_key, int> rev{triangle_corner_key(m.positions, &m.tri_positions[3 * size_t(t)], true), -1};
      auto it = std::lower_bound(keys.begin(), keys.end(), rev);
      if (it == keys.end() || it->first != rev.first || it->second == t) continue;
      if (s.tri_twin.empty()) s.tri_twin.assign(size_t(n), invalid_id);
      s.tri_twin[size_t(t)] = it->second;
    }
  }
  s.material_emissive.resize(m.materials.size());
  for (size_t i = 0; i < m.materials.size(); i++) {
    s.material_emissive[i] = !is_black(m.materials[i].ke);
    s.has_alpha = s.has_alpha || m.materials[i].alpha_texture != invalid_id;
  }
  s.camera = camera;
  if (camera.automatic || camera.frame_eye || camera.frame_target) {
    camera_params f = frame_bounds(s.bounds, camera.fov_y_deg, aspect);
    if (!camera.frame_target) s.camera.eye = camera.frame_eye ? camera.target + (f.eye - f.target) : f.eye;
    if (!camera.frame_eye) s.camera.target = f.target;
  }
  // (Few scenes: the camera's first hits test their triangle's plane only where some plane holds the eye.)
  for (int t = 0; t < n && !s.eye_on_a_plane; t++) s.eye_on_a_plane = on_plane_of(s, t, s.camera.eye);
  s.sun = sun;
  s.two_sided_emitters = two_sided;
  return s;
}

scene_data build_scene(const scene_desc& desc, float aspect) {
  scene_data s = build_scene(load_obj(desc.mesh_path), desc.camera, desc.sun, desc.two_sided_emitters, aspect);
  // A camera completed from the mesh bounds (scene_desc.h) can only be checked now. Embree refuses ray origins beyond
  // about 1.8e18; the framing distance grows with the scene's extent and as 1 / sin of half the field of view.
  for (const vec3f* v : {&s.camera.eye, &s.camera.target})
    if (!(max_abs_component(*v) <= 1e17f)) {
      char where[96];
      std::snprintf(where, sizeof where, "(%.3g, %.3g, %.3g)", double(v->x), double(v->y), double(v->z));
      throw input_error(desc.path, std::string("the camera framed from the mesh bounds would have its ") +
                                       (v == &s.camera.eye ? "eye" : "target") + " at " + where +
                                       ", beyond 1e17 of the origin (the scene's extent, or a tiny \"fov_y_deg\"): "
                                       "give the camera's \"eye\" and \"target\" in a scene file, or a wider "
                                       "\"fov_y_deg\"");
    }
  const camera_params& c = desc.camera;
  vec3f dir = s.camera.target - s.camera.eye;
  if (!(length(normalize(dir)) > 0)) {
    if (c.frame_eye)
      throw input_error(desc.path, c.target_line,
                        "the camera's \"eye\", framed from the mesh bounds toward the given \"target\", rounds onto it "
                        "in float (a target this far from the origin for a mesh this small): give an \"eye\" too");
    throw input_error(desc.path, c.eye_line,
                      "the camera's \"eye\" is the mesh's centre, its default \"target\": give a target");
  }
  if (!(length(cross(normalize(dir), normalize(s.camera.up))) > 1e-6f)) {
    if (c.up_given)
      throw input_error(desc.path, c.up_line, "camera \"up\" must not be parallel to the viewing direction");
    // A view straight down or up along the default up, [0, 1, 0] (a plan view, refused before; a review): the up a
    // camera looking along -z has once tilted to it, -z looking down and +z looking up.
    s.camera.up = dir.y < 0 ? vec3f{0, 0, -1} : vec3f{0, 0, 1};
    stderr_text() << desc.path << (c.camera_line > 0 ? ":" + std::to_string(c.camera_line) : std::string())
                  << ": warning: the camera looks straight " << (dir.y < 0 ? "down" : "up")
                  << ", along the default \"up\" [0, 1, 0]: [0, 0, " << (dir.y < 0 ? "-1" : "1")
                  << "] is taken as up (give \"up\" to choose)\n";
  }
  {
    // A camera whose rays float cannot place to a hundredth of the view's height at its target (5 pixels of 480 rows)
    // renders a distorted image, or a black one: an eye 1e8 from the origin with a field of view of 5e-6
    // degrees framing a 10-unit stage wrote zeros without a word (a review).
    // The direction errs by the rounding of the coordinates eye and target differ in, across the view only: a target
    // on an axis through the eye gives an exact direction however near (a target 1e-6 before the eye was warned
    // about, its image that of a far target; a review). The eye's own rounding errs by an ulp of its coordinates at
    // the scene, taken at the target or at the scene bounds' centre, whichever is farther.
    const float dist = length(dir);
    const double tan_half = std::tan(double(s.camera.fov_y_deg) * M_PI / 360.0);
    const float far = max_abs_component(s.camera.eye);
    auto ulp = [](float v) { return double(std::nextafter(v, INFINITY) - v); };
    double across = 0;
    for (int a = 0; a < 3; a++)
      if (s.camera.eye[a] != s.camera.target[a]) {
        const double along = double(dir[a]) / double(dist);
        across += ulp(std::max(std::fabs(s.camera.eye[a]), std::fabs(s.camera.target[a]))) *
                  std::sqrt(std::max(0.0, 1.0 - along * along));
      }
    const double scene_dist = std::max(double(dist), double(length(center(s.bounds) - s.camera.eye)));
    // (as an angle: radians, against the view's 2 tan(fov / 2))
    const double angle = across / double(dist) + ulp(far) / scene_dist + std::ldexp(1.0, -23);
    const double view = 2.0 * double(dist) * tan_half, rounding = angle * double(dist);
    if (!(rounding <= 1e-2 * view)) {
      char buf[512];
      std::snprintf(buf, sizeof buf,
                    ": warning: the camera's rays are placed only to about %.3g at its target, %.2g of the view's "
                    "height there (an eye %.3g from the origin, a target %.3g away, a field of view of %.3g degrees): "
                    "the image will be distorted or black; move the eye nearer and widen \"fov_y_deg\", or move the "
                    "scene nearer the origin\n",
                    rounding, rounding / view, double(far), double(dist), double(s.camera.fov_y_deg));
      stderr_text() << desc.path << buf;
    }
  }
  return s;
}

surface_point eval_surface(const scene_data& scene, int tri, float b1, float b2, vec3f p, vec3f dir) {
  const mesh_data& m = scene.mesh;
  surface_point sp;
  sp.tri = tri;
  sp.material = m.tri_materials[tri];
  float b0 = 1.0f - b1 - b2;
  sp.p = p;
  vec3f ng = scene.tri_ng[tri];
  sp.front = dot(ng, dir) < 0;
  sp.ng = sp.front ? ng : -ng;
  sp.ns = sp.ng;
  const int* cn = &m.tri_normals[3 * tri];
  if (cn[0] != invalid_id && cn[1] != invalid_id && cn[2] != invalid_id) {
    vec3f ns = normalize(m.normals[cn[0]] * b0 + m.normals[cn[1]] * b1 + m.normals[cn[2]] * b2);
    if (dot(ns, sp.ng) < 0) ns = -ns;
    if (length_sq(ns) > 0) sp.ns = ns;
  }
  sp.uv = surface_uv(scene, tri, b1, b2);
  return sp;
}

vec2f surface_uv(const scene_data& scene, int tri, float b1, float b2) {
  const mesh_data& m = scene.mesh;
  const int* ct = &m.tri_texcoords[3 * tri];
  if (ct[0] == invalid_id || ct[1] == invalid_id || ct[2] == invalid_id) return {0, 0};
  float b0 = 1.0f - b1 - b2;
  vec2f t0 = m.texcoords[ct[0]], t1 = m.texcoords[ct[1]], t2 = m.texcoords[ct[2]];
  return {t0.x * b0 + t1.x * b1 + t2.x * b2, t0.y * b0 + t1.y * b1 + t2.y * b2};
}

bool alpha_hole(const scene_data& scene, int tri, float b1, float b2) {
  const material_data& m = scene.mesh.materials[size_t(scene.mesh.tri_materials[size_t(tri)])];
  if (m.alpha_texture == invalid_id) return false;
  vec2f uv = transform_uv(m.alpha_map, surface_uv(scene, tri, b1, b2));
  return eval_texture_alpha(scene.mesh.textures[size_t(m.alpha_texture)], uv, m.alpha_map.clamp, m.alpha_map.channel) < 0.5f;
}

}  // namespace bl
