// light_tree: binned SAOH build (12 bins per axis; cost = intensity * M_omega(cone) * surface area, as in
// Conty Estevez & Kulla 2018), normal-cone unions, region bounds and intensity descent.
#include "light_tree.h"

#include <algorithm>
#include <numeric>

#include <tbb/parallel_invoke.h>

namespace bl {

namespace {

// A normal cone (axis, half-angle theta, with its cosine and sine) during the build; empty cones hold no
// direction yet.
struct cone_bound {
  vec3f axis = {0, 0, 1};
  float theta = 0, cos_t = 1, sin_t = 0;
  bool empty = true;
};
cone_bound make_cone(vec3f axis, float theta) {
  if (theta >= pi_f) return {axis, pi_f, -1, 0, false};
  return {axis, theta, std::cos(theta), std::sin(theta), false};
}

// The smallest cone (Conty-Kulla's union) containing both cones.
cone_bound cone_union(cone_bound a, cone_bound b) {
  if (a.empty) return b;
  if (b.empty) return a;
  if (b.theta > a.theta) std::swap(a, b);
  if (a.theta >= pi_f) return a;
  // Containment without inverse trigonometry (the common case while binning): the angle between the axes is at
  // most theta_a - theta_b, i.e. its cosine is at least cos(theta_a - theta_b).
  float cos_d = dot(a.axis, b.axis);
  if (cos_d >= a.cos_t * b.cos_t + a.sin_t * b.sin_t) return a;
  float theta_d = safe_acos(cos_d);
  if (std::min(theta_d + b.theta, pi_f) <= a.theta) return a;
  float theta = 0.5f * (a.theta + theta_d + b.theta);
  if (theta >= pi_f) return make_cone(a.axis, pi_f);
  float theta_r = theta - a.theta;
  vec3f wr = cross(a.axis, b.axis);
  if (!(length_sq(wr) > 0)) return make_cone(a.axis, pi_f);
  wr = normalize(wr);
  // Rotate a.axis by theta_r toward b.axis (a.axis is perpendicular to wr).
  vec3f axis = normalize(a.axis * std::cos(theta_r) + cross(wr, a.axis) * std::sin(theta_r));
  return make_cone(axis, theta);
}

// Bounds of a set of emitters during the build.
struct build_bounds {
  bbox3f box;
  cone_bound cone;
  float intensity = 0;
};
// a = the bounds of a and b, in place: cone_union(a.cone, b.cone) without copying cones where it returns one of
// them (the common case; the same result bit for bit).
void merge_into(build_bounds& a, const build_bounds& b) {
  a.box = merge(a.box, b.box);
  a.intensity += b.intensity;
  if (b.cone.empty) return;
  if (!a.cone.empty) {
    const bool b_wider = b.cone.theta > a.cone.theta;  // (cone_union's swap)
    const cone_bound& wide = b_wider ? b.cone : a.cone;
    const cone_bound& narrow = b_wider ? a.cone : b.cone;
    if (!(wide.theta >= pi_f) &&
        !(dot(wide.axis, narrow.axis) >= wide.cos_t * narrow.cos_t + wide.sin_t * narrow.sin_t)) {
      a.cone = cone_union(a.cone, b.cone);
      return;
    }
    if (!b_wider) return;  // a's cone holds b's
  }
  a.cone = b.cone;
}

float surface_area(const bbox3f& b) {
  if (is_empty(b)) return 0;
  vec3f e = extent(b);
  return 2 * (e.x * e.y + e.y * e.z + e.z * e.x);
}

// Orientation measure M_omega of a cone (theta_e = pi / 2 for diffuse emitters).
float orientation_measure(const cone_bound& c) {
  float theta_o = c.theta, theta_e = 0.5f * pi_f;
  float theta_w = std::min(theta_o + theta_e, pi_f);
  // (make_cone's cosine and sine below pi; at pi it holds 0 for the sine, where this measure has always taken sin(pi))
  float so = theta_o < pi_f ? c.sin_t : std::sin(theta_o), co = theta_o < pi_f ? c.cos_t : std::cos(theta_o);
  return 2 * pi_f * (1 - co) +
         0.5f * pi_f * (2 * theta_w * so - std::cos(theta_o - 2 * theta_w) - 2 * theta_o * so + co);
}

float split_cost(const build_bounds& b) {
  return b.intensity * orientation_measure(b.cone) * std::max(surface_area(b.box), 1e-30f);
}

// Per-light inputs of the build.
struct build_item {
  build_bounds bounds;
  vec3f centroid;
  int light;
};

struct builder {
  light_tree_data& t;
  std::vector<build_item>& items;
  static constexpr int parallel_items = 4096;  // larger ranges are split and binned by parallel tasks

