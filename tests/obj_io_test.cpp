// Tests of the OBJ loader: triangulation (winding, concave polygons), index forms, materials and textures,
// degenerate triangles, compaction, and that every malformed or hostile input is an input_error naming the
// file and line. Each test writes its OBJ/MTL/PNG files into a fresh mkdtemp directory.
#include "errors.h"
#include "material.h"
#include "obj_io.h"
#include "obj_validate.h"
#include "scene.h"
#include "triangulate.h"

#include <catch2/catch.hpp>
#include <stb_image_write.h>
#include <tiny_obj_loader.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

using namespace bl;

namespace {

// A fresh temporary directory, removed with everything in it at the end of the test.
struct temp_dir {
  std::string path;
  temp_dir() {
    char tmpl[] = "/tmp/bl_obj_test_XXXXXX";
    REQUIRE(mkdtemp(tmpl) != nullptr);
    path = tmpl;
  }
  ~temp_dir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  // Writes a file (text or bytes) into the directory and returns its path.
  std::string write(const std::string& name, const std::string& content) const {
    std::string p = path + "/" + name;
    std::ofstream(p, std::ios::binary) << content;
    return p;
  }
};

// The message of the input_error that loading path throws ("" when it loads); other exceptions escape.
std::string load_error(const std::string& path) {
  try {
    load_obj(path);
  } catch (const input_error& e) {
    return e.what();
  }
  return "";
}

// What loading path writes to stderr (its warnings); the mesh goes to *mesh when given.
std::string load_warnings(const std::string& path, mesh_data* mesh = nullptr) {
  std::fflush(stderr);
  FILE* capture = std::tmpfile();
  REQUIRE(capture != nullptr);
  int saved = ::dup(2);
  ::dup2(::fileno(capture), 2);
  std::string error;
  try {
    mesh_data m = load_obj(path);
    if (mesh) *mesh = std::move(m);
  } catch (const std::exception& e) {  // (any: stderr is restored below before the test goes on)
    error = e.what();
  }
  std::fflush(stderr);
  ::dup2(saved, 2);
  ::close(saved);
  std::rewind(capture);
  std::string text;
  char buf[4096];
  for (size_t got; (got = std::fread(buf, 1, sizeof buf, capture)) > 0;) text.append(buf, got);
  std::fclose(capture);
  REQUIRE(error == "");
  return text;
}

// Occurrences of what in text.
int count_of(const std::string& text, const std::string& what) {
  int n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) n++;
  return n;
}

// Corner c of triangle t.
vec3f corner(const mesh_data& m, int t, int c) { return m.positions[size_t(m.tri_positions[size_t(3 * t + c)])]; }

// Unnormalised geometric normal (twice the area vector) of triangle t.
vec3f area_vector(const mesh_data& m, int t) {
  return cross(corner(m, t, 1) - corner(m, t, 0), corner(m, t, 2) - corner(m, t, 0));
}

// Checks the invariants every loaded mesh keeps.
void check_invariants(const mesh_data& m) {
  int n = triangle_count(m);
  REQUIRE(m.tri_positions.size() == size_t(3 * n));
  REQUIRE(m.tri_normals.size() == size_t(3 * n));
  REQUIRE(m.tri_texcoords.size() == size_t(3 * n));
  for (int i = 0; i < 3 * n; i++) {
    REQUIRE(m.tri_positions[size_t(i)] >= 0);
    REQUIRE(m.tri_positions[size_t(i)] < int(m.positions.size()));
    REQUIRE(m.tri_normals[size_t(i)] < int(m.normals.size()));
    REQUIRE(m.tri_texcoords[size_t(i)] < int(m.texcoords.size()));
  }
  for (int t = 0; t < n; t++) {
    REQUIRE(m.tri_materials[size_t(t)] >= 0);
    REQUIRE(m.tri_materials[size_t(t)] < int(m.materials.size()));
    REQUIRE(length_sq(area_vector(m, t)) > 0);
  }
  for (vec3f nn : m.normals) REQUIRE(std::fabs(length(nn) - 1.0f) < 1e-6f);
}

// A 2x1 RGBA PNG: texel 0 sRGB 128 grey with alpha 255, texel 1 white with alpha 0.
std::string write_png(const temp_dir& dir, const std::string& name) {
  std::string p = dir.path + "/" + name;
  unsigned char px[8] = {128, 128, 128, 255, 255, 255, 255, 0};
  REQUIRE(stbi_write_png(p.c_str(), 2, 1, 4, px, 8) != 0);
  return p;
}

const char* square_vertices = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";

}  // namespace

TEST_CASE("a quad and a pentagon are triangulated with their winding kept", "[obj]") {
  temp_dir dir;
  auto obj = dir.write("poly.obj", std::string(square_vertices) +
                                       "v 2 0 0\nv 3 0 0\nv 3.5 1 0\nv 2.5 2 0\nv 1.5 1 0\n"
                                       "f 1 2 3 4\nf 5 6 7 8 9\n");
  mesh_data m = load_obj(obj);
  check_invariants(m);
  REQUIRE(triangle_count(m) == 5);
  float quad_area = 0, pentagon_area = 0;
  for (int t = 0; t < 5; t++) {
    vec3f a = area_vector(m, t);
    CHECK(a.z > 0);  // counter-clockwise seen from +z, as written
    (t < 2 ? quad_area : pentagon_area) += 0.5f * a.z;
  }
  CHECK(quad_area == Approx(1.0f));
  CHECK(pentagon_area == Approx(2.5f));  // shoelace area of the pentagon
  CHECK(m.dropped_degenerate == 0);
}

TEST_CASE("a rectangle and its reverse are triangulated as exact reversed twins, in any corner order", "[obj]") {
  // Equal diagonals: the split went by corner order (1-3), so a quad and its reverse were split along different
  // diagonals and their faces overlapped without being twins (a review: a two-faced lamp written as quads).
  temp_dir dir;
  // Every triangle of the file has a reversed twin: the same corners in the opposite order, facing the other way.
  auto check_all_twins = [&](const std::string& name, const std::string& text, int triangles) {
    INFO(name);
    mesh_data m = load_obj(dir.write(name, text));
    REQUIRE(triangle_count(m) == triangles);
    scene_data s = build_scene(m, camera_params{}, sun_params{}, false, 1.0f);
    REQUIRE(s.tri_twin.size() == size_t(triangles));
    for (int t = 0; t < triangles; t++) {
      INFO("triangle " << t);
      int w = s.tri_twin[size_t(t)];
      REQUIRE(w != invalid_id);
      CHECK(triangle_corner_key(m.positions, &m.tri_positions[3 * size_t(w)]) ==
            triangle_corner_key(m.positions, &m.tri_positions[3 * size_t(t)], true));
      CHECK(dot(s.tri_ng[size_t(t)], s.tri_ng[size_t(w)]) < 0);
    }
  };
  // (The repeats among them are dropped: 4 triangles remain only when every rotation was split the same way.)
  check_all_twins("q.obj",
                  "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 0 1 0\nf 1 2 3 4\nf 4 3 2 1\nf 2 3 4 1\nf 1 4 3 2\nf 3 2 1 4\n", 4);
  // A convex hexagon and its reverse, written from other first corners: fanned from their smallest corner, twins too.
  check_all_twins("h.obj", "v 0 0 0\nv 2 0 0\nv 3 1 0\nv 2 2 0\nv 0 2 0\nv -1 1 0\nf 3 4 5 6 1 2\nf 5 4 3 2 1 6\n", 8);
  // Concave polygons (an L and a comb) and their reverses from other first corners: ear-clipped from the smallest
  // corner toward its smaller neighbour, twins too.
  check_all_twins("L.obj", "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\nf 1 2 3 4 5 6\nf 4 3 2 1 6 5\n", 8);
  check_all_twins("comb.obj",
                  "v 0 0 0\nv 5 0 0\nv 5 2 0\nv 4 2 0\nv 4 1 0\nv 3 1 0\nv 3 2 0\nv 2 2 0\nv 2 1 0\nv 1 1 0\n"
                  "v 1 2 0\nv 0 2 0\nf 3 4 5 6 7 8 9 10 11 12 1 2\nf 8 7 6 5 4 3 2 1 12 11 10 9\n", 20);
  // A lone quad has no twin, and the column stays empty.
  scene_data lone = build_scene(load_obj(dir.write("l.obj", "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 0 1 0\nf 1 2 3 4\n")),
                                camera_params{}, sun_params{}, false, 1.0f);
  CHECK(lone.tri_twin.empty());
}

TEST_CASE("a concave polygon in a tilted plane is triangulated inside its outline", "[obj]") {
  temp_dir dir;
  // An L of area 3 in the plane x = z, wound so that its normal points along (1, 0, -1) / sqrt 2.
  std::string text;
  float pts[6][2] = {{0, 0}, {0, 1}, {1, 1}, {1, 2}, {2, 2}, {2, 0}};
  for (auto& p : pts)
    text += "v " + std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(p[0]) + "\n";
  text += "f 1 2 3 4 5 6\n";
  mesh_data m = load_obj(dir.write("l.obj", text));
  check_invariants(m);
  REQUIRE(triangle_count(m) == 4);
  float area = 0;
  for (int t = 0; t < 4; t++) {
    vec3f a = area_vector(m, t);
    CHECK(a.x > 0);
    CHECK(a.z < 0);
    area += 0.5f * length(a);
  }
  CHECK(area == Approx(3.0f * std::sqrt(2.0f)));
}

TEST_CASE("a corner written twice in a row does not hide a concave polygon's notch", "[obj]") {
  // Its zero-length edge made both copies of the notch's corner look straight, so the polygon was taken as convex and
  // fanned over the notch: 4 triangles of area 14 (one of them turned over) for an outline of area 10.
  temp_dir dir;
  const std::string v = "v 0 0 0\nv 4 0 0\nv 4 4 0\nv 2 1 0\nv 2 1 0\nv 0 4 0\n";
  for (const char* face : {"f 1 2 3 4 4 6\n", "f 1 2 3 4 5 6\n", "f 6 5 4 3 2 1\n", "f 1 1 2 3 4 6 6\n"}) {
    mesh_data m = load_obj(dir.write("notch.obj", v + face));
    INFO(face);
    check_invariants(m);
    REQUIRE(triangle_count(m) == 3);
    float area = 0;
    float sign = std::string(face) == "f 6 5 4 3 2 1\n" ? -1.0f : 1.0f;
    for (int t = 0; t < 3; t++) {
      vec3f a = area_vector(m, t);
      CHECK(sign * a.z > 0);  // every triangle keeps the polygon's winding
      area += 0.5f * length(a);
    }
    CHECK(area == Approx(10.0f));
  }
}

TEST_CASE("negative indices count back from the latest element", "[obj]") {
  temp_dir dir;
  auto obj = dir.write("neg.obj", "v 5 5 5\n" + std::string(square_vertices) +
                                      "vt 0 0\nvt 1 0\nvt 1 1\n"
                                      "f -4/-3 -3/-2 -2/-1\n");
  mesh_data m = load_obj(obj);
  check_invariants(m);
  REQUIRE(triangle_count(m) == 1);
  CHECK(corner(m, 0, 0).x == 0.0f);
  CHECK(corner(m, 0, 1).x == 1.0f);
  CHECK(corner(m, 0, 2).y == 1.0f);
  CHECK(m.positions.size() == 3);  // the unused vertices are compacted away
  CHECK(m.texcoords[size_t(m.tri_texcoords[2])].x == 1.0f);
}

namespace {

// The corners of the OBJ text `text` as tinyobjloader (a second reader) resolves them, with its face sizes and
// vertex count: what the loader's own reading must agree with.
struct second_reading {
  std::vector<obj_corner> corners;
  std::vector<int> face_sizes;
  size_t positions = 0;
};
second_reading read_with_tinyobj(const std::string& text) {
  std::istringstream in(text);
  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> materials;
  std::string warn, err;
  REQUIRE(tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, &in, nullptr, false, false));
  second_reading r;
  for (const auto& s : shapes) {  // (one per g/o statement, in file order)
    for (const auto& i : s.mesh.indices) r.corners.push_back({i.vertex_index, i.texcoord_index, i.normal_index});
    for (auto n : s.mesh.num_face_vertices) r.face_sizes.push_back(int(n));  // (an unsigned char: modulo 256)
  }
  r.positions = attrib.vertices.size() / 3;
  return r;
}

