// Tests of the light tree: structural invariants over random triangle-light sets (leaves, parent/child links,
// nested boxes, summed intensities, normal cones, depth, deterministic build), intensity descent (chi-square
// of sampled leaves against intensity_descent_pmf at significance 1e-3, returned probabilities bitwise equal
// to the pmf, every leaf of positive intensity reachable with probability > 0), conservativeness of node_importance and node_region_bound (a zero never hides a light that can
// reach the point), and the partition property of compute_light_cut.
#include "cluster_bounds.h"
#include "light_tree.h"
#include "lights.h"
#include "region_grid.h"
#include "rng.h"
#include "sampling.h"
#include "scene.h"
#include "scene_fixture.h"
#include "test_util.h"

#include <catch2/catch.hpp>
#include <tbb/global_control.h>

#include <cstring>
#include <functional>
#include <sstream>

using namespace bl;
using namespace bl::test;

namespace {

constexpr double alpha = 1e-3;  // chi-square significance level of every test here

// A set of emissive triangles (with some non-emissive ones in between) and its tree.
struct light_set {
  scene_data scene;
  light_data lights;
  light_tree_data tree;
};

// Kinds of random light sets.
enum class layout {
  scattered,   // random positions, sizes and orientations
  ceiling,     // a grid of downward-facing triangles (normal cone of angle 0 everywhere)
  coincident,  // copies of one triangle (identical centroids: the median-split fallback)
  clusters,    // a few tight clusters far apart, random orientations, one degenerate (zero-area) emitter
};

light_set make_light_set(uint64_t seed, int n, layout kind, bool two_sided) {
  pcg32 rng(seed, 7);
  mesh_builder b;
  int wall = b.add_material({0.5f, 0.5f, 0.5f});
  vec3f cluster_centers[4];
  for (vec3f& c : cluster_centers) c = random_in(rng, {-50, -50, -50}, {50, 50, 50});
  for (int i = 0; i < n; i++) {
    float le = log_uniform(rng, 1e-3f, 1e3f);
    int m = b.add_material({0, 0, 0}, {le, le * unif(rng), le * unif(rng) + 1e-3f});
    vec3f a, c1, c2;
    switch (kind) {
      case layout::scattered: {
        vec3f ctr = random_in(rng, {-5, -5, -5}, {5, 5, 5});
        float s = log_uniform(rng, 1e-3f, 1.0f);
        a = ctr + random_unit(rng) * s;
        c1 = ctr + random_unit(rng) * s;
        c2 = ctr + random_unit(rng) * s;
        break;
      }
      case layout::ceiling: {
        float x = float(i % 16), z = float(i / 16);
        a = {x, 3, z};
        c1 = {x + 0.5f, 3, z};
        c2 = {x, 3, z + 0.5f};  // (c1 - a) x (c2 - a) points along -y
        break;
      }
      case layout::coincident: {
        a = {0, 1, 0};
        c1 = {1, 1, 0};
        c2 = {0, 1, 1};
        if (i % 2) std::swap(c1, c2);  // half of them face the other way
        break;
      }
      case layout::clusters: {
        vec3f ctr = cluster_centers[i % 4] + random_in(rng, {-0.1f, -0.1f, -0.1f}, {0.1f, 0.1f, 0.1f});
        float s = log_uniform(rng, 1e-3f, 0.05f);
        a = ctr + random_unit(rng) * s;
        c1 = ctr + random_unit(rng) * s;
        c2 = i == 5 ? a : ctr + random_unit(rng) * s;  // triangle 5: zero area
        break;
      }
    }
    b.add_triangle(a, c1, c2, m);
    if (i % 3 == 0) b.add_triangle(a + vec3f{0, -0.2f, 0}, c2 + vec3f{0, -0.2f, 0}, c1 + vec3f{0, -0.2f, 0}, wall);
  }
  light_set s;
  s.scene = build_scene(std::move(b.mesh), camera_params{}, sun_params{}, two_sided, 1.0f);
  s.lights = build_lights(s.scene);
  s.tree = build_light_tree(s.lights, s.scene);
  return s;
}

// Corners of the triangle of light l (the float expressions the renderer uses).
void light_corners(const light_set& s, int l, vec3f c[3]) {
  int t = s.lights.tri[size_t(l)];
  c[0] = s.scene.tri_p0[size_t(t)];
  c[1] = c[0] + s.scene.tri_e1[size_t(t)];
  c[2] = c[0] + s.scene.tri_e2[size_t(t)];
}

// Leaves below `node` (itself for a leaf).
void leaves_under(const light_tree_data& t, int node, std::vector<int>& out) {
  if (is_leaf(t, node)) {
    out.push_back(node);
    return;
  }
  leaves_under(t, t.left[size_t(node)], out);
  leaves_under(t, t.right[size_t(node)], out);
}

std::string sci(double v) {
  std::ostringstream o;
  o.precision(3);
  o << std::scientific << v;
  return o.str();
}

bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool same_bits(vec3f a, vec3f b) { return same_bits(a.x, b.x) && same_bits(a.y, b.y) && same_bits(a.z, b.z); }
template <class T>
bool same_column(const std::vector<T>& a, const std::vector<T>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); i++)
    if (!same_bits(a[i], b[i])) return false;
  return true;
}
bool same_column(const std::vector<int>& a, const std::vector<int>& b) { return a == b; }

