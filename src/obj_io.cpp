// obj_io: turns a validated OBJ (obj_validate: vertex values, faces as resolved corner triples, materials) into
// mesh_data: we triangulate (triangulate.h), drop degenerate triangles, compact the vertex arrays and load each
// distinct texture once.
// Invariants: triangles keep the polygon's winding and come in file order; arrays hold only referenced
// elements, in file order; nothing iterates a hash or pointer order; geometry tests are float maths.
#include "obj_io.h"

#include "errors.h"
#include "obj_validate.h"
#include "rng.h"
#include "triangulate.h"

#include <sys/stat.h>

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <new>

namespace bl {

namespace fs = std::filesystem;

const char* const degenerate_reason =
    "zero area, or an area float maths cannot square: outside about 2e-23 to 9e18 square units; rescale the scene, "
    "or move it near the origin where float corners far from it collapse";

// How triangle (a, b, c) fares in float maths: kept (|cross|^2 a positive finite float), flat (cross exactly 0: its
// corners on one line) or unusable (an area float cannot square: underflow, overflow).
enum class triangle_fit { kept, flat, unusable };
static triangle_fit fit_triangle(vec3f a, vec3f b, vec3f c) {
  vec3f n = cross(b - a, c - a);
  float l2 = length_sq(n);
  if (is_finite(n) && l2 > 0 && l2 < inf_f) return triangle_fit::kept;
  return n.x == 0 && n.y == 0 && n.z == 0 ? triangle_fit::flat : triangle_fit::unusable;
}

// The unit normal along vn, or false when vn is zero or not finite (that corner then has no normal).
static bool unit_normal(vec3f vn, vec3f& out) {
  float m = max_abs_component(vn);
  if (!(m > 0) || !(m < inf_f)) return false;
  out = normalize(vn / m);  // scaled first so tiny normals do not underflow
  return is_finite(out) && length_sq(out) > 0;
}

// Index of the texture for (mtl, line, name) in mesh.textures, loading it on first use of its file.
static int texture_index(mesh_data& mesh, std::map<std::string, int>& loaded, folder_cache& folders,
                         const std::string& obj_path, const std::string& mtl_path, int line, const char* statement,
                         const std::string& name) {
  if (name.empty()) return invalid_id;
  const std::string dir = fs::path(mtl_path).parent_path().string();
  const std::string written = resolve_file_name(dir, name);
  auto it = loaded.find(written);
  if (it != loaded.end()) return it->second;
  std::string path = written;
  std::error_code ec;
  if (!fs::exists(path, ec)) {
    // A path from the machine that wrote the MTL (C:\Users\...\textures\wood.png), or a name in another case: the
    // file beside the MTL (find_beside: in its last folder, then alone), said once per name (later references find it
    // in `loaded`).
    std::string beside = find_beside(dir, name, folders);
    // An MTL in a subfolder (mtllib materials/a.mtl) whose textures were named from the OBJ's folder, as some
    // exporters and readers take them: there, as written, then as find_beside looks.
    const std::string obj_dir = fs::path(obj_path).parent_path().string();
    if (beside.empty() && fs::path(obj_dir).lexically_normal() != fs::path(dir).lexically_normal()) {
      const std::string from_obj = resolve_file_name(obj_dir, name);
      beside = fs::is_regular_file(from_obj, ec) ? from_obj : find_beside(obj_dir, name, folders);
    }
    if (!beside.empty()) {
      folders.note(mtl_path, line, statement, name, beside);
      path = beside;
    }
  }
  // The same file by another name (absolute and relative, a symbolic or hard link) is decoded once: by its identity.
  struct stat st;
  std::string identity = path;
  if (::stat(path.c_str(), &st) == 0)
    identity = "\n" + std::to_string(uint64_t(st.st_dev)) + ":" + std::to_string(uint64_t(st.st_ino));  // no path
  auto same = loaded.find(identity);
  int index = same != loaded.end() ? same->second : int(mesh.textures.size());
  if (same == loaded.end()) {
    try {
      uint64_t used = 0;
      for (const texture_data& t : mesh.textures) used += texture_bytes(t);
      mesh.textures.push_back(load_texture(path, max_textures_bytes - std::min(used, max_textures_bytes)));
    } catch (const input_error& e) {
      throw input_error(mtl_path, line, std::string(statement) + ": " + e.what());
    }
    loaded.emplace(identity, index);
  }
  loaded.emplace(written, index);
  return index;
}

// Renumbers refs (invalid_id stays) to count only the referenced elements, in their original order; returns
// the original index of each element kept.
static std::vector<size_t> compact_refs(std::vector<int>& refs, size_t count) {
  std::vector<int> remap(count, invalid_id);
  for (int r : refs)
    if (r >= 0) remap[size_t(r)] = 0;
  std::vector<size_t> kept;
  for (size_t i = 0; i < count; i++)
    if (remap[i] == 0) remap[i] = int(kept.size()), kept.push_back(i);
  for (int& r : refs)
    if (r >= 0) r = remap[size_t(r)];
  return kept;
}

// Largest corner coordinate accepted: Embree refuses ray origins beyond about 1.8e18, and squared distances in float
// overflow from about 1.8e19 (a grid or light bounds over a scene spanning 3e38 would be NaN).
constexpr float max_corner_coordinate = 1e18f;

// Refuses a mesh with a used corner beyond max_corner_coordinate (only slivers or far-off small triangles get there:
// larger areas are degenerate in float already), naming the first such 'v' line by its number.
static void check_corner_range(const std::string& path, const std::vector<vec3f>& positions,
                               const std::vector<int>& refs) {
  size_t first = SIZE_MAX;
  for (int r : refs)
    if (!(max_abs_component(positions[size_t(r)]) <= max_corner_coordinate)) first = std::min(first, size_t(r));
  if (first == SIZE_MAX) return;
  vec3f v = positions[first];
  char buf[160];
  std::snprintf(buf, sizeof buf, "vertex %zu (counting 'v' lines from 1) at (%.3g, %.3g, %.3g)", first + 1,
                double(v.x), double(v.y), double(v.z));
  throw input_error(path, std::string(buf) +
                              " lies beyond 1e18 of the origin, where float squared distances and ray origins "
                              "overflow: rescale the scene or remove the far-off geometry");
}

// Emitted power (luminance of Ke times area times pi) above which light sums and importances could overflow float.
constexpr double max_emitted_power = 1e30;

// Refuses emitters whose power, one by one or all together, is beyond max_emitted_power: light selection sums
// powers and intensities in float, and an infinite one would leave every light but the one seen directly unsampled.
static void check_emitted_power(const std::string& path, const obj_clean_data& clean, const mesh_data& mesh) {
  double total = 0;
  for (size_t t = 0; t < mesh.tri_materials.size(); t++) {
    int k = mesh.tri_materials[t];
    if (k < 0 || size_t(k) >= clean.materials.size()) continue;  // the default material emits nothing
    const mtl_material_data& m = clean.materials[size_t(k)];
    double le = luminance(m.material.ke);
    if (!(le > 0)) continue;
    vec3f p[3];
    for (int c = 0; c < 3; c++) p[c] = mesh.positions[size_t(mesh.tri_positions[3 * t + size_t(c)])];
    // (The squared length of the cross product is finite: fit_triangle kept only such triangles.)
    double power = le * 0.5 * std::sqrt(double(length_sq(cross(p[1] - p[0], p[2] - p[0])))) * M_PI;
    total += power;
    if (power > max_emitted_power || total > max_emitted_power) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "%.3g", power > max_emitted_power ? power : total);
      throw input_error(m.mtl_path.empty() ? path : m.mtl_path, m.mtl_path.empty() ? 0 : m.line,
                        "material \"" + m.material.name + "\": " +
                            (power > max_emitted_power ? "Ke makes a triangle of " + path + " emit a power of "
                                                       : "with it the emitters of " + path + " emit a power of ") +
                            buf + " (luminance x area x pi), above 1e30, beyond what light selection sums in float; "
                            "scale Ke or the scene down");
    }
  }
}

