// obj_validate: reads OBJ and MTL text line by line, accepting tinyobjloader's number grammar and index forms (the
// loader once parsed with it; the files it took load as they did) and naming file and line on every rejection.
// Invariants: lines end at \n, \r\n or a lone \r (a statement ending in a backslash continues on the next); a
// token starting with '#' starts a comment (in material and texture names only a lone '#': "Material #1" is a
// name); tokens are split at spaces, tabs, \v and \f; numbers are finite floats of at most max_number_chars
// characters and decimal exponent at most 300 (any negative one: 1e-310 is 0); every index refers to an element
// defined earlier in the file.
#include "obj_validate.h"

#include "errors.h"
#include "file_io.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <set>
#include <string_view>

namespace bl {

namespace fs = std::filesystem;
using std::string_view;

// Where a statement is, for error messages.
struct text_pos {
  const std::string& file;
  size_t line;
};

// Throws input_error at pos (lines beyond INT_MAX are reported as INT_MAX).
[[noreturn]] static void fail(const text_pos& pos, const std::string& msg) {
  throw input_error(pos.file, int(std::min<size_t>(pos.line, INT_MAX)), msg);
}

// A token quoted for a message: at most 40 characters, non-printable bytes shown as '?'.
static std::string quote(string_view t) {
  std::string q = "'";
  for (size_t i = 0; i < t.size() && i < 40; i++) q += (t[i] >= 32 && t[i] < 127) ? t[i] : '?';
  return q + (t.size() > 40 ? "...'" : "'");
}

// t with ASCII letters in lower case.
static std::string ascii_lower(string_view t) {
  std::string out(t);
  for (char& c : out) c = char(std::tolower((unsigned char)c));
  return out;
}

// Each kind of warning about materials names its first few cases; the rest are counted in one line (a generated file
// may hold 100k of them).
constexpr int named_warnings = 3;

std::string read_text_file(const std::string& path, const char* what) {
  std::error_code ec;
  auto status = fs::status(path, ec);
  if (ec || !fs::exists(status)) throw input_error(path, std::string("cannot open ") + what + ": no such file");
  // Regular files only: a FIFO would block the read forever, a directory or device is not a scene file.
  if (!fs::is_regular_file(status))
    throw input_error(path, std::string("cannot open ") + what + ": not a regular file");
  return read_file(path);
}

// Splits text into lines (\n, \r\n or lone \r), skipping a UTF-8 byte-order mark. A statement line ending in a
// backslash continues on the next line (the OBJ format's continuation; not a comment line, whose text may end in a
// Windows path). `line` is the first line of the statement, for messages.
struct line_reader {
  const std::string& text;
  size_t pos = 0;
  size_t line = 0;      // first physical line of the statement last returned
  size_t physical = 0;  // physical lines read
  std::string joined;   // a continued statement's text
  explicit line_reader(const std::string& t) : text(t) {
    if (text.compare(0, 3, "\xEF\xBB\xBF") == 0) pos = 3;
  }
  bool next_physical(string_view& out) {
    if (pos >= text.size()) return false;
    size_t end = pos;  // (a plain loop: find_first_of searches its set once per character)
    while (end < text.size() && text[end] != '\n' && text[end] != '\r') end++;
    out = string_view(text).substr(pos, end - pos);
    pos = end + ((end + 1 < text.size() && text[end] == '\r' && text[end + 1] == '\n') ? 2 : 1);
    physical++;
    return true;
  }
  // The line without trailing blanks ends in a backslash that is not inside a comment (a token starting with '#'
  // starts one, as in tokenize: "f 1 2 3 # from C:\\scans\\" does not continue).
  static bool continues(string_view l) {
    size_t e = l.find_last_not_of(" \t\v\f");
    if (e == string_view::npos || l[e] != '\\') return false;
    for (size_t i = 0; i < e; i++)
      if (l[i] == '#' && (i == 0 || l[i - 1] == ' ' || l[i - 1] == '\t' || l[i - 1] == '\v' || l[i - 1] == '\f'))
        return false;
    return true;
  }
  bool next(string_view& out) {
    if (!next_physical(out)) return false;
    line = physical;
    if (!continues(out)) return true;
    joined.clear();
    string_view more = out;
    while (continues(more)) {
      joined.append(more.substr(0, more.find_last_not_of(" \t\v\f"))) += ' ';
      if (!next_physical(more)) {
        more = {};
        break;
      }
    }
    joined.append(more);
    out = joined;
    return true;
  }
};

// Splits a line into tokens, dropping a trailing comment (from a token that starts with '#'); rejects NUL bytes.
// Returns whether a comment was dropped. With in_name (the arguments of newmtl, usemtl and texture statements) only
// a lone '#' starts the comment: "Material #1" (3ds Max's default names, kept by exporters) is one name.
static bool tokenize(string_view line, const text_pos& pos, std::vector<string_view>& tokens, bool in_name = false) {
  tokens.clear();
  if (line.find('\0') != string_view::npos) fail(pos, "NUL byte in text (binary file?)");
  size_t i = 0, n = line.size();
  auto is_sep = [](char c) { return c == ' ' || c == '\t' || c == '\v' || c == '\f'; };
  while (i < n) {
    while (i < n && is_sep(line[i])) i++;
    if (i == n) return false;
    if (line[i] == '#' && (!in_name || tokens.empty() || i + 1 == n || is_sep(line[i + 1]))) return true;
    size_t b = i;
    while (i < n && !is_sep(line[i])) i++;
    tokens.push_back(line.substr(b, i - b));
  }
  return false;
}

// The text of tokens [first, end) as written, blanks between them included (names and file names that contain
// spaces: "my  tex.png" keeps both); tokens are views into one line, so this is one span of it.
static std::string join_from(const std::vector<string_view>& t, size_t first) {
  if (first >= t.size()) return {};
  const char* b = t[first].data();
  const char* e = t.back().data() + t.back().size();
  return std::string(b, size_t(e - b));
}

// True when t follows tinyobjloader's number grammar in full: [sign] (digits [. digits] | . digits)
// [(e|E) [sign] digits]; exponent_too_big when the decimal exponent is above 300 (a negative one of any size is
// fine: the value rounds to a denormal or 0).
static bool number_grammar(string_view t, bool& exponent_too_big) {
  size_t i = 0, n = t.size();
  exponent_too_big = false;
  if (i < n && (t[i] == '+' || t[i] == '-')) i++;
  size_t digits = 0;
  while (i < n && t[i] >= '0' && t[i] <= '9') i++, digits++;
  if (i < n && t[i] == '.') {
    i++;
    while (i < n && t[i] >= '0' && t[i] <= '9') i++, digits++;
  }
  if (digits == 0) return false;
  if (i < n && (t[i] == 'e' || t[i] == 'E')) {
    i++;
    bool negative = i < n && t[i] == '-';
    if (i < n && (t[i] == '+' || t[i] == '-')) i++;
    size_t exp_digits = 0;
    long exponent = 0;
    while (i < n && t[i] >= '0' && t[i] <= '9') {
      exponent = std::min(exponent * 10 + (t[i] - '0'), 100000L);
      i++, exp_digits++;
    }
    if (exp_digits == 0) return false;
    exponent_too_big = !negative && exponent > 300;
  }
  return i == n;
}

// Parses t as a number (see number_grammar) into out; false (with a reason) when it is not one.
static bool try_number(string_view t, float& out, std::string* why) {
  bool too_big = false;
  if (t.size() > size_t(max_number_chars)) {
    if (why) *why = "number too long " + quote(t);
    return false;
  }
  if (!number_grammar(t, too_big)) {
    std::string lower = ascii_lower(t);
    if (!lower.empty() && (lower[0] == '+' || lower[0] == '-')) lower.erase(0, 1);
    bool special = lower == "nan" || lower == "inf" || lower == "infinity" || lower.compare(0, 4, "nan(") == 0;
    if (why) *why = (special ? "non-finite number " : "malformed number ") + quote(t);
    return false;
  }
  char buf[max_number_chars + 1];
  std::memcpy(buf, t.data(), t.size());
  buf[t.size()] = '\0';
  out = too_big ? HUGE_VALF : std::strtof(buf, nullptr);  // correctly rounded, locale "C"
  if (!std::isfinite(out)) {
    if (why) *why = "number out of range " + quote(t);
    return false;
  }
  return true;
}

// The number in token t, or an input_error at pos.
static float number_at(string_view t, const text_pos& pos) {
  float v = 0;
  std::string why;
  if (!try_number(t, v, &why)) fail(pos, why);
  return v;
}

// Resolves one OBJ index component (1-based, negative = relative) against count elements defined so far: the
// 0-based index.
static int check_index(string_view t, int count, const char* what, const text_pos& pos) {
  size_t i = (!t.empty() && (t[0] == '+' || t[0] == '-')) ? 1 : 0;
  bool digits_only = i < t.size();
  for (size_t k = i; k < t.size(); k++) digits_only = digits_only && t[k] >= '0' && t[k] <= '9';
  if (!digits_only) fail(pos, std::string("malformed ") + what + " index " + quote(t));
  long long v = 0;
  for (size_t k = i; k < t.size(); k++) v = std::min(v * 10 + (t[k] - '0'), (long long)INT_MAX + 1);
  if (t[0] == '-') v = -v;
  if (v == 0) fail(pos, std::string(what) + " index 0 is invalid (OBJ indices start at 1)");
  long long resolved = v > 0 ? v - 1 : count + v;
  if (resolved < 0 || resolved >= count)
    fail(pos, std::string(what) + " index " + quote(t) + " out of range (" + std::to_string(count) + " " +
                  (count == 1                      ? what
                   : std::string(what) == "vertex" ? "vertices"
                                                   : std::string(what) + "s") +
                  " defined so far)");
  return int(resolved);
}

// Reads one face corner: v, v/vt, v//vn or v/vt/vn, with an empty trailing part taken as not written ("1/" and
// "1//" are "1", "1/2/" is "1/2", as other OBJ readers take them); the parts not written are invalid_id.
static obj_corner check_corner(string_view c, const obj_clean_data& d, const text_pos& pos) {
  size_t s1 = c.find('/');
  if (s1 != string_view::npos && c.size() >= 2 && c.substr(c.size() - 2) == "//" && c.find('/') == c.size() - 2)
    c = c.substr(0, c.size() - 2);  // v//
  else if (s1 != string_view::npos && c.back() == '/' && std::count(c.begin(), c.end(), '/') <= 2)
    c = c.substr(0, c.size() - 1);  // v/ or v/vt/
  obj_corner out{invalid_id, invalid_id, invalid_id};
  s1 = c.find('/');
  if (s1 == string_view::npos) {
    out.v = check_index(c, int(d.positions.size()), "vertex", pos);
    return out;
  }
  size_t s2 = c.find('/', s1 + 1);
  if (s2 != string_view::npos && c.find('/', s2 + 1) != string_view::npos)
    fail(pos, "malformed face corner " + quote(c) + " (expected v, v/vt, v//vn or v/vt/vn)");
  out.v = check_index(c.substr(0, s1), int(d.positions.size()), "vertex", pos);
  string_view vt = c.substr(s1 + 1, s2 == string_view::npos ? string_view::npos : s2 - s1 - 1);
  if (s2 == string_view::npos || !vt.empty()) out.vt = check_index(vt, int(d.texcoords.size()), "texcoord", pos);
  if (s2 != string_view::npos) out.vn = check_index(c.substr(s2 + 1), int(d.normals.size()), "normal", pos);
  return out;
}

// The part of a name before its first word that starts with '#', blanks after it dropped ("" when it has none, or
// starts with one): what the name was taken as when every '#' word started a comment.
static std::string name_before_hash_word(const std::string& name) {
  for (size_t i = 1; i < name.size(); i++)
    if (name[i] == '#' && (name[i - 1] == ' ' || name[i - 1] == '\t')) {
      size_t e = name.find_last_not_of(" \t", i - 1);
      return e == std::string::npos ? std::string() : name.substr(0, e + 1);
    }
  return {};
}

// Counts unrecognised statements of one file and reports them once.
struct unknown_log {
  int count = 0;
  std::string first;
  size_t first_line = 0;
  void add(string_view keyword, size_t line) {
    if (count++ == 0) first = quote(keyword), first_line = line;
  }
  void report(const std::string& file) const {
    if (count > 0)
      stderr_text() << "warning: " << file << ": ignored " << count << " unrecognised statement"
                    << (count > 1 ? "s" : "") << " (first " << first << " at line " << first_line << ")\n";
  }
};

std::string resolve_file_name(const std::string& dir, const std::string& written) {
  std::string name = written;
  if (name.size() >= 2 && name.front() == '"' && name.back() == '"') name = name.substr(1, name.size() - 2);
  auto resolve = [&](const std::string& nm) {
    fs::path p(nm);
    if (!p.is_absolute() && !dir.empty()) p = fs::path(dir) / p;
    return p.lexically_normal().string();
  };
  std::string path = resolve(name);
  std::error_code ec;
  if (name.find('\\') != std::string::npos && !fs::exists(path, ec)) {
    std::string slashed = name;
    std::replace(slashed.begin(), slashed.end(), '\\', '/');
    std::string alt = resolve(slashed);
    if (fs::exists(alt, ec)) return alt;
  }
  return path;
}

void folder_cache::note(const std::string& file, int line, const std::string& what, const std::string& name,
                        const std::string& beside) {
  if (said >= 3) {
    unsaid++;
    return;
  }
  said++;
  stderr_text() << "warning: " << file << ":" << line << ": " << what << ": " << name << " does not exist; using "
                << beside << "\n";
}

std::string find_beside(const std::string& dir, const std::string& written, folder_cache& cache) {
  std::string name = written;
  if (name.size() >= 2 && name.front() == '"' && name.back() == '"') name = name.substr(1, name.size() - 2);
  size_t slash = name.find_last_of("/\\");
  std::string base = slash == std::string::npos ? name : name.substr(slash + 1);
  if (base.empty() || base == "." || base == "..") return {};
  std::error_code ec;
  fs::path folder = dir.empty() ? fs::path(".") : fs::path(dir);
  // With its last folder first: textures/wood.png of C:\proj\textures\wood.png or of Blender's //textures/wood.png.
  const std::string head = slash == std::string::npos ? std::string() : name.substr(0, slash);
  const std::string parent = head.substr(head.find_last_of("/\\") + 1);  // (npos + 1 = 0: all of head)
  fs::path in_parent = folder / parent / base;
  if (!parent.empty() && parent != "." && parent != ".." && fs::is_regular_file(in_parent, ec))
    return in_parent.lexically_normal().string();
  fs::path exact = folder / base;
  if (fs::is_regular_file(exact, ec)) return exact.lexically_normal().string();
  auto [listing, fresh] = cache.folders.try_emplace(folder.lexically_normal().string());
  if (fresh)
    for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
      std::error_code type_ec;
      if (!it->is_regular_file(type_ec)) continue;  // (files only: a folder of the same name is no rival)
      std::string entry = it->path().filename().string();
      listing->second[ascii_lower(entry)].push_back(entry);
    }
  auto same = listing->second.find(ascii_lower(base));
  if (same == listing->second.end() || same->second.size() != 1) return {};  // (two that differ only in case: neither
                                                                             // is more right)
  fs::path found = folder / same->second[0];
  return fs::is_regular_file(found, ec) ? found.lexically_normal().string() : std::string();
}