// Every column of two trees bit for bit (the colour column too unless `colors` is false).
void check_same_tree(const light_tree_data& a, const light_tree_data& b, bool colors = true) {
  REQUIRE(node_count(a) == node_count(b));
  CHECK(same_column(a.lo, b.lo));
  CHECK(same_column(a.hi, b.hi));
  CHECK(same_column(a.left, b.left));
  CHECK(same_column(a.right, b.right));
  CHECK(same_column(a.parent, b.parent));
  CHECK(same_column(a.light, b.light));
  CHECK(same_column(a.leaf_of_light, b.leaf_of_light));
  CHECK(same_column(a.left_prob, b.left_prob));
  if (colors) CHECK(same_column(a.color, b.color));
  REQUIRE(a.packed.size() == b.packed.size());
  CHECK(std::memcmp(a.packed.data(), b.packed.data(), a.packed.size() * sizeof(node_pack)) == 0);
  CHECK(a.depth == b.depth);
  CHECK(a.two_sided == b.two_sided);
}

// Angle in double between two (not necessarily unit) vectors.
double angle_between(vec3f a, vec3f b) {
  double ax = a.x, ay = a.y, az = a.z, bx = b.x, by = b.y, bz = b.z;
  double cx = ay * bz - az * by, cy = az * bx - ax * bz, cz = ax * by - ay * bx;
  return std::atan2(std::sqrt(cx * cx + cy * cy + cz * cz), ax * bx + ay * by + az * bz);
}

// Whether an emitter point q with unit normal ne can send light to p (a receiver with normal n, or any normal
// when n is null). Grazing configurations within 1e-5 rad of a tangent plane count as "cannot": the bounds are
// evaluated in float, whose rounding near a tangent plane is of order 1e-7 rad, and such a configuration
// carries at most 1e-5 of the cosine-weighted contribution anyway.
bool can_light(vec3f q, vec3f ne, bool two_sided, vec3f p, const vec3f* n) {
  constexpr double margin = 1e-5;
  double qp[3] = {double(p.x) - q.x, double(p.y) - q.y, double(p.z) - q.z};
  double len = std::sqrt(qp[0] * qp[0] + qp[1] * qp[1] + qp[2] * qp[2]);
  if (!(len > 0)) return false;
  double ce = (ne.x * qp[0] + ne.y * qp[1] + ne.z * qp[2]) / len;
  if (two_sided) ce = std::fabs(ce);
  if (!(ce > margin)) return false;
  if (!n) return true;
  double cr = -(n->x * qp[0] + n->y * qp[1] + n->z * qp[2]) / len;
  return cr > margin;
}

// Points on light l: its corners and `k` uniform samples.
std::vector<vec3f> points_on_light(const light_set& s, int l, pcg32& rng, int k) {
  vec3f c[3];
  light_corners(s, l, c);
  std::vector<vec3f> pts = {c[0], c[1], c[2]};
  int t = s.lights.tri[size_t(l)];
  for (int i = 0; i < k; i++) {
    vec2f bc = sample_triangle(unif(rng), unif(rng));
    pts.push_back(s.scene.tri_p0[size_t(t)] + s.scene.tri_e1[size_t(t)] * bc.x + s.scene.tri_e2[size_t(t)] * bc.y);
  }
  return pts;
}

struct set_case {
  uint64_t seed;
  int n;
  layout kind;
  bool two_sided;
  const char* name;
};
const set_case set_cases[] = {
    {1, 1, layout::scattered, false, "one light"},
    {2, 2, layout::scattered, false, "two lights"},
    {3, 300, layout::scattered, false, "300 scattered"},
    {4, 300, layout::scattered, true, "300 scattered two sided"},
    {5, 256, layout::ceiling, false, "256 ceiling"},
    {6, 200, layout::coincident, false, "200 coincident"},
    {7, 200, layout::clusters, false, "200 in clusters"},
};

