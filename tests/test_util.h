// test_util: shared helpers of the tests — statistics (chi-square p-values, t statistics), temporary
// directories, running the bayeslight binary, and in-memory meshes for analytic scenes.
#pragma once

#include "math.h"
#include "obj_io.h"
#include "rng.h"

#include <sys/wait.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace bl::test {

// Built with a sanitizer (make test-sanitize, make test-tsan): a render costs tens to hundreds of times as much there,
// so tests that render thousands of tiny images render fewer.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
inline constexpr bool sanitized_build = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
inline constexpr bool sanitized_build = true;
#else
inline constexpr bool sanitized_build = false;
#endif
#else
inline constexpr bool sanitized_build = false;
#endif

// Regularised upper incomplete gamma Q(a, x) (series / continued fraction, double precision).
inline double gamma_q(double a, double x) {
  if (x <= 0) return 1;
  double gln = std::lgamma(a);
  if (x < a + 1) {
    double ap = a, sum = 1 / a, del = sum;
    for (int n = 0; n < 10000; n++) {
      ap += 1;
      del *= x / ap;
      sum += del;
      if (std::fabs(del) < std::fabs(sum) * 1e-15) break;
    }
    return 1 - sum * std::exp(-x + a * std::log(x) - gln);
  }
  double b = x + 1 - a, c = 1e300, d = 1 / b, h = d;
  for (int i = 1; i < 10000; i++) {
    double an = -i * (i - a);
    b += 2;
    d = an * d + b;
    if (std::fabs(d) < 1e-300) d = 1e-300;
    c = b + an / c;
    if (std::fabs(c) < 1e-300) c = 1e-300;
    d = 1 / d;
    double del = d * c;
    h *= del;
    if (std::fabs(del - 1) < 1e-15) break;
  }
  return std::exp(-x + a * std::log(x) - gln) * h;
}

// Chi-square test of observed counts against expected counts; cells with expected < 5 are pooled
// (as in nori's chi2 test). Returns the p-value of the null hypothesis "counts follow the expectation".
inline double chi2_pvalue(const std::vector<double>& observed, const std::vector<double>& expected) {
  double chi2 = 0, pool_o = 0, pool_e = 0;
  int dof = -1;
  for (size_t i = 0; i < observed.size(); i++) {
    if (expected[i] < 5) {
      pool_o += observed[i];
      pool_e += expected[i];
      if (expected[i] == 0 && observed[i] > 0) return 0;  // a sample where the pdf says none can occur
      continue;
    }
    chi2 += (observed[i] - expected[i]) * (observed[i] - expected[i]) / expected[i];
    dof++;
  }
  if (pool_e >= 5) {
    chi2 += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
    dof++;
  }
  if (dof < 1) return 1;
  return gamma_q(0.5 * dof, 0.5 * chi2);
}

// Mean and standard error of a set of independent estimates.
struct mean_se {
  double mean = 0, se = 0;
};
inline mean_se mean_and_se(const std::vector<double>& v) {
  double m = 0;
  for (double x : v) m += x;
  m /= double(v.size());
  double var = 0;
  for (double x : v) var += (x - m) * (x - m);
  var /= double(v.size() - 1);
  return {m, std::sqrt(var / double(v.size()))};
}

// Uniform pair number i of a seeded stream (the renderer's own PCG32 keys; any seed, any i).
inline vec2f uniform_pair(uint64_t seed, uint64_t i) {
  auto r = draw_vertex(sample_key(seed, i, 0), 1);
  return {r.u[0], r.u[1]};
}

// A fresh temporary directory, removed on destruction.
struct temp_dir {
  std::filesystem::path path;
  temp_dir() {
    char tmpl[] = "/tmp/bayeslight_test_XXXXXX";
    char* p = mkdtemp(tmpl);
    // (Never "/tmp" itself on failure: the destructor would remove everything in it; a review.)
    if (!p) throw std::runtime_error(std::string("mkdtemp failed: ") + std::strerror(errno));
    path = p;
  }
  ~temp_dir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  std::string operator/(const std::string& name) const { return (path / name).string(); }
};

// Writes text to a file.
inline std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}
inline void write_text(const std::string& path, const std::string& text) {
  std::ofstream f(path, std::ios::binary);
  f << text;
}

// Result of running the binary: exit status and captured stdout+stderr.
struct run_result {
  int status = -1;
  std::string output;
};

// Runs `bayeslight ARGS` (ARGS already shell-quoted), capturing output.
inline run_result run_bayeslight(const std::string& args) {
  std::string cmd = std::string(BAYESLIGHT_BINARY) + " " + args + " 2>&1";
  run_result r;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) r.output.append(buf, n);
  int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
  return r;
}

// A render (`args`: a render command without its output) stopped after `passes` passes with a checkpoint in `d`,
// then resumed: the stopped run's status, the resumed run, and whether its image has the bytes of `full_path`.
struct resume_run {
  int stopped = -1;
  run_result resumed;
  bool same = false;
};
inline resume_run stop_and_resume(const temp_dir& d, const std::string& args, int passes, const std::string& full_path) {
  resume_run r;
  const std::string ck = d / "ck.bin";
  r.stopped = run_bayeslight(args + " -o " + (d / "part.pfm") + " --checkpoint " + ck + " --stop-after-passes " +
                             std::to_string(passes)).status;
  r.resumed = run_bayeslight(args + " -o " + (d / "resumed.pfm") + " --resume " + ck);
  r.same = r.resumed.status == 0 && read_text(d / "resumed.pfm") == read_text(full_path);
  return r;
}