// Number of numeric arguments (min, max) of a texture option, or min = -1 when it takes one word.
struct texture_option {
  const char* name;
  int min_args, max_args;
};
static const texture_option texture_options[] = {
    {"-blendu", -1, 1}, {"-blendv", -1, 1},     {"-clamp", -1, 1}, {"-cc", -1, 1}, {"-imfchan", -1, 1},
    {"-type", -1, 1},   {"-colorspace", -1, 1}, {"-boost", 1, 1},  {"-bm", 1, 1},  {"-texres", 1, 1},
    {"-mm", 1, 2},      {"-o", 1, 3},           {"-s", 1, 3},      {"-t", 1, 3}};

// Checks a texture statement (options, then a file name) and returns the file name; -s, -o, -clamp and (map_d)
// -imfchan go to xf (when given): u and v of -s and -o (a v left out is u's default, 1 for -s and 0 for -o; w has no
// use on a 2D image). Options given that would change the texture but are not applied are appended to not_applied
// (when given): -mm other than 0 1, -t other than 0, -cc on, -blendu or -blendv off, -colorspace, -imfchan z or on a
// colour texture. (-boost, -texres, -type and -bm change nothing of a 2D colour or cut-out texture without mipmaps.)
static std::string check_texture_statement(const std::vector<string_view>& t, const text_pos& pos,
                                           texture_transform* xf = nullptr,
                                           std::vector<std::string>* not_applied = nullptr) {
  auto skip = [&](string_view name) {
    if (not_applied) not_applied->emplace_back(name);
  };
  const bool scalar = ascii_lower(t[0]) == "map_d";
  texture_transform local;
  if (!xf) xf = &local;
  *xf = {};
  size_t i = 1;
  while (i < t.size() && t[i].size() > 1 && t[i][0] == '-') {
    const texture_option* opt = nullptr;
    for (const auto& o : texture_options)
      if (t[i] == o.name) opt = &o;
    if (!opt) break;  // a file name that starts with '-'
    string_view name = t[i++];
    if (opt->min_args < 0) {
      if (i >= t.size()) fail(pos, "texture option " + quote(name) + " needs a value");
      bool on_off = name == "-blendu" || name == "-blendv" || name == "-clamp" || name == "-cc";
      if (on_off && t[i] != "on" && t[i] != "off") fail(pos, "texture option " + quote(name) + " takes on or off");
      if (name == "-clamp") xf->clamp = t[i] == "on";
      if (name == "-imfchan") {
        const std::string c = ascii_lower(t[i]);
        if (scalar && (c == "r" || c == "g" || c == "b" || c == "m" || c == "l")) xf->channel = c[0];
        else skip(name);  // (z, depth, or a word the format does not define; or a colour texture's channel)
      }
      // (-colorspace as applied: colour textures are decoded as sRGB, masks read as they are stored)
      const std::string space = ascii_lower(t[i]);
      const bool as_applied = scalar ? space == "linear" || space == "raw" : space == "srgb";
      if ((name == "-cc" && t[i] == "on") || ((name == "-blendu" || name == "-blendv") && t[i] == "off") ||
          (name == "-colorspace" && !as_applied))
        skip(name);
      i++;
      continue;
    }
    float args[3] = {0, 0, 0};
    int got = 0;
    for (int k = 0; k < opt->max_args; k++) {
      float v = 0;
      if (k < opt->min_args) {
        if (i >= t.size()) fail(pos, "texture option " + quote(name) + " needs a number");
        v = number_at(t[i], pos);
      } else if (i >= t.size() || !try_number(t[i], v, nullptr)) {
        break;
      }
      args[k] = v;
      got++;
      i++;
    }
    if ((name == "-mm" && (args[0] != 0 || (got > 1 && args[1] != 1))) ||
        (name == "-t" && (args[0] != 0 || args[1] != 0 || args[2] != 0)))
      skip(name);
    if (name == "-s") xf->scale = {args[0], got > 1 ? args[1] : 1.0f};
    if (name == "-o") xf->offset = {args[0], got > 1 ? args[1] : 0.0f};
  }
  if (i >= t.size()) fail(pos, quote(t[0]) + " needs a file name");
  return join_from(t, i);
}

