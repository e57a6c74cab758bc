// region_grid: grid levels, keys, the lookup table, region creation under a pair budget, and light cuts.
#include "region_grid.h"

#include "rng.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <queue>
#include <unordered_set>

#include <tbb/parallel_for.h>

namespace bl {

namespace {

// Key layout: 2 bits level | 20 bits k | 21 bits j | 21 bits i (cells per axis are capped at 2^20).
constexpr int max_cells_per_axis = 1 << 20;

uint64_t make_key(int level, int i, int j, int k) {
  return (uint64_t(level) << 62) | (uint64_t(k) << 42) | (uint64_t(j) << 21) | uint64_t(i);
}
int key_level(uint64_t key) { return int(key >> 62); }
void key_cell(uint64_t key, int& i, int& j, int& k) {
  i = int(key & 0x1fffff);
  j = int((key >> 21) & 0x1fffff);
  k = int((key >> 42) & 0xfffff);
}

void table_insert(region_state& s, int id) {
  size_t mask = s.table.size() - 1;
  size_t r = size_t(id);
  size_t h = size_t(mix64(s.key[r])) & mask;
  while (s.table[h].key != empty_region_key) h = (h + 1) & mask;
  s.table[h] = {s.key[r], id, s.cut_size[r], s.cut_offset[r], s.pair_offset[r], s.pair_count[r]};
}

// Grows the table to keep its load at most 1/2 for `regions` entries.
void reserve_table(region_state& s, size_t regions) {
  size_t want = 16;
  while (want < 2 * regions) want *= 2;
  if (want <= s.table.size()) return;
  s.table.assign(want, region_entry{empty_region_key, invalid_id, 0, 0, 0, 0});
  for (size_t r = 0; r < s.key.size(); r++) table_insert(s, int(r));
}

// The last node of `node`'s subtree in depth-first numbering: its rightmost leaf.
int subtree_last(const light_tree_data& tree, int node) {
  while (!is_leaf(tree, node)) node = tree.right[size_t(node)];
  return node;
}

// Appends a region with the given cut (or the shared cut 0) and members (or one per cluster; `tree` is needed with
// members) under `parent` (or invalid_id), linking each of its pairs to the parent's pair of the same member node, or
// with members of the subtree holding it (members are sorted, so one merge walk finds them).
int append_region(region_state& s, uint64_t key, const std::vector<int>* cut, const std::vector<int>* members,
                  const std::vector<int>* group, int parent, const light_tree_data* tree = nullptr) {
  int id = int(s.key.size());
  s.key.push_back(key);
  s.parent.push_back(parent);
  if (cut) {
    s.cut_offset.push_back(int(s.cut_nodes.size()));
    s.cut_size.push_back(int(cut->size()));
    s.cut_nodes.insert(s.cut_nodes.end(), cut->begin(), cut->end());
    s.member_begin.resize(s.cut_nodes.size(), 0);
  } else {
    s.cut_offset.push_back(0);
    s.cut_size.push_back(s.cut_size.empty() ? 0 : s.cut_size[0]);
  }
  int groups = s.cut_size.back(), offset = s.cut_offset.back();
  const int* cut_nodes = s.cut_nodes.data() + offset;
  int n = members ? int(members->size()) : groups;
  s.pair_offset.push_back(int(s.pairs));
  s.pair_count.push_back(n);
  s.pairs += n;
  for (int j = 0; j < n; j++) {
    int g = members ? (*group)[size_t(j)] : j;
    s.pair_node.push_back(members ? (*members)[size_t(j)] : cut_nodes[g]);
    s.pair_slot.push_back(offset + g);
    if (cut && (!members || j == 0 || g != (*group)[size_t(j - 1)])) s.member_begin[size_t(offset + g)] = j;
  }
  const int* mine = s.pair_node.data() + s.pair_offset.back();
  for (int j = 0; j < n; j++) s.pair_parent.push_back(invalid_id);
  if (parent != invalid_id) {
    const int* theirs = s.pair_node.data() + s.pair_offset[size_t(parent)];
    int m = s.pair_count[size_t(parent)];
    int* links = s.pair_parent.data() + s.pair_offset.back();
    // Both member lists hold ascending node ids, then possibly sun_cluster (-2) last. A member links to the parent's
    // member of the same node, or with members (the coarse parent's cut may stop higher in the tree) of the subtree
    // holding it: depth-first ids, so a subtree's nodes run from its root to the last leaf down its right children,
    // and the parent's members are disjoint such ranges in ascending order.
    for (int j = 0, k = 0; j < n; j++) {
      if (mine[j] == sun_cluster) {
        if (m > 0 && theirs[m - 1] == sun_cluster) links[j] = s.pair_offset[size_t(parent)] + m - 1;
        continue;
      }
      if (members) {
        while (k < m && theirs[k] != sun_cluster && subtree_last(*tree, theirs[k]) < mine[j]) k++;
        if (k < m && theirs[k] != sun_cluster && theirs[k] <= mine[j]) links[j] = s.pair_offset[size_t(parent)] + k;
        continue;
      }
      while (k < m && theirs[k] != sun_cluster && theirs[k] < mine[j]) k++;
      if (k < m && theirs[k] == mine[j]) links[j] = s.pair_offset[size_t(parent)] + k;
    }
  }
  reserve_table(s, s.key.size());
  table_insert(s, id);
  return id;
}



}  // namespace

bbox3f padded(const bbox3f& b) {
  // A thousandth of the box, and at least a few ulps of its coordinates: a point's cell is found by a float division
  // that may round it across a face of a box far from the origin by about an ulp.
  const float ulps = 4 * FLT_EPSILON * std::max(max_abs_component(b.lo), max_abs_component(b.hi));
  vec3f e = extent(b) * 1e-3f;
  vec3f m = {std::max(e.x, ulps), std::max(e.y, ulps), std::max(e.z, ulps)};
  return {b.lo - m, b.hi + m};
}

bool shares_one_cut(int triangle_lights, bool has_sun, const region_params& params) {
  // (The sun alone too: bound built a cut per region and took 3x power's time per NEE sample in a sun-only scene, two
  // thirds of it between passes; a review.)
  return (triangle_lights > 0 || has_sun) && triangle_lights <= std::min(params.max_cut, params.shared_cut_lights);
}

bbox3f grid_bounds(const bbox3f& bounds) { return is_empty(bounds) ? bbox3f{{0, 0, 0}, {1, 1, 1}} : bounds; }

float fine_cell_side(const bbox3f& bounds, int grid, float* shortest_out) {
  bbox3f b = grid_bounds(bounds);
  vec3f ext = extent(b);
  float longest = std::max(max_component(ext), 1e-20f);
  float shortest = std::min(ext.x, std::min(ext.y, ext.z));
  // A flat scene (one plane, up to a few ulps of its coordinates) has no shortest extent: use a thousandth of the
  // longest one instead. A scene that is only thin for its size (a room on a ground plane reaching 1e5) keeps its own:
  // with a thousandth of the ground's side the room fitted in a few cells (max_cells_per_axis still bounds the count,
  // so cells shrink less than the extent from about 6e-5 of the longest side down).
  const float coords = std::max(max_abs_component(b.lo), max_abs_component(b.hi));
  if (!(shortest > 4 * FLT_EPSILON * coords)) shortest = 1e-3f * longest;
  if (shortest_out) *shortest_out = shortest;
  float cell = shortest / float(std::max(1, grid));
  cell = std::max(cell, longest / float(max_cells_per_axis - 1));
  // Cells of at least a few ulps of the coordinates (a 1 cm thick scene 10 m wide at x = 1e4 would have cells below
  // one: boxes of zero size whose bounds are infinite).
  return std::max(cell, 4 * FLT_EPSILON * coords);
}

region_state make_region_state(const bbox3f& bounds, const light_tree_data& tree, bool has_sun,
                               const region_params& params) {
  region_state s;
  s.params = params;
  s.has_sun = has_sun;
  region_grid_data& g = s.grid;
  bbox3f b = grid_bounds(bounds);
  vec3f ext = extent(b);
  float longest = std::max(max_component(ext), 1e-20f);
  float cell = fine_cell_side(bounds, params.grid);
  g.origin = b.lo;
  g.cell[0] = cell;
  g.cell[1] = cell * 8;
  g.cell[2] = longest * 1.001f;
  for (int l = 0; l < region_levels; l++)
    for (int a = 0; a < 3; a++)
      if (l == 2) g.dims[l][a] = 1;
      else {
        // (clamped before the conversion: no float-to-int of a value beyond int, or of NaN)
        double cells = double(std::ceil(ext[a] / g.cell[l])) + 1;
        g.dims[l][a] = cells < double(max_cells_per_axis) ? std::max(1, int(cells)) : max_cells_per_axis;
      }
  std::vector<int> all;
  if (shares_one_cut((node_count(tree) + 1) / 2, has_sun, params)) {
    // A handful of lights: one cut of all lights serves every region.
    s.shared_cut = true;
    for (int n = 0; n < node_count(tree); n++)
      if (is_leaf(tree, n)) all.push_back(n);
    if (has_sun) all.push_back(sun_cluster);
  }
  uint64_t root_key = make_key(2, 0, 0, 0);
  s.members = !s.shared_cut && params.max_members > 0;
  if (s.shared_cut) append_region(s, root_key, &all, nullptr, nullptr, invalid_id);
  else {
    std::vector<int> cut = compute_light_cut(tree, padded(b), has_sun, params);
    append_region(s, root_key, &cut, nullptr, nullptr, invalid_id);  // the root (a last resort) is not refined
  }
  s.root = 0;
  return s;
}

// 64 * sqrt(pixels / (320 * 240)), rounded, within [16, 64]: 160x120 gets 32, 80x60 16 (README).
int region_params::auto_grid(int64_t pixels) {
  const double g =
      std::round(double(default_grid) * std::sqrt(double(std::max<int64_t>(pixels, 1)) / (320.0 * 240.0)));
  return int(std::clamp(g, 16.0, double(default_grid)));
}

uint64_t fine_region_key(const region_grid_data& g, vec3f p) {
  int c[3];
  for (int a = 0; a < 3; a++) {
    float f = (p[a] - g.origin[a]) / g.cell[0];
    int v = f >= 0 ? (f < float(g.dims[0][a]) ? int(f) : g.dims[0][a] - 1) : 0;  // NaN lands in cell 0
    c[a] = v;
  }
  return make_key(0, c[0], c[1], c[2]);
}

uint64_t parent_region_key(const region_grid_data& g, uint64_t fine_key, int level) {
  if (level >= 2) return make_key(2, 0, 0, 0);
  int i, j, k;
  key_cell(fine_key, i, j, k);
  int shift = level == 1 ? 3 : 0;  // coarse cells are 8 fine cells (i, j, k >= 0: a shift is the division)
  return make_key(level, std::min(i >> shift, g.dims[level][0] - 1), std::min(j >> shift, g.dims[level][1] - 1),
                  std::min(k >> shift, g.dims[level][2] - 1));
}

bbox3f region_box(const region_grid_data& g, uint64_t key) {
  int level = key_level(key);
  if (level >= 2) return {g.origin, g.origin + vec3f{g.cell[2], g.cell[2], g.cell[2]}};
  int i, j, k;
  key_cell(key, i, j, k);
  float c = g.cell[level];
  vec3f lo = g.origin + vec3f{float(i) * c, float(j) * c, float(k) * c};
  return {lo, lo + vec3f{c, c, c}};
}

namespace {

// The pending count that marks a fine key over the pair budget: its region can never fit (the pair count only grows,
// and a key's pairs are a function of the key), so the key is neither requested nor its cut computed again.
constexpr int over_budget = -1;

// Most keys the pending table holds: a fine grid (--grid 100000) gives nearly every sample a cell of its own that
// never reaches min_samples, and the table grew by 35-40 bytes per NEE sample without end. At the limit the counts
// are forgotten (the marks of keys over the budget kept while they fit); a grid of the default size never gets near
// it. The limit is reached at the same request of the same pass with any thread count: deterministic.
size_t pending_limit(const region_state& s) { return std::max<size_t>(size_t(1) << 20, size_t(s.params.max_pairs)); }

// Rebuilds the pending table with the entries that `keep` selects.
template <class Keep>
void rebuild_pending(region_state& s, size_t slots, Keep keep) {
  std::vector<region_slot> old = std::move(s.pending);
  s.pending.assign(slots, region_slot{empty_region_key, 0});
  s.pending_count = 0;
  size_t mask = s.pending.size() - 1;
  for (const region_slot& e : old)
    if (e.key != empty_region_key && keep(e)) {
      size_t h = size_t(mix64(e.key)) & mask;
      while (s.pending[h].key != empty_region_key) h = (h + 1) & mask;
      s.pending[h] = e;
      s.pending_count++;
    }
}

// The pending slot of a key, inserted with count 0 if new.
region_slot& pending_slot(region_state& s, uint64_t key) {
  if (s.pending_count + 1 > pending_limit(s)) {
    size_t marks = 0;
    for (const region_slot& e : s.pending) marks += e.key != empty_region_key && e.id == over_budget;
    bool keep_marks = 2 * marks <= pending_limit(s);
    rebuild_pending(s, s.pending.size(), [&](const region_slot& e) { return keep_marks && e.id == over_budget; });
  }
  if (2 * (s.pending_count + 1) > s.pending.size())
    rebuild_pending(s, std::max<size_t>(64, 2 * s.pending.size()), [](const region_slot&) { return true; });
  size_t mask = s.pending.size() - 1;
  size_t h = size_t(mix64(key)) & mask;
  while (s.pending[h].key != empty_region_key && s.pending[h].key != key) h = (h + 1) & mask;
  if (s.pending[h].key == empty_region_key) {
    s.pending[h] = {key, 0};
    s.pending_count++;
  }
  return s.pending[h];
}

// The pending slot of a key, or nullptr.
const region_slot* find_pending(const region_state& s, uint64_t key) {
  if (s.pending.empty()) return nullptr;
  size_t mask = s.pending.size() - 1;
  for (size_t h = size_t(mix64(key)) & mask;; h = (h + 1) & mask) {
    if (s.pending[h].key == key) return &s.pending[h];
    if (s.pending[h].key == empty_region_key) return nullptr;
  }
}

}  // namespace

bool add_pending(region_state& s, uint64_t key, uint32_t count) {
  region_slot& slot = pending_slot(s, key);
  if (slot.id == over_budget) return false;
  slot.id = int(std::min<int64_t>(int64_t(slot.id) + count, 1 << 30));
  return slot.id >= s.params.min_samples;
}

void remove_pending(region_state& s, uint64_t key) {
  // Linear probing deletion by backward shift (keeps every remaining key reachable).
  if (s.pending.empty()) return;
  size_t mask = s.pending.size() - 1;
  size_t h = size_t(mix64(key)) & mask;
  while (s.pending[h].key != key) {
    if (s.pending[h].key == empty_region_key) return;
    h = (h + 1) & mask;
  }
  size_t hole = h;
  for (size_t j = (hole + 1) & mask; s.pending[j].key != empty_region_key; j = (j + 1) & mask) {
    size_t home = size_t(mix64(s.pending[j].key)) & mask;
    // Move j into the hole if its home is not cyclically in (hole, j].
    bool in_between = hole <= j ? (home > hole && home <= j) : (home > hole || home <= j);
    if (!in_between) {
      s.pending[hole] = s.pending[j];
      hole = j;
    }
  }
  s.pending[hole] = {empty_region_key, 0};
  s.pending_count--;
}

const region_entry* find_region_entry(const region_state& s, uint64_t key) {
  size_t mask = s.table.size() - 1;
  for (size_t h = size_t(mix64(key)) & mask;; h = (h + 1) & mask) {
    const region_entry& slot = s.table[h];
    if (slot.key == key) return &slot;
    if (slot.key == empty_region_key) return nullptr;
  }
}

int find_region_key(const region_state& s, uint64_t key) {
  const region_entry* e = find_region_entry(s, key);
  return e ? e->id : invalid_id;
}

void rebuild_region_table(region_state& s) {
  s.table.clear();
  reserve_table(s, s.key.size());
}

int find_region(const region_state& s, uint64_t fine_key) {
  int r = find_region_key(s, fine_key);
  if (r != invalid_id) return r;
  r = find_region_key(s, parent_region_key(s.grid, fine_key, 1));
  return r != invalid_id ? r : s.root;
}

int add_regions(region_state& s, const light_tree_data& tree, const std::vector<uint64_t>& fine_keys) {
  // The candidates in key order (each fine key after its coarse parent, if that is new); chunk by chunk their cuts and
  // members are computed in parallel (each a function of its key only); then, in the same order, coarse regions are
  // created and fine ones while their actual pairs fit the budget. Ids follow this order, so they do not depend on
  // threads.
  struct pending {
    uint64_t key;
    uint64_t parent_key;  // empty_region_key for coarse regions
  };
  std::vector<pending> todo;
  std::unordered_set<uint64_t> new_coarse;  // (a set: a list searched per key was quadratic in the new keys)
  auto refused = [&](uint64_t key) {
    const region_slot* slot = find_pending(s, key);
    return slot && slot->id == over_budget;
  };
  for (uint64_t key : fine_keys) {
    if (find_region_key(s, key) != invalid_id) continue;
    bool coarse_only = is_coarse_key(key);
    uint64_t ckey = coarse_only ? key : parent_region_key(s.grid, key, 1);
    if (find_region_key(s, ckey) == invalid_id) {
      if (refused(ckey)) {  // the coarse allowance is spent: neither it nor its fine cells get a region
        if (!coarse_only) pending_slot(s, key).id = over_budget;
        continue;
      }
      if (new_coarse.insert(ckey).second) todo.push_back({ckey, empty_region_key});
    }
    if (!coarse_only) todo.push_back({key, ckey});
  }
  // Coarse regions are few against the fine ones (a coarse cell holds 512 fine ones: in the data/ scenes their pairs
  // are 2-6 % of all) and take no part in the budget while their own pairs stay within it; then (a fine grid whose
  // fine regions the budget turned down, a coarse region for each: 7.6 times the budget at --grid 1024) they are
  // turned down too, and their fine cells with them: the root serves there. So all pairs stay within twice it.
  int64_t coarse_pairs = 0;
  for (size_t r = 0; r < s.key.size(); r++)
    if (is_coarse_key(s.key[r])) coarse_pairs += s.pair_count[r];
  const int64_t coarse_allowance = s.params.max_pairs;
  // In chunks, so that once the budget is spent no cut is computed for a key it would turn down: with a very fine
  // grid and --region-min-samples 1 nearly every NEE sample asked for a new cell, and every one had its cut and
  // members computed and held (1-12 KB each) before the budget was looked at: 2.8 GB at 64 x 48, 64 spp.
  constexpr size_t chunk = 4096;
  std::vector<std::vector<int>> cuts, members, group;
  std::vector<char> computed;
  int added = 0;
  for (size_t c0 = 0; c0 < todo.size(); c0 += chunk) {
    const size_t c1 = std::min(todo.size(), c0 + chunk), m = c1 - c0;
    // A region has at least one pair (the sun's, or a cluster whose bound over the box is positive; one of none is
    // sampled exactly as its coarse region or the root would be, none of whose clusters reaches the box either).
    computed.assign(m, 0);
    for (size_t i = 0; i < m; i++) {
      computed[i] = todo[c0 + i].parent_key == empty_region_key ? coarse_pairs < coarse_allowance
                                                                : s.pairs < s.params.max_pairs;
      s.cuts_computed += computed[i] && !s.shared_cut;
    }
    if (!s.shared_cut) {
      cuts.assign(m, {});
      members.assign(s.members ? m : 0, {});
      group.assign(members.size(), {});
      // Members are refined only up to one more than the pairs left at the chunk's start: a region that would need
      // more is turned down below either way (the refinement splits in the same order whatever its limit, so one
      // that stops short of the limit is the same as with max_members). With a fine grid and the budget nearly
      // spent, every new key had up to 1024 members refined for nothing (20-80 times the render's time, a review).
      auto limit = [&](int64_t left) { return int(std::min<int64_t>(s.params.max_members, std::max<int64_t>(left, 0) + 1)); };
      const int fine_limit = limit(s.params.max_pairs - s.pairs), coarse_limit = limit(coarse_allowance - coarse_pairs);
      tbb::parallel_for(size_t(0), m, [&](size_t i) {
        if (!computed[i]) return;
        bbox3f box = padded(region_box(s.grid, todo[c0 + i].key));
        cuts[i] = compute_light_cut(tree, box, s.has_sun, s.params);
        const bool coarse = todo[c0 + i].parent_key == empty_region_key;
        if (s.members) compute_members(tree, box, cuts[i], coarse ? coarse_limit : fine_limit, members[i], group[i]);
      });
    }
    for (size_t i = 0; i < m; i++) {
      const pending& t = todo[c0 + i];
      bool coarse = t.parent_key == empty_region_key;
      int64_t n = s.shared_cut ? s.cut_size[0] : s.members ? int64_t(members[i].size()) : int64_t(cuts[i].size());
      // Over budget, the coarse region serves for good (the key is marked in the pending table and not tried again).
      if (!computed[i] || (coarse ? coarse_pairs + n > coarse_allowance : s.pairs + n > s.params.max_pairs)) {
        pending_slot(s, t.key).id = over_budget;
        continue;
      }
      int parent = coarse ? invalid_id : find_region_key(s, t.parent_key);
      if (!coarse && parent == invalid_id) {  // its coarse region was turned down just now
        pending_slot(s, t.key).id = over_budget;
        continue;
      }
      if (coarse) coarse_pairs += n;
      append_region(s, t.key, s.shared_cut ? nullptr : &cuts[i], s.members ? &members[i] : nullptr,
                    s.members ? &group[i] : nullptr, parent, &tree);
      added++;
    }
  }
  return added;
}

// Whether node's lights light every point of the box in nearly the same proportions (splitting it would
// not change sampling much): its radius is small against its gap to the box and its normals agree.
static bool coherent_node(const light_tree_data& tree, int node, const bbox3f& box, float coherence) {
  constexpr float cos_30 = 0.8660254f;
  if (node_cos_o(tree, node) < cos_30) return false;
  float r = node_radius(tree, node);
  float gap = length(center(box) - node_center(tree, node)) - 0.5f * diagonal(box) - r;
  return gap > 0 && r <= coherence * gap;
}

std::vector<int> compute_light_cut(const light_tree_data& tree, bbox3f box, bool has_sun, const region_params& p) {
  std::vector<int> cut;
  if (node_count(tree) > 0) {
    // Max-heap of (bound, node); ties go to the smaller node id so the cut is a function of the box only.
    using entry = std::pair<float, int>;
    auto less = [](const entry& a, const entry& b) { return a.first < b.first || (a.first == b.first && a.second > b.second); };
    std::priority_queue<entry, std::vector<entry>, decltype(less)> heap(less);
    float root_bound = node_region_bound(tree, 0, box.lo, box.hi);
    if (root_bound > 0) heap.push({root_bound, 0});
    double total = root_bound;
    while (!heap.empty()) {
      entry top = heap.top();
      if (is_leaf(tree, top.second) || coherent_node(tree, top.second, box, p.coherence)) {
        heap.pop();
        cut.push_back(top.second);
        continue;
      }
      if (int(cut.size() + heap.size()) >= p.max_cut) break;
      if (double(top.first) <= double(p.cut_threshold) * total) break;
      heap.pop();
      total -= top.first;
      for (int child : {tree.left[size_t(top.second)], tree.right[size_t(top.second)]}) {
        float b = node_region_bound(tree, child, box.lo, box.hi);
        if (b > 0) {
          heap.push({b, child});
          total += b;
        }
      }
    }
    while (!heap.empty()) {
      cut.push_back(heap.top().second);
      heap.pop();
    }
    std::sort(cut.begin(), cut.end());
  }
  if (has_sun) cut.push_back(sun_cluster);
  return cut;
}

void compute_members(const light_tree_data& tree, bbox3f box, const std::vector<int>& cut, int max_members,
                     std::vector<int>& members, std::vector<int>& group) {
  members.clear();
  group.clear();
  // Max-heap of (bound, node, cut entry); ties go to the smaller node id, so the members depend on the box only.
  struct entry {
    float bound;
    int node, g;
  };
  auto less = [](const entry& a, const entry& b) { return a.bound < b.bound || (a.bound == b.bound && a.node > b.node); };
  std::priority_queue<entry, std::vector<entry>, decltype(less)> heap(less);
  std::vector<std::pair<int, int>> done;  // (node, cut entry) of members that stay whole
  for (int g = 0; g < int(cut.size()); g++) {
    int node = cut[size_t(g)];
    if (node == sun_cluster || is_leaf(tree, node)) done.push_back({node, g});
    else heap.push({node_region_bound(tree, node, box.lo, box.hi), node, g});
  }
  int count = int(cut.size());
  while (!heap.empty() && count < max_members) {
    entry top = heap.top();
    heap.pop();
    entry kids[2];
    int kept = 0;
    for (int child : {tree.left[size_t(top.node)], tree.right[size_t(top.node)]}) {
      float b = node_region_bound(tree, child, box.lo, box.hi);
      if (b > 0) kids[kept++] = {b, child, top.g};  // a subtree that cannot light the box is left out, as in cuts
    }
    if (kept == 0) {
      done.push_back({top.node, top.g});  // (bounds are conservative: not expected, but never drop a whole member)
      continue;
    }
    count += kept - 1;
    for (int k = 0; k < kept; k++) {
      if (is_leaf(tree, kids[k].node)) done.push_back({kids[k].node, kids[k].g});
      else heap.push(kids[k]);
    }
  }
  for (; !heap.empty(); heap.pop()) done.push_back({heap.top().node, heap.top().g});
  // Depth-first node ids: a subtree's ids follow its root's, so sorting by id keeps every group's members together
  // and the groups in cut order; the sun (-2) goes last, as in the cut.
  std::sort(done.begin(), done.end(), [](const std::pair<int, int>& a, const std::pair<int, int>& b) {
    bool sa = a.first == sun_cluster, sb = b.first == sun_cluster;
    return sa != sb ? sb : a.first < b.first;
  });
  for (const auto& d : done) {
    members.push_back(d.first);
    group.push_back(d.second);
  }
}

size_t region_memory_bytes(const region_state& s) {
  return s.key.size() * (sizeof(uint64_t) + 5 * sizeof(int)) +
         (s.cut_nodes.size() + s.member_begin.size() + s.pair_parent.size() + s.pair_node.size() +
          s.pair_slot.size()) * sizeof(int) +
         s.table.size() * sizeof(region_entry) + s.pending.size() * sizeof(region_slot);
}

}  // namespace bl