  // Builds the subtree over items [b, e) as node `node` (depth-first numbering: its left child is node + 1, its
  // right child node + 2 (mid - b), since a subtree over k items has 2k - 1 nodes) and returns its depth. Large
  // subtrees are built in parallel: ids are fixed in advance and each half touches only its own items and
  // nodes, so the tree does not depend on the thread count.
  int build(int b, int e, int node, int parent, int depth) {
    t.parent[size_t(node)] = parent;
    build_bounds bounds;
    bbox3f cbox;
    for (int i = b; i < e; i++) {
      merge_into(bounds, items[size_t(i)].bounds);
      cbox = merge(cbox, items[size_t(i)].centroid);
    }
    store(node, bounds);
    if (e - b == 1) {
      int l = items[size_t(b)].light;
      t.light[size_t(node)] = l;
      t.leaf_of_light[size_t(l)] = node;
      return depth;
    }
    int mid = split(b, e, bounds, cbox, depth);
    int left = node + 1, right = node + 2 * (mid - b);
    t.left[size_t(node)] = left;
    t.right[size_t(node)] = right;
    int dl = 0, dr = 0;
    if (e - b > parallel_items) {
      tbb::parallel_invoke([&] { dl = build(b, mid, left, node, depth + 1); },
                           [&] { dr = build(mid, e, right, node, depth + 1); });
    } else {
      dl = build(b, mid, left, node, depth + 1);
      dr = build(mid, e, right, node, depth + 1);
    }
    return std::max(dl, dr);
  }

  void store(int node, const build_bounds& bb) {
    size_t i = size_t(node);
    t.lo[i] = bb.box.lo;
    t.hi[i] = bb.box.hi;
    vec3f c = center(bb.box);
    vec3f a = bb.cone.axis;
    // (make_cone's cosine and sine of theta: -1 and 0 at pi)
    t.packed[i] = {c.x, c.y, c.z, 0.5f * diagonal(bb.box), a.x, a.y, a.z, bb.cone.cos_t, bb.cone.sin_t, bb.intensity,
                   0, 0};
  }