uint64_t corner_set_hash(const std::vector<vec3f>& positions, const int* corners) {
  uint64_t h = 0;
  for (int i = 0; i < 3; i++) {
    vec3f p = positions[size_t(corners[i])] + vec3f{0, 0, 0};  // (-0 as +0)
    uint32_t b[3];
    std::memcpy(b, &p, sizeof b);
    h += mix64((uint64_t(b[0]) << 32 | b[1]) ^ mix64(b[2]));  // a sum: independent of the corners' order
  }
  return h;
}

corner_key triangle_corner_key(const std::vector<vec3f>& positions, const int* corners, bool reversed) {
  std::array<std::array<uint32_t, 3>, 3> c{};
  for (int i = 0; i < 3; i++) {
    int k = reversed && i > 0 ? 3 - i : i;
    vec3f p = positions[size_t(corners[k])] + vec3f{0, 0, 0};  // (-0 + 0 = +0)
    std::memcpy(c[size_t(i)].data(), &p, sizeof p);
  }
  int r = 0;
  for (int i = 1; i < 3; i++)
    if (c[size_t(i)] < c[size_t(r)]) r = i;
  corner_key key{};
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) key[size_t(3 * i + j)] = c[size_t((r + i) % 3)][size_t(j)];
  return key;
}

// Triangles drop_repeated_triangles dropped of one kind: how many, the first in file order, the copy it repeats.
struct repeat_drops {
  int count = 0;
  int first = 0, kept = 0;  // triangle indices before the drop
};