// Checks a colour statement (1 or 3 finite non-negative numbers) and returns it.
static vec3f colour_at(const std::vector<string_view>& t, const text_pos& pos) {
  if (t.size() != 2 && t.size() != 4)
    fail(pos, quote(t[0]) + " takes 1 or 3 numbers, got " + std::to_string(t.size() - 1));
  vec3f c;
  for (size_t i = 1; i < t.size(); i++) {
    float v = number_at(t[i], pos);
    if (v < 0) fail(pos, quote(t[0]) + " must not be negative");
    c[int(i - 1)] = v;
  }
  return t.size() == 2 ? vec3f{c.x, c.x, c.x} : c;
}

// Checks a scalar statement (one finite number) and returns it.
static float scalar_at(const std::vector<string_view>& t, const text_pos& pos) {
  if (t.size() != 2) fail(pos, quote(t[0]) + " takes 1 number, got " + std::to_string(t.size() - 1));
  return number_at(t[1], pos);
}

// Validates one MTL file, appending its materials (file order) to out.
static void validate_mtl(const std::string& path, std::vector<mtl_material_data>& out, folder_cache& folders) {
  std::string text = read_text_file(path, "material library");
  line_reader lines(text);
  std::vector<string_view> t;
  string_view line;
  unknown_log unknown;
  mtl_material_data* cur = nullptr;
  size_t first = out.size();
  std::vector<size_t> kd_line;  // per material of this file: the line of its last Kd statement (0: none)
  size_t transparent_line = 0;  // the first d or Tr statement asking for partial transparency (reported once)
  std::map<std::string, size_t> ignored_maps;  // texture statements other than map_Kd and map_d: first line of each
  std::vector<std::string> ignored_order;     // their keywords in order of first appearance
  std::map<std::string, size_t> skipped_options;  // options of map_Kd and map_d that are not applied: first line
  std::vector<std::string> skipped_order;
  std::vector<string_view> named;  // a name statement's tokens, '#' inside names kept (see tokenize)
  const std::string dir = fs::path(path).parent_path().string();
  while (lines.next(line)) {
    text_pos pos{path, lines.line};
    bool commented = tokenize(line, pos, t);
    if (t.empty()) continue;
    string_view k = t[0];
    // map_Kd and map_d in any case (map_kd, MAP_D), as Assimp and three.js read them; other keywords as written.
    const std::string lower_k = ascii_lower(k);
    if (lower_k == "map_kd" || lower_k == "map_d") k = lower_k == "map_kd" ? "map_Kd" : "map_d";
    bool texture = lower_k.compare(0, 4, "map_") == 0 || k == "bump" || k == "disp" || k == "decal" || k == "refl" ||
                   k == "norm";
    if (k == "newmtl" || texture) {
      if (commented) tokenize(line, pos, named, true);
      else named = t;
    }
    if (k == "newmtl") {
      if (named.size() < 2) fail(pos, "newmtl needs a material name");
      out.emplace_back();
      cur = &out.back();
      cur->material.name = join_from(named, 1);
      kd_line.push_back(0);
      cur->mtl_path = path;
      cur->line = int(std::min<size_t>(lines.line, INT_MAX));
      continue;
    }
    bool known = texture || k == "Kd" || k == "Ks" || k == "Ke" || k == "Ka" || k == "Tf" || k == "Kt" || k == "Ns" ||
                 k == "Ni" || k == "d" || k == "Tr" || k == "illum";
    if (!known) {
      unknown.add(k, lines.line);
      continue;
    }
    if (!cur) fail(pos, quote(k) + " before any newmtl");
    material_data& m = cur->material;
    if (texture) {
      if (k != "map_Kd" && k != "map_d" && ignored_maps.emplace(std::string(k), lines.line).second)
        ignored_order.emplace_back(k);
      texture_transform xf;
      std::vector<std::string> skipped;
      std::string file = check_texture_statement(named, pos, &xf, &skipped);
      if (k == "map_Kd" || k == "map_d")  // (the other maps are named as not rendered at all)
        for (const std::string& o : skipped)
          if (skipped_options.emplace(o, lines.line).second) skipped_order.push_back(o);
      // "map_Kd wood.png #2": a file name with a '#' word when there is such a file (here, or beside the MTL when the
      // word is in its last path component: "C:\...\Wood #2.png"), else a comment after the name.
      std::error_code ec;
      if (named.size() != t.size() && t.size() >= 2 && !fs::is_regular_file(resolve_file_name(dir, file), ec)) {
        texture_transform cut_xf;
        std::string cut = check_texture_statement(t, pos, &cut_xf);
        size_t slash = file.find_last_of("/\\");
        std::string last = slash == std::string::npos ? file : file.substr(slash + 1);
        bool hash_in_last = !name_before_hash_word(last).empty() || (!last.empty() && last[0] == '#');
        if (fs::is_regular_file(resolve_file_name(dir, cut), ec) || !hash_in_last ||
            find_beside(dir, file, folders).empty())
          file = cut, xf = cut_xf;
      }
      if (k == "map_Kd") {
        cur->kd_map = file, cur->kd_map_line = int(std::min<size_t>(lines.line, INT_MAX));
        cur->material.kd_map = xf;
      }
      if (k == "map_d") {
        cur->alpha_map = file, cur->alpha_map_line = int(std::min<size_t>(lines.line, INT_MAX));
        cur->material.alpha_map = xf;
      }
    } else if (k == "Ka" || k == "Tf" || k == "Kt") {
      // Not rendered: any form is accepted (Ka spectral file.rfl, Tf xyz x y z, ...).
    } else if (k == "Kd" || k == "Ks" || k == "Ke") {
      if (t.size() >= 2 && (t[1] == "spectral" || t[1] == "xyz"))
        fail(pos, quote(k) + " " + std::string(t[1]) + " (" + (t[1] == "xyz" ? "CIE XYZ" : "a spectral curve") +
                      ") is not supported: write " + std::string(k) + " r g b (linear RGB)");
      vec3f c = colour_at(t, pos);
      if (k == "Kd") m.kd = c, kd_line.back() = lines.line;
      if (k == "Ks") m.ks = c;
      if (k == "Ke") m.ke = c;
    } else {
      if (k == "d" && t.size() == 3 && t[1] == "-halo") t.erase(t.begin() + 1);  // "d -halo 0.8": not rendered either
      float v = scalar_at(t, pos);
      if (k == "Ns" && v < 0) fail(pos, "Ns must not be negative");
      if ((k == "d" || k == "Tr") && !(v >= 0 && v <= 1)) fail(pos, quote(k) + " must lie in [0, 1]");
      if (k == "Ns") m.ns = v;
      if (((k == "d" && v < 1) || (k == "Tr" && v > 0)) && transparent_line == 0) transparent_line = lines.line;
    }
  }
  // A material without Kd has no diffuse part (Kd 0, as tinyobjloader reads it: a lamp written with Ke alone does
  // not also reflect, a lobe written with Ks and Ns alone stays a pure lobe), unless it has a map_Kd: then it shows
  // the texture as it is (Kd multiplies the texture, as the MTL format says).
  for (size_t i = first; i < out.size(); i++)
    if (kd_line[i - first] == 0) out[i].material.kd = out[i].kd_map.empty() ? vec3f{0, 0, 0} : vec3f{1, 1, 1};
  // Kd + Ks above 1 reflects more than arrives: make_bsdf scales such a material down (one line per file, naming
  // the first few).
  std::vector<std::string> bright;
  for (size_t i = first; i < out.size(); i++) {
    const material_data& m = out[i].material;
    if (std::max({m.kd.x + m.ks.x, m.kd.y + m.ks.y, m.kd.z + m.ks.z}) > 1) bright.push_back(quote(m.name));
  }
  if (!bright.empty()) {
    constexpr size_t named = 5;
    std::string list;
    for (size_t i = 0; i < std::min(bright.size(), named); i++) list += (i > 0 ? ", " : "") + bright[i];
    if (bright.size() > named) list += " and " + std::to_string(bright.size() - named) + " more";
    stderr_text() << "warning: " << path << ": material" << (bright.size() > 1 ? "s " : " ") << list
                  << (bright.size() > 1 ? " have" : " has") << " Kd + Ks above 1, scaled down to conserve energy\n";
  }
  // One warning naming each keyword with the line of its first appearance.
  auto first_lines = [&](const char* what, const std::vector<std::string>& order, std::map<std::string, size_t>& line) {
    if (order.empty()) return;
    stderr_text w;
    w << "warning: " << path << ": " << what << ":";
    for (size_t i = 0; i < order.size(); i++) w << (i ? ", " : " ") << order[i] << " (line " << line[order[i]] << ")";
    w << "\n";
  };
  first_lines("textures other than map_Kd and map_d are not rendered", ignored_order, ignored_maps);
  first_lines("texture options that are not applied (the texture is used without them)", skipped_order, skipped_options);
  if (transparent_line > 0)
    stderr_text() << "warning: " << path << ":" << transparent_line
                  << ": dissolve (d below 1 or Tr above 0) is not rendered, surfaces stay opaque; map_d cuts out\n";
  // A map_Kd under an explicit Kd 0 (as Maya writes textured materials) is multiplied by 0 and never shows. Not said
  // of emitters: they show their Ke, and a lamp that does not reflect is a choice.
  int unseen = 0;
  for (size_t i = first; i < out.size(); i++) {
    const material_data& m = out[i].material;
    if (kd_line[i - first] == 0 || !is_black(m.kd) || out[i].kd_map.empty() || !is_black(m.ke)) continue;
    if (unseen++ < named_warnings)
      stderr_text() << "warning: " << path << ":" << kd_line[i - first] << ": material " << quote(m.name)
                    << " has map_Kd but Kd 0: it renders " << (is_black(m.ks) ? "black" : "as its Ks lobe alone")
                    << " (map_Kd multiplies Kd)\n";
  }
  if (unseen > named_warnings)
    stderr_text() << "warning: " << path << ": " << unseen - named_warnings
                  << " more materials have map_Kd but Kd 0 (map_Kd multiplies Kd)\n";
  unknown.report(path);
}

