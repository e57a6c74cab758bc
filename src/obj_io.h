// obj_io: reads a Wavefront OBJ and its MTL files into flat arrays (obj_validate reads them).
// Invariants: every returned triangle has finite vertices and non-zero float area (degenerate ones are dropped
// and counted; flat ones of a face with area are dropped without loss); every index is valid; polygons are
// triangulated keeping their winding; triangles are in file order and the vertex arrays hold only referenced
// elements, in file order. Malformed input throws input_error naming the file and, where there is one, the line;
// the result never depends on hash or pointer order.
#pragma once

#include "math.h"
#include "texture.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace bl {

// Why load_obj drops a triangle as degenerate: the renderer's float maths squares a triangle's doubled area
// (|cross|^2), which must be a positive finite float.
extern const char* const degenerate_reason;

// One OBJ material (MTL statement names in comments). Colours are linear RGB; a statement the MTL omits keeps
// the default below (Kd aside: see kd).
struct material_data {
  std::string name;
  vec3f kd = {0.8f, 0.8f, 0.8f};  // Kd diffuse albedo, multiplies kd_texture (0.8: the default material's; a library
                                  // material without Kd gets 0, or 1 when it has a map_Kd)
  vec3f ks = {0, 0, 0};           // Ks specular albedo of the normalized Phong lobe
  float ns = 1;                   // Ns Phong exponent (>= 0)
  vec3f ke = {0, 0, 0};           // Ke emitted radiance (non-zero: the triangle is an area light)
  int kd_texture = invalid_id;    // map_Kd: index into mesh_data::textures
  int alpha_texture = invalid_id; // map_d: index into mesh_data::textures
  texture_transform kd_map, alpha_map;  // map_Kd's and map_d's -s, -o and -clamp
  // map_Kd is also the map_d, read at the same uv (an RGBA leaf): its colour blends the solid texels only, so that
  // the colour stored in the holes does not darken the edges (set on load from the fields above).
  bool kd_is_cutout = false;
};

// A triangle mesh as flat columns; corner c of triangle t is entry 3*t+c of the tri_* corner arrays.
// materials: those named by usemtl, in order of first use, then one named "default" (Kd 0.8) when some face
// came before any usemtl. textures: one per distinct resolved path, in order of first reference.
struct mesh_data {
  std::vector<vec3f> positions;
  std::vector<vec3f> normals;     // `vn`, unit length (a zero-length vn leaves its corners without one)
  std::vector<vec2f> texcoords;   // `vt`
  std::vector<int> tri_positions; // 3 per triangle: indices into positions
  std::vector<int> tri_normals;   // 3 per triangle: indices into normals, or invalid_id
  std::vector<int> tri_texcoords; // 3 per triangle: indices into texcoords, or invalid_id
  std::vector<int> tri_materials; // 1 per triangle: index into materials
  std::vector<material_data> materials;
  std::vector<texture_data> textures;
  int first_degenerate_line = 0;  // OBJ line of the first face that lost a triangle as degenerate (0: none)
  int dropped_degenerate = 0;     // triangles removed on load (degenerate_reason): n - 2 of each face without area
                                  // (corners on one line or at fewer than 3 points), and those float cannot square
  int dropped_flat = 0;           // zero-area triangles between corners on one line of a face with area (T-junction
                                  // points on its edges), removed without loss: not degenerate, not reported
  std::vector<std::string> source_files;  // the OBJ, the MTL files of its used materials, their textures
};

inline int triangle_count(const mesh_data& m) { return int(m.tri_materials.size()); }

// A triangle's corners (indices into positions) as 9 float bit patterns (-0 as +0: the same point), rotated to start
// at the smallest corner: two triangles have the same key when they have the same corners in the same cyclic order
// (the same side in front). `reversed`: the key of its other side (corners 0, 2, 1).
using corner_key = std::array<uint32_t, 9>;
corner_key triangle_corner_key(const std::vector<vec3f>& positions, const int* corners, bool reversed = false);
// A hash of a triangle's corner set, whatever their order (-0 as +0): triangles with the same corners in any order
// share it, so grouping by it finds repeats and reverses without comparing every pair.
uint64_t corner_set_hash(const std::vector<vec3f>& positions, const int* corners);

// Loads an OBJ file with its MTL libraries (relative to the OBJ's folder) and the map_Kd / map_d textures of
// the materials it uses (relative to their MTL's folder). Unrecognised statements are reported on stderr.
mesh_data load_obj(const std::string& path);

}  // namespace bl
