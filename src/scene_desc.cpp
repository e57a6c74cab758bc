// scene_desc: JSON scene files (nlohmann::json, comments allowed) validated key by key.
#include "scene_desc.h"

#include "errors.h"
#include "file_io.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <sstream>
#include <string>
#include <unordered_set>
#include <vector>

namespace bl {

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

// A message part of at most 200 characters (a 1 MB number literal was echoed whole).
std::string shorten(const std::string& s) { return s.size() <= 200 ? s : s.substr(0, 200) + "..."; }

// The text of the scene file and helpers to raise errors pointing into it.
struct desc_context {
  std::string path;
  std::string text;

  // Offset of the first quoted string equal to "key" at or after `from` that is not inside a // or /* */ comment
  // (a commented-out old value must not take the line), or npos.
  size_t find_quoted(const std::string& key, size_t from = 0) const {
    const std::string quoted = "\"" + key + "\"";
    size_t i = 0, n = text.size();
    while (i < n) {
      if (text[i] == '/' && i + 1 < n && text[i + 1] == '/') {
        i = text.find('\n', i);
        if (i == std::string::npos) return i;
      } else if (text[i] == '/' && i + 1 < n && text[i + 1] == '*') {
        i = text.find("*/", i + 2);
        if (i == std::string::npos) return i;
        i += 2;
      } else if (text[i] == '"') {
        size_t j = i + 1;
        while (j < n && text[j] != '"') j += text[j] == '\\' ? 2 : 1;
        if (i >= from && text.compare(i, quoted.size(), quoted) == 0 && j == i + quoted.size() - 1) return i;
        i = j + 1;
      } else {
        i++;
      }
    }
    return std::string::npos;
  }
  // 1-based line of an offset into the text (0 for npos).
  int line_at(size_t at) const {
    if (at == std::string::npos || at > text.size()) return 0;
    return 1 + int(std::count(text.begin(), text.begin() + long(at), '\n'));
  }
  // 1-based line of the first occurrence of "key" in the file outside comments (0 when not found).
  int line_of(const std::string& key) const { return line_at(find_quoted(key)); }
  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw input_error(path, line_of(key), what);
  }
};

// Rejects keys of `obj` that are not in `allowed` (typos must not silently change a render).
void check_keys(const desc_context& ctx, const json& obj, const std::string& where,
                std::initializer_list<const char*> allowed) {
  if (!obj.is_object()) ctx.fail(where, "\"" + where + "\" must be an object");
  for (auto it = obj.begin(); it != obj.end(); ++it) {
    bool ok = false;
    for (const char* a : allowed) ok = ok || it.key() == a;
    if (!ok) {
      std::string list;
      for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
      ctx.fail(it.key(), "unknown key \"" + it.key() + "\" in " + where + " (allowed: " + list + ")");
    }
  }
}

// Whether an object gives a key a value: a key written as null is left out (its default), as JSON writers emit null
// for a value not set ("sun": null is no sun). Unknown keys are refused whatever their value (check_keys).
bool given(const json& obj, const char* key) { return obj.contains(key) && !obj[key].is_null(); }

// A finite number, in double.
double get_double(const desc_context& ctx, const json& v, const std::string& key) {
  if (!v.is_number()) ctx.fail(key, "\"" + key + "\" must be a number");
  double d = v.get<double>();
  if (!std::isfinite(d) || std::fabs(d) > 1e30)
    ctx.fail(key, "\"" + key + "\" must be a finite number of magnitude at most 1e30");
  return d;
}
float get_number(const desc_context& ctx, const json& v, const std::string& key) {
  return float(get_double(ctx, v, key));
}

// Whether v is a float-written whole number (64.0, 1e3: what many JSON writers emit for an integer) of magnitude
// below `limit`; its value in out.
bool whole_float(const json& v, double limit, double& out) {
  if (!v.is_number_float()) return false;
  out = v.get<double>();
  return std::floor(out) == out && std::fabs(out) < limit;
}