// A random box of sides 2e-3..10 whose centre lies in the scene bounds grown by a quarter (and 1) on every side.
bbox3f random_region_box(pcg32& rng, const bbox3f& bounds) {
  vec3f grow = extent(bounds) * 0.25f + vec3f{1, 1, 1};
  vec3f c = random_in(rng, bounds.lo - grow, bounds.hi + grow);
  vec3f half = {log_uniform(rng, 1e-3f, 5.0f), log_uniform(rng, 1e-3f, 5.0f), log_uniform(rng, 1e-3f, 5.0f)};
  return {c - half, c + half};
}

}  // namespace

TEST_CASE("light tree structure holds its invariants on random light sets", "[light_tree]") {
  for (const set_case& sc : set_cases) {
    INFO("set " << sc.name);
    light_set s = make_light_set(sc.seed, sc.n, sc.kind, sc.two_sided);
    const light_tree_data& t = s.tree;
    int n = s.lights.tri_count;
    REQUIRE(n == sc.n);
    REQUIRE(node_count(t) == 2 * n - 1);
    REQUIRE(t.two_sided == sc.two_sided);
    // Every light has exactly one leaf, and the leaf holds it.
    std::vector<int> leaf_seen(size_t(n), 0);
    for (int i = 0; i < node_count(t); i++)
      if (is_leaf(t, i)) {
        REQUIRE(t.light[size_t(i)] >= 0);
        REQUIRE(t.light[size_t(i)] < n);
        leaf_seen[size_t(t.light[size_t(i)])]++;
      }
    for (int l = 0; l < n; l++) {
      REQUIRE(leaf_seen[size_t(l)] == 1);
      int leaf = t.leaf_of_light[size_t(l)];
      REQUIRE(leaf >= 0);
      REQUIRE(leaf < node_count(t));
      REQUIRE(t.light[size_t(leaf)] == l);
    }
    // Parent and children agree; every node but the root is somebody's child exactly once.
    CHECK(t.parent[0] == invalid_id);
    std::vector<int> child_seen(size_t(node_count(t)), 0);
    for (int i = 0; i < node_count(t); i++) {
      size_t k = size_t(i);
      if (is_leaf(t, i)) {
        CHECK(t.left[k] == invalid_id);
        CHECK(t.right[k] == invalid_id);
        continue;
      }
      REQUIRE(t.left[k] > 0);
      REQUIRE(t.right[k] > 0);
      REQUIRE(t.left[k] != t.right[k]);
      REQUIRE(t.parent[size_t(t.left[k])] == i);
      REQUIRE(t.parent[size_t(t.right[k])] == i);
      child_seen[size_t(t.left[k])]++;
      child_seen[size_t(t.right[k])]++;
    }
    CHECK(child_seen[0] == 0);
    for (int i = 1; i < node_count(t); i++) REQUIRE(child_seen[size_t(i)] == 1);
    // Boxes nest, centres and radii describe the boxes, intensities add up.
    for (int i = 0; i < node_count(t); i++) {
      size_t k = size_t(i);
      CHECK(same_bits(node_center(t, i), (t.lo[k] + t.hi[k]) * 0.5f));
      CHECK(node_radius(t, i) == Approx(0.5 * length(t.hi[k] - t.lo[k])).epsilon(1e-6));
      if (is_leaf(t, i)) {
        int l = t.light[k];
        vec3f c[3];
        light_corners(s, l, c);
        for (vec3f v : c)
          for (int a = 0; a < 3; a++) {
            CHECK(t.lo[k][a] <= v[a]);
            CHECK(t.hi[k][a] >= v[a]);
          }
        int tri = s.lights.tri[size_t(l)];
        CHECK(same_bits(node_intensity(t, i), luminance(s.lights.radiance[size_t(l)]) * s.scene.tri_area[size_t(tri)]));
        continue;
      }
      for (int c : {t.left[k], t.right[k]}) {
        for (int a = 0; a < 3; a++) {
          CHECK(t.lo[k][a] <= t.lo[size_t(c)][a]);
          CHECK(t.hi[k][a] >= t.hi[size_t(c)][a]);
        }
      }
      double sum = double(node_intensity(t, t.left[k])) + double(node_intensity(t, t.right[k]));
      CHECK(std::fabs(double(node_intensity(t, i)) - sum) <= 1e-5 * sum);
    }
    // The normal cone of every node contains the normals of all its emitters.
    for (int i = 0; i < node_count(t); i++) {
      CHECK(std::fabs(node_cos_o(t, i) * node_cos_o(t, i) + node_sin_o(t, i) * node_sin_o(t, i) - 1) < 1e-5f);
      CHECK(std::fabs(length(node_axis(t, i)) - 1) < 1e-5f);
      if (node_cos_o(t, i) == -1) continue;  // theta_o = pi: any normal
      double theta_o = std::atan2(double(node_sin_o(t, i)), double(node_cos_o(t, i)));
      std::vector<int> leaves;
      leaves_under(t, i, leaves);
      for (int leaf : leaves) {
        vec3f ng = s.scene.tri_ng[size_t(s.lights.tri[size_t(t.light[size_t(leaf)])])];
        double ang = angle_between(node_axis(t, i), ng);
        INFO("node " << i << " leaf " << leaf << " angle " << ang << " theta_o " << theta_o);
        CHECK(ang <= theta_o + 1e-4);
      }
    }
    // Depth: the recorded depth is the longest root-to-leaf path and within the limit.
    int deepest = 0;
    for (int i = 0; i < node_count(t); i++) {
      if (!is_leaf(t, i)) continue;
      int d = 0;
      for (int m = i; m != 0; m = t.parent[size_t(m)]) d++;
      deepest = std::max(deepest, d);
    }
    CHECK(deepest == t.depth);
    CHECK(t.depth <= max_tree_depth);
    // Deterministic: a second build is bit-identical.
    check_same_tree(t, build_light_tree(s.lights, s.scene));
  }
}