void check_same_reading(const obj_clean_data& d, const second_reading& r) {
  REQUIRE(d.corners.size() == r.corners.size());
  for (size_t i = 0; i < r.corners.size(); i++) {
    INFO("corner " << i);
    CHECK(d.corners[i].v == r.corners[i].v);
    CHECK(d.corners[i].vt == r.corners[i].vt);
    CHECK(d.corners[i].vn == r.corners[i].vn);
  }
  REQUIRE(d.face_sizes.size() == r.face_sizes.size());
  for (size_t f = 0; f < r.face_sizes.size(); f++) CHECK((d.face_sizes[f] & 0xff) == r.face_sizes[f]);
  CHECK(d.positions.size() == r.positions);
}

}  // namespace

TEST_CASE("face corners resolve to the indices another OBJ reader gives", "[obj]") {
  // Random files (seeded) of v, vt, vn, g and f statements interleaved, each corner in one of the four forms with
  // each index written from the front (1-based, sometimes with '+' or leading zeros) or the back (negative: relative
  // to what is defined so far); now and then a face of 300 corners.
  temp_dir dir;
  std::mt19937 rng(20261204);
  auto pick = [&](int n) { return int(rng() % uint32_t(n)); };
  int compared = 0;
  for (int file = 0; file < 300; file++) {
    std::string text;
    int nv = 0, nt = 0, nn = 0;
    auto index = [&](int count) {
      int i = pick(count);  // 0-based
      const char* prefix[] = {"", "", "", "", "", "0", "00", "+"};
      if (pick(2)) return prefix[pick(8)] + std::to_string(i + 1);
      return "-" + std::string(pick(8) == 0 ? "0" : "") + std::to_string(count - i);
    };
    for (int s = 0; s < 60; s++) {
      int kind = pick(10);
      if (kind < 3 || nv < 3) {
        text += "v " + std::to_string(pick(7)) + " " + std::to_string(pick(5)) + ".5 -" + std::to_string(pick(3)) + "\n";
        nv++;
      } else if (kind == 3) {
        text += "vt 0." + std::to_string(pick(10)) + " 1\n", nt++;
      } else if (kind == 4) {
        text += "vn 0 1 0." + std::to_string(pick(10)) + "\n", nn++;
      } else if (kind == 5) {
        text += "g part" + std::to_string(s) + "\n";
      } else {
        text += "f";
        for (int c = 0, n = pick(40) ? 3 + pick(4) : 300; c < n; c++) {
          int form = pick(4);  // v, v/vt, v//vn, v/vt/vn (those with a missing kind fall back to v)
          if ((form & 1) && nt == 0) form &= 2;
          if ((form & 2) && nn == 0) form &= 1;
          text += " " + index(nv);
          if (form == 1) text += "/" + index(nt);
          if (form == 2) text += "//" + index(nn);
          if (form == 3) text += "/" + index(nt) + "/" + index(nn);
        }
        text += "\n";
      }
    }
    INFO(text);
    obj_clean_data d = validate_obj(dir.write("r.obj", text));
    check_same_reading(d, read_with_tinyobj(text));
    compared += int(d.corners.size());
  }
  CHECK(compared > 10000);
  // And the data/ scenes, as written.
  for (const char* scene : {"cornell/cornell", "living_room/living_room", "plant_room/plant_room", "hall/hall"}) {
    std::string path = std::string(BAYESLIGHT_SOURCE_DIR) + "/data/" + scene + ".obj";
    INFO(path);
    std::ifstream in(path, std::ios::binary);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    obj_clean_data d = validate_obj(path);
    CHECK(d.corners.size() > 100);
    check_same_reading(d, read_with_tinyobj(text));
  }
}

TEST_CASE("corners of the forms v//vn and v/vt/vn carry unit normals and texcoords", "[obj]") {
  temp_dir dir;
  auto obj = dir.write("n.obj", std::string(square_vertices) +
                                    "vt 0.25 0.5\nvt 0.75 0.5 0\nvn 0 0 2\nvn 0 0 0\nvn 1e-30 0 0\n"
                                    "f 1//1 2//2 3//3\nf 1/1/1 3/2/1 4/1/2\n");
  mesh_data m = load_obj(obj);
  check_invariants(m);
  REQUIRE(triangle_count(m) == 2);
  REQUIRE(m.normals.size() == 2);  // vn 0 0 0 is absent, the tiny one is kept
  CHECK(m.normals[size_t(m.tri_normals[0])].z == 1.0f);
  CHECK(m.tri_normals[1] == invalid_id);
  CHECK(m.normals[size_t(m.tri_normals[2])].x == 1.0f);
  for (int c = 0; c < 3; c++) CHECK(m.tri_texcoords[size_t(c)] == invalid_id);
  CHECK(m.texcoords[size_t(m.tri_texcoords[3])].x == 0.25f);
  CHECK(m.texcoords[size_t(m.tri_texcoords[4])].x == 0.75f);
  CHECK(m.tri_normals[5] == invalid_id);
}

TEST_CASE("a corner's empty trailing part is left out as if not written", "[obj]") {
  // Some exporters end a corner with its slash ("1/", "1//", "1/2/"): the same mesh as without it.
  temp_dir dir;
  const std::string head = std::string(square_vertices) + "vt 0.25 0.5\nvt 0.75 0.5\n";
  mesh_data a = load_obj(dir.write("a.obj", head + "f 1/ 2// 3\nf 1/1/ 3/2/ 4/1\n"));
  mesh_data b = load_obj(dir.write("b.obj", head + "f 1 2 3\nf 1/1 3/2 4/1\n"));
  check_invariants(a);
  CHECK(a.tri_positions == b.tri_positions);
  CHECK(a.tri_texcoords == b.tri_texcoords);
  CHECK(a.tri_normals == b.tri_normals);
  REQUIRE(a.tri_texcoords.size() == 6);
  CHECK(a.tri_texcoords[0] == invalid_id);
  CHECK(a.texcoords[size_t(a.tri_texcoords[4])].x == 0.75f);
  // Only one empty part may go: three slashes stay malformed.
  CHECK_THAT(load_error(dir.write("c.obj", head + "f 1/1/1/ 2 3\n")), Catch::Contains("c.obj:7: malformed face corner"));
}

TEST_CASE("materials read Kd Ks Ns and Ke (no Kd: 0) and faces without one get the default", "[obj]") {
  temp_dir dir;
  dir.write("m.mtl",
            "# comment\nnewmtl red\n  Kd 0.5 0.25 0.125 # inline comment\n\tKs 0.1\nNs 20\nKa 0 0 0\nillum 2\n"
            "newmtl lamp\nKe 10 8 6\nd 1\nPr 0.5\n");
  auto obj = dir.write("m.obj", "mtllib m.mtl\n" + std::string(square_vertices) +
                                    "f 1 2 3\nusemtl lamp\nf 1 3 4\nusemtl red\nf 1 2 4\nusemtl lamp\nf 2 3 4\n");
  mesh_data m = load_obj(obj);
  check_invariants(m);
  REQUIRE(m.materials.size() == 3);  // lamp, red (order of first use), then the default
  CHECK(m.materials[0].name == "lamp");
  CHECK(m.materials[0].ke.x == 10.0f);
  CHECK(m.materials[0].ke.z == 6.0f);
  CHECK(is_black(m.materials[0].kd));  // no Kd: no diffuse part (tinyobjloader's reading), the lamp only emits
  CHECK(m.materials[1].name == "red");
  CHECK(m.materials[1].kd.y == 0.25f);
  CHECK(m.materials[1].ks.z == 0.1f);  // one value means grey
  CHECK(m.materials[1].ns == 20.0f);
  CHECK(is_black(m.materials[1].ke));
  CHECK(m.materials[2].kd.x == 0.8f);
  CHECK(m.materials[2].kd_texture == invalid_id);
  REQUIRE(triangle_count(m) == 4);
  CHECK(m.tri_materials == std::vector<int>{2, 0, 1, 0});
}

TEST_CASE("the energy warning sums a material's own Kd and Ks: 0 and Ks without Kd", "[obj]") {
  // A review: Ks 0.25 and Ns 1 without Kd was said to be above 1 and scaled down (the check took Kd 0.8 before the
  // material got its Kd 0), though it renders as Kd 0 0 0 does.
  temp_dir dir;
  write_png(dir, "a.png");
  dir.write("m.mtl", "newmtl lobe\nKs 0.25 0.25 0.25\nNs 1\nnewmtl black\nKd 0 0 0\nKs 0.25 0.25 0.25\nNs 1\n"
                     "newmtl bright\nKd 0.8 0.8 0.8\nKs 0.25 0.25 0.25\nnewmtl tex\nmap_Kd a.png\nKs 0.25\n");
  mesh_data m;
  std::string said = load_warnings(
      dir.write("m.obj", "mtllib m.mtl\n" + std::string(square_vertices) + "usemtl lobe\nf 1 2 3\n"), &m);
  CHECK(is_black(m.materials[0].kd));
  // Named: the material with Kd 0.8 and the one whose map_Kd (without Kd: the texture as it is, Kd 1) may be white.
  CHECK_THAT(said, Catch::Contains("m.mtl: materials 'bright', 'tex' have Kd + Ks above 1"));
}

TEST_CASE("dissolve is said to be not rendered for d below 1 or Tr above 0 only, at its first line", "[obj]") {
  // d 1 and Tr 0 are opaque (what most exporters write for every material): no warning for them.
  temp_dir dir;
  dir.write("o.mtl", "newmtl opaque\nKd 0.5 0.5 0.5\nd 1\nTr 0\n");
  std::string said =
      load_warnings(dir.write("o.obj", "mtllib o.mtl\n" + std::string(square_vertices) + "usemtl opaque\nf 1 2 3\n"));
  CHECK(count_of(said, "dissolve") == 0);
  dir.write("t.mtl", "newmtl opaque\nKd 0.5\nd 1\nTr 0\nnewmtl glass\nKd 0.5\nTr 0.25\nd 0.5\n");
  said = load_warnings(dir.write("t.obj", "mtllib t.mtl\n" + std::string(square_vertices) + "usemtl glass\nf 1 2 3\n"));
  CHECK_THAT(said, Catch::Contains("t.mtl:7: dissolve (d below 1 or Tr above 0) is not rendered"));
  CHECK(count_of(said, "dissolve") == 1);
}

TEST_CASE("a map_Kd under Kd 0 is said to render black", "[obj]") {
  // Maya writes Kd 0 0 0 with map_Kd: the texture, multiplied by Kd, never shows, and the surface rendered black
  // without a word. Emitters show their Ke (a lamp that does not reflect is a choice); without Kd the texture shows.
  temp_dir dir;
  write_png(dir, "a.png");
  dir.write("m.mtl", "newmtl maya\nKd 0 0 0\nmap_Kd a.png\n"                   // lines 1-3
                     "newmtl glossy\nmap_Kd a.png\nKd 0\nKs 0.5 0.5 0.5\n"    // 4-7
                     "newmtl lamp\nKd 0 0 0\nKe 1 1 1\nmap_Kd a.png\n"        // 8-11
                     "newmtl plain\nmap_Kd a.png\nnewmtl dark\nKd 0 0 0\n"    // 12-15
                     "newmtl grey\nKd 0 0.5 0\nmap_Kd a.png\n"                 // 16-18
                     "newmtl m3\nKd 0 0 0\nmap_Kd a.png\nnewmtl m4\nKd 0 0 0\nmap_Kd a.png\n");
  std::string said =
      load_warnings(dir.write("m.obj", "mtllib m.mtl\n" + std::string(square_vertices) + "usemtl maya\nf 1 2 3\n"));
  CHECK_THAT(said, Catch::Contains("m.mtl:2: material 'maya' has map_Kd but Kd 0: it renders black (map_Kd "
                                   "multiplies Kd)"));
  CHECK_THAT(said, Catch::Contains("m.mtl:6: material 'glossy' has map_Kd but Kd 0: it renders as its Ks lobe alone"));
  CHECK_THAT(said, Catch::Contains("m.mtl:20: material 'm3' has map_Kd but Kd 0"));
  CHECK_THAT(said, Catch::Contains("m.mtl: 1 more materials have map_Kd but Kd 0"));
  for (const char* quiet : {"'lamp'", "'plain'", "'dark'", "'grey'", "'m4'"}) CHECK(count_of(said, quiet) == 0);
}