// An integer in [lo, hi].
int64_t get_integer(const desc_context& ctx, const json& v, const std::string& key, int64_t lo, int64_t hi) {
  int64_t i;
  double d;
  if (v.is_number_float()) {
    if (!(std::floor(v.get<double>()) == v.get<double>())) ctx.fail(key, "\"" + key + "\" must be an integer");
    if (!whole_float(v, 9007199254740994.0, d)) ctx.fail(key, "\"" + key + "\" is out of range");  // up to 2^53
    i = int64_t(d);
  } else {
    if (!v.is_number_integer()) ctx.fail(key, "\"" + key + "\" must be an integer");
    if (v.is_number_unsigned() && v.get<uint64_t>() > uint64_t(std::numeric_limits<int64_t>::max()))
      ctx.fail(key, "\"" + key + "\" is out of range");
    i = v.get<int64_t>();
  }
  if (i < lo || i > hi)
    ctx.fail(key, "\"" + key + "\" must be between " + std::to_string(lo) + " and " + std::to_string(hi) +
                      " (got " + std::to_string(i) + ")");
  return i;
}

// What a JSON value is, for messages: "a string", "an array", "null".
std::string kind_of(const json& v) {
  if (v.is_null()) return "null";
  const std::string t = v.type_name();
  return (t[0] == 'a' || t[0] == 'o' ? "an " : "a ") + t;
}

// An array of three finite numbers.
vec3f get_vec3(const desc_context& ctx, const json& v, const std::string& key) {
  if (!v.is_array() || v.size() != 3) ctx.fail(key, "\"" + key + "\" must be an array of 3 numbers");
  for (int i = 0; i < 3; i++)  // (which one is not: ["1", 1, 5] said only that "eye" must be a number)
    if (!v[size_t(i)].is_number())
      ctx.fail(key, "\"" + key + "\" must be an array of 3 numbers; its element " + std::to_string(i + 1) + " is " +
                        kind_of(v[size_t(i)]));
  return {get_number(ctx, v[0], key), get_number(ctx, v[1], key), get_number(ctx, v[2], key)};
}

// A direction: three finite numbers, as float; where float cannot normalise them (1e-300s underflow to zero and were
// called a zero vector, a review), normalised in double first. {0, 0, 0} when all are zero. (Vectors float can
// normalise are kept as written: their renders and checkpoints stay those of earlier versions.)
vec3f get_direction(const desc_context& ctx, const json& v, const std::string& key) {
  if (!v.is_array() || v.size() != 3) ctx.fail(key, "\"" + key + "\" must be an array of 3 numbers");
  double x = get_double(ctx, v[0], key), y = get_double(ctx, v[1], key), z = get_double(ctx, v[2], key);
  vec3f f = {float(x), float(y), float(z)};
  if (length(normalize(f)) > 0) return f;
  double m = std::max({std::fabs(x), std::fabs(y), std::fabs(z)});
  if (!(m > 0)) return {0, 0, 0};
  x /= m, y /= m, z /= m;  // (scaled first: squares of 1e-300 underflow in double too)
  double len = std::sqrt(x * x + y * y + z * z);
  return {float(x / len), float(y / len), float(z / len)};
}

void parse_camera(const desc_context& ctx, const json& j, camera_params& cam) {
  check_keys(ctx, j, "camera", {"eye", "target", "up", "fov_y_deg"});
  bool has_eye = given(j, "eye"), has_target = given(j, "target");
  cam.automatic = !has_eye && !has_target;
  cam.frame_eye = has_target && !has_eye;
  cam.frame_target = has_eye && !has_target;
  if (has_eye) cam.eye = get_vec3(ctx, j["eye"], "eye");
  if (has_target) cam.target = get_vec3(ctx, j["target"], "target");
  cam.camera_line = ctx.line_of("camera");
  cam.eye_line = has_eye ? ctx.line_of("eye") : 0;
  cam.target_line = has_target ? ctx.line_of("target") : 0;
  cam.up_given = given(j, "up");
  cam.up_line = cam.up_given ? ctx.line_of("up") : 0;
  // Embree refuses ray origins beyond about 1.8e18 (a camera framed from a target-only key sits near its target);
  // no mesh that keeps a triangle reaches 1e17 (float spacing there exceeds any triangle whose area is finite).
  auto within_range = [&](bool given, vec3f v, const std::string& key) {
    if (given && !(max_abs_component(v) <= 1e17f))
      ctx.fail(key, "camera \"" + key + "\" must lie within 1e17 of the origin in every coordinate");
  };
  within_range(has_eye, cam.eye, "eye");
  within_range(has_target, cam.target, "target");
  if (given(j, "up")) cam.up = get_direction(ctx, j["up"], "up");
  if (given(j, "fov_y_deg")) {
    // Checked in double, then kept inside the interval in float (178.999999 rounded to 179, 1e-300 to 0; a review).
    double fov = get_double(ctx, j["fov_y_deg"], "fov_y_deg");
    if (!(fov > 0 && fov < 179)) ctx.fail("fov_y_deg", "\"fov_y_deg\" must be in (0, 179) degrees");
    cam.fov_y_deg = std::min(std::max(float(fov), std::numeric_limits<float>::denorm_min()), std::nextafter(179.0f, 0.0f));
  }
  vec3f dir = cam.target - cam.eye;
  bool both = has_eye && has_target;  // otherwise checked once the mesh bounds are known (scene.cpp)
  if (both && !(length(normalize(dir)) > 0)) ctx.fail("target", "camera \"eye\" and \"target\" must differ");
  if (!(length(normalize(cam.up)) > 0)) ctx.fail("up", "camera \"up\" must be a non-zero vector");
  if (both && cam.up_given && !(length(cross(normalize(dir), normalize(cam.up))) > 1e-6f))
    ctx.fail("up", "camera \"up\" must not be parallel to the viewing direction");
  // (A view along the default up is given another up once the camera is complete: build_scene.)
}