TEST_CASE("a light tree built by parallel tasks does not depend on the thread count", "[light_tree]") {
  // 10000 lights: ranges over 4096 build their halves and bin their axes in parallel tasks.
  light_set s = make_light_set(8, 10000, layout::scattered, false);
  light_tree_data one;
  {
    tbb::global_control serial(tbb::global_control::max_allowed_parallelism, 1);
    one = build_light_tree(s.lights, s.scene);
  }
  tbb::global_control two(tbb::global_control::max_allowed_parallelism, 2);
  check_same_tree(build_light_tree(s.lights, s.scene), one);
}

TEST_CASE("a node's colour is its lights' RGB intensity over their luminance intensity", "[light_tree]") {
  // Lights of random colours: each node's colour times its intensity is the sum of its lights' radiance times area
  // (luminance 1 for a node that emits). Built without colours (every sampler but bayes), the column is empty and
  // every other column the same.
  light_set s = make_light_set(5, 3000, layout::scattered, false);
  light_tree_data t = build_light_tree(s.lights, s.scene);
  REQUIRE(t.color.size() == t.light.size());
  for (int i = 0; i < node_count(t); i++) {
    std::vector<int> leaves;
    leaves_under(t, i, leaves);
    double rgb[3] = {0, 0, 0};
    for (int leaf : leaves) {
      int l = t.light[size_t(leaf)];
      vec3f e = s.lights.radiance[size_t(l)] * s.scene.tri_area[size_t(s.lights.tri[size_t(l)])];
      for (int c = 0; c < 3; c++) rgb[c] += double(e[c]);
    }
    vec3f col = t.color[size_t(i)];
    INFO("node " << i << " of " << leaves.size() << " lights");
    CHECK(double(luminance(col)) == Approx(1).epsilon(1e-4));
    for (int c = 0; c < 3; c++)
      CHECK(double(col[c]) * double(node_intensity(t, i)) == Approx(rgb[c]).epsilon(1e-3).margin(1e-30));
  }
  light_tree_data bare = build_light_tree(s.lights, s.scene, false);
  CHECK(bare.color.empty());
  check_same_tree(bare, t, false);
}

TEST_CASE("a scene without emitters has an empty light tree", "[light_tree]") {
  mesh_builder b;
  int wall = b.add_material({0.5f, 0.5f, 0.5f});
  b.add_quad({0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}, wall);
  scene_data scene = build_scene(std::move(b.mesh), camera_params{}, sun_params{}, false, 1.0f);
  light_data lights = build_lights(scene);
  light_tree_data t = build_light_tree(lights, scene);
  CHECK(node_count(t) == 0);
  CHECK(t.leaf_of_light.empty());
}

