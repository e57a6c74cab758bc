// region_grid: the sparse uniform grid of regions over the scene bounds, and each region's light cut.
// Three levels: fine cells (`grid` cells along the shortest axis of the bounds), coarse cells (8x8x8 fine
// cells) and the root (the whole scene). Only regions that shading points reach exist; a point uses the
// finest existing region containing it. Invariants: regions are created only between passes, from requests
// in a deterministic order, so region content and ids never depend on thread timing; the root always
// exists; the total number of (region, member) pairs stays under `max_pairs` (then coarser regions serve).
// A region's cut lists clusters (tree nodes, then the sun); with members the clusters of fine and coarse regions
// are refined into members (subtrees), one (region, member) pair each.
// Keys are 64-bit (level, i, j, k) hashed with a strong mixer in an open-addressing table (load <= 1/2).
#pragma once

#include "light_tree.h"
#include "math.h"

#include <cstdint>
#include <vector>

namespace bl {

// Options of regions and cuts.
struct region_params {
  // The command line's default grid (grid -1, resolved by effective_region_params): for bayes auto_grid(pixels),
  // 64 (the paper's) from 320x240 up, coarser in smaller images, whose regions would otherwise each get under a
  // pixel's samples per pass and learn too slowly (README); for the other samplers 64.
  static constexpr int default_grid = 64;
  static int auto_grid(int64_t pixels);
  int grid = default_grid;         // fine cells along the shortest axis of the scene bounds; -1: automatic (above)
  int max_cut = 64;                // clusters per region (the sun, if any, comes on top)
  float cut_threshold = 0.005f;    // stop refining when every cluster bound < threshold * total
  float coherence = 0.25f;         // keep a node whole when radius / gap to the region <= this and its
                                   // normals lie within 30 degrees (its lights light the region alike)
  int shared_cut_lights = 16;      // at most this many lights: one cut of all lights, no clustering
  int max_members = -1;            // learned sub-clusters per region (bayes): the clusters of a region's cut are
                                   // refined into at most this many members in all, whose statistics are learned
                                   // apart and chosen inside their cluster (0 or at most the cut size: one member
                                   // per cluster, i.e. none refined); -1: auto_members by the path depth
  static constexpr int auto_members = 128;  // the default in direct illumination (max depth 1); 0 in path tracing
  int min_samples = 16;            // NEE samples a fine cell must ask for before its region is created
  int fine_depth = 1;              // path vertices up to this depth use fine regions, deeper ones coarse regions
  // bayes: a first hit uses its fine cell only where that cell holds at least this many of its pixel's footprints
  // (cell side^2 >= min_pixels x footprint^2), else its coarse region: a cell smaller than that receives under
  // min_pixels of a pixel's samples per spp and learns little (README, Regions). 0: off; the other samplers and
  // images under footprint_pixels: 0.
  float min_pixels = 0.125f;
  static constexpr int64_t footprint_pixels = 320 * 240;  // images below this many pixels: min_pixels 0
  static constexpr int64_t default_pairs = int64_t(3) << 19;  // 1.5 M
  // The command line's default budget (max_pairs -1, resolved by effective_region_params): for bayes at most
  // auto_pairs_per_pixel pairs per pixel of the image, within default_pairs (a render of fewer than 49152 pixels then
  // learns more per pair and spends less between passes: README), for the other samplers default_pairs.
  static constexpr int64_t auto_pairs_per_pixel = 32;
  int64_t max_pairs = default_pairs;  // memory budget in (region, cluster) pairs (see README); -1: automatic (above)
};

// Cluster id of the sun inside a cut (tree nodes are >= 0).
constexpr int sun_cluster = -2;
constexpr int region_levels = 3;  // fine, coarse, root

// Geometry of the grid levels.
struct region_grid_data {
  vec3f origin;
  float cell[region_levels];
  int dims[region_levels][3];
};

// One slot of a key -> count table (pending region requests).
struct region_slot {
  uint64_t key;
  int id;
};
// One slot of the key -> region table: the key with everything a shading point needs of its region, so that a
// lookup touches one cache line.
struct region_entry {
  uint64_t key;
  int id, cut_size, cut_offset, pair_offset, pair_count;
};

// Regions as flat columns, plus the key -> region lookup table.
struct region_state {
  region_grid_data grid;
  region_params params;
  bool has_sun = false;
  bool shared_cut = false;             // few lights: every region uses cut 0 (all lights), no clustering
  bool members = false;                // clusters of fine and coarse regions are refined into members
                                       // (params.max_members, not shared_cut); the root is not
  std::vector<uint64_t> key;           // per region
  std::vector<int> cut_offset;         // per region: first entry in cut_nodes
  std::vector<int> cut_size;           // per region
  std::vector<int> pair_offset;        // per region: its first (region, cluster) pair
  std::vector<int> parent;             // per region: the coarse region containing a fine one (else invalid_id)
  std::vector<int> cut_nodes;          // concatenated sorted cuts (tree node ids, then sun_cluster)
  // Members: each cluster of a cut (a group) holds one or more members, subtrees of its node (or the sun), whose
  // pairs carry the statistics; a region's members are sorted like its cut, so a group's members are contiguous
  // and in the order of the groups. Without refinement every group has one member, itself.
  std::vector<int> member_begin;       // per cut entry: its group's first member (index within the region)
  std::vector<int> pair_count;         // per region: its members (= pairs)
  std::vector<int> pair_node;          // per pair: the member's tree node (or sun_cluster)
  std::vector<int> pair_slot;          // per pair: cut_offset of its region + its group (the group's column index)
  std::vector<int> pair_parent;        // per pair: the parent region's pair of the same member node, or invalid_id
  int64_t pairs = 0;                   // total (region, member) pairs
  std::vector<region_entry> table;     // open addressing; empty slots hold empty_region_key
  std::vector<region_slot> pending;    // fine keys not yet created -> NEE samples requested so far (same scheme;
                                       // -1: over the pair budget, never created)
  size_t pending_count = 0;
  int root = 0;
  int64_t cuts_computed = 0;           // cuts add_regions computed (a statistic: not saved, not in the image)
};

constexpr uint64_t empty_region_key = ~uint64_t(0);

// The bounds the grid divides (a unit box for an empty scene).
bbox3f grid_bounds(const bbox3f& bounds);
// The side of the fine cells over `bounds` for `grid` cells along their shortest axis (*shortest_out: that axis's
// length, a thousandth of the longest for a flat scene). Larger than shortest / grid where the longest axis would need
// more than 2^20 cells, or where the cells would be under a few ulps of the coordinates.
float fine_cell_side(const bbox3f& bounds, int grid, float* shortest_out = nullptr);
// Whether every region shares one cut of all lights (a handful: no clustering), for `triangle_lights` emissive
// triangles and the sun if `has_sun`.
bool shares_one_cut(int triangle_lights, bool has_sun, const region_params& params);
// Builds the grid over `bounds` with the root region (and, for few lights, the shared cut).
region_state make_region_state(const bbox3f& bounds, const light_tree_data& tree, bool has_sun,
                               const region_params& params);

// Whether a first hit whose pixel footprint has side `footprint` uses the coarse region (region_params::min_pixels).
inline bool footprint_too_large(const region_params& p, const region_grid_data& g, float footprint) {
  return p.min_pixels > 0 && p.min_pixels * footprint * footprint > g.cell[0] * g.cell[0];
}
// Key of the fine cell containing p.
uint64_t fine_region_key(const region_grid_data& g, vec3f p);
// Whether a key is a coarse cell's.
inline bool is_coarse_key(uint64_t key) { return (key >> 62) == 1; }
// Key of the cell of `level` containing the fine cell `fine_key`.
uint64_t parent_region_key(const region_grid_data& g, uint64_t fine_key, int level);
// Box of the cell with this key.
bbox3f region_box(const region_grid_data& g, uint64_t key);
// The box grown by a small margin: bounds are evaluated over it, so points that round onto a neighbouring cell
// are still covered by a conservative bound.
bbox3f padded(const bbox3f& b);
// Region id of a key, or invalid_id.
int find_region_key(const region_state& s, uint64_t key);
// The table entry of a key, or nullptr.
const region_entry* find_region_entry(const region_state& s, uint64_t key);
// Rebuilds the key -> region table from the region columns.
void rebuild_region_table(region_state& s);
// The finest existing region containing the fine cell `fine_key` (the root at worst).
int find_region(const region_state& s, uint64_t fine_key);

// Adds `count` requests for the fine key; true when its total reached params.min_samples (never for a key that
// add_regions found over the pair budget).
bool add_pending(region_state& s, uint64_t key, uint32_t count);
// Forgets the pending count of a key (its region is being created).
void remove_pending(region_state& s, uint64_t key);

// Creates regions for requested keys (sorted, deduplicated by the caller): for a fine key its coarse parent
// first, then the fine region while the pair budget allows; a coarse key creates only the coarse region.
// Returns the number of regions added.
int add_regions(region_state& s, const light_tree_data& tree, const std::vector<uint64_t>& fine_keys);

// The light cut of a box: tree nodes sorted by id (then sun_cluster if has_sun), Lightcuts-style refinement of
// conservative bounds in order of decreasing bound, except that coherent nodes (small and far as seen from
// the box, narrow normal cone) stay whole; nodes that cannot light any point of the box are left out.
std::vector<int> compute_light_cut(const light_tree_data& tree, bbox3f box, bool has_sun, const region_params& p);

// The members of a region's cut (see region_state): every cluster that is a tree node is refined, largest
// bound over the box first, into subtrees whose bound over the box is non-zero, until the cut holds `max_members`
// members or only leaves remain; sorted by node id, the sun (if in the cut) last. group[i]: the cut entry that
// member i refines.
void compute_members(const light_tree_data& tree, bbox3f box, const std::vector<int>& cut, int max_members,
                     std::vector<int>& members, std::vector<int>& group);

// Bytes used by the region state (columns and table).
size_t region_memory_bytes(const region_state& s);

}  // namespace bl
