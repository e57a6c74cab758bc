// fuzz_entry: the entry points shared by the libFuzzer targets (fuzz/fuzz_*.cpp) and the corpus replay test
// (tests/fuzz_corpus_test.cpp). Each writes the input bytes to files in a private scratch folder and calls one
// parser exactly as the renderer does (by path), so fuzzing needs no change to the parsers.
// Contract under test: every input ends in a result or a bl::input_error; anything else (another exception, a
// crash, a sanitizer report) is a bug. Input layouts: see each feed_* function.
#pragma once

#include "errors.h"
#include "image_io.h"
#include "obj_io.h"
#include "scene_desc.h"
#include "texture.h"

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>

namespace bl::fuzz {

// The parsers that can be fuzzed, in the order of their corpus folders.
enum class target { scene, obj, texture, image };
constexpr target all_targets[] = {target::scene, target::obj, target::texture, target::image};

// Name of t: its corpus folder fuzz/corpus/<name> and its binary fuzz_<name>.
inline const char* target_name(target t) {
  switch (t) {
    case target::scene: return "scene";
    case target::obj: return "obj";
    case target::texture: return "texture";
    case target::image: return "image";
  }
  return "?";
}

// A fresh folder (in /dev/shm when it is writable: no disk I/O per input), removed on destruction. It holds
// the input files and a valid 2x2 PNG "tex.png" that fuzzed MTL files may name (map_Kd tex.png).
struct scratch_dir {
  std::string path;
  scratch_dir() {
    for (const char* base : {"/dev/shm", "/tmp"}) {
      std::string tmpl = std::string(base) + "/bayeslight_fuzz_XXXXXX";
      if (::mkdtemp(tmpl.data())) {
        path = tmpl;
        break;
      }
    }
    if (path.empty()) std::abort();  // no temporary folder at all: nothing can be tested
    image_data tex;
    tex.width = tex.height = 2;
    tex.pixels = {0.1f, 0.2f, 0.3f, 1, 0, 0, 0, 1, 0, 0.5f, 0.5f, 0.5f};
    write_image(file("tex.png"), tex);
  }
  ~scratch_dir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  scratch_dir(const scratch_dir&) = delete;
  scratch_dir& operator=(const scratch_dir&) = delete;
  std::string file(const std::string& name) const { return path + "/" + name; }
};

// Replaces the file at path with n bytes (plain stdio: the code under test is not used to set up its input).
inline void write_bytes(const std::string& path, const void* data, size_t n) {
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) std::abort();
  if (n > 0 && std::fwrite(data, 1, n, f) != n) std::abort();
  if (std::fclose(f) != 0) std::abort();
}

// Scene file: the bytes are scene.json, parsed by load_scene_desc (the mesh it names is not loaded).
inline void feed_scene(const scratch_dir& dir, const uint8_t* data, size_t size) {
  std::string path = dir.file("scene.json");
  write_bytes(path, data, size);
  scene_desc desc = load_scene_desc(path);
  (void)desc;
}

// The line that separates the OBJ from its MTL in an obj input.
constexpr std::string_view mtl_separator = "\n#=mtl\n";

// OBJ + MTL: the bytes before the first line "#=mtl" are m.obj, those after it m.mtl (an empty file when there
// is no such line); both go through load_obj (which reads m.mtl only when the OBJ says `mtllib m.mtl`). Inputs
// that mention /proc or /sys are skipped: an mtllib or map_Kd line naming e.g. /proc/kcore would only measure
// the machine's memory, not the parser.
inline void feed_obj(const scratch_dir& dir, const uint8_t* data, size_t size) {
  std::string_view bytes(reinterpret_cast<const char*>(data), size);
  if (bytes.find("/proc") != std::string_view::npos || bytes.find("/sys") != std::string_view::npos) return;
  size_t cut = bytes.find(mtl_separator);
  std::string_view obj = bytes.substr(0, cut);
  std::string_view mtl = cut == std::string_view::npos ? std::string_view() : bytes.substr(cut + mtl_separator.size());
  write_bytes(dir.file("m.obj"), obj.data(), obj.size());
  write_bytes(dir.file("m.mtl"), mtl.data(), mtl.size());
  mesh_data mesh = load_obj(dir.file("m.obj"));
  (void)mesh;
}

// Texture: the bytes are t.tga, decoded by load_texture. PNG, JPEG and BMP are recognised by their magic bytes
// whatever the name; the .tga name is the only way in for TGA (it has no magic), so every decoder is reachable.
inline void feed_texture(const scratch_dir& dir, const uint8_t* data, size_t size) {
  std::string path = dir.file("t.tga");
  write_bytes(path, data, size);
  texture_data tex = load_texture(path);
  (void)tex;
}

// EXR / PFM reader: the bytes are i.pfm when they start with 'P' (every PFM does), else i.exr; read by
// read_image (the --reference and diff reader).
inline void feed_image(const scratch_dir& dir, const uint8_t* data, size_t size) {
  std::string path = dir.file(size > 0 && data[0] == 'P' ? "i.pfm" : "i.exr");
  write_bytes(path, data, size);
  image_data img = read_image(path);
  (void)img;
}

// Feeds one input to target t; throws what the parser throws.
inline void feed(target t, const scratch_dir& dir, const uint8_t* data, size_t size) {
  switch (t) {
    case target::scene: return feed_scene(dir, data, size);
    case target::obj: return feed_obj(dir, data, size);
    case target::texture: return feed_texture(dir, data, size);
    case target::image: return feed_image(dir, data, size);
  }
}

}  // namespace bl::fuzz