TEST_CASE("intensity descent samples leaves with the probability its pmf states", "[light_tree]") {
  const int samples = 200000;
  for (const set_case& sc : set_cases) {
    if (sc.n < 2) continue;
    light_set s = make_light_set(sc.seed, sc.n, sc.kind, sc.two_sided);
    const light_tree_data& t = s.tree;
    pcg32 rng(sc.seed, 11);
    // From the root and from three interior nodes picked at random.
    std::vector<int> starts = {0};
    while (starts.size() < 4) {
      int i = int(rng(uint32_t(node_count(t))));
      if (!is_leaf(t, i)) starts.push_back(i);
    }
    for (int start : starts) {
      INFO("set " << sc.name << " start node " << start);
      std::vector<int> leaves;
      leaves_under(t, start, leaves);
      std::vector<int> bin(size_t(node_count(t)), -1);
      for (size_t j = 0; j < leaves.size(); j++) bin[size_t(leaves[j])] = int(j);
      std::vector<double> obs(leaves.size(), 0.0), exp(leaves.size(), 0.0);
      double total = 0;
      int starved = 0;
      std::string which;
      for (size_t j = 0; j < leaves.size(); j++) {
        double pmf = intensity_descent_pmf(t, start, leaves[j]);
        CHECK(pmf >= 0);
        // Unbiasedness inside a cluster: a light with positive intensity keeps a positive probability.
        if (node_intensity(t, leaves[j]) > 0 && !(pmf > 0)) {
          starved++;
          if (starved <= 3)
            which += " leaf " + std::to_string(leaves[j]) + " (intensity " +
                     sci(node_intensity(t, leaves[j])) + ", sibling " +
                     sci(node_intensity(t, t.left[size_t(t.parent[size_t(leaves[j])])] == leaves[j]
                                               ? t.right[size_t(t.parent[size_t(leaves[j])])]
                                               : t.left[size_t(t.parent[size_t(leaves[j])])])) +
                     ")";
        }
        exp[j] = samples * double(pmf);
        total += pmf;
      }
      CHECK(std::fabs(total - 1) < 1e-5);
      INFO("leaves with positive intensity but descent probability 0:" << which);
      CHECK(starved == 0);
      int mismatches = 0, outside = 0;
      for (int i = 0; i < samples; i++) {
        double prob = -1;
        int leaf = sample_by_intensity(t, start, unif(rng), prob);
        if (leaf < 0 || leaf >= node_count(t) || bin[size_t(leaf)] < 0) {
          outside++;
          continue;
        }
        // Bitwise equality: MIS and the cut sampler rely on it.
        if (!same_bits(prob, intensity_descent_pmf(t, start, leaf))) mismatches++;
        obs[size_t(bin[size_t(leaf)])] += 1;
      }
      CHECK(outside == 0);
      CHECK(mismatches == 0);
      CHECK(chi2_pvalue(obs, exp) > alpha);
    }
    // A leaf outside the start node's subtree has pmf 0.
    if (!is_leaf(t, 0)) {
      int l = t.left[0], r = t.right[0];
      std::vector<int> right_leaves;
      leaves_under(t, r, right_leaves);
      CHECK(intensity_descent_pmf(t, l, right_leaves[0]) == 0);
    }
  }
}

TEST_CASE("node importance is zero only for nodes that cannot light the point", "[light_tree]") {
  // For every (p, n) and every node whose importance is 0, no sampled point of any emitter below the node
  // may face p from above p's tangent plane (see can_light for the grazing margin).
  for (const set_case& sc : set_cases) {
    light_set s = make_light_set(sc.seed, sc.n, sc.kind, sc.two_sided);
    const light_tree_data& t = s.tree;
    pcg32 rng(sc.seed, 13);
    bbox3f bounds = s.scene.bounds;
    vec3f grow = extent(bounds) * 0.5f + vec3f{1, 1, 1};
    // Emitter points per light, shared by all receivers (corners plus 8 samples).
    std::vector<std::vector<vec3f>> pts(size_t(s.lights.tri_count));
    for (int l = 0; l < s.lights.tri_count; l++) pts[size_t(l)] = points_on_light(s, l, rng, 8);
    int zeros = 0, violations = 0;
    const int receivers = sc.n > 100 ? 150 : 400;
    for (int k = 0; k < receivers; k++) {
      vec3f p;
      if (k % 2 == 0) {
        p = random_in(rng, bounds.lo - grow, bounds.hi + grow);
      } else {
        // Close to an emitter: a point of a random light moved a little.
        int l = int(rng(uint32_t(s.lights.tri_count)));
        p = pts[size_t(l)][3] + random_unit(rng) * log_uniform(rng, 1e-4f, 1.0f);
      }
      vec3f n = random_unit(rng);
      for (int node = 0; node < node_count(t); node++) {
        float imp = node_importance(t, node, p, n);
        REQUIRE(std::isfinite(imp));
        REQUIRE(imp >= 0);
        if (imp > 0) continue;
        zeros++;
        std::vector<int> leaves;
        leaves_under(t, node, leaves);
        for (int leaf : leaves) {
          int l = t.light[size_t(leaf)];
          vec3f ne = s.scene.tri_ng[size_t(s.lights.tri[size_t(l)])];
          if (s.scene.tri_area[size_t(s.lights.tri[size_t(l)])] == 0) continue;  // emits nothing
          for (vec3f q : pts[size_t(l)])
            if (can_light(q, ne, t.two_sided, p, &n)) {
              violations++;
              UNSCOPED_INFO("set " << sc.name << " node " << node << " light " << l << " p " << p.x << " " << p.y
                                   << " " << p.z << " n " << n.x << " " << n.y << " " << n.z);
              break;
            }
        }
      }
    }
    INFO("set " << sc.name << ": " << zeros << " zero-importance (node, point) pairs checked");
    CHECK(violations == 0);
  }
}