// Path of a file in the source tree.
inline std::string source_path(const std::string& rel) { return std::string(BAYESLIGHT_SOURCE_DIR) + "/" + rel; }

// Builds meshes in memory: materials by value, triangles and quads by corner positions.
struct mesh_builder {
  mesh_data mesh;
  int add_material(vec3f kd, vec3f ke = {0, 0, 0}, vec3f ks = {0, 0, 0}, float ns = 1) {
    material_data m;
    m.name = "m" + std::to_string(mesh.materials.size());
    m.kd = kd;
    m.ke = ke;
    m.ks = ks;
    m.ns = ns;
    mesh.materials.push_back(m);
    return int(mesh.materials.size()) - 1;
  }
  // Triangle a, b, c (counter-clockwise seen from its front).
  void add_triangle(vec3f a, vec3f b, vec3f c, int material) {
    int base = int(mesh.positions.size());
    mesh.positions.push_back(a);
    mesh.positions.push_back(b);
    mesh.positions.push_back(c);
    for (int i = 0; i < 3; i++) {
      mesh.tri_positions.push_back(base + i);
      mesh.tri_normals.push_back(invalid_id);
      mesh.tri_texcoords.push_back(invalid_id);
    }
    mesh.tri_materials.push_back(material);
  }
  // Quad a, b, c, d (counter-clockwise seen from its front) as two triangles.
  void add_quad(vec3f a, vec3f b, vec3f c, vec3f d, int material) {
    add_triangle(a, b, c, material);
    add_triangle(a, c, d, material);
  }
  // Axis-aligned box [lo, hi] with outward-facing sides.
  void add_box(vec3f lo, vec3f hi, int material) {
    vec3f p[8];
    for (int i = 0; i < 8; i++) p[i] = {i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z};
    add_quad(p[0], p[2], p[3], p[1], material);  // -z
    add_quad(p[4], p[5], p[7], p[6], material);  // +z
    add_quad(p[0], p[4], p[6], p[2], material);  // -x
    add_quad(p[1], p[3], p[7], p[5], material);  // +x
    add_quad(p[0], p[1], p[5], p[4], material);  // -y
    add_quad(p[2], p[6], p[7], p[3], material);  // +y
  }
  // Sphere of `rings` bands of latitude and 2 * rings sectors of longitude (quads; triangles at the poles).
  void add_sphere(vec3f centre, float radius, int rings, int material) {
    auto at = [&](int i, int j) {
      double theta = M_PI * i / rings, phi = M_PI * j / rings;
      return centre + vec3f{float(std::sin(theta) * std::cos(phi)), float(std::cos(theta)),
                            float(std::sin(theta) * std::sin(phi))} * radius;
    };
    for (int i = 0; i < rings; i++)
      for (int j = 0; j < 2 * rings; j++) {
        vec3f a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
        if (i > 0 && i + 1 < rings) add_quad(a, b, c, d, material);
        else if (i == 0) add_triangle(a, b, c, material);
        else add_triangle(a, b, d, material);
      }
  }
};

// A floor beside a closed box that holds a bright lamp (Ke `bright`, default 200), lit only by a dim lamp (Ke 1)
// outside the box, a 0.5 x 0.5 square at y = 2, or `dims` small ones in a row there: a bound-style prior sends most
// NEE samples to the shut-in lamp. Seen well from eye (2, 4, 0.01) looking down.
inline mesh_data boxed_lamp_mesh(float bright_ke = 200, int dims = 1) {
  mesh_builder m;
  int floor = m.add_material({0.5f, 0.5f, 0.5f});
  int box = m.add_material({0.6f, 0.6f, 0.6f});
  int bright = m.add_material({0, 0, 0}, {bright_ke, bright_ke, bright_ke});
  int dim = m.add_material({0, 0, 0}, {1, 1, 1});
  m.add_quad({-5, 0, -5}, {-5, 0, 5}, {5, 0, 5}, {5, 0, -5}, floor);
  m.add_box({-0.5f, 0.01f, -0.5f}, {0.5f, 1, 0.5f}, box);
  m.add_quad({-0.1f, 0.9f, -0.1f}, {0.1f, 0.9f, -0.1f}, {0.1f, 0.9f, 0.1f}, {-0.1f, 0.9f, 0.1f}, bright);  // inside
  for (int k = 0; k < dims; k++) {
    const float x = dims == 1 ? 1.0f : 0.4f + 0.1f * float(k), h = dims == 1 ? 0.5f : 0.05f;
    m.add_quad({x, 2, -0.25f}, {x + h, 2, -0.25f}, {x + h, 2, 0.25f}, {x, 2, 0.25f}, dim);
  }
  return std::move(m.mesh);
}

}  // namespace bl::test