  // Chooses the split of items [b, e) and partitions them; returns the first index of the right half.
  // Below depth max_sah_depth only median splits are made, so the depth stays under max_tree_depth.
  int split(int b, int e, const build_bounds& bounds, const bbox3f& cbox, int depth) {
    constexpr int bins = 12;
    vec3f ext = extent(bounds.box);
    float max_ext = max_component(ext);
    float best_cost = inf_f;
    int best_axis = -1, best_bin = -1;
    // Each axis's bins (in item order, whichever thread fills them: the same bins on any thread count).
    build_bounds bins_of[3][bins];
    auto fill = [&](int axis) {
      float lo = cbox.lo[axis], hi = cbox.hi[axis];
      if (!(hi > lo)) return;
      for (int i = b; i < e; i++) {
        int k = std::min(bins - 1, int(bins * ((items[size_t(i)].centroid[axis] - lo) / (hi - lo))));
        merge_into(bins_of[axis][k], items[size_t(i)].bounds);
      }
    };
    if (depth >= max_sah_depth) {
      // median splits only (below): no bins
    } else if (e - b > parallel_items) {
      tbb::parallel_invoke([&] { fill(0); }, [&] { fill(1); }, [&] { fill(2); });
    } else {
      fill(0), fill(1), fill(2);
    }
    for (int axis = 0; axis < 3 && depth < max_sah_depth; axis++) {
      float lo = cbox.lo[axis], hi = cbox.hi[axis];
      if (!(hi > lo)) continue;
      const build_bounds* bin = bins_of[axis];
      build_bounds below[bins];
      build_bounds acc;
      for (int k = 0; k < bins; k++) merge_into(acc, bin[k]), below[k] = acc;
      acc = {};
      // Kr penalises thin slabs along the split axis (pbrt-v4's regularisation).
      float kr = ext[axis] > 0 ? max_ext / ext[axis] : 1.0f;
      for (int k = bins - 1; k >= 1; k--) {
        merge_into(acc, bin[k]);
        if (below[k - 1].intensity == 0 && is_empty(below[k - 1].box)) continue;
        if (is_empty(acc.box)) continue;
        float cost = kr * (split_cost(below[k - 1]) + split_cost(acc));
        if (cost < best_cost) best_cost = cost, best_axis = axis, best_bin = k;
      }
    }
    int mid = b;
    if (best_axis >= 0) {
      float lo = cbox.lo[best_axis], hi = cbox.hi[best_axis];
      auto first = items.begin() + b, last = items.begin() + e;
      mid = int(std::partition(first, last, [&](const build_item& it) {
                  int k = std::min(bins - 1, int(bins * ((it.centroid[best_axis] - lo) / (hi - lo))));
                  return k < best_bin;
                }) - items.begin());
    }
    if (mid == b || mid == e) {
      // No useful split (coincident centroids): halve by (centroid on the widest axis, light index).
      int axis = 0;
      vec3f ce = extent(cbox);
      if (ce.y > ce[axis]) axis = 1;
      if (ce.z > ce[axis]) axis = 2;
      mid = (b + e) / 2;
      std::nth_element(items.begin() + b, items.begin() + mid, items.begin() + e,
                       [axis](const build_item& x, const build_item& y) {
                         if (x.centroid[axis] != y.centroid[axis]) return x.centroid[axis] < y.centroid[axis];
                         return x.light < y.light;
                       });
    }
    return mid;
  }
};

// Squared distance between two boxes (0 when they overlap).
float box_distance_sq(vec3f alo, vec3f ahi, vec3f blo, vec3f bhi) {
  float d2 = 0;
  for (int k = 0; k < 3; k++) {
    float gap = std::max(0.0f, std::max(alo[k] - bhi[k], blo[k] - ahi[k]));
    d2 += gap * gap;
  }
  return d2;
}

// Emission colour per node: RGB intensity over luminance intensity, white where a node emits nothing. Children
// before parents: depth-first ids put every child after its parent, so a walk down the ids sums them in order.
std::vector<vec3f> node_colors(const light_tree_data& t, const light_data& lights, const scene_data& scene) {
  size_t nodes = t.light.size();
  std::vector<vec3f> rgb(nodes, vec3f{0, 0, 0});
  for (size_t v = nodes; v-- > 0;) {
    if (t.light[v] != invalid_id) {
      int l = t.light[v];
      rgb[v] = lights.radiance[size_t(l)] * scene.tri_area[size_t(lights.tri[size_t(l)])];
    } else {
      rgb[v] = rgb[size_t(t.left[v])] + rgb[size_t(t.right[v])];
    }
  }
  for (size_t v = 0; v < nodes; v++) {  // in place: each entry is read once, where it is written
    float y = luminance(rgb[v]);
    rgb[v] = y > 0 ? rgb[v] / y : vec3f{1, 1, 1};
  }
  return rgb;
}

}  // namespace

light_tree_data build_light_tree(const light_data& lights, const scene_data& scene, bool colors) {
  light_tree_data t;
  t.two_sided = lights.two_sided;
  int n = lights.tri_count;
  t.leaf_of_light.assign(size_t(n), invalid_id);
  if (n == 0) return t;
  std::vector<build_item> items(static_cast<size_t>(n));
  for (int l = 0; l < n; l++) {
    int tri = lights.tri[size_t(l)];
    vec3f p0 = scene.tri_p0[size_t(tri)];
    vec3f p1 = p0 + scene.tri_e1[size_t(tri)], p2 = p0 + scene.tri_e2[size_t(tri)];
    build_item& it = items[size_t(l)];
    it.bounds.box = merge(merge(merge(bbox3f{}, p0), p1), p2);
    it.bounds.cone = make_cone(scene.tri_ng[size_t(tri)], lights.two_sided ? pi_f : 0.0f);
    it.bounds.intensity = luminance(lights.radiance[size_t(l)]) * scene.tri_area[size_t(tri)];
    it.centroid = center(it.bounds.box);
    it.light = l;
  }
  size_t nodes = size_t(2 * n - 1);
  t.lo.resize(nodes);
  t.hi.resize(nodes);
  t.packed.resize(nodes);
  t.left.assign(nodes, invalid_id);
  t.right.assign(nodes, invalid_id);
  t.parent.assign(nodes, invalid_id);
  t.light.assign(nodes, invalid_id);
  builder bld{t, items};
  t.depth = bld.build(0, n, 0, invalid_id, 0);
  std::vector<build_item>().swap(items);  // (the peak of a large build: not held with the colour pass's arrays)
  if (colors) t.color = node_colors(t, lights, scene);
  // Descent probabilities once per node (the same double expression the descent used to evaluate per visit).
  t.left_prob.assign(nodes, 0.0);
  for (size_t i = 0; i < nodes; i++)
    if (t.light[i] == invalid_id)
      t.left_prob[i] = left_share(node_intensity(t, t.left[i]), node_intensity(t, t.right[i]));
  return t;
}

// Emitter cos bound of a node over the directions between its bounding sphere and the box's.
static float emitter_cos_toward_box(const light_tree_data& t, int node, vec3f lo, vec3f hi) {
  vec3f cb = (lo + hi) * 0.5f;
  float rb = 0.5f * length(hi - lo);
  vec3f to_b = cb - node_center(t, node);
  float d = length(to_b);
  float r = rb + node_radius(t, node);
  float sin_b = 0, cos_b = -1;
  if (d > r) {
    sin_b = r / d;
    cos_b = safe_sqrt(1 - sin_b * sin_b);
  }
  vec3f w = d > 0 ? to_b / d : vec3f{0, 0, 1};
  return node_emitter_cos_bound(t, node, w, sin_b, cos_b);
}

float node_region_intensity(const light_tree_data& t, int node, vec3f lo, vec3f hi) {
  return node_intensity(t, node) * emitter_cos_toward_box(t, node, lo, hi);
}

float node_region_bound(const light_tree_data& t, int node, vec3f lo, vec3f hi) {
  size_t i = size_t(node);
  float rb = 0.5f * length(hi - lo);
  float ce = emitter_cos_toward_box(t, node, lo, hi);
  if (ce == 0) return 0;
  float d2 = box_distance_sq(lo, hi, t.lo[i], t.hi[i]);
  return node_intensity(t, node) * ce / std::max(d2, rb * rb);
}

// Probability of taking the left child of an interior node when descending by intensity.
static double left_probability(const light_tree_data& t, int node) { return t.left_prob[size_t(node)]; }

double intensity_descent_pmf(const light_tree_data& t, int node, int leaf) {
  // Collect the path bottom-up, then multiply top-down: the same products as sample_by_intensity.
  int path[max_tree_depth + 1];
  int len = 0;
  for (int n = leaf; n != node; n = t.parent[size_t(n)]) {
    if (n == invalid_id || len > max_tree_depth) return 0;  // leaf is not below node
    path[len++] = n;
  }
  double prob = 1;
  for (int k = len - 1; k >= 0; k--) {
    int child = path[k], p = t.parent[size_t(child)];
    double pl = left_probability(t, p);
    prob *= t.left[size_t(p)] == child ? pl : 1 - pl;
  }
  return prob;
}

int sample_by_intensity(const light_tree_data& t, int node, double u, double& prob) {
  prob = 1;
  while (!is_leaf(t, node)) {
    double pl = left_probability(t, node);
    if (u < pl) {
      u = std::min(u / pl, 0x1.fffffffffffffp-1);
      prob *= pl;
      node = t.left[size_t(node)];
    } else {
      u = std::min((u - pl) / (1 - pl), 0x1.fffffffffffffp-1);
      prob *= 1 - pl;
      node = t.right[size_t(node)];
    }
  }
  return node;
}

}  // namespace bl