// Per-OBJ state of the validation pass beside the output.
struct obj_pass_state {
  std::map<std::string, int> used_index;   // usemtl name -> k
  std::vector<std::string> used_names;     // k -> name
  std::vector<size_t> used_lines;          // k -> line of its first usemtl
  std::set<std::string> mtl_files;         // resolved MTL paths already read
  std::vector<mtl_material_data> defined;  // all materials of all MTL files, in load order
  folder_cache* folders = nullptr;         // the output's listings for find_beside
};

// Handles an mtllib statement: every named file must exist; each file is read once.
static void handle_mtllib(const std::vector<string_view>& t, const std::string& dir, obj_pass_state& st,
                          const text_pos& pos) {
  if (t.size() < 2) fail(pos, "mtllib needs a file name");
  std::vector<std::string> names;
  std::string whole = join_from(t, 1);
  std::error_code ec;
  if (t.size() > 2 && fs::is_regular_file(resolve_file_name(dir, whole), ec)) {
    names.push_back(whole);  // one file name with spaces in it
  } else {
    for (size_t i = 1; i < t.size(); i++) names.emplace_back(t[i]);
  }
  for (const auto& name : names) {
    std::string file = resolve_file_name(dir, name);
    if (!fs::exists(file, ec)) {
      std::string beside = find_beside(dir, name, *st.folders);  // (a path from the machine that wrote the OBJ)
      if (!beside.empty()) {
        st.folders->note(pos.file, int(std::min<size_t>(pos.line, INT_MAX)), "mtllib", name, beside);
        file = beside;
      }
    }
    if (!st.mtl_files.insert(file).second) continue;
    try {
      validate_mtl(file, st.defined, *st.folders);
    } catch (const input_error& e) {
      if (e.line > 0) throw;
      fail(pos, std::string("mtllib: ") + e.what());  // the MTL itself is unreadable: point at this line
    }
  }
}