void parse_sun(const desc_context& ctx, const json& j, sun_params& sun) {
  check_keys(ctx, j, "sun", {"direction", "irradiance", "angular_diameter_deg", "direction_end"});
  if (!given(j, "direction") || !given(j, "irradiance"))
    ctx.fail("sun", "\"sun\" needs \"direction\" and \"irradiance\"");
  sun.enabled = true;
  vec3f d = get_direction(ctx, j["direction"], "direction");
  if (!(length(normalize(d)) > 0)) ctx.fail("direction", "sun \"direction\" must be a non-zero vector");
  sun.direction = normalize(d);
  if (given(j, "direction_end")) {
    vec3f e = get_direction(ctx, j["direction_end"], "direction_end");
    if (!(length(normalize(e)) > 0)) ctx.fail("direction_end", "sun \"direction_end\" must be a non-zero vector");
    sun.direction_end = normalize(e);
    sun.animated = true;
  }
  sun.irradiance = get_vec3(ctx, j["irradiance"], "irradiance");
  if (sun.irradiance.x < 0 || sun.irradiance.y < 0 || sun.irradiance.z < 0)
    ctx.fail("irradiance", "sun \"irradiance\" must not be negative");
  if (given(j, "angular_diameter_deg")) {
    // Checked in double, then kept above zero in float (1e-50 had become 0 and was refused as outside the interval;
    // sun_one_minus_cos takes any disk below a micro-radian as one).
    // (180: a half-angle of 90 degrees, the whole sky on the sun's side; a wider disk would reach below the horizon of
    // a surface facing it, which its irradiance could not then describe.)
    double deg = get_double(ctx, j["angular_diameter_deg"], "angular_diameter_deg");
    if (!(deg > 0 && deg <= 180))
      ctx.fail("angular_diameter_deg", "sun \"angular_diameter_deg\" must be in (0, 180]");
    sun.angular_diameter_deg = std::max(float(deg), std::numeric_limits<float>::denorm_min());
  }
  // The disk's radiance (irradiance over its projected solid angle) must stay far inside float's range.
  double omc = sun_one_minus_cos(sun.angular_diameter_deg);
  double radiance = double(max_component(sun.irradiance)) / (M_PI * omc * (2 - omc));
  if (!(radiance <= 1e35)) {
    char buf[128];
    std::snprintf(buf, sizeof buf, "sun \"irradiance\" over a disk of %g degrees is a radiance of %.3g, above 1e35",
                  double(sun.angular_diameter_deg), radiance);
    ctx.fail("irradiance", std::string(buf) + ": lower the irradiance or widen the disk");
  }
}


}  // namespace

// Largest image side a scene may ask for (the CLI applies the same limit; the pixel count is checked in cli.cpp).
constexpr int64_t max_image_side = 65536;