TEST_CASE("the four-wide node bounds are the scalar node importance, bit for bit", "[light_tree]") {
  // eval_node_bounds (SSE, what bound and bayes weigh clusters by) promises node_importance_parts's bits; the bound
  // and bayes samplers share it, so comparing them could not see a factor it dropped (a mutation review: the
  // receiver's cosine bound left out was caught by two ablation tests only).
  for (const set_case& sc : set_cases) {
    light_set s = make_light_set(sc.seed, sc.n, sc.kind, sc.two_sided);
    const light_tree_data& t = s.tree;
    if (node_count(t) == 0) continue;
    pcg32 rng(sc.seed, 17);
    bbox3f bounds = s.scene.bounds;
    vec3f grow = extent(bounds) * 0.5f + vec3f{1, 1, 1};
    std::vector<int> nodes(size_t(node_count(t)));
    for (int k = 0; k < node_count(t); k++) nodes[size_t(k)] = k;
    std::vector<float> num(nodes.size() + 4), inv(nodes.size() + 4);
    int mismatches = 0;
    for (int k = 0; k < 100; k++) {
      vec3f p = random_in(rng, bounds.lo - grow, bounds.hi + grow), n = random_unit(rng);
      // Every node, in runs of each length mod 4 (the SSE loop's tail).
      int count = node_count(t) - int(rng(4u)) % std::max(1, node_count(t));
      eval_node_bounds(t, nodes.data(), count, p, n, num.data(), inv.data());
      for (int j = 0; j < count; j++) {
        float ref_inv;
        float ref = node_importance_parts(t, nodes[size_t(j)], p, n, ref_inv);
        if (std::memcmp(&ref, &num[size_t(j)], 4) != 0 || std::memcmp(&ref_inv, &inv[size_t(j)], 4) != 0) {
          if (mismatches++ == 0)
            UNSCOPED_INFO("set " << sc.name << " node " << j << ": " << num[size_t(j)] << " / " << inv[size_t(j)]
                                 << " against " << ref << " / " << ref_inv);
        }
      }
    }
    INFO("set " << sc.name);
    CHECK(mismatches == 0);
  }
}

TEST_CASE("node region bounds are zero only for nodes that cannot light the box", "[light_tree]") {
  for (const set_case& sc : set_cases) {
    light_set s = make_light_set(sc.seed, sc.n, sc.kind, sc.two_sided);
    const light_tree_data& t = s.tree;
    pcg32 rng(sc.seed, 17);
    bbox3f bounds = s.scene.bounds;
    vec3f grow = extent(bounds) * 0.5f + vec3f{1, 1, 1};
    std::vector<std::vector<vec3f>> pts(size_t(s.lights.tri_count));
    for (int l = 0; l < s.lights.tri_count; l++) pts[size_t(l)] = points_on_light(s, l, rng, 8);
    int zeros = 0, violations = 0;
    for (int k = 0; k < 120; k++) {
      vec3f c = random_in(rng, bounds.lo - grow, bounds.hi + grow);
      vec3f half = {log_uniform(rng, 1e-3f, 3.0f), log_uniform(rng, 1e-3f, 3.0f), log_uniform(rng, 1e-3f, 3.0f)};
      vec3f lo = c - half, hi = c + half;
      // Points of the box: its corners and random interior points.
      std::vector<vec3f> ps;
      for (int i = 0; i < 8; i++) ps.push_back({i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z});
      for (int i = 0; i < 24; i++) ps.push_back(random_in(rng, lo, hi));
      for (int node = 0; node < node_count(t); node++) {
        float bound = node_region_bound(t, node, lo, hi);
        REQUIRE(std::isfinite(bound));
        REQUIRE(bound >= 0);
        if (bound > 0) continue;
        zeros++;
        std::vector<int> leaves;
        leaves_under(t, node, leaves);
        for (int leaf : leaves) {
          int l = t.light[size_t(leaf)];
          if (s.scene.tri_area[size_t(s.lights.tri[size_t(l)])] == 0) continue;
          vec3f ne = s.scene.tri_ng[size_t(s.lights.tri[size_t(l)])];
          bool bad = false;
          for (vec3f p : ps)
            for (vec3f q : pts[size_t(l)])
              if (!bad && can_light(q, ne, t.two_sided, p, nullptr)) bad = true;
          if (bad) {
            violations++;
            UNSCOPED_INFO("set " << sc.name << " node " << node << " light " << l << " box " << lo.x << " " << lo.y
                                 << " " << lo.z << " .. " << hi.x << " " << hi.y << " " << hi.z);
          }
        }
      }
    }
    INFO("set " << sc.name << ": " << zeros << " zero-bound (node, box) pairs checked");
    CHECK(violations == 0);
  }
}