TEST_CASE("a triangle repeating another is dropped, the first emissive one kept", "[obj]") {
  // Light sampling would count every copy of a lamp while a ray sees one of them; rays test every copy (400k copies of
  // one wall cost a millisecond per ray), and which one they report, with its material, was the traversal's choice.
  temp_dir dir;
  dir.write("m.mtl", "newmtl lamp\nKe 5 5 5\nnewmtl wall\nKd 0.5 0.5 0.5\n");
  auto obj = dir.write("m.obj", "mtllib m.mtl\n" + std::string(square_vertices) +
                                    "v 0 0 0\n"  // a second vertex at corner 1's place: repeats by position count
                                    "v -0 0 -0\n"  // and a third, written with negative zeros
                                    "usemtl lamp\nf 1 2 3\nf 2 3 1\nf 5 2 3\nf 3 2 1\n"  // same, rotated, copy, reversed
                                    "f 6 2 3\n"
                                    "usemtl wall\nf 1 2 3\nf 1 2 3\n");                  // non-emissive repeats
  mesh_data m;
  const std::string said = load_warnings(obj, &m);
  check_invariants(m);
  // The warnings name where the first dropped copy is written and the line it repeats (lamp: f 2 3 1 at line 10 of
  // the lamp at line 9; walls: f 1 2 3 at line 15, also of line 9).
  CHECK_THAT(said, Catch::Contains("dropped 3 emissive triangles repeating an earlier one (same corners, same side; "
                                   "the first at line 10, repeating line 9)"));
  CHECK_THAT(said, Catch::Contains("dropped 2 triangles repeating another (same corners, same side; an emissive one is "
                                   "kept first, else the first; the first at line 15, repeating line 9)"));
  // A polygon that goes round twice repeats its own triangles.
  CHECK_THAT(load_warnings(dir.write("twice.obj", std::string(square_vertices) + "f 1 2 3 4 1 2 3 4\n")),
             Catch::Contains("dropped 2 triangles repeating another (same corners, same side; an emissive one is kept "
                             "first, else the first; the first at line 5, within its face)"));
  // Kept: the first lamp triangle and its reversed twin (the other side emits); the walls repeat the lamp.
  REQUIRE(triangle_count(m) == 2);
  CHECK(m.materials[size_t(m.tri_materials[0])].name == "lamp");
  CHECK(m.materials[size_t(m.tri_materials[1])].name == "lamp");
  CHECK(dot(area_vector(m, 0), area_vector(m, 1)) < 0);
  // A wall written before the same lamp, and a wall written twice elsewhere: the lamp stays, and one wall.
  auto obj2 = dir.write("w.obj", "mtllib m.mtl\n" + std::string(square_vertices) +
                                     "usemtl wall\nf 1 2 3\nf 1 3 4\nf 3 4 1\nusemtl lamp\nf 2 3 1\n");
  mesh_data w = load_obj(obj2);
  check_invariants(w);
  REQUIRE(triangle_count(w) == 2);
  CHECK(w.materials[size_t(w.tri_materials[0])].name == "wall");  // 1 3 4 (its repeat 3 4 1 dropped)
  CHECK(w.materials[size_t(w.tri_materials[1])].name == "lamp");  // 2 3 1 (the wall 1 2 3 before it dropped)
  // With a cut-out among the copies both stay (a ray through a hole meets the other copy: solid together), but for
  // emissive repeats of an emissive copy.
  write_png(dir, "a.png");
  dir.write("c.mtl", "newmtl leaf\nmap_d a.png\nnewmtl wall\nKd 0.5 0.5 0.5\nnewmtl lamp\nKe 5 5 5\nmap_d a.png\n");
  auto obj3 = dir.write("c.obj", "mtllib c.mtl\n" + std::string(square_vertices) +
                                     "usemtl leaf\nf 1 2 3\nusemtl wall\nf 1 2 3\n"
                                     "usemtl lamp\nf 1 3 4\nf 3 4 1\nusemtl wall\nf 1 3 4\n");
  mesh_data c = load_obj(obj3);
  REQUIRE(triangle_count(c) == 4);  // leaf, wall; lamp, wall (the lamp's repeat dropped)
  CHECK(c.materials[size_t(c.tri_materials[0])].name == "leaf");
  CHECK(c.materials[size_t(c.tri_materials[1])].name == "wall");
  CHECK(c.materials[size_t(c.tri_materials[2])].name == "lamp");
  CHECK(c.materials[size_t(c.tri_materials[3])].name == "wall");
}

TEST_CASE("a file without usemtl has only the default material", "[obj]") {
  temp_dir dir;
  mesh_data m = load_obj(dir.write("plain.obj", std::string(square_vertices) + "f 1 2 3 4\n"));
  REQUIRE(m.materials.size() == 1);
  CHECK(m.materials[0].kd.y == 0.8f);
  CHECK(m.tri_materials == std::vector<int>{0, 0});
}

TEST_CASE("map_Kd and map_d are resolved beside the MTL and decoded once", "[obj]") {
  temp_dir dir;
  std::filesystem::create_directory(dir.path + "/mats");
  std::filesystem::create_directory(dir.path + "/mats/tex");
  write_png(dir, "mats/tex/a.png");
  dir.write("mats/lib.mtl",
            "newmtl leaf\nmap_Kd -s 1 1 1 -clamp off tex/a.png\nmap_d tex/a.png\n"
            "newmtl bark\nKd 0.2 0.2 0.2\nmap_Kd tex/a.png\n");
  auto obj = dir.write("t.obj", "mtllib mats/lib.mtl\n" + std::string(square_vertices) +
                                    "vt 0.25 0.5\nusemtl leaf\nf 1/1 2/1 3/1\nusemtl bark\nf 1 3 4\n");
  mesh_data m = load_obj(obj);
  check_invariants(m);
  REQUIRE(m.textures.size() == 1);  // one distinct path
  REQUIRE(m.materials.size() == 2);
  CHECK(m.materials[0].kd_texture == 0);
  CHECK(m.materials[0].alpha_texture == 0);
  CHECK(m.materials[1].kd_texture == 0);
  CHECK(m.materials[1].alpha_texture == invalid_id);
  CHECK(m.materials[0].kd.x == 1.0f);  // map_Kd without Kd: the texture as it is
  CHECK(m.materials[1].kd.x == 0.2f);  // Kd given: it multiplies the texture
  const texture_data& t = m.textures[0];
  CHECK(t.path == dir.path + "/mats/tex/a.png");
  REQUIRE(t.width == 2);
  CHECK(texel_rgb(t, 0).x == Approx(0.2158605f).margin(1e-7));
  CHECK(texel_alpha(t, 0) == 1.0f);
  CHECK(texel_alpha(t, 1) == 0.0f);
  CHECK(eval_texture_alpha(t, {0.9f, 0.5f}) == 0.0f);
  // Texture options: -s and -o (u v, w ignored; a v left out takes u's default) and -clamp reach the material.
  CHECK(m.materials[0].kd_map.clamp == false);
  CHECK(m.materials[0].kd_map.scale.x == 1.0f);
  dir.write("mats/opt.mtl", "newmtl a\nmap_Kd -s 2 3 1 -o 0.25 0.5 7 -clamp on tex/a.png\n"
                            "map_d -s 4 -o 0.125 tex/a.png\n");
  auto obj2 = dir.write("o.obj", "mtllib mats/opt.mtl\n" + std::string(square_vertices) + "usemtl a\nf 1 2 3\n");
  mesh_data o = load_obj(obj2);
  REQUIRE(o.materials.size() == 1);
  const material_data& a = o.materials[0];
  CHECK(a.kd_map.scale.x == 2.0f);
  CHECK(a.kd_map.scale.y == 3.0f);
  CHECK(a.kd_map.offset.x == 0.25f);
  CHECK(a.kd_map.offset.y == 0.5f);
  CHECK(a.kd_map.clamp);
  CHECK(a.alpha_map.scale.x == 4.0f);
  CHECK(a.alpha_map.scale.y == 1.0f);
  CHECK(a.alpha_map.offset.x == 0.125f);
  CHECK(a.alpha_map.offset.y == 0.0f);
  CHECK_FALSE(a.alpha_map.clamp);
}

TEST_CASE("map_Kd and map_d are read in any case, as other readers do", "[obj]") {
  // A review: map_kd was named among the textures not rendered, and not applied (Assimp and three.js read MTL
  // keywords in any case). Other keywords keep tinyobjloader's reading: as written.
  temp_dir dir;
  write_png(dir, "a.png");
  dir.write("m.mtl", "newmtl a\nmap_kd a.png\nMAP_D a.png\nnewmtl b\nKd 0.5 0.5 0.5\nmap_KD a.png\nmap_D a.png\n"
                     "newmtl c\nmap_ks a.png\nMAP_KS a.png\n");
  mesh_data m;
  std::string said = load_warnings(dir.write("m.obj", "mtllib m.mtl\n" + std::string(square_vertices) +
                                                          "usemtl a\nf 1 2 3\nusemtl b\nf 1 3 4\nusemtl c\nf 2 3 4\n"),
                                   &m);
  REQUIRE(m.materials.size() == 3);
  REQUIRE(m.textures.size() == 1);
  for (int k : {0, 1}) {
    CHECK(m.materials[size_t(k)].kd_texture == 0);
    CHECK(m.materials[size_t(k)].alpha_texture == 0);
  }
  CHECK(m.materials[0].kd.x == 1.0f);  // map_Kd without Kd: the texture as it is
  CHECK(m.materials[1].kd.x == 0.5f);
  CHECK(m.materials[2].kd_texture == invalid_id);
  CHECK_THAT(said, Catch::Contains("textures other than map_Kd and map_d are not rendered: map_ks (line 9), MAP_KS "
                                   "(line 10)\n"));  // (upper case: named as a texture, not an unknown keyword)
}

TEST_CASE("shading and cut-outs read textures through the statement's -o and -clamp", "[obj]") {
  // The 2x1 texture: texel 0 grey and opaque, texel 1 white and a hole. A point at uv (0.75, 0.25) reads texel 1; with
  // -o 0.5 (read at u + 0.5, wrapped) texel 0; with -s 2 -clamp on (u 1.5, clamped) texel 1 again; -s 3, texel 0.
  temp_dir dir;
  write_png(dir, "a.png");
  camera_params cam;
  cam.eye = {0.5f, 0.5f, 2};
  cam.target = {0.5f, 0.5f, 0};
  for (const char* options : {"", "-o 0.5 ", "-o 1.5 ", "-s 2 -clamp on ", "-s 3 "}) {
    INFO("options: " << options);
    dir.write("x.mtl", std::string("newmtl a\nmap_Kd ") + options + "a.png\nmap_d " + options + "a.png\n");
    auto obj = dir.write("x.obj", "mtllib x.mtl\n" + std::string(square_vertices) +
                                      "vt 0 0\nvt 1 0\nvt 1 1\nusemtl a\nf 1/1 2/2 3/3\n");
    scene_data scene = build_scene(load_obj(obj), cam, sun_params{}, false, 1.0f);
    REQUIRE(triangle_count(scene.mesh) == 1);
    surface_point sp = eval_surface(scene, 0, 0.5f, 0.25f, {0, 0, -1});
    REQUIRE(sp.uv.x == 0.75f);
    const bool texel1 = std::string(options).find("-o 0.5") == std::string::npos &&
                        std::string(options).find("-o 1.5") == std::string::npos &&
                        std::string(options) != "-s 3 ";  // unclamped, u 2.25 wraps to texel 0
    CHECK(alpha_hole(scene, 0, 0.5f, 0.25f) == texel1);
    CHECK(make_bsdf(scene, sp).kd.x == Approx(texel1 ? 1.0f : 0.2158605f).margin(1e-6));
  }
}

TEST_CASE("one image file named in several ways is decoded once", "[obj]") {
  // Relative, absolute, through a symbolic link and a hard link: each was decoded again (an 8192^2 image four times
  // took 1.3 GB).
  temp_dir dir;
  write_png(dir, "a.png");
  std::filesystem::create_symlink(dir.path + "/a.png", dir.path + "/sym.png");
  std::filesystem::create_hard_link(dir.path + "/a.png", dir.path + "/hard.png");
  dir.write("l.mtl", "newmtl a\nmap_Kd a.png\nnewmtl b\nmap_Kd " + dir.path +
                         "/a.png\nnewmtl c\nmap_Kd sym.png\nnewmtl d\nmap_Kd hard.png\nmap_d ./a.png\n");
  auto obj = dir.write("l.obj", "mtllib l.mtl\n" + std::string(square_vertices) +
                                    "usemtl a\nf 1 2 3\nusemtl b\nf 1 3 4\nusemtl c\nf 1 2 4\nusemtl d\nf 2 3 4\n");
  mesh_data m = load_obj(obj);
  REQUIRE(m.materials.size() == 4);
  CHECK(m.textures.size() == 1);
  for (const material_data& mat : m.materials) CHECK(mat.kd_texture == 0);
  CHECK(m.materials[3].alpha_texture == 0);
}