scene_desc load_scene_desc(const std::string& path) {
  scene_desc desc;
  desc.path = path;
  std::string ext = lower_extension(path);
  // (An empty argument, `render ""`: said ": unknown scene type" with no name before it.)
  if (path.empty()) throw input_error("(an empty scene path)", "give a .json scene file or a .obj mesh");
  if (ext != ".json" && ext != ".obj")
    throw input_error(path, "unknown scene type \"" + ext + "\" (expected a .json scene file or a .obj mesh)");
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw input_error(path, "is a directory, not a scene file");
  require_regular_file(path);  // a FIFO would block the read, a device might never end
  if (ext == ".obj") {
    desc.mesh_path = path;
    return desc;
  }
  desc_context ctx{path, read_file(path)};

  json root;
  // Keys given twice in one object: nlohmann keeps the last silently, which would drop the first's settings.
  std::vector<std::unordered_set<std::string>> open_objects;  // (a set: a file of 10^5 keys took seconds)
  std::string duplicate;
  auto on_event = [&](int, json::parse_event_t event, json& parsed) {
    if (event == json::parse_event_t::object_start) open_objects.emplace_back();
    else if (event == json::parse_event_t::object_end && !open_objects.empty()) open_objects.pop_back();
    else if (event == json::parse_event_t::key && !open_objects.empty() && duplicate.empty()) {
      const std::string& k = parsed.get_ref<const std::string&>();
      if (!open_objects.back().insert(k).second) duplicate = k;
    }
    return true;
  };
  try {
    root = json::parse(ctx.text, on_event, true, /*ignore_comments=*/true);
  } catch (const json::parse_error& e) {
    // e.byte is the 1-based offset of the offending byte; turn it into a line number.
    size_t at = std::min<size_t>(e.byte > 0 ? e.byte - 1 : 0, ctx.text.size());
    int line = 1 + int(std::count(ctx.text.begin(), ctx.text.begin() + long(at), '\n'));
    std::string msg = e.what();
    size_t cut = msg.find("syntax error");
    throw input_error(path, line, "malformed JSON: " + shorten(cut == std::string::npos ? msg : msg.substr(cut)));
  } catch (const json::exception& e) {
    // The parser's other error: out_of_range.406 for a number literal beyond double range ("1e400"). It has no
    // byte offset; the line is that of the literal quoted in the message, when the file holds it verbatim.
    std::string msg = e.what();
    size_t open = msg.find('\''), close = msg.rfind('\'');
    size_t at = open != std::string::npos && close > open + 1 ? ctx.text.find(msg.substr(open + 1, close - open - 1))
                                                              : std::string::npos;
    int line = at == std::string::npos ? 0 : 1 + int(std::count(ctx.text.begin(), ctx.text.begin() + long(at), '\n'));
    size_t tag_end = msg.find("] ");
    throw input_error(path, line,
                      "malformed JSON: " + shorten(tag_end == std::string::npos ? msg : msg.substr(tag_end + 2)));
  }
  if (!duplicate.empty()) {
    // The line of its second appearance as a quoted string (the best a callback without offsets can tell).
    size_t first = ctx.find_quoted(duplicate);
    size_t second = first == std::string::npos ? first : ctx.find_quoted(duplicate, first + 1);
    throw input_error(path, ctx.line_at(second), "key \"" + shorten(duplicate) + "\" is given twice in one object");
  }
  // (A whole file that is not an object: its value's line, which a key search cannot find.)
  if (!root.is_object())
    throw input_error(path, ctx.line_at(ctx.text.find_first_not_of(" \t\r\n")),
                      "the scene file must be a JSON object ({\"mesh\": ...}), not " + kind_of(root));
  check_keys(ctx, root, "the scene file", {"mesh", "camera", "image", "render", "sun", "two_sided_emitters"});
  if (!root.contains("mesh")) throw input_error(path, "missing required key \"mesh\"");
  if (!root["mesh"].is_string() || root["mesh"].get<std::string>().empty())
    ctx.fail("mesh", "\"mesh\" must be a non-empty string (a path to an .obj file)");
  if (root["mesh"].get<std::string>().find('\0') != std::string::npos)
    ctx.fail("mesh", "\"mesh\" must not contain a NUL character (\\u0000)");
  fs::path mesh = root["mesh"].get<std::string>();
  desc.mesh_path = mesh.is_absolute() ? mesh.string() : (fs::path(path).parent_path() / mesh).string();

  if (given(root, "camera")) parse_camera(ctx, root["camera"], desc.camera);
  if (given(root, "image")) {
    const json& im = root["image"];
    check_keys(ctx, im, "image", {"width", "height"});
    // Each side at most 65536; the pixel count (at most 2^28) is checked once --width and --height have had their say.
    if (given(im, "width")) desc.width = int(get_integer(ctx, im["width"], "width", 1, max_image_side));
    if (given(im, "height")) desc.height = int(get_integer(ctx, im["height"], "height", 1, max_image_side));
  }
  if (given(root, "render")) {
    const json& r = root["render"];
    check_keys(ctx, r, "render", {"spp", "max_depth", "seed"});
    if (given(r, "spp")) desc.spp = int(get_integer(ctx, r["spp"], "spp", 1, std::numeric_limits<int>::max()));
    if (given(r, "max_depth")) desc.max_depth = int(get_integer(ctx, r["max_depth"], "max_depth", 1, 1000));
    if (given(r, "seed")) {
      const json& s = r["seed"];
      double d;
      if (whole_float(s, 18446744073709551616.0, d) && d >= 0) {
        desc.seed = uint64_t(d);  // a whole number written as 7.0 (as other integers)
      } else {
        if (!s.is_number_unsigned())
          ctx.fail("seed", "\"seed\" must be an integer from 0 to 18446744073709551615");
        desc.seed = s.get<uint64_t>();
      }
    }
  }
  if (given(root, "sun")) parse_sun(ctx, root["sun"], desc.sun);
  if (given(root, "two_sided_emitters")) {
    if (!root["two_sided_emitters"].is_boolean())
      ctx.fail("two_sided_emitters", "\"two_sided_emitters\" must be true or false");
    desc.two_sided_emitters = root["two_sided_emitters"].get<bool>();
  }
  return desc;
}