TEST_CASE("a light cut partitions the lights that can reach its box", "[light_tree]") {
  for (const set_case& sc : set_cases) {
    light_set s = make_light_set(sc.seed, sc.n, sc.kind, sc.two_sided);
    const light_tree_data& t = s.tree;
    pcg32 rng(sc.seed, 19);
    for (int k = 0; k < 60; k++) {
      bbox3f box = random_region_box(rng, s.scene.bounds);
      region_params p;
      const int max_cuts[] = {1, 2, 8, 64};
      p.max_cut = max_cuts[k % 4];
      p.cut_threshold = k % 3 == 0 ? 0.0f : 0.005f;
      p.coherence = k % 5 == 0 ? 0.0f : 0.25f;
      bool has_sun = k % 2 == 1;
      INFO("set " << sc.name << " box " << k << " max_cut " << p.max_cut << " sun " << has_sun);
      std::vector<int> cut = compute_light_cut(t, box, has_sun, p);
      CHECK(cut == compute_light_cut(t, box, has_sun, p));
      REQUIRE(int(cut.size()) <= p.max_cut + (has_sun ? 1 : 0));
      if (has_sun) {
        REQUIRE(!cut.empty());
        CHECK(cut.back() == sun_cluster);
        cut.pop_back();
      }
      // Sorted tree nodes, no duplicates.
      for (size_t j = 0; j < cut.size(); j++) {
        REQUIRE(cut[j] >= 0);
        REQUIRE(cut[j] < node_count(t));
        if (j > 0) CHECK(cut[j - 1] < cut[j]);
      }
      std::vector<char> in_cut(size_t(node_count(t)), 0);
      for (int nd : cut) in_cut[size_t(nd)] = 1;
      // Every leaf: exactly one cut node on its path to the root, or none and then a node on that path whose
      // region bound is 0 (left out because it cannot light the box).
      for (int l = 0; l < s.lights.tri_count; l++) {
        int covered = 0;
        bool zero_bound = false;
        for (int m = t.leaf_of_light[size_t(l)]; m != invalid_id; m = t.parent[size_t(m)]) {
          covered += in_cut[size_t(m)];
          if (node_region_bound(t, m, box.lo, box.hi) == 0) zero_bound = true;
        }
        INFO("light " << l);
        CHECK(covered <= 1);
        if (covered == 0) CHECK(zero_bound);
      }
    }
  }
}

TEST_CASE("members refined under a smaller limit are the same, or reach that limit", "[light_tree]") {
  // add_regions refines a region's members only up to one more than the pairs left in the budget: exact only if a
  // refinement that ends below its limit is the one a larger limit gives, and one that would go past it stops at it.
  for (const set_case& sc : set_cases) {
    light_set s = make_light_set(sc.seed, sc.n, sc.kind, sc.two_sided);
    const light_tree_data& t = s.tree;
    pcg32 rng(sc.seed, 29);
    for (int k = 0; k < 20; k++) {
      bbox3f box = random_region_box(rng, s.scene.bounds);
      region_params p;
      p.max_cut = k % 2 ? 8 : 64;
      std::vector<int> cut = compute_light_cut(t, box, k % 3 == 1, p);
      std::vector<int> full, full_group;
      compute_members(t, box, cut, 1024, full, full_group);
      int n = int(full.size());
      for (int limit : {int(cut.size()), int(cut.size()) + 1, n / 2 + 1, n - 1, n, n + 1, 1023}) {
        if (limit < 1) continue;
        std::vector<int> m, g;
        compute_members(t, box, cut, limit, m, g);
        INFO("set " << sc.name << " box " << k << ": " << n << " members in full, limit " << limit);
        if (n < limit) {
          CHECK(m == full);
          CHECK(g == full_group);
        } else {
          CHECK(int(m.size()) == std::max(limit, int(cut.size())));
        }
      }
    }
  }
}

