// obj_validate: the OBJ loader's reader. Reads the OBJ and every MTL it names exactly once, checks each
// statement with its line number, and keeps what the mesh is built from: vertex values, faces as corner index
// triples, the used materials.
// Invariants: any input ends in an obj_clean_data or an input_error; every index in it is resolved (0-based) and in
// range. Unrecognised statements are counted and reported once per file on stderr.
#pragma once

#include "obj_io.h"

#include <map>
#include <string>
#include <vector>

namespace bl {

// One material as read from an MTL file, with where its texture statements were (for error messages).
struct mtl_material_data {
  material_data material;         // kd, ks, ns, ke, name; texture ids still invalid_id
  std::string kd_map, alpha_map;  // map_Kd / map_d file names as written ("" when absent)
  int kd_map_line = 0, alpha_map_line = 0;
  std::string mtl_path;  // the MTL file that defined it (texture paths are relative to its folder)
  int line = 0;          // its newmtl line there
};

// Folder listings for find_beside, read once per folder and load (a scene of 10000 missing names in a folder of
// 2000 files listed the folder 10000 times: 6 s): folder -> lower-case file name -> the names with it.
struct folder_cache {
  std::map<std::string, std::map<std::string, std::vector<std::string>>> folders;
  int said = 0, unsaid = 0;  // names found beside: warned about, and beyond the first few only counted
  // Warns (the first three times) that `name` was not found and `beside` is taken, at file:line.
  void note(const std::string& file, int line, const std::string& what, const std::string& name,
            const std::string& beside);
};

// One face corner: 0-based indices of its v, vt and vn (invalid_id where the corner has no such part).
struct obj_corner {
  int v, vt, vn;
};

// The validated OBJ.
struct obj_clean_data {
  std::vector<mtl_material_data> materials;  // used materials; k = order of first usemtl in the OBJ
  std::vector<int> face_sizes;               // corners of each face, in file order
  std::vector<int> face_materials;           // k of each face, or invalid_id before any usemtl
  std::vector<int> face_lines;               // line of each face's f statement (at most INT_MAX), for warnings
  std::vector<obj_corner> corners;           // the faces' corners, face after face
  // v, vn and vt values as correctly rounded floats (strtof, locale "C").
  std::vector<vec3f> positions, normals;
  std::vector<vec2f> texcoords;
  mutable folder_cache folders;  // find_beside's listings, kept for the textures the mesh build resolves
};

// Longest accepted number token (real files write at most ~25 characters).
constexpr int max_number_chars = 128;

// Reads and validates the OBJ at path and its MTL libraries; throws input_error naming file and line.
obj_clean_data validate_obj(const std::string& path);

// The path of a file named `written` in a file inside folder `dir` (mtllib, map_Kd, map_d): relative names are
// relative to dir; one pair of surrounding double quotes is dropped; Windows separators ('\\') are tried as '/'
// when the name as written is not a file.
std::string resolve_file_name(const std::string& dir, const std::string& written);
// Where a file named `written` that resolve_file_name did not find may be after all, as other readers look for it:
// its last two path components (after '/' or '\\': a path from the machine that wrote the file, textures/wood.png
// of C:\proj\textures\wood.png), else its last one, in folder dir, written exactly, else the one entry of dir equal to
// the last one but for ASCII case; "" when there is none.
std::string find_beside(const std::string& dir, const std::string& written, folder_cache& cache);

// Reads a whole regular file; throws input_error (naming what, e.g. "material library") when it cannot.
std::string read_text_file(const std::string& path, const char* what);

}  // namespace bl