vec3f animated_sun_direction(const sun_params& sun, int frame, int frames) {
  if (!sun.animated || frames <= 1 || frame == 0) return sun.direction;
  if (frame == frames - 1) return sun.direction_end;  // exactly, as a scene with that direction has it
  float t = float(frame) / float(frames - 1);
  vec3f a = sun.direction, b = sun.direction_end;
  float cos_ab = clampf(dot(a, b), -1.0f, 1.0f);
  float angle = std::acos(cos_ab);
  vec3f d;
  if (angle < 1e-6f) {
    d = a * (1 - t) + b * t;
  } else {
    // Spherical interpolation. Opposite directions have no one great circle between them: the sun passes over the
    // zenith, +y (a sunrise [1, 0, 0] to a sunset [-1, 0, 0] went round the horizon, a dark animation: a review),
    // or where a is +-y itself, through +x.
    vec3f perp = b - a * cos_ab;
    if (!(length(perp) > 1e-6f)) {
      perp = vec3f{0, 1, 0} - a * a.y;
      if (!(length(perp) > 1e-3f)) perp = vec3f{1, 0, 0} - a * a.x;
    }
    perp = normalize(perp);
    d = a * std::cos(t * angle) + perp * std::sin(t * angle);
  }
  return normalize(d);
}

float sun_one_minus_cos(float angular_diameter_deg) {
  constexpr float min_half_angle = 1e-6f;
  float half = std::max(0.5f * angular_diameter_deg * pi_f / 180.0f, min_half_angle);
  float s = std::sin(0.5f * half);
  return 2 * s * s;  // 1 - cos(half) without cancellation
}

camera_params frame_bounds(const bbox3f& bounds, float fov_y_deg, float aspect) {
  camera_params cam;
  cam.automatic = true;
  cam.fov_y_deg = fov_y_deg;
  vec3f c = center(bounds);
  float radius = 0.5f * diagonal(bounds);
  if (!(radius > 0)) radius = 1;
  // The bounding sphere fits inside the narrower of the two fields of view.
  float half_y = 0.5f * fov_y_deg * pi_f / 180.0f;
  float half_x = std::atan(std::tan(half_y) * aspect);
  float dist = radius / std::sin(std::min(half_y, half_x));
  cam.target = c;
  cam.eye = c + vec3f{0, 0, dist};
  cam.up = {0, 1, 0};
  return cam;
}

}  // namespace bl