obj_clean_data validate_obj(const std::string& path) {
  std::string text = read_text_file(path, "OBJ file");
  std::string dir = fs::path(path).parent_path().string();
  obj_clean_data d;
  obj_pass_state st;
  st.folders = &d.folders;
  unknown_log unknown;
  int current = invalid_id;  // material k of the next faces
  size_t colour_line = 0;    // the first v with a colour (x y z r g b; reported once)
  line_reader lines(text);
  std::vector<string_view> t;
  string_view line;
  std::vector<string_view> named;  // usemtl's tokens, '#' inside names kept (see tokenize)
  while (lines.next(line)) {
    text_pos pos{path, lines.line};
    bool commented = tokenize(line, pos, t);
    if (t.empty()) continue;
    string_view k = t[0];
    size_t args = t.size() - 1;
    if (k == "v" || k == "vn" || k == "vt") {
      bool ok = k == "v" ? (args == 3 || args == 4 || args == 6) : k == "vn" ? args == 3 : (args >= 1 && args <= 3);
      if (!ok)
        fail(pos, quote(k) +
                      (k == "v"    ? " takes 3 numbers (or x y z w, or x y z r g b)"
                       : k == "vn" ? " takes 3 numbers"
                                   : " takes 1 to 3 numbers") +
                      ", got " + std::to_string(args));
      float x[3] = {0, 0, 0};
      for (size_t i = 1; i <= args; i++) {
        float v = number_at(t[i], pos);
        if (i <= 3) x[i - 1] = v;
      }
      size_t count = k == "v" ? d.positions.size() : k == "vn" ? d.normals.size() : d.texcoords.size();
      if (count >= size_t(INT_MAX - 1)) fail(pos, "too many " + std::string(k) + " statements");
      if (k == "v") d.positions.push_back({x[0], x[1], x[2]});
      if (k == "v" && args == 6 && colour_line == 0) colour_line = lines.line;
      if (k == "vn") d.normals.push_back({x[0], x[1], x[2]});
      if (k == "vt") d.texcoords.push_back({x[0], x[1]});
    } else if (k == "f") {
      if (args < 3) fail(pos, "a face needs at least 3 vertices, got " + std::to_string(args));
      if (args > size_t(INT_MAX / 4)) fail(pos, "face has too many vertices");
      for (size_t i = 1; i <= args; i++) d.corners.push_back(check_corner(t[i], d, pos));
      d.face_sizes.push_back(int(args));
      d.face_materials.push_back(current);
      d.face_lines.push_back(int(std::min<size_t>(lines.line, INT_MAX)));
    } else if (k == "usemtl") {
      if (commented) tokenize(line, pos, named, true);
      else named = t;
      if (named.size() < 2) fail(pos, "usemtl needs a material name");
      std::string name = join_from(named, 1);
      auto it = st.used_index.emplace(name, int(st.used_names.size())).first;
      if (it->second == int(st.used_names.size())) {
        st.used_names.push_back(name);
        st.used_lines.push_back(lines.line);
      }
      current = it->second;  // (faces carry it in face_materials: tinyobjloader is given no materials)
    } else if (k == "mtllib") {
      handle_mtllib(t, dir, st, pos);
    } else if (k == "o" || k == "g" || k == "s" || k == "l" || k == "p" || k == "vp") {
      // Accepted and not needed: groups, smoothing, lines, points, parameter-space vertices.
    } else {
      unknown.add(k, lines.line);
    }
  }
  unknown.report(path);
  if (colour_line > 0)
    stderr_text() << "warning: " << path << ":" << colour_line
                  << ": vertex colours (v x y z r g b) are not rendered; materials give the colour (Kd, map_Kd)\n";
  text = std::string();

  // Resolve the used names (first definition wins, as in tinyobjloader) in order of first use; warnings name the
  // first named_warnings cases.
  std::map<std::string, int> defined_index;
  int redefined = 0, undefined = 0, approximate = 0;
  for (size_t i = 0; i < st.defined.size(); i++)
    if (!defined_index.emplace(st.defined[i].material.name, int(i)).second && redefined++ < named_warnings)
      stderr_text() << "warning: " << st.defined[i].mtl_path << ":" << st.defined[i].line << ": material "
                    << quote(st.defined[i].material.name) << " is defined again; its first definition is used\n";
  if (redefined > named_warnings)
    stderr_text() << "warning: " << redefined - named_warnings << " more materials are defined again\n";
  // A name with a '#' word that matches nothing may have meant a comment after the name, on either side: "usemtl
  // wood #planks" and "newmtl red #red paint" (before, every '#' word started a comment): the names before the
  // '#' words are tried too, the used one against the defined ones, then against the defined ones' (first wins).
  std::map<std::string, int> short_index;
  for (size_t i = 0; i < st.defined.size(); i++) {
    std::string cut = name_before_hash_word(st.defined[i].material.name);
    if (!cut.empty() && cut != st.defined[i].material.name) short_index.emplace(cut, int(i));
  }
  for (size_t k = 0; k < st.used_names.size(); k++) {
    int found = -1;  // index into st.defined
    const std::string used_cut = name_before_hash_word(st.used_names[k]);
    auto lookup = [&](const std::map<std::string, int>& index, const std::string& name) {
      auto it = index.find(name);
      if (found < 0 && it != index.end()) found = it->second;
    };
    lookup(defined_index, st.used_names[k]);
    if (!used_cut.empty()) lookup(defined_index, used_cut);
    lookup(short_index, used_cut.empty() ? st.used_names[k] : used_cut);
    if (found >= 0 && st.defined[size_t(found)].material.name != st.used_names[k] && approximate++ < named_warnings)
      stderr_text() << "warning: " << path << ":" << st.used_lines[k] << ": usemtl " << quote(st.used_names[k])
                    << " takes material " << quote(st.defined[size_t(found)].material.name)
                    << " (no exact match; the names agree before their '#' words)\n";
    if (found >= 0) {
      d.materials.push_back(st.defined[size_t(found)]);
    } else {
      // As other OBJ readers do (tinyobjloader, Blender): the faces get the default material (Kd 0.8), said once per
      // name. OBJ files often outlive or lose their MTL's entries, or name materials with no mtllib at all.
      if (undefined++ < named_warnings)
        stderr_text() << "warning: " << path << ":" << st.used_lines[k] << ": usemtl of undefined material "
                      << quote(st.used_names[k]) << (st.defined.empty() ? " (no material library defines any)" : "")
                      << ": its faces get the default material (Kd 0.8)\n";
      d.materials.emplace_back();
      d.materials.back().material.name = st.used_names[k];
    }
  }
  if (approximate > named_warnings)
    stderr_text() << "warning: " << path << ": " << approximate - named_warnings
                  << " more usemtl names take a material whose name agrees before its '#' word\n";
  if (undefined > named_warnings)
    stderr_text() << "warning: " << path << ": " << undefined - named_warnings
                  << " more undefined materials: their faces get the default material too\n";
  return d;
}

}  // namespace bl