TEST_CASE("a cut's members partition its clusters' lights that can reach the box", "[light_tree]") {
  for (const set_case& sc : set_cases) {
    light_set s = make_light_set(sc.seed, sc.n, sc.kind, sc.two_sided);
    const light_tree_data& t = s.tree;
    pcg32 rng(sc.seed, 23);
    for (int k = 0; k < 40; k++) {
      bbox3f box = random_region_box(rng, s.scene.bounds);
      region_params p;
      const int max_cuts[] = {1, 2, 8, 64};
      p.max_cut = max_cuts[k % 4];
      bool has_sun = k % 2 == 1;
      std::vector<int> cut = compute_light_cut(t, box, has_sun, p);
      const int caps[] = {0, int(cut.size()), 16, 64, 1024};
      for (int cap : caps) {
        INFO("set " << sc.name << " box " << k << " max_cut " << p.max_cut << " sun " << has_sun << " members " << cap);
        std::vector<int> members, group, again, group2;
        compute_members(t, box, cut, cap, members, group);
        compute_members(t, box, cut, cap, again, group2);
        CHECK(members == again);
        CHECK(group == group2);
        REQUIRE(members.size() == group.size());
        CHECK(members.size() <= std::max(cut.size(), size_t(cap)));
        CHECK(members.size() >= cut.size());
        if (cap <= int(cut.size())) CHECK(members == cut);
        // Sorted like the cut (sun last), clusters in cut order, each cluster at least one member that is its node
        // or a node of its subtree.
        for (size_t j = 0; j < members.size(); j++) {
          REQUIRE(group[j] >= 0);
          REQUIRE(group[j] < int(cut.size()));
          if (j > 0) {
            CHECK(group[j - 1] <= group[j]);
            CHECK(group[j] - group[j - 1] <= 1);
            if (members[j] != sun_cluster) CHECK(members[j - 1] < members[j]);
          }
          int g = cut[size_t(group[j])];
          if (g == sun_cluster) {
            CHECK(members[j] == sun_cluster);
            CHECK(j + 1 == members.size());
            continue;
          }
          REQUIRE(members[j] >= 0);
          REQUIRE(members[j] < node_count(t));
          bool below = false;
          for (int m = members[j]; m != invalid_id && !below; m = t.parent[size_t(m)]) below = m == g;
          CHECK(below);
        }
        if (!group.empty()) {
          CHECK(group.front() == 0);
          CHECK(group.back() == int(cut.size()) - 1);
        }
        // Every light under a tree cluster: exactly one member on its path, or none and then a node of zero bound
        // between it and the cluster (it cannot light the box). With room for every light, members are leaves.
        std::vector<char> is_member(size_t(node_count(t)), 0), is_cluster(size_t(node_count(t)), 0);
        for (int m : members)
          if (m != sun_cluster) is_member[size_t(m)] = 1;
        for (int g : cut)
          if (g != sun_cluster) is_cluster[size_t(g)] = 1;
        for (int l = 0; l < s.lights.tri_count; l++) {
          int covered = 0;
          bool zero_bound = false, under_cluster = false;
          for (int m = t.leaf_of_light[size_t(l)]; m != invalid_id && !under_cluster; m = t.parent[size_t(m)]) {
            covered += is_member[size_t(m)];
            if (node_region_bound(t, m, box.lo, box.hi) == 0) zero_bound = true;
            under_cluster = is_cluster[size_t(m)];
          }
          if (!under_cluster) continue;
          INFO("light " << l);
          CHECK(covered <= 1);
          if (covered == 0) CHECK(zero_bound);
        }
        // With room for every light, a member is a leaf, or a node kept whole because both its children have bound
        // 0 over the box (bounds need not shrink monotonically down the tree: a node's wider cone can reach the box
        // where neither child's does).
        if (cap >= 1024)
          for (int m : members)
            if (m != sun_cluster && !is_leaf(t, m)) {
              CHECK(node_region_bound(t, t.left[size_t(m)], box.lo, box.hi) == 0);
              CHECK(node_region_bound(t, t.right[size_t(m)], box.lo, box.hi) == 0);
            }
      }
    }
  }
}