TEST_CASE("a map_Kd that is also the map_d at the same uv is marked as a cut-out colour on load", "[obj]") {
  // make_bsdf blends such a colour over its solid texels only (texture_test.cpp); the same image read at another
  // scale, offset or clamp, or a colour without a mask, is an ordinary colour.
  temp_dir dir;
  write_png(dir, "leaf.png");
  write_png(dir, "mask.png");
  dir.write("l.mtl",
            "newmtl same\nmap_Kd leaf.png\nmap_d leaf.png\n"
            "newmtl channel\nmap_Kd leaf.png\nmap_d -imfchan g leaf.png\n"
            "newmtl scaled\nmap_Kd leaf.png\nmap_d -s 2 1 1 leaf.png\n"
            "newmtl clamped\nmap_Kd -clamp on leaf.png\nmap_d leaf.png\n"
            "newmtl other\nmap_Kd leaf.png\nmap_d mask.png\n"
            "newmtl colour\nmap_Kd leaf.png\n");
  auto obj = dir.write("l.obj", "mtllib l.mtl\n" + std::string(square_vertices) +
                                    "vt 0.25 0.5\nusemtl same\nf 1/1 2/1 3/1\nusemtl channel\nf 1/1 3/1 4/1\n"
                                    "usemtl scaled\nf 1/1 2/1 4/1\nusemtl clamped\nf 2/1 3/1 4/1\n"
                                    "usemtl other\nf 1/1 2/1 3/1\nusemtl colour\nf 1/1 3/1 4/1\n");
  mesh_data m = load_obj(obj);
  REQUIRE(m.materials.size() == 6);
  CHECK(m.materials[0].kd_is_cutout);
  CHECK(m.materials[1].kd_is_cutout);  // the mask's channel is the one blended over (eval_texture_rgb)
  CHECK_FALSE(m.materials[2].kd_is_cutout);
  CHECK_FALSE(m.materials[3].kd_is_cutout);
  CHECK_FALSE(m.materials[4].kd_is_cutout);
  CHECK_FALSE(m.materials[5].kd_is_cutout);
}

TEST_CASE("library and texture names may be quoted or use Windows separators", "[obj]") {
  // mtllib, map_Kd and map_d resolve names alike: one pair of surrounding double quotes is dropped (a name with a
  // space), and '\\' is tried as '/' when the name as written is not a file.
  temp_dir dir;
  std::filesystem::create_directory(dir.path + "/my mats");
  std::filesystem::create_directory(dir.path + "/my mats/tex");
  write_png(dir, "my mats/tex/a b.png");
  dir.write("my mats/lib.mtl", "newmtl leaf\nmap_Kd \"tex/a b.png\"\nmap_d tex\\a b.png\n");
  for (std::string lib : {"mtllib \"my mats/lib.mtl\"\n", "mtllib my mats\\lib.mtl\n"}) {
    INFO(lib);
    auto obj = dir.write("q.obj", lib + std::string(square_vertices) + "vt 0.25 0.5\nusemtl leaf\nf 1/1 2/1 3/1\n");
    mesh_data m = load_obj(obj);
    REQUIRE(m.textures.size() == 1);
    CHECK(m.textures[0].path == dir.path + "/my mats/tex/a b.png");
    CHECK(m.materials[0].kd_texture == 0);
    CHECK(m.materials[0].alpha_texture == 0);
  }
  // Blanks inside a name are kept as written (two spaces are not one).
  write_png(dir, "my mats/tex/two  spaces.png");
  dir.write("my mats/two.mtl", "newmtl leaf\nmap_Kd tex/two  spaces.png\n");
  auto obj = dir.write("t.obj", "mtllib my mats/two.mtl\n" + std::string(square_vertices) +
                                    "vt 0.25 0.5\nusemtl leaf\nf 1/1 2/1 3/1\n");
  mesh_data m = load_obj(obj);
  REQUIRE(m.textures.size() == 1);
  CHECK(m.textures[0].path == dir.path + "/my mats/tex/two  spaces.png");
}

TEST_CASE("material and texture names may hold '#' words; a lone '#' starts a comment", "[obj]") {
  // 3ds Max names materials "Material #25" and exporters keep the names: every such name was cut at its '#' and all
  // became one material (the first), with a warning that it was defined again.
  temp_dir dir;
  write_png(dir, "Wood #2.png");
  write_png(dir, "plain.png");
  dir.write("m.mtl",
            "newmtl Material #1\nKd 1 0 0\nnewmtl Material #2\nKd 0 1 0\n"
            "newmtl wood # the floor\nKd 0 0 1\nmap_Kd Wood #2.png\n"
            "newmtl plain\nKd 0.5 0.5 0.5\nmap_Kd plain.png #no such file: a comment\n"
            "newmtl red #red paint\nKd 0.7 0 0\nmap_Kd C:\\Users\\artist\\Wood #2.png\n");
  auto obj = dir.write("m.obj", "mtllib m.mtl\n" + std::string(square_vertices) +
                                    "usemtl Material #1\nf 1 2 3\nusemtl Material #2\nf 1 3 4\n"
                                    "usemtl wood #planks\nf 1 2 4\nusemtl plain # comment\nf 2 3 4\n"
                                    "v 5 5 5\nusemtl red\nf 1 2 5\n");
  mesh_data m = load_obj(obj);
  REQUIRE(m.materials.size() == 5);
  // "usemtl red" meant "newmtl red #red paint" (a comment after the name, as the '#' word was read before).
  CHECK(m.materials[4].name == "red #red paint");
  CHECK(m.materials[4].kd.x == 0.7f);
  // A '#' word in a name written on another machine: the whole name, found beside the MTL.
  CHECK(m.materials[4].kd_texture == m.materials[2].kd_texture);
  // A comment holding a path after a name that exists: the name, not a file of the comment's last part found beside.
  std::filesystem::create_directory(dir.path + "/tex");
  write_png(dir, "tex/wood.png");
  write_png(dir, "wood.png");
  dir.write("c.mtl", "newmtl a\nmap_Kd tex/wood.png #was C:\\Users\\me\\textures\\wood.png\n");
  mesh_data c = load_obj(dir.write("c.obj", "mtllib c.mtl\n" + std::string(square_vertices) + "usemtl a\nf 1 2 3\n"));
  REQUIRE(c.textures.size() == 1);
  CHECK(c.textures[0].path == dir.path + "/tex/wood.png");
  CHECK(m.materials[0].name == "Material #1");
  CHECK(m.materials[0].kd.x == 1.0f);
  CHECK(m.materials[1].name == "Material #2");
  CHECK(m.materials[1].kd.y == 1.0f);
  CHECK(m.materials[2].name == "wood");  // "wood #planks" is not defined: the name before its '#' word
  CHECK(m.materials[2].kd.z == 1.0f);
  CHECK(m.materials[3].name == "plain");
  REQUIRE(m.textures.size() == 2);
  CHECK(m.textures[size_t(m.materials[2].kd_texture)].path == dir.path + "/Wood #2.png");
  CHECK(m.textures[size_t(m.materials[3].kd_texture)].path == dir.path + "/plain.png");
}

TEST_CASE("files named with another machine's path or in another case are found beside the file naming them",
          "[obj]") {
  temp_dir dir;
  write_png(dir, "wood.png");
  write_png(dir, "Leaf.png");
  std::filesystem::create_directory(dir.path + "/LEAF.png");  // a folder of the same name but for case: no rival
  dir.write("lib2.mtl", "newmtl a\nmap_Kd C:\\Users\\artist\\Documents\\maps\\wood.png\n"
                        "newmtl b\nmap_d leaf.PNG\nmap_Kd /home/someone/wood.png\n");
  auto obj = dir.write("p.obj", "mtllib D:\\work\\lib2.mtl\n" + std::string(square_vertices) +
                                    "vt 0.25 0.5\nusemtl a\nf 1/1 2/1 3/1\nusemtl b\nf 1/1 3/1 4/1\n");
  // Also through a relative path with folders (the path found beside was resolved against the folder again, and
  // again: unbounded recursion, a segfault).
  const std::string relative = std::filesystem::relative(obj).string();
  REQUIRE(relative.find('/') != std::string::npos);
  for (const std::string& name : {obj, relative}) {
    INFO(name);
    mesh_data r = load_obj(name);
    REQUIRE(r.textures.size() == 2);
    CHECK(std::filesystem::equivalent(r.textures[0].path, dir.path + "/wood.png"));
  }
  mesh_data m = load_obj(obj);
  REQUIRE(m.materials.size() == 2);
  REQUIRE(m.textures.size() == 2);  // wood.png once, for both names that lead to it
  CHECK(m.textures[size_t(m.materials[0].kd_texture)].path == dir.path + "/wood.png");
  CHECK(m.materials[1].kd_texture == m.materials[0].kd_texture);
  CHECK(m.textures[size_t(m.materials[1].alpha_texture)].path == dir.path + "/Leaf.png");
  // Not found under any of those names: the error names the file as written.
  dir.write("lib3.mtl", "newmtl a\nmap_Kd C:\\maps\\stone.png\n");
  auto bad = dir.write("q.obj", "mtllib lib3.mtl\n" + std::string(square_vertices) + "usemtl a\nf 1 2 3\n");
  CHECK_THAT(load_error(bad), Catch::Contains("stone.png"));
}

TEST_CASE("a texture written with another machine's path is taken from its folder beside the MTL first", "[obj]") {
  // A review: C:\\Users\\bob\\proj\\textures\\wood.png and Blender's //textures/wood.png were looked for only as
  // wood.png beside the MTL; textures/wood.png beside it comes first (the file's own folder), then wood.png.
  temp_dir dir;
  std::filesystem::create_directory(dir.path + "/textures");
  write_png(dir, "textures/wood.png");
  write_png(dir, "wood.png");
  write_png(dir, "leaf.png");
  dir.write("m.mtl", "newmtl a\nmap_Kd C:\\Users\\bob\\proj\\textures\\wood.png\n"
                     "newmtl b\nmap_Kd //textures/wood.png\n"
                     "newmtl c\nmap_Kd C:\\Users\\bob\\proj\\other\\wood.png\nmap_d D:\\textures\\leaf.png\n");
  mesh_data m;
  std::string said = load_warnings(dir.write("m.obj", "mtllib m.mtl\n" + std::string(square_vertices) +
                                                          "usemtl a\nf 1 2 3\nusemtl b\nf 1 3 4\nusemtl c\nf 2 3 4\n"),
                                   &m);
  REQUIRE(m.materials.size() == 3);
  auto kd_path = [&](int k) { return m.textures[size_t(m.materials[size_t(k)].kd_texture)].path; };
  CHECK(kd_path(0) == dir.path + "/textures/wood.png");
  CHECK(kd_path(1) == dir.path + "/textures/wood.png");
  CHECK(kd_path(2) == dir.path + "/wood.png");  // no folder "other" beside the MTL: the name alone
  CHECK(m.textures[size_t(m.materials[2].alpha_texture)].path == dir.path + "/leaf.png");
  CHECK_THAT(said, Catch::Contains("m.mtl:2: map_Kd: C:\\Users\\bob\\proj\\textures\\wood.png does not exist; using " +
                                   dir.path + "/textures/wood.png\n"));
  CHECK_THAT(said, Catch::Contains("m.mtl:4: map_Kd: //textures/wood.png does not exist; using " + dir.path +
                                   "/textures/wood.png\n"));
}