// Drops triangles that repeat another exactly (the same three corners in the same cyclic order: the same side).
// An emissive repeat would be counted by light sampling once per copy while a ray sees one (next-event and
// BSDF-sampled estimates of that light would disagree); any repeat makes rays test every copy (Embree cannot split
// identical boxes: 400k copies cost a millisecond per ray) and leaves which copy a ray reports, with its material,
// to the traversal. Of each set of repeats the first emissive one stays, else the first. Where a copy has a map_d
// cut-out, only emissive copies after the first emissive one go: a ray through a hole of one copy goes on to the
// other at the same distance, so together they are as solid as the solid one. Keeps file order. Returns what it
// dropped, emissive and other triangles apart.
static std::array<repeat_drops, 2> drop_repeated_triangles(mesh_data& mesh, const std::vector<vec3f>& pos,
                                                           const std::vector<char>& emissive,
                                                           const std::vector<char>& cutout) {
  size_t n = mesh.tri_materials.size();
  auto is_emissive = [&](size_t t) { return emissive[size_t(mesh.tri_materials[t])] != 0; };
  auto has_cutout = [&](size_t t) { return cutout[size_t(mesh.tri_materials[t])] != 0; };
  // Grouped by a hash of the corner set (cheap; exact keys are compared within a group only).
  std::vector<std::pair<uint64_t, uint32_t>> groups(n);
  for (size_t t = 0; t < n; t++) groups[t] = {corner_set_hash(pos, &mesh.tri_positions[3 * t]), uint32_t(t)};
  std::sort(groups.begin(), groups.end());
  std::vector<char> drop(n, 0);
  std::vector<std::pair<corner_key, uint32_t>> keys;
  std::array<repeat_drops, 2> dropped{};  // [0]: emissive, [1]: the others
  for (size_t g = 0, e; g < n; g = e) {
    for (e = g + 1; e < n && groups[e].first == groups[g].first;) e++;
    if (e - g < 2) continue;
    keys.clear();
    for (size_t k = g; k < e; k++)
      keys.push_back({triangle_corner_key(pos, &mesh.tri_positions[3 * size_t(groups[k].second)]), groups[k].second});
    std::sort(keys.begin(), keys.end());  // by key, then by triangle
    for (size_t a = 0, b; a < keys.size(); a = b) {
      for (b = a + 1; b < keys.size() && keys[b].first == keys[a].first;) b++;
      size_t keep = a;
      for (size_t k = a; k < b; k++)
        if (is_emissive(keys[k].second)) {
          keep = k;
          break;
        }
      bool holes = false;
      for (size_t k = a; k < b; k++) holes = holes || has_cutout(keys[k].second);
      for (size_t k = a; k < b; k++)
        if (k != keep && (!holes || (is_emissive(keys[k].second) && is_emissive(keys[keep].second)))) {
          const uint32_t t = keys[k].second;
          drop[t] = 1;
          repeat_drops& r = dropped[is_emissive(t) ? 0 : 1];
          if (r.count++ == 0 || int(t) < r.first) r.first = int(t), r.kept = int(keys[keep].second);
        }
    }
  }
  if (dropped[0].count + dropped[1].count == 0) return dropped;
  size_t out = 0;
  for (size_t t = 0; t < n; t++) {
    if (drop[t]) continue;
    for (int i = 0; i < 3; i++) {
      mesh.tri_positions[3 * out + size_t(i)] = mesh.tri_positions[3 * t + size_t(i)];
      mesh.tri_normals[3 * out + size_t(i)] = mesh.tri_normals[3 * t + size_t(i)];
      mesh.tri_texcoords[3 * out + size_t(i)] = mesh.tri_texcoords[3 * t + size_t(i)];
    }
    mesh.tri_materials[out++] = mesh.tri_materials[t];
  }
  mesh.tri_positions.resize(3 * out), mesh.tri_normals.resize(3 * out), mesh.tri_texcoords.resize(3 * out);
  mesh.tri_materials.resize(out);
  return dropped;
}