TEST_CASE("a texture of an MTL in a subfolder, named from the OBJ's folder, is found there", "[obj]") {
  // A review: mtllib mats/a.mtl whose map_Kd tex2.png lies beside the OBJ was refused ("mats/tex2.png: cannot open
  // image"), though the case-, backslash- and folder-tolerant look-ups beside the MTL were tried.
  temp_dir dir;
  std::filesystem::create_directory(dir.path + "/mats");
  std::filesystem::create_directory(dir.path + "/textures");
  write_png(dir, "tex2.png");
  write_png(dir, "textures/wood.png");
  write_png(dir, "Leaf.png");
  dir.write("mats/a.mtl", "newmtl a\nmap_Kd tex2.png\nnewmtl b\nmap_Kd textures/wood.png\nmap_d LEAF.png\n");
  mesh_data m;
  std::string said = load_warnings(dir.write("sub.obj", "mtllib mats/a.mtl\n" + std::string(square_vertices) +
                                                            "usemtl a\nf 1 2 3\nusemtl b\nf 1 3 4\n"),
                                   &m);
  REQUIRE(m.materials.size() == 2);
  REQUIRE(m.textures.size() == 3);
  CHECK(std::filesystem::equivalent(m.textures[size_t(m.materials[0].kd_texture)].path, dir.path + "/tex2.png"));
  CHECK(std::filesystem::equivalent(m.textures[size_t(m.materials[1].kd_texture)].path,
                                    dir.path + "/textures/wood.png"));
  CHECK(std::filesystem::equivalent(m.textures[size_t(m.materials[1].alpha_texture)].path,
                                    dir.path + "/Leaf.png"));  // (in another case, too)
  CHECK_THAT(said, Catch::Contains("a.mtl:2: map_Kd: tex2.png does not exist; using "));
  // Beside the MTL first, where both hold one.
  write_png(dir, "mats/tex2.png");
  mesh_data both = load_obj(dir.path + "/sub.obj");
  CHECK(std::filesystem::equivalent(both.textures[size_t(both.materials[0].kd_texture)].path,
                                    dir.path + "/mats/tex2.png"));
  // Found in neither: the error names the file as written beside the MTL.
  dir.write("mats/c.mtl", "newmtl a\nmap_Kd stone.png\n");
  auto bad = dir.write("c.obj", "mtllib mats/c.mtl\n" + std::string(square_vertices) + "usemtl a\nf 1 2 3\n");
  CHECK_THAT(load_error(bad), Catch::Contains("stone.png"));
}

TEST_CASE("MTL statements that are not rendered are accepted in any of their forms", "[obj]") {
  temp_dir dir;
  write_png(dir, "glow.png");
  dir.write("n.mtl",
            "newmtl a\nKd 0.5 0.5 0.5\nKa spectral ident.rfl 1.0\nTf xyz 1 1 1\nKt 1\nd -halo 0.8\n"
            "map_Ke glow.png\nbump -bm 0.5 glow.png\nmap_Ks glow.png\n");
  auto obj = dir.write("n.obj", "mtllib n.mtl\n" + std::string(square_vertices) + "usemtl a\nf 1 2 3\n");
  mesh_data m = load_obj(obj);
  REQUIRE(m.materials.size() == 1);
  CHECK(m.materials[0].kd.x == 0.5f);
  CHECK(m.materials[0].kd_texture == invalid_id);
  CHECK(m.textures.empty());  // (only map_Kd and map_d are read)
  // Kd, Ks and Ke are rendered: a spectral or XYZ form is refused by name.
  dir.write("s.mtl", "newmtl a\nKd spectral wood.rfl 1.0\n");
  auto bad = dir.write("s.obj", "mtllib s.mtl\n" + std::string(square_vertices) + "usemtl a\nf 1 2 3\n");
  CHECK_THAT(load_error(bad), Catch::Contains("'Kd' spectral (a spectral curve) is not supported: write Kd r g b"));
}

TEST_CASE("degenerate triangles are dropped and counted", "[obj]") {
  temp_dir dir;
  auto obj = dir.write("deg.obj", std::string(square_vertices) +
                                      "v 2 0 0\nv 1 1 0\n"  // 5 is collinear with 1 and 2; 6 repeats 3
                                      "f 1 2 4\nf 1 2 5\nf 3 3 4\nf 3 6 4\nf 1 2 3 4\n");  // (no repeats)
  mesh_data m = load_obj(obj);
  check_invariants(m);
  CHECK(triangle_count(m) == 3);
  CHECK(m.dropped_degenerate == 3);
  CHECK(m.first_degenerate_line == 8);  // f 1 2 5 (the warning names it)
  CHECK(load_obj(dir.write("ok.obj", std::string(square_vertices) + "f 1 2 3\n")).first_degenerate_line == 0);
}

TEST_CASE("faces without area are counted as degenerate, whatever their corner count", "[obj]") {
  // A review: a quad whose corners collapse to fewer than 3 points (corners equal by value, as UTM coordinates
  // rounded to float make them) was dropped without a count (a photogrammetry OBJ lost 143 of 722 triangles).
  // Each such face counts the n - 2 triangles it would have given, as a triangle of coincident corners counts 1.
  temp_dir dir;
  auto obj = dir.write("deg.obj", std::string(square_vertices) +
                                      "v 5 0 0\nv 5 0 0\nv 6 1 0\nv 6 1 0\n"                       // 5 = 6, 7 = 8
                                      "v 500000.001 4000000.001 0\nv 500000.002 4000000.002 0\n"  // 9 = 10 in float
                                      "v 2 0 0\nv 3 0 0\n"                                          // on line 1-2
                                      "f 1 2 3\nf 5 6 7 8\nf 5 5 6 6\nf 5 6 7\nf 9 10 9 10 9\nf 1 2 11 12\n");
  mesh_data m = load_obj(obj);
  check_invariants(m);
  CHECK(triangle_count(m) == 1);
  CHECK(m.dropped_degenerate == 2 + 2 + 1 + 3 + 2);
  CHECK(m.dropped_flat == 0);
}

TEST_CASE("zero-area triangles between a polygon's corners on one line are not degenerate faces", "[obj]") {
  // A review: a rectangle with T-junction points on its edges lost a zero-area triangle of its fan, counted as a
  // degenerate triangle with the advice to rescale the scene, though the image was right. They are dropped without
  // loss: the polygon's area is covered by the triangles kept.
  temp_dir dir;
  auto obj = dir.write("t.obj",
                       "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 0 1 0\n"                  // a hexagon
                       "v 0 0 1\nv 1 0 1\nv 2 0 1\nv 2 1 1\nv 1 1 1\nv 1 2 1\nv 0 2 1\nv 0 1 1\n"  // an L
                       "v 0 0 2\nv 1 0 2\nv 2 0 2\nv 3 0 2\nv 3 1 2\nv 0 1 2\n"                  // 2 on an edge
                       "f 1 2 3 4 5 6\nf 7 8 9 10 11 12 13 14\nf 14 13 12 11 10 9 8 7\nf 15 16 17 18 19 20\n");
  mesh_data m = load_obj(obj);
  check_invariants(m);
  CHECK(m.dropped_degenerate == 0);
  CHECK(m.dropped_flat == 3);
  CHECK(triangle_count(m) + m.dropped_flat == 4 + 6 + 6 + 4);
  // Each face's triangles are wound as it is and add up to its area.
  double area[3] = {0, 0, 0}, l_reversed = 0;
  for (int t = 0; t < triangle_count(m); t++) {
    vec3f a = area_vector(m, t);
    int z = int(corner(m, t, 0).z);
    CHECK((a.z > 0 || z == 1));
    (a.z < 0 ? l_reversed : area[z]) += 0.5 * std::fabs(double(a.z));
  }
  CHECK(area[0] == 2.0);
  CHECK(area[1] == 3.0);
  CHECK(l_reversed == 3.0);
  CHECK(area[2] == 3.0);
}

TEST_CASE("vertex colours are said once per file not to be rendered", "[obj]") {
  // A review: v x y z r g b lost its colours without a word. (v x y z w is a weight, not a colour.)
  temp_dir dir;
  std::string said = load_warnings(
      dir.write("c.obj", "v 0 0 0 1\nv 1 0 0 1 0 0\nv 1 1 0 0 1 0\nv 0 1 0 0 0 1\nf 1 2 3\nf 1 3 4\n"));
  CHECK(count_of(said, "vertex colours") == 1);
  CHECK_THAT(said, Catch::Contains("c.obj:2: vertex colours (v x y z r g b) are not rendered"));
  CHECK(load_warnings(dir.write("w.obj", "v 0 0 0 1\nv 1 0 0 0.5\nv 1 1 0\nf 1 2 3\n")).empty());
}

TEST_CASE("odd but legal files from real tools load", "[obj]") {
  temp_dir dir;
  // BOM, CRLF and lone CR line endings, tabs, groups, smoothing, lines, points, vp, w, vertex colours,
  // unknown statements (a warning, not an error), usemtl before its mtllib, a material name with a space.
  dir.write("odd.mtl", "newmtl my mat\r\nKd 1 1 1\r\n");
  auto obj = dir.write("odd.obj",
                       "\xEF\xBB\xBF# exported\r\nusemtl my mat\r\nmtllib odd.mtl\r\no thing\rg a b\ns off\ns 1\n"
                       "v\t0 0 0 1\nv 1 0 0 0.5 0.5 0.5\nv 1 1 0\nvp 0.5\nl 1 2\np 1\ncstype bezier\n"
                       "f 1 2 3 # trailing comment\nfoo bar\n");
  mesh_data m = load_obj(obj);
  check_invariants(m);
  CHECK(triangle_count(m) == 1);
  REQUIRE(m.materials.size() == 1);
  CHECK(m.materials[0].name == "my mat");
  CHECK(m.materials[0].kd.x == 1.0f);
}

TEST_CASE("a statement ending in a backslash continues on the next line", "[obj]") {
  // The OBJ format's line continuation; a comment ending in a backslash (a Windows path) does not swallow the next
  // line; an error in a continued statement names its first line.
  temp_dir dir;
  auto obj = dir.write("c.obj", "v 0 0 0\nv 1 0 \\\n 0\nv 1 1 0\n# from C:\\scenes\\\nv 0 1 0\nf 1 \\\r\n2 \\  \n3 4\n");
  mesh_data m = load_obj(obj);
  check_invariants(m);
  CHECK(m.positions.size() == 4);
  CHECK(triangle_count(m) == 2);
  auto bad = dir.write("d.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 \\\n 2 \\\n 9\n");
  CHECK_THAT(load_error(bad), Catch::Contains(bad + ":4: ") && Catch::Contains("9"));
  // A trailing comment ending in a backslash ends its statement: the next line stays a statement of its own.
  auto trailing = dir.write("e.obj", "v 0 0 0 # from C:\\scans\\\nv 1 0 0\nv 1 1 0\t#\\\nv 0 1 0\nf 1 2 3 4\n");
  mesh_data t = load_obj(trailing);
  CHECK(t.positions.size() == 4);
  CHECK(triangle_count(t) == 2);
}

TEST_CASE("the subdivided Cornell box layout loads", "[obj]") {
  // Statement shapes of a real exported scene: mtllib first, o/usemtl per object, quads.
  temp_dir dir;
  dir.write("box.mtl",
            "newmtl White\nKd 0.73 0.73 0.73\nKa 0.0000 0.0000 0.0000\nKs 0.0000 0.0000 0.0000\n"
            "illum 1\n\nnewmtl Light\nKd 0.78 0.78 0.78\nKe 18.4 15.6 8\nillum 1\n");
  auto obj = dir.write("box.obj", "# Cornell\nmtllib box.mtl\n\n" + std::string(square_vertices) +
                                      "v 0 0 1\nv 1 0 1\n\no floor\nusemtl White\nf 1 2 3 4\n"
                                      "o light\nusemtl Light\nf 1 5 6 2\n");
  mesh_data m = load_obj(obj);
  check_invariants(m);
  CHECK(triangle_count(m) == 4);
  CHECK(m.materials[1].ke.y == 15.6f);
}

TEST_CASE("a missing OBJ or a directory is an input error naming it", "[obj]") {
  temp_dir dir;
  CHECK_THAT(load_error(dir.path + "/nope.obj"), Catch::Contains("nope.obj: cannot open OBJ file"));
  CHECK_THAT(load_error(dir.path), Catch::Contains("not a regular file"));
}