// Builds the mesh from the parsed OBJ: triangles, compacted vertex arrays, materials and textures.
static mesh_data build_mesh(const std::string& path, const obj_clean_data& clean) {
  auto position = [&](size_t i) { return clean.positions[i]; };
  std::vector<vec3f> normals(clean.normals.size());
  std::vector<char> normal_ok(normals.size());
  for (size_t i = 0; i < normals.size(); i++) normal_ok[i] = unit_normal(clean.normals[i], normals[i]);

  mesh_data mesh;
  triangulate_state st;
  std::vector<vec3f> corner_pos;
  std::vector<int> local;
  int default_material = int(clean.materials.size());
  size_t next_corner = 0;
  int64_t untextured = 0;   // faces of a textured material with a corner without vt
  int untextured_material = invalid_id;  // the first such face's material
  int untextured_line = 0, fan_line = 0;  // lines of the first such face, and of the first fan-triangulated one
  std::vector<int> tri_face;               // face of each triangle kept, for the warnings' line numbers
  for (size_t face = 0; face < clean.face_sizes.size(); face++) {
    int n = clean.face_sizes[face];
    const obj_corner* c = &clean.corners[next_corner];
    next_corner += size_t(n);
    corner_pos.resize(size_t(n));
    for (int i = 0; i < n; i++) corner_pos[size_t(i)] = position(size_t(c[i].v));
    const int fans_before = st.fan_fallbacks;
    triangulate_polygon(corner_pos, st, local);
    if (st.fan_fallbacks > fans_before && fan_line == 0) fan_line = clean.face_lines[face];
    int material = clean.face_materials[face] >= 0 ? clean.face_materials[face] : default_material;
    if (material != default_material && (!clean.materials[size_t(material)].kd_map.empty() ||
                                         !clean.materials[size_t(material)].alpha_map.empty())) {
      bool missing = false;
      for (int i = 0; i < n; i++) missing = missing || c[i].vt < 0;
      if (missing && untextured++ == 0) untextured_material = material, untextured_line = clean.face_lines[face];
    }
    int kept = 0, flat = 0, unusable = 0;
    for (size_t t = 0; t < local.size(); t += 3) {
      const obj_corner* tc[3] = {&c[local[t]], &c[local[t + 1]], &c[local[t + 2]]};
      triangle_fit fit =
          fit_triangle(position(size_t(tc[0]->v)), position(size_t(tc[1]->v)), position(size_t(tc[2]->v)));
      if (fit != triangle_fit::kept) {
        (fit == triangle_fit::flat ? flat : unusable)++;
        continue;
      }
      kept++;
      for (const obj_corner* x : tc) {
        mesh.tri_positions.push_back(x->v);
        mesh.tri_normals.push_back(x->vn >= 0 && normal_ok[size_t(x->vn)] ? x->vn : invalid_id);
        mesh.tri_texcoords.push_back(x->vt);
      }
      mesh.tri_materials.push_back(material);
      tri_face.push_back(int(face));
      if (mesh.tri_materials.size() > size_t(INT_MAX / 3)) throw input_error(path, "too many triangles");
    }
    // A face with no triangle left has no area (its corners on one line or at fewer than 3 points, as written or
    // rounded to float): all n - 2 of its triangles count as degenerate, also those triangulation left out. A face
    // with area loses nothing with its flat triangles (between corners on one of its edges: T-junction points).
    const int degenerate = kept == 0 ? n - 2 : unusable;
    if (degenerate > 0 && mesh.dropped_degenerate == 0) mesh.first_degenerate_line = clean.face_lines[face];
    mesh.dropped_degenerate += degenerate;
    if (kept > 0) mesh.dropped_flat += flat;
  }
  std::vector<char> emissive(clean.materials.size() + 1, 0);  // the last: the default material
  for (size_t k = 0; k < clean.materials.size(); k++) emissive[k] = !is_black(clean.materials[k].material.ke);
  std::vector<char> cutout(clean.materials.size() + 1, 0);
  for (size_t k = 0; k < clean.materials.size(); k++) cutout[k] = !clean.materials[k].alpha_map.empty();
  const auto [repeated, copies] = drop_repeated_triangles(mesh, clean.positions, emissive, cutout);
  // Where the first dropped repeat is written, and the copy it repeats (the same line for two triangles of a face).
  auto repeat_lines = [&](const repeat_drops& r) {
    const int a = clean.face_lines[size_t(tri_face[size_t(r.first)])];
    const int b = clean.face_lines[size_t(tri_face[size_t(r.kept)])];
    return "; the first at line " + std::to_string(a) + (a == b ? ", within its face" : ", repeating line " + std::to_string(b));
  };
  if (repeated.count > 0)
    stderr_text() << "warning: " << path << ": dropped " << repeated.count << " emissive triangle"
                  << (repeated.count > 1 ? "s" : "") << " repeating an earlier one (same corners, same side"
                  << repeat_lines(repeated) << "), which would light the scene once per copy\n";
  if (copies.count > 0)
    stderr_text() << "warning: " << path << ": dropped " << copies.count << " triangle" << (copies.count > 1 ? "s" : "")
                  << " repeating another (same corners, same side; an emissive one is kept first, else the first"
                  << repeat_lines(copies) << ")\n";
  if (untextured > 0)
    stderr_text() << "warning: " << path << ": " << untextured << " face" << (untextured > 1 ? "s" : "")
                  << " of a textured material (the first: line " << untextured_line << ", \""
                  << clean.materials[size_t(untextured_material)].material.name << "\") "
                  << (untextured > 1 ? "have" : "has") << " a corner without texture coordinates (vt): "
                  << "texture coordinates (0, 0) are used there\n";
  if (st.fan_fallbacks > 0)
    stderr_text() << "warning: " << path << ": " << st.fan_fallbacks
                  << " polygon(s) that cross themselves, too complex to ear-clip in the time budget, were "
                     "fan-triangulated (the first at line " << fan_line << ")\n";
  if (mesh.tri_materials.empty())
    throw input_error(path,
                      "no triangles" + (mesh.dropped_degenerate > 0
                                            ? " (" + std::to_string(mesh.dropped_degenerate) +
                                                  " degenerate dropped: " + degenerate_reason + ")"
                                            : std::string()));

  check_corner_range(path, clean.positions, mesh.tri_positions);

  // Compact each vertex array to the referenced elements, keeping file order.
  for (size_t i : compact_refs(mesh.tri_positions, clean.positions.size())) mesh.positions.push_back(position(i));
  for (size_t i : compact_refs(mesh.tri_normals, normals.size())) mesh.normals.push_back(normals[i]);
  for (size_t i : compact_refs(mesh.tri_texcoords, clean.texcoords.size()))
    mesh.texcoords.push_back(clean.texcoords[i]);
  check_emitted_power(path, clean, mesh);

  // Materials in order of first usemtl, then the default one if some face had none; textures once per path.
  std::map<std::string, int> loaded;
  for (const auto& m : clean.materials) {
    material_data md = m.material;
    md.kd_texture =
        texture_index(mesh, loaded, clean.folders, path, m.mtl_path, m.kd_map_line, "map_Kd", m.kd_map);
    md.alpha_texture =
        texture_index(mesh, loaded, clean.folders, path, m.mtl_path, m.alpha_map_line, "map_d", m.alpha_map);
    md.kd_is_cutout =
        md.kd_texture != invalid_id && md.alpha_texture == md.kd_texture && same_lookup(md.kd_map, md.alpha_map);
    mesh.materials.push_back(md);
  }
  if (clean.folders.unsaid > 0)
    stderr_text() << "warning: " << path << ": " << clean.folders.unsaid
                  << " more texture or library names that do not exist were taken from beside the files naming them\n";
  for (int m : mesh.tri_materials)
    if (m == default_material) {
      mesh.materials.push_back(material_data{});
      mesh.materials.back().name = "default";
      break;
    }
  mesh.source_files.push_back(path);
  for (const auto& m : clean.materials)  // (an undefined material, given the default, has no MTL file)
    if (!m.mtl_path.empty() &&
        std::find(mesh.source_files.begin(), mesh.source_files.end(), m.mtl_path) == mesh.source_files.end())
      mesh.source_files.push_back(m.mtl_path);
  for (const texture_data& t : mesh.textures) mesh.source_files.push_back(t.path);
  return mesh;
}

mesh_data load_obj(const std::string& path) {
  try {
    return build_mesh(path, validate_obj(path));
  } catch (const std::bad_alloc&) {
    throw input_error(path, "out of memory while loading (input too large?)");
  } catch (const std::length_error&) {
    throw input_error(path, "input too large");
  }
}

}  // namespace bl