TEST_CASE("malformed statements are input errors with file and line", "[obj]") {
  temp_dir dir;
  struct bad_case {
    const char* body;
    int line;
    const char* says;
  };
  const bad_case cases[] = {
      {"v 0 0 0\nv 1 0.5x 0\n", 2, "malformed number '0.5x'"},
      {"v 0 0 0\nv nan 0 0\n", 2, "non-finite number 'nan'"},
      {"v 0 0 0\nv 0 -inf 0\n", 2, "non-finite number '-inf'"},
      {"v 1e39 0 0\n", 1, "out of range"},
      {"v 0e999 0 0\n", 1, "out of range"},
      {"v . 0 0\n", 1, "malformed number '.'"},
      {"v 1 2\n", 1, "takes 3 numbers"},
      {"vn 0 0 1 0\n", 1, "takes 3 numbers"},
      {"vt\n", 1, "takes 1 to 3 numbers"},
      {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", 4, "vertex index '4' out of range (3 vertices"},
      {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n", 4, "index 0 is invalid"},
      {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n", 4, "out of range"},
      {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1 2/1 3/1\n", 4, "texcoord index '1' out of range"},
      {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//1 2 3\n", 4, "normal index '1' out of range"},
      {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3.0\n", 4, "malformed vertex index '3.0'"},
      {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 /3\n", 4, "malformed vertex index ''"},
      {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3/1/1/1\n", 4, "malformed face corner"},
      {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999999999999\n", 4, "out of range"},
      {"v 0 0 0\nv 1 0 0\nf 1 2\n", 3, "at least 3 vertices"},
      {"v 0 0 0\n\rv 0 \0 0\n", 3, "NUL byte"},
      {"usemtl\n", 1, "usemtl needs a material name"},
      {"mtllib\n", 1, "mtllib needs a file name"},
  };
  for (const auto& c : cases) {
    std::string body(c.body, c.body + std::char_traits<char>::length(c.body));
    if (std::string(c.says) == "NUL byte") body = std::string("v 0 0 0\n\rv 0 \0 0\n", 17);
    auto obj = dir.write("bad.obj", body);
    INFO(c.body);
    CHECK_THAT(load_error(obj), Catch::Contains(obj + ":" + std::to_string(c.line) + ": ") && Catch::Contains(c.says));
  }
}

TEST_CASE("material library errors name the MTL file and line", "[obj]") {
  temp_dir dir;
  const std::string faces = std::string(square_vertices) + "usemtl a\nf 1 2 3\n";
  auto obj_for = [&](const std::string& mtl) {
    dir.write("lib.mtl", mtl);
    return dir.write("o.obj", "mtllib lib.mtl\n" + faces);
  };
  const std::string mtl = dir.path + "/lib.mtl";
  CHECK_THAT(load_error(obj_for("newmtl a\nKd 0.5 0.5\n")), Catch::Contains(mtl + ":2: 'Kd' takes 1 or 3 numbers"));
  CHECK_THAT(load_error(obj_for("newmtl a\nKd 0.5 -1 0\n")), Catch::Contains(mtl + ":2: 'Kd' must not be negative"));
  CHECK_THAT(load_error(obj_for("newmtl a\nKe 1 nan 1\n")), Catch::Contains(mtl + ":2: non-finite number 'nan'"));
  CHECK_THAT(load_error(obj_for("Kd 1 1 1\nnewmtl a\n")), Catch::Contains(mtl + ":1: 'Kd' before any newmtl"));
  CHECK_THAT(load_error(obj_for("newmtl a\nd 1.5\n")), Catch::Contains(mtl + ":2: 'd' must lie in [0, 1]"));
  CHECK_THAT(load_error(obj_for("newmtl a\nNs -3\n")), Catch::Contains(mtl + ":2: Ns must not be negative"));
  CHECK_THAT(load_error(obj_for("newmtl a\nNs 1 2\n")), Catch::Contains(mtl + ":2: 'Ns' takes 1 number"));
  CHECK_THAT(load_error(obj_for("newmtl a\nmap_Kd -s 1 1 1\n")),
             Catch::Contains(mtl + ":2: 'map_Kd' needs a file name"));
  CHECK_THAT(load_error(obj_for("newmtl a\nmap_Kd -clamp maybe x.png\n")), Catch::Contains(mtl + ":2: texture option"));
  CHECK_THAT(load_error(obj_for("newmtl\n")), Catch::Contains(mtl + ":1: newmtl needs a material name"));
}

TEST_CASE("emitters whose power would overflow light selection's float sums are input errors", "[obj]") {
  // Power = luminance(Ke) x area x pi, refused above 1e30 per triangle or for all emitters together; the message
  // names the material's newmtl line.
  temp_dir dir;
  const std::string mtl = dir.path + "/lib.mtl";
  auto obj_for = [&](const std::string& ke, int triangles) {
    dir.write("lib.mtl", "newmtl a\nKd 0 0 0\nKe " + ke + "\n");
    std::string obj = "mtllib lib.mtl\nusemtl a\n";
    for (int i = 0; i < triangles; i++) {  // right triangles of area 0.5, one above the other
      std::string y = std::to_string(i);
      obj += "v 0 " + y + " 0\nv 1 " + y + " 0\nv 0 " + y + " 1\nf -3 -2 -1\n";
    }
    return dir.write("o.obj", obj);
  };
  // 1e30 / (0.5 pi) = 6.4e29: a luminance of 1e30 is too much for one triangle, 4e29 for two, 3e29 for neither.
  CHECK_THAT(load_error(obj_for("1e30 1e30 1e30", 1)), Catch::Contains(mtl + ":1: material \"a\": Ke makes a triangle"));
  CHECK_THAT(load_error(obj_for("1e30 1e30 1e30", 1)), Catch::Contains("power of 1.57e+30"));
  CHECK_THAT(load_error(obj_for("4e29 4e29 4e29", 2)), Catch::Contains(mtl + ":1: material \"a\": with it the emitters"));
  CHECK(load_obj(obj_for("3e29 3e29 3e29", 2)).tri_materials.size() == 2);
  CHECK(load_obj(obj_for("3e29 3e29 3e29", 1)).tri_materials.size() == 1);
}

TEST_CASE("a missing MTL is an input error at its OBJ line; an undefined material gets the default", "[obj]") {
  temp_dir dir;
  auto obj = dir.write("a.obj", std::string(square_vertices) + "mtllib missing.mtl\nf 1 2 3\n");
  CHECK_THAT(load_error(obj),
             Catch::Contains(obj + ":5: mtllib: ") && Catch::Contains("missing.mtl: cannot open material library"));
  // As other OBJ readers do: faces of a name no library defines (with a library, or with none at all) render with
  // the default material (a warning names the line; checked in cli_test).
  dir.write("ok.mtl", "newmtl known\nKd 0.25 0.5 0.75\n");
  for (std::string lib : {"mtllib ok.mtl\n", ""}) {
    obj = dir.write("b.obj", lib + std::string(square_vertices) + "usemtl known\nf 1 2 3\nusemtl ghost\nf 1 3 4\n");
    INFO(lib);
    mesh_data m = load_obj(obj);
    REQUIRE(m.tri_materials.size() == 2);
    const material_data& known = m.materials[size_t(m.tri_materials[0])];
    const material_data& ghost = m.materials[size_t(m.tri_materials[1])];
    CHECK(ghost.name == "ghost");
    CHECK(ghost.kd.x == material_data{}.kd.x);
    CHECK(ghost.kd.z == material_data{}.kd.z);
    CHECK(ghost.ke.x == 0);
    CHECK(known.name == "known");
    CHECK(known.kd.z == (lib.empty() ? material_data{}.kd.z : 0.75f));
    CHECK(m.source_files.size() == (lib.empty() ? 1u : 2u));  // the OBJ (and its library): no empty name
  }
}

TEST_CASE("a missing or undecodable texture is an input error at its MTL line", "[obj]") {
  temp_dir dir;
  const std::string faces = "mtllib t.mtl\n" + std::string(square_vertices) + "usemtl a\nf 1 2 3\n";
  dir.write("t.mtl", "newmtl a\nKd 1 1 1\nmap_Kd none.png\n");
  auto obj = dir.write("t.obj", faces);
  CHECK_THAT(load_error(obj),
             Catch::Contains(dir.path + "/t.mtl:3: map_Kd: ") && Catch::Contains("none.png: cannot open image"));
  dir.write("junk.png", "\x89PNG\r\n\x1a\n this is not a png");
  dir.write("t.mtl", "newmtl a\nmap_d junk.png\n");
  CHECK_THAT(load_error(obj),
             Catch::Contains(dir.path + "/t.mtl:2: map_d: ") && Catch::Contains("junk.png: cannot decode image"));
  // An unused material's texture is never opened.
  dir.write("t.mtl", "newmtl a\nnewmtl unused\nmap_Kd none.png\n");
  CHECK(load_error(obj).empty());
}

TEST_CASE("files without triangles are input errors", "[obj]") {
  temp_dir dir;
  auto empty = dir.write("empty.obj", "");
  CHECK_THAT(load_error(empty), Catch::Equals(empty + ": no triangles"));
  CHECK_THAT(load_error(dir.write("verts.obj", square_vertices)), Catch::EndsWith(": no triangles"));
  CHECK_THAT(load_error(dir.write("flat.obj", std::string(square_vertices) + "f 1 1 2\n")),
             Catch::Contains("no triangles (1 degenerate dropped: zero area"));
}

TEST_CASE("hostile input ends in an input error or a mesh", "[obj]") {
  temp_dir dir;
  // A 10 MB line of digits, a huge face, binary garbage, absurd numbers: none may crash or hang.
  CHECK_THAT(load_error(dir.write("long.obj", "v " + std::string(10'000'000, '7') + " 0 0\n")),
             Catch::Contains("number too long"));
  std::string big_face = std::string(square_vertices) + "f";
  for (int i = 0; i < 200000; i++) big_face += " " + std::to_string(1 + i % 4);
  auto big = dir.write("big.obj", big_face + "\n");
  std::string err = load_error(big);
  CHECK((err.empty() || err.find("no triangles") != std::string::npos));
  std::string garbage;
  for (int i = 0; i < 100000; i++) garbage += char((i * 7919 + i / 13) % 256);
  CHECK_FALSE(load_error(dir.write("garbage.obj", garbage)).empty());
  CHECK_THAT(load_error(dir.write("exp.obj", "v 1e99999999999999 0 0\n")), Catch::Contains("out of range"));
  // A negative exponent of any size is a number that rounds to 0 (C programs print denormals as 1e-310).
  mesh_data tiny = load_obj(dir.write("tiny.obj", "v 0 0 0\nv 1 1e-310 0\nv 0 1 -1e-99999999999999\nf 1 2 3\n"));
  REQUIRE(triangle_count(tiny) == 1);
  CHECK(corner(tiny, 0, 1).y == 0.0f);
  CHECK(corner(tiny, 0, 2).z == 0.0f);
  // Finite but enormous coordinates: triangles whose area overflows float are dropped as non-finite.
  mesh_data m =
      load_obj(dir.write("huge.obj", "v 0 0 0\nv 3e38 0 0\nv 0 3e38 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 4 5\n"));
  CHECK(triangle_count(m) == 1);
  CHECK(m.dropped_degenerate == 1);
}

namespace {

// Outlines (counter-clockwise, simple) that ear clipping would take quadratic time on, and the small ones the
// sweep's special cases come from: horizontal edges, runs of collinear corners, many corners at one height.
struct outline {
  std::vector<double> x, y;
  void add(double px, double py) { x.push_back(px), y.push_back(py); }
};

// A star of n corners around the origin, radius r(i) at angle 2 pi i / n.
template <class Radius>
outline star(int n, Radius r) {
  outline o;
  for (int i = 0; i < n; i++) {
    double a = 2 * 3.14159265358979323846 * i / n;
    o.add(r(i) * std::cos(a), r(i) * std::sin(a));
  }
  return o;
}

// A comb: `teeth` teeth of height h and width 1, gaps of 1, on a base of height 1 (4 teeth + 2 corners).
outline comb(int teeth, double h, bool down = false) {
  outline o;
  o.add(0, 0), o.add(2 * teeth - 1, 0);
  for (int t = teeth - 1; t >= 0; t--) {
    o.add(2 * t + 1, 1 + h), o.add(2 * t, 1 + h);
    if (t > 0) o.add(2 * t, 1), o.add(2 * t - 1, 1);
  }
  if (down) {  // upside down: mirrored, then reversed to stay counter-clockwise
    for (double& v : o.y) v = -v;
    std::reverse(o.x.begin(), o.x.end()), std::reverse(o.y.begin(), o.y.end());
  }
  return o;
}

// A band zigzagging n times between heights 0 and 1, 0.5 thick (2n + 2 corners).
outline zigzag(int n) {
  outline o;
  for (int i = 0; i <= n; i++) o.add(i, (i % 2) ? 1.0 : 0.0);
  for (int i = n; i >= 0; i--) o.add(i, (i % 2) ? 1.5 : 0.5);
  return o;
}

// A spiral band of `turns` turns (its sides 0.8 apart, the turns 2), n corners per side: out along its outer side,
// back along its inner one.
outline spiral(int turns, int n) {
  outline o;
  for (int pass = 0; pass < 2; pass++)
    for (int k = 0; k < n; k++) {
      int i = pass == 0 ? k : n - 1 - k;
      double a = 2 * 3.14159265358979323846 * turns * i / n, r = (pass == 0 ? 1.8 : 1.0) + 2 * turns * double(i) / n;
      o.add(r * std::cos(a), r * std::sin(a));
    }
  return o;
}

// A k x k square with a notch of depth k/2 in its top side, every integer point of its outline a corner.
outline notched_square(int k) {
  outline o;
  for (int i = 0; i < k; i++) o.add(i, 0);
  for (int i = 0; i < k; i++) o.add(k, i);
  for (int i = k; i > k / 2 + 1; i--) o.add(i, k);
  for (int j = k; j >= k / 2; j--) o.add(k / 2 + 1, j);
  for (int j = k / 2; j <= k; j++) o.add(k / 2, j);
  for (int i = k / 2 - 1; i > 0; i--) o.add(i, k);
  for (int j = k; j > 0; j--) o.add(0, j);
  return o;
}

// A row of `units` keyholes: each a square hole joined to the top of a notch in the outline's bottom by a bridge
// written twice (the bridge goes on from the notch's wall), beside a slot from the top that reaches below the hole's
// top.
outline keyholes(int units) {
  outline o;
  o.add(0, 0);
  for (int k = 0; k < units; k++) {
    double ox = 8.0 * k;
    o.add(ox + 2, 0), o.add(ox + 2, 2), o.add(ox + 4, 2);                    // the notch (x 2 to 4, up to 2)
    o.add(ox + 4, 4), o.add(ox + 2, 4), o.add(ox + 2, 6), o.add(ox + 4, 6);  // bridge up, round the hole
    o.add(ox + 4, 4), o.add(ox + 4, 2), o.add(ox + 4, 0), o.add(ox + 8, 0);  // bridge down, on down the wall
  }
  for (int k = units - 1; k >= 0; k--) {
    double ox = 8.0 * k;
    o.add(ox + 8, 8), o.add(ox + 7, 8), o.add(ox + 7, 5), o.add(ox + 6, 5), o.add(ox + 6, 8);  // the slot
  }
  o.add(0, 8);
  return o;
}

// o turned (0: as it is, 1: mirrored in x, 2: mirrored in y, 3: half a turn), still counter-clockwise, its corner list
// starting at corner `start`.
outline transformed(const outline& o, int how, size_t start) {
  outline t;
  size_t n = o.x.size();
  for (size_t k = 0; k < n; k++) {
    size_t i = (start + k) % n;
    if (how == 1 || how == 2) i = n - 1 - i;  // a mirror image runs the other way round
    t.add(how == 1 || how == 3 ? -o.x[i] : o.x[i], how == 2 || how == 3 ? -o.y[i] : o.y[i]);
  }
  return t;
}

double shoelace(const outline& o) {
  double a = 0;
  for (size_t i = 0; i < o.x.size(); i++) {
    size_t j = (i + 1) % o.x.size();
    a += o.x[i] * o.y[j] - o.x[j] * o.y[i];
  }
  return 0.5 * a;
}

// Checks that tris is a triangulation of o: n-2 triangles, none turned over, their areas adding up to the outline's.
void check_triangulation(const outline& o, const std::vector<int>& tris, double tolerance) {
  size_t n = o.x.size();
  REQUIRE(tris.size() == 3 * (n - 2));
  double sum = 0, worst = 0;
  for (size_t t = 0; t < tris.size(); t += 3) {
    size_t a = size_t(tris[t]), b = size_t(tris[t + 1]), c = size_t(tris[t + 2]);
    REQUIRE((a < n && b < n && c < n));
    double area = 0.5 * ((o.x[b] - o.x[a]) * (o.y[c] - o.y[a]) - (o.y[b] - o.y[a]) * (o.x[c] - o.x[a]));
    worst = std::min(worst, area);
    sum += area;
  }
  double outline_area = shoelace(o);
  CHECK(worst >= -tolerance * outline_area);
  CHECK(std::fabs(sum - outline_area) <= tolerance * outline_area);
}

// Writes an OBJ of one outline (in the plane z = 0) and loads it.
mesh_data load_outline(const temp_dir& dir, const outline& o) {
  std::string text;
  char line[96];
  for (size_t i = 0; i < o.x.size(); i++) {
    std::snprintf(line, sizeof line, "v %.9g %.9g 0\n", o.x[i], o.y[i]);
    text += line;
  }
  text += "f";
  for (size_t i = 0; i < o.x.size(); i++) text += " " + std::to_string(i + 1);
  return load_obj(dir.write("outline.obj", text + "\n"));
}

}  // namespace

TEST_CASE("the monotone sweep triangulates simple polygons exactly", "[obj]") {
  uint64_t state = 12345;
  auto uniform = [&] {  // a fixed-seed LCG in [0, 1)
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return double(state >> 11) / 9007199254740992.0;
  };
  std::vector<std::pair<std::string, outline>> cases = {
      {"triangle", star(3, [](int) { return 1.0; })},
      {"L",
       [] {
         outline o;
         o.add(0, 0), o.add(2, 0), o.add(2, 1), o.add(1, 1), o.add(1, 2), o.add(0, 2);
         return o;
       }()},
      {"comb up", comb(7, 3)},
      {"comb down", comb(7, 3, true)},
      {"zigzag", zigzag(9)},
      {"spiral", spiral(3, 60)},
      {"notched square", notched_square(12)},
      {"alternating star", star(40, [](int i) { return i % 2 ? 0.5 : 1.0; })},
  };
  // Keyholes: a square hole joined to the outline by a bridge written twice (as exporters write holes).
  auto keyhole = [](std::vector<double> x, std::vector<double> y) {
    outline o;
    o.x = x, o.y = y;
    return o;
  };
  cases.push_back(
      {"keyhole, bridge at a corner", keyhole({0, 4, 4, 0, 0, 1, 1, 3, 3, 1}, {0, 0, 4, 4, 0, 1, 3, 3, 1, 1})});
  cases.push_back(
      {"keyhole, slanted bridge", keyhole({0, 4, 4, 0, 0, 1, 1, 3, 3, 1}, {0, 0, 4, 4, 0, 1.5, 3, 3, 1, 1.5})});
  cases.push_back(
      {"keyhole, slot", keyhole({0, 4, 4, 3, 3, 1, 1, 3, 3, 4, 4, 0}, {0, 0, 2, 2, 1, 1, 3, 3, 2, 2, 4, 4})});
  // Corners at one point (the bridges' ends) are ordered by index, so every turn and starting corner: a review found
  // the sweep joining a corner to the other copy of its point (its status took the copy's edge as the one west of it).
  cases.push_back({"keyhole, slot on the bridge", keyhole({0, 3, 3, 4, 4, 2, 2, 2, 2, 1, 1, 2, 2, 1, 1, 0},
                                                          {0, 0, 3, 3, 4, 4, 3, 2, 1, 1, 2, 2, 3, 3, 4, 4})});
  for (int units = 1; units <= 3; units++)
    for (int how = 0; how < 4; how++)
      for (size_t start = 0; start < keyholes(units).x.size(); start++)
        cases.push_back(
            {"keyholes " + std::to_string(units) + " turned " + std::to_string(how) + " from " + std::to_string(start),
             transformed(keyholes(units), how, start)});
  for (int k = 0; k < 200; k++) {
    std::vector<double> r(size_t(4 + k % 50));
    for (double& v : r) v = 0.2 + uniform();
    cases.push_back({"random star " + std::to_string(k), star(int(r.size()), [&](int i) { return r[size_t(i)]; })});
  }
  // Random orthogonal staircase blocks: columns of random integer heights (many corners at one height).
  for (int k = 0; k < 100; k++) {
    outline o;
    int w = 2 + k % 20;
    o.add(0, 0), o.add(w, 0);
    for (int i = w; i > 0; i--) {
      double h = 1 + std::floor(uniform() * 4);
      o.add(i, h), o.add(i - 1, h);
    }
    // Drop corners that repeat the one before (equal neighbouring heights give straight runs, which are kept).
    outline q;
    for (size_t i = 0; i < o.x.size(); i++)
      if (q.x.empty() || q.x.back() != o.x[i] || q.y.back() != o.y[i]) q.add(o.x[i], o.y[i]);
    cases.push_back({"columns " + std::to_string(k), q});
  }
  for (const auto& [name, o] : cases) {
    INFO(name);
    std::vector<int> tris;
    REQUIRE(sweep_triangulate(o.x, o.y, tris));
    check_triangulation(o, tris, 1e-9);
  }
}

TEST_CASE("the monotone sweep refuses polygons that are not simple", "[obj]") {
  auto refuses = [](outline o) {
    std::vector<int> tris = {7};
    bool ok = sweep_triangulate(o.x, o.y, tris);
    CHECK(tris == std::vector<int>{7});  // untouched
    return !ok;
  };
  outline bowtie;
  bowtie.add(0, 0), bowtie.add(2, 2), bowtie.add(2, 0), bowtie.add(0, 2);
  CHECK(refuses(bowtie));
  outline spike;  // a square with a spike out and back along one line
  spike.add(0, 0), spike.add(2, 0), spike.add(2, 1), spike.add(3, 1), spike.add(2, 1), spike.add(2, 2), spike.add(0, 2);
  CHECK(refuses(spike));
  outline clockwise;
  clockwise.add(0, 0), clockwise.add(0, 1), clockwise.add(1, 1), clockwise.add(1, 0);
  CHECK(refuses(clockwise));
  outline two = clockwise;
  two.x.resize(2), two.y.resize(2);
  CHECK(refuses(two));
}

TEST_CASE("concave polygons of many corners load as exact triangulations", "[obj]") {
  // Ear clipping tests every candidate ear against every reflex corner: a star of 10^5 corners spent the file's budget
  // and was fanned into overlapping triangles of ~4800 times its area (with a warning). The sweep takes over there.
  temp_dir dir;
  uint64_t state = 99;
  // (Sizes: well past where the sweep takes over, n x reflex corners > 2^24, and past where ear clipping spent the
  // file's budget for the stars, the comb and the spiral; small enough for the sanitizer build, whose strict string
  // checks make the parsers' number reads cost a scan of the rest of the file.)
  std::vector<double> radius(20000);
  for (double& r : radius) {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    r = 0.2 + double(state >> 11) / 9007199254740992.0;
  }
  std::vector<std::pair<std::string, outline>> shapes = {
      {"alternating star", star(20000, [](int i) { return i % 2 ? 0.5 : 1.0; })},
      {"random star", star(20000, [&](int i) { return radius[size_t(i)]; })},
      {"comb", comb(5000, 10)},
      {"zigzag", zigzag(5000)},
      {"spiral", spiral(10, 10000)},
      {"notched square", notched_square(5000)},
      {"keyholes", keyholes(1000)},
      {"keyholes mirrored in x", transformed(keyholes(1000), 1, 0)},
      {"keyholes mirrored in y", transformed(keyholes(1000), 2, 0)},
      {"keyholes turned half a turn", transformed(keyholes(1000), 3, 0)}};
  for (auto& [name, o] : shapes) {
    INFO(name);
    for (size_t i = 0; i < o.x.size(); i++) o.x[i] = double(float(o.x[i])), o.y[i] = double(float(o.y[i]));
    mesh_data m = load_outline(dir, o);
    // Every triangle wound as the outline and their areas adding up to its area: no overlap, nothing left out
    // (triangles of three collinear corners have no area and are dropped, not as degenerate: the outline has area).
    CHECK(m.dropped_degenerate == 0);
    CHECK(triangle_count(m) + m.dropped_flat == int(o.x.size()) - 2);
    double area = 0;
    int turned = 0;
    for (int t = 0; t < triangle_count(m); t++) {
      vec3f a = area_vector(m, t);
      turned += a.z < 0;
      area += 0.5 * std::fabs(double(a.z));  // (a fan's turned-over triangles would cancel in a signed sum)
    }
    CHECK(turned == 0);
    CHECK(area == Approx(shoelace(o)).epsilon(1e-5));
  }
}

TEST_CASE("the monotone sweep triangulates random simple polygons of grid points", "[obj]") {
  // Random corners on a small integer grid, untangled (2-opt) into simple polygons: runs of collinear corners, many
  // corners at one height and horizontal edges everywhere, the cases the sweep's order has to break ties in.
  uint64_t state = 77;
  auto draw = [&](int m) {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return double((state >> 33) % uint64_t(m));
  };
  auto side = [](const outline& o, size_t p, size_t q, size_t r) {
    double v = (o.x[q] - o.x[p]) * (o.y[r] - o.y[p]) - (o.y[q] - o.y[p]) * (o.x[r] - o.x[p]);
    return v > 0 ? 1 : v < 0 ? -1 : 0;
  };
  auto within = [](const outline& o, size_t p, size_t q, size_t r) {  // r in the box of segment pq
    return std::min(o.x[p], o.x[q]) <= o.x[r] && o.x[r] <= std::max(o.x[p], o.x[q]) &&
           std::min(o.y[p], o.y[q]) <= o.y[r] && o.y[r] <= std::max(o.y[p], o.y[q]);
  };
  auto touch = [&](const outline& o, size_t a, size_t b, size_t c, size_t d) {  // segments ab and cd meet
    int s1 = side(o, a, b, c), s2 = side(o, a, b, d), s3 = side(o, c, d, a), s4 = side(o, c, d, b);
    return (s1 * s2 < 0 && s3 * s4 < 0) || (s1 == 0 && within(o, a, b, c)) || (s2 == 0 && within(o, a, b, d)) ||
           (s3 == 0 && within(o, c, d, a)) || (s4 == 0 && within(o, c, d, b));
  };
  int tested = 0;
  for (int k = 0; k < 3000; k++) {
    size_t n = size_t(4 + draw(24));
    int grid = 3 + int(draw(16));
    outline o;
    for (size_t i = 0; i < n; i++) o.add(draw(grid), draw(grid));
    for (int pass = 0, changed = 1; changed && pass < 500; pass++) {
      changed = 0;
      for (size_t i = 0; i < n && !changed; i++)
        for (size_t j = i + 2; j < n && !changed; j++)
          if (!(i == 0 && j == n - 1) && touch(o, i, i + 1, j, (j + 1) % n)) {
            std::reverse(o.x.begin() + long(i) + 1, o.x.begin() + long(j) + 1);
            std::reverse(o.y.begin() + long(i) + 1, o.y.begin() + long(j) + 1);
            changed = 1;
          }
    }
    // Keep the simple ones: distinct corners, edges that meet only at the corner two neighbours share, no spike.
    bool simple = true;
    for (size_t i = 0; i < n && simple; i++)
      for (size_t j = i + 1; j < n && simple; j++) {
        size_t a = i, b = (i + 1) % n, c = j, d = (j + 1) % n;
        simple = !(o.x[i] == o.x[j] && o.y[i] == o.y[j]);
        if (b == c || d == a) {
          size_t m = b == c ? b : a, p = b == c ? a : c, q = b == c ? d : b;
          simple = simple && !(side(o, p, m, q) == 0 &&
                               (o.x[q] - o.x[m]) * (o.x[p] - o.x[m]) + (o.y[q] - o.y[m]) * (o.y[p] - o.y[m]) > 0);
        } else {
          simple = simple && !touch(o, a, b, c, d);
        }
      }
    double area = shoelace(o);
    if (!simple || area == 0) continue;
    if (area < 0) std::reverse(o.x.begin(), o.x.end()), std::reverse(o.y.begin(), o.y.end());
    INFO("polygon " << k);
    std::vector<int> tris;
    REQUIRE(sweep_triangulate(o.x, o.y, tris));
    check_triangulation(o, tris, 0);  // integer corners: every area exact
    tested++;
  }
  CHECK(tested > 1000);
}

TEST_CASE("dead ends in concave polygons of many corners load as exact triangulations", "[obj]") {
  // A slit cut into the surface or a hair sticking out of it (the outline runs out along a line and straight back)
  // has no area, but the sweep cannot order its two edges along one line: a review's comb with one slit in its base
  // was refused and fanned (25 times its area). The loader sweeps the polygon without its dead ends.
  temp_dir dir;
  outline base = comb(5000, 10);  // corners: (0, 0), (9999, 0), ..., (0, 11)
  outline o;
  auto copy = [&](size_t from, size_t to) {
    for (size_t i = from; i < to; i++) o.add(base.x[i], base.y[i]);
  };
  o.add(0, 0);
  o.add(5000, 0), o.add(5000, 0.5), o.add(5000, 0);                                        // a slit
  o.add(7000, 0), o.add(7000, 0.25), o.add(7000, 0.5), o.add(7000, 0.25), o.add(7000, 0);  // one of three corners
  copy(1, base.x.size());
  o.add(0, 0.5), o.add(-3, 0.5), o.add(0, 0.5);  // a hair out of the left side
  mesh_data m = load_outline(dir, o);
  double area = 0;
  int turned = 0;
  for (int t = 0; t < triangle_count(m); t++) {
    vec3f a = area_vector(m, t);
    turned += a.z < 0;
    area += 0.5 * std::fabs(double(a.z));
  }
  CHECK(turned == 0);
  CHECK(area == Approx(shoelace(base)).epsilon(1e-6));
  CHECK(shoelace(o) == shoelace(base));  // (dead ends add no area)
}

TEST_CASE("corners beyond 1e18 of the origin are refused, naming the vertex", "[obj]") {
  // Two slivers out to +-3e38 passed every per-triangle check; the scene's extent was then infinite and the region
  // grid NaN (a review). Unused far-off vertices stay harmless.
  temp_dir dir;
  auto far = dir.write("far.obj",
                       "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 3e38 0 0\nv 3e38 1e-30 0\nv -3e38 0 0\nv -3e38 0 1e-30\n"
                       "f 1 2 3\nf 1 4 5\nf 1 6 7\n");
  std::string e = load_error(far);
  CHECK_THAT(e, Catch::Contains("far.obj") && Catch::Contains("vertex 4 ") && Catch::Contains("beyond 1e18"));
  auto unused = dir.write("unused.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 3e38 0 0\nf 1 2 3\n");
  CHECK(load_error(unused).empty());
  auto edge = dir.write("edge.obj", "v 1e18 0 0\nv 1e18 1 0\nv 1e18 0 1\nf 1 2 3\n");  // at the limit: kept
  CHECK(load_error(edge).empty());
}

TEST_CASE("map_d takes the channel -imfchan names, an RGB mask's luminance by default", "[obj]") {
  // An RGB mask without alpha was read by its red channel, and -imfchan was ignored: a green mask written with
  // "-imfchan g" cut out its complement (a review). The MTL format's default for scalar textures is luminance.
  temp_dir dir;
  const unsigned char px[9] = {0, 255, 0, 255, 0, 0, 0, 0, 255};  // green, red, blue
  REQUIRE(stbi_write_png((dir.path + "/m.png").c_str(), 3, 1, 3, px, 9) != 0);
  dir.write("lib.mtl", "newmtl plain\nmap_d m.png\nnewmtl green\nmap_d -imfchan g m.png\n"
                       "newmtl depth\nmap_d -imfchan z m.png\nnewmtl upper\nMAP_D -imfchan R m.png\n");
  auto obj = dir.write("t.obj", "mtllib lib.mtl\n" + std::string(square_vertices) + "vt 0 0\n"
                                "usemtl plain\nf 1/1 2/1 3/1\nusemtl green\nf 1/1 3/1 4/1\n"
                                "usemtl depth\nf 1/1 2/1 4/1\nusemtl upper\nf 2/1 3/1 4/1\n");
  mesh_data m;
  std::string warnings = load_warnings(obj, &m);
  REQUIRE(m.textures.size() == 1);
  REQUIRE(m.materials.size() == 4);
  const texture_data& t = m.textures[0];
  CHECK(m.materials[0].alpha_map.channel == 0);
  CHECK(m.materials[1].alpha_map.channel == 'g');
  CHECK(m.materials[2].alpha_map.channel == 0);  // depth has no meaning here: named as not applied
  CHECK(m.materials[3].alpha_map.channel == 'r');
  CHECK(texel_alpha(t, 0) == Approx(0.7152f));  // luminance
  CHECK(texel_alpha(t, 1) == Approx(0.2126f));
  CHECK(texel_alpha(t, 2) == Approx(0.0722f));
  CHECK(texel_alpha(t, 0, 'g') == 1.0f);
  CHECK(texel_alpha(t, 1, 'g') == 0.0f);
  CHECK(texel_alpha(t, 1, 'r') == 1.0f);
  CHECK(texel_alpha(t, 2, 'b') == 1.0f);
  CHECK(texel_alpha(t, 0, 'm') == Approx(0.7152f));  // no alpha channel: luminance
  CHECK(eval_texture_alpha(t, {0.1f, 0.5f}, false, 'g') == 1.0f);
  CHECK(eval_texture_alpha(t, {0.5f, 0.5f}, false, 'g') == 0.0f);
  CHECK_THAT(warnings, Catch::Contains("texture options that are not applied (the texture is used without them): "
                                       "-imfchan (line 6)"));
}

TEST_CASE("texture options that are not applied, and textured faces without vt, are named in a warning", "[obj]") {
  temp_dir dir;
  write_png(dir, "a.png");
  dir.write("lib.mtl", "newmtl a\nmap_Kd -mm 0 1 -t 0 0 0 -blendu on -cc off -bm 2 -boost 1 a.png\n"
                       "newmtl b\nmap_Kd -mm 0.2 0.5 -cc on a.png\nmap_d -blendv off -t 0.1 a.png\n");
  auto obj = dir.write("t.obj", "mtllib lib.mtl\n" + std::string(square_vertices) + "vt 0 0\n"
                                "usemtl a\nf 1/1 2/1 3/1\nusemtl b\nf 1 3 4\nf 1/1 2/1 4\n");
  mesh_data m;
  std::string warnings = load_warnings(obj, &m);
  INFO(warnings);
  CHECK_THAT(warnings, Catch::Contains("lib.mtl: texture options that are not applied (the texture is used without "
                                       "them): -mm (line 4), -cc (line 4), -blendv (line 5), -t (line 5)\n"));
  CHECK_THAT(warnings, Catch::Contains("t.obj: 2 faces of a textured material (the first: line 10, \"b\") have a corner without "
                                       "texture coordinates (vt)"));
  // Defaults written out (as exporters do) and options that change nothing of a 2D texture: no warning.
  auto quiet = dir.write("q.obj", "mtllib lib.mtl\n" + std::string(square_vertices) + "vt 0 0\nusemtl a\nf 1/1 2/1 3/1\n");
  dir.write("lib.mtl", "newmtl a\nmap_Kd -mm 0 1 -t 0 0 0 -blendu on -cc off -bm 2 -boost 1 -texres 8 -type sphere "
                       "-colorspace sRGB a.png\nmap_d -colorspace linear a.png\n");
  CHECK(load_warnings(quiet) == "");
  // A colour space other than the one applied (colour textures sRGB, masks as stored) is named.
  dir.write("lib.mtl", "newmtl a\nmap_Kd -colorspace linear a.png\n");
  CHECK_THAT(load_warnings(quiet), Catch::Contains("not applied (the texture is used without them): -colorspace (line 2)"));
}

TEST_CASE("a concave polygon's corners on one line are each a corner of a triangle with area", "[obj]") {
  // Ear clipping must not cut a corner that lies on the line of its neighbours as a zero-area "ear": the corner would
  // then belong to no triangle with area, a T-junction on the edge a neighbouring face shares (a crack between the
  // faces where rounding differs). An L and two Us, with corners in the middle of edges, from every first corner
  // and in both windings (a mutation of the ear test from > 0 to >= 0 passed every other test).
  const std::vector<std::vector<vec3f>> shapes = {
      {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {2, 1, 0}, {1, 1, 0}, {1, 2, 0}, {0, 2, 0}, {0, 1, 0}},
      {{0, 0, 0}, {1.5f, 0, 0}, {3, 0, 0}, {3, 2, 0}, {2, 2, 0}, {2, 1, 0}, {1, 1, 0}, {1, 2, 0}, {0, 2, 0},
       {0, 1, 0}},
      // A deep U: the first corner clipping tries, (0, 0), holds the notch's corner (1, 0.5) in its ear, so clipping
      // moves on to (0, 1), still on the line of both its neighbours.
      {{0, 0, 0}, {3, 0, 0}, {3, 2, 0}, {2, 2, 0}, {2, 0.5f, 0}, {1, 0.5f, 0}, {1, 2, 0}, {0, 2, 0}, {0, 1, 0}}};
  for (size_t s = 0; s < shapes.size(); s++)
    for (bool reversed : {false, true})
      for (size_t first = 0; first < shapes[s].size(); first++) {
        std::vector<vec3f> p;
        const size_t n = shapes[s].size();
        for (size_t k = 0; k < n; k++) {
          size_t i = (first + (reversed ? n - k : k)) % n;
          p.push_back(shapes[s][i]);
        }
        triangulate_state st;
        std::vector<int> tris;
        triangulate_polygon(p, st, tris);
        std::vector<int> used(n, 0);
        for (size_t t = 0; t + 2 < tris.size(); t += 3) {
          vec3f a = p[size_t(tris[t])], b = p[size_t(tris[t + 1])], c = p[size_t(tris[t + 2])];
          if (length(cross(b - a, c - a)) == 0) continue;
          for (int k = 0; k < 3; k++) used[size_t(tris[t + size_t(k)])]++;
        }
        for (size_t k = 0; k < n; k++) {
          INFO("shape " << s << " reversed " << reversed << " first " << first << " corner " << k);
          CHECK(used[k] > 0);
        }
      }
}
