// checkpoint: binary (de)serialisation of render state and sampler state, and the fingerprint.
// Layout: magic, version, fingerprint, sampler kind, pass state, log, film, sampler state, checksum; all integers
// and floats little-endian as in memory (x86-64 only, like the rest of the renderer's determinism promise).
#include "checkpoint.h"
#include "light_points.h"

#include "errors.h"
#include "file_io.h"
#include "rng.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <type_traits>

namespace bl {

namespace {

constexpr char magic[16] = {'B', 'A', 'Y', 'E', 'S', 'L', 'I', 'G', 'H', 'T', '-', 'C', 'K', 'P', 'T', 0};
// 2: pass schedule, lazy refold; 3: weighted passes (film weight); 4: z = Y d^2 / cos; 5: mean hierarchy (k_folded);
// 6: bayes fallback check; 7: no point-prior weights in region-prior mode; 8: the stratified set's first sample;
// 9: members; 10: reversed twin faces (a ray meets the one turned toward it); 11: hashed per-vertex PCG32 seeds; 12: the
// reference's hash; 13: the region options as resolved in the fingerprint, Kd 0 for a library material without one;
// 14: hits on huge triangles take the ray's point, a thin scene's cells its own shortest extent; 15: map_d's
// -imfchan and an RGB mask's luminance, cells of at least 4 ulps; 16: the fingerprint's parts
// 17: the first vertex's BSDF direction in the render's stratified set
// 18: the tiles' statistics of --light-points auto
// 19: bayes's staged pass weights (the first passes' film where learning paid)
// 20: the sun's control-variate threshold apart from the lamps' (in the fingerprint)
// 21: bayes's early draws (in the fingerprint)
// 22: Russian roulette's survival probability (path-traced images changed)
// 23: the fallback check's first-vertex sum (path-traced renders)
// 24: passes after bayes's fallback weigh as the first one after it
// 25: ... with the share of the plain schedule (the passes before it kept apart)
// 27: one cut shared by all regions with the sun alone; bayes with one light is power
// 28: bayes's fallback check also weighs the bvh sampler, and can fall back to it
// 29: --light-points auto draws each pass's points from a set of its own
// 30: --light-points auto's tile statistics hold blocks of samples (3 fields more)
// 31: --light-points auto draws each light's points from a set of its own
constexpr uint32_t version = 32;  // 32: bayes's first hits choose the coarse region by their pixel footprint

}  // namespace

uint32_t checkpoint_format_version() { return version; }

namespace {

// Running 64-bit hash of bytes (8 at a time through mix64).
struct hasher {
  uint64_t h = 0x243f6a8885a308d3ull;
  void bytes(const void* data, size_t n) {
    const unsigned char* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < n; i += 8) {
      uint64_t w = 0;
      std::memcpy(&w, p + i, std::min<size_t>(8, n - i));
      h = mix64(h ^ w);
    }
    h = mix64(h ^ n);
  }
  template <class T>
  void value(const T& v) {
    static_assert(std::is_arithmetic_v<T>, "hash fields one by one (no struct padding)");
    bytes(&v, sizeof v);
  }
  void vec(vec3f v) { value(v.x), value(v.y), value(v.z); }
  template <class T>
  void column(const std::vector<T>& v) {
    bytes(v.data(), v.size() * sizeof(T));
  }
};

// Hashes the fingerprint as one sequence (the total) and each part alone: a value goes to the total and to the part
// begun last (or, value_in, to another part: the total's order stays that of the fingerprint before its parts).
struct part_hasher {
  hasher total;
  hasher parts[fp_part_count];
  int current = 0;
  void begin(int p) { current = p; }
  void bytes(const void* data, size_t n) { total.bytes(data, n), parts[current].bytes(data, n); }
  template <class T>
  void value(const T& v) {
    total.value(v), parts[current].value(v);
  }
  template <class T>
  void value_in(int part, const T& v) {
    total.value(v), parts[part].value(v);
  }
  void vec(vec3f v) { total.vec(v), parts[current].vec(v); }
  template <class T>
  void column(const std::vector<T>& v) {
    total.column(v), parts[current].column(v);
  }
};

// Appends plain values and columns to a buffer that goes to a sink in pieces of about 4 MB (write_checkpoint), while
// `sum` hashes them as checkpoint_checksum hashes the whole.
struct streaming_checksum;
struct writer {
  std::string out;
  const byte_sink* sink = nullptr;
  streaming_checksum* sum = nullptr;
  void bytes(const void* p, size_t n);
  void flush();
  template <class T>
  void value(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>, "plain data only");
    bytes(&v, sizeof v);
  }
  template <class T>
  void column(const std::vector<T>& v) {
    value(uint64_t(v.size()));
    if (!v.empty()) bytes(v.data(), v.size() * sizeof(T));
  }
};

// Reads what writer wrote; every read is bounds-checked and failures name the file.
struct reader {
  std::string_view in;
  const std::string& path;
  size_t pos = 0;
  [[noreturn]] void fail(const std::string& what) const { throw input_error(path, "corrupt checkpoint: " + what); }
  template <class T>
  T value() {
    T v;
    if (in.size() - pos < sizeof v) fail("truncated");
    std::memcpy(&v, in.data() + pos, sizeof v);
    pos += sizeof v;
    return v;
  }
  template <class T>
  std::vector<T> column(size_t expected = size_t(-1)) {
    uint64_t n = value<uint64_t>();
    if (n > (in.size() - pos) / sizeof(T)) fail("truncated column");
    if (expected != size_t(-1) && n != expected) fail("column of unexpected size");
    std::vector<T> v(n);
    if (n > 0) std::memcpy(v.data(), in.data() + pos, n * sizeof(T));  // an empty vector's data() may be null
    pos += n * sizeof(T);
    return v;
  }
};

void write_regions(writer& w, const region_state& s) {
  w.column(s.key);
  w.column(s.cut_offset);
  w.column(s.cut_size);
  w.column(s.pair_offset);
  w.column(s.parent);
  w.column(s.cut_nodes);
  w.column(s.pair_parent);
  w.value(s.pairs);
  w.value(uint8_t(s.members));
  w.column(s.member_begin);
  w.column(s.pair_count);
  w.column(s.pair_node);
  w.column(s.pair_slot);
  w.column(s.pending);
  w.value(uint64_t(s.pending_count));
}

// Whether every value of a column is finite and not negative.
template <class T>
bool finite_non_negative(const std::vector<T>& v) {
  for (T x : v)
    if (!(std::isfinite(x) && x >= 0)) return false;
  return true;
}

// A checksum guards against accidental damage only: every index the renderer follows is checked against the light
// tree and the other columns, so that an edited checkpoint is an input error, never a crash or an endless loop.
// `nodes`: the light tree's node count; `sun`: whether the scene has a sun (sun_cluster entries are then allowed).
void read_regions(reader& r, region_state& s, int nodes, bool sun) {
  s.key = r.column<uint64_t>();
  size_t n = s.key.size();
  s.cut_offset = r.column<int>(n);
  s.cut_size = r.column<int>(n);
  s.pair_offset = r.column<int>(n);
  s.parent = r.column<int>(n);
  s.cut_nodes = r.column<int>();
  s.pair_parent = r.column<int>();
  s.pairs = r.value<int64_t>();
  if (s.pairs != int64_t(s.pair_parent.size())) r.fail("pair count");
  s.members = r.value<uint8_t>() != 0;
  s.member_begin = r.column<int>(s.cut_nodes.size());
  s.pair_count = r.column<int>(n);
  s.pair_node = r.column<int>(size_t(s.pairs));
  s.pair_slot = r.column<int>(size_t(s.pairs));
  s.pending = r.column<region_slot>();
  s.pending_count = size_t(r.value<uint64_t>());
  // Region 0 is the root, every point's last resort (a render always has it, and it has no parent).
  if (n == 0 || s.parent[0] != invalid_id) r.fail("region layout");
  for (size_t i = 0; i < n; i++) {
    int c = s.cut_size[i], m = s.pair_count[i];
    if (s.cut_offset[i] < 0 || c < 0 || size_t(s.cut_offset[i]) + size_t(c) > s.cut_nodes.size() ||
        s.pair_offset[i] < 0 || m < c || (!s.members && m != c) || int64_t(s.pair_offset[i]) + m > s.pairs)
      r.fail("region layout");
    // Every cluster's members: consecutive, a positive run each, their pairs naming that cluster.
    const int* begin = s.member_begin.data() + s.cut_offset[i];
    for (int g = 0; g < c; g++) {
      int e = g + 1 < c ? begin[g + 1] : m;
      if (begin[g] < 0 || begin[g] >= e || (g == 0 && begin[g] != 0)) r.fail("region members");
      for (int k = begin[g]; k < e; k++)
        if (s.pair_slot[size_t(s.pair_offset[i] + k)] != s.cut_offset[i] + g) r.fail("region members");
    }
  }
  // Regions hold consecutive runs of the pair columns, in region order (as they were appended); cuts may be shared
  // (scenes with a handful of lights), and were checked to lie within the column above.
  int64_t pairs = 0;
  for (size_t i = 0; i < n; i++) {
    if (s.pair_offset[i] != pairs) r.fail("region layout");
    pairs += s.pair_count[i];
    int up = s.parent[i];
    if (up != invalid_id && (up < 0 || size_t(up) >= n || s.parent[size_t(up)] != invalid_id)) r.fail("region parent");
  }
  if (pairs != s.pairs) r.fail("region layout");
  // A region's clusters and members: tree nodes in increasing order, the sun (if any) last.
  auto sorted_nodes = [&](const int* v, int count) {
    for (int k = 0; k < count; k++) {
      int node = v[k];
      bool ok = node == sun_cluster ? sun && k == count - 1 : node >= 0 && node < nodes && (k == 0 || v[k - 1] < node);
      if (!ok) return false;
    }
    return true;
  };
  for (size_t i = 0; i < n; i++)
    if (!sorted_nodes(s.cut_nodes.data() + s.cut_offset[i], s.cut_size[i]) ||
        !sorted_nodes(s.pair_node.data() + s.pair_offset[i], s.pair_count[i]))
      r.fail("region clusters");
  // A pair's parent: a pair without a parent of its own (two levels: the coarse pairs' lists of fine children
  // cannot loop).
  for (size_t k = 0; k < size_t(s.pairs); k++) {
    int up = s.pair_parent[k];
    if (up == invalid_id) continue;
    if (up < 0 || up >= s.pairs || s.pair_parent[size_t(up)] != invalid_id) r.fail("pair parent");
  }
  // The pending table: a power of two at most half full (lookups stop at an empty slot), its count the slots in use.
  if (!s.pending.empty() && (s.pending.size() & (s.pending.size() - 1)) != 0) r.fail("pending table size");
  size_t used = 0;
  for (const region_slot& e : s.pending) {
    if (e.key == empty_region_key) continue;
    used++;
    if (e.id < -1) r.fail("pending table");
  }
  if (used != s.pending_count || 2 * used > s.pending.size()) r.fail("pending table");
  // The lookup table is rebuilt from the keys (its layout does not matter, its answers do).
  rebuild_region_table(s);
}

// Field f of a pair's statistics: n0, n1, mean, m2.
template <class M>  // pair_moments, or const pair_moments to read
auto& moment_field(M& m, int f) { return f == 0 ? m.n0 : f == 1 ? m.n1 : f == 2 ? m.mean : m.m2; }

void write_sampler(writer& w, const light_sampler& ls) {
  if (auto* b = std::get_if<bound_sampler>(&ls)) write_regions(w, b->regions);
  if (auto* b = std::get_if<bayes_sampler>(&ls)) {
    write_regions(w, b->regions);
    // Four columns (n0, n1, mean, m2), as the statistics were laid out when the format was fixed.
    std::vector<double> col(b->stats.m.size());
    for (int f = 0; f < 4; f++) {
      for (size_t i = 0; i < col.size(); i++) col[i] = moment_field(b->stats.m[i], f);
      w.column(col);
    }
    // The sampling weights are folded lazily (a pair's children only when its p1 moved by more than a tolerance),
    // so they depend on the history, not only on the statistics: saved as they are.
    w.column(b->stats.weight);
    w.column(b->stats.w);
    w.column(b->stats.w_cv);
    w.column(b->stats.cv);
    w.column(b->stats.p1_folded);
    w.column(b->stats.k_folded);
    w.column(b->stats.unseen);  // (set as weights are folded, lazily like them)
    w.value(uint8_t(b->frozen));
    // The fallback check: its decision and votes, and the state it carries from one pass to the next (the per-pixel
    // sums are reset after every pass: only whether they run; the samples of a pass of one spp, to pair with).
    w.value(uint8_t(b->fallback));
    w.value(int32_t(b->fallback_votes));
    w.value(int32_t(b->fallback_spp));
    w.value(b->check_ratio);
    w.value(b->window_var), w.value(b->window_delta), w.value(b->window_samples), w.value(b->window_first);
    w.value(uint8_t(b->fallback_bvh)), w.value(b->check_ratio_bvh), w.value(b->window_var_bvh);
    w.value(b->window_delta_bvh);
    w.value(int32_t(b->bvh_windows));
    w.value(uint8_t(b->check_pairs));
    w.value(uint8_t(b->check_done));
    w.value(uint64_t(b->px_var.size()));
    w.column(b->px_prev);
  }
  if (auto* d = std::get_if<donikian_sampler>(&ls)) {
    write_regions(w, d->deeper.regions);
    w.column(d->pixel_sum);
    w.column(d->pixel_count);
    w.column(d->block_sum);
    w.column(d->block_count);
  }
}

// `pixels`: the image's pixel count (the fallback check's columns are indexed by pixel).
void read_sampler(reader& r, light_sampler& ls, size_t pixels) {
  if (auto* b = std::get_if<bound_sampler>(&ls))
    read_regions(r, b->regions, node_count(*b->tree), b->lights->sun != invalid_id);
  if (auto* b = std::get_if<bayes_sampler>(&ls)) {
    read_regions(r, b->regions, node_count(*b->tree), b->lights->sun != invalid_id);
    size_t pairs = size_t(b->regions.pairs);
    b->stats.m.assign(pairs, pair_moments{});
    for (int f = 0; f < 4; f++) {
      std::vector<double> col = r.column<double>(pairs);
      if (!finite_non_negative(col)) r.fail("statistics");
      for (size_t i = 0; i < pairs; i++) moment_field(b->stats.m[i], f) = col[i];
    }
    std::vector<pair_weight> weight = r.column<pair_weight>(b->params.region_prior ? 0 : pairs);
    std::vector<float> wcol = r.column<float>(pairs + 4), w_cv = r.column<float>(pairs + 4),
                       cv = r.column<float>(pairs + 4), p1_folded = r.column<float>(pairs),
                       k_folded = r.column<float>(pairs);
    std::vector<uint8_t> unseen = r.column<uint8_t>(pairs + 16);
    for (size_t i = 0; i < unseen.size(); i++)
      if (unseen[i] > (i < pairs && b->params.region_prior ? 1 : 0)) r.fail("sampling weights");
    auto valid = [](float x) { return std::isfinite(x) && x >= 0; };
    for (const std::vector<float>* c : {&wcol, &w_cv, &p1_folded, &k_folded})
      for (float x : *c)
        if (!valid(x)) r.fail("sampling weights");
    for (float x : cv)
      if (!std::isfinite(x)) r.fail("sampling weights");
    for (const pair_weight& x : weight)
      if (!std::isfinite(x.w2) || !std::isfinite(x.w1) || !std::isfinite(x.w0) || !std::isfinite(x.wc)) r.fail("sampling weights");
    b->frozen = r.value<uint8_t>() != 0;
    b->fallback = r.value<uint8_t>() != 0;
    b->fallback_votes = r.value<int32_t>();
    b->fallback_spp = r.value<int32_t>();
    b->check_ratio = r.value<double>();
    b->window_var = r.value<double>(), b->window_delta = r.value<double>(), b->window_samples = r.value<double>();
    b->window_first = r.value<double>();
    b->fallback_bvh = r.value<uint8_t>() != 0;
    b->check_ratio_bvh = r.value<double>(), b->window_var_bvh = r.value<double>();
    b->window_delta_bvh = r.value<double>();
    b->bvh_windows = r.value<int32_t>();
    b->check_pairs = r.value<uint8_t>() != 0;
    b->check_done = r.value<uint8_t>() != 0;
    uint64_t checked = r.value<uint64_t>();
    b->px_prev = r.column<float>();
    if (b->fallback_votes < 0 || b->fallback_spp < 0 || !std::isfinite(b->check_ratio) ||
        (checked != 0 && checked != pixels) || !(b->window_samples >= 0) || std::isnan(b->window_var) ||
        std::isnan(b->window_delta) || std::isnan(b->window_first) || std::isnan(b->check_ratio_bvh) ||
        std::isnan(b->window_var_bvh) || std::isnan(b->window_delta_bvh) || (b->fallback_bvh && !b->fallback) ||
        b->bvh_windows < 0 ||
        (!b->px_prev.empty() && b->px_prev.size() != checked))
      r.fail("fallback check");
    b->px_var.assign(size_t(checked), 0.0);
    b->px_delta.assign(size_t(checked), 0.0);
    if (b->checks_bvh()) b->px_delta_bvh.assign(size_t(checked), 0.0);
    if (b->params.path_traced) b->px_first.assign(size_t(checked), 0.0);
    b->px_cur.assign(b->px_prev.size(), NAN);
    // Prior means and coefficients are functions of the regions and statistics: recomputed (bit for bit the same);
    // then the saved weights replace the recomputed ones.
    b->rebuild_posterior();
    b->stats.weight = std::move(weight);
    b->stats.w = std::move(wcol);
    b->stats.w_cv = std::move(w_cv);
    b->stats.cv = std::move(cv);
    b->stats.p1_folded = std::move(p1_folded);
    b->stats.k_folded = std::move(k_folded);
    b->stats.unseen = std::move(unseen);
    b->refresh_groups(nullptr);  // the clusters' sums of the saved weights
  }
  if (auto* d = std::get_if<donikian_sampler>(&ls)) {
    read_regions(r, d->deeper.regions, node_count(*d->deeper.tree), d->deeper.lights->sun != invalid_id);
    d->pixel_sum = r.column<float>(d->pixel_sum.size());
    d->pixel_count = r.column<float>(d->pixel_count.size());
    d->block_sum = r.column<float>(d->block_sum.size());
    d->block_count = r.column<float>(d->block_count.size());
    for (const std::vector<float>* c : {&d->pixel_sum, &d->pixel_count, &d->block_sum, &d->block_count})
      if (!finite_non_negative(*c)) r.fail("statistics");
  }
}

}  // namespace

const char* fingerprint_part_name(int part) {
  switch (part) {
    case fp_scene: return "the scene (its mesh, materials, textures, camera, sun or two_sided_emitters)";
    case fp_image_size: return "the image size";
    case fp_max_depth: return "--max-depth";
    case fp_seed: return "the seed";
    case fp_sampler: return "the sampler";
    case fp_light_samples: return "the light samples (--independent-samples, --light-samples, --light-points)";
    case fp_animation: return "the animation (--frames, the sun's direction_end, --spp or --time)";
    case fp_learning_weights: return "--pass-weighting or --frame-decay";
    case fp_regions:
      return "the region options (--grid, --max-cut, --cut-*, --region-*, --shared-cut-lights, --fine-depth)";
    case fp_bayes: return "the bayes options (--bayes-*)";
    case fp_donikian: return "the donikian options";
    default: return "?";
  }
}

render_fingerprint_data render_fingerprint(const scene_data& scene, const render_params& p) {
  part_hasher h;
  h.begin(fp_scene);
  const mesh_data& m = scene.mesh;
  h.column(m.positions);
  h.column(m.normals);
  h.column(m.texcoords);
  h.column(m.tri_positions);
  h.column(m.tri_normals);
  h.column(m.tri_texcoords);
  h.column(m.tri_materials);
  for (const material_data& mat : m.materials) {
    h.vec(mat.kd), h.vec(mat.ks), h.vec(mat.ke), h.value(mat.ns);
    h.value(mat.kd_texture), h.value(mat.alpha_texture);
    for (const texture_transform* t : {&mat.kd_map, &mat.alpha_map})
      h.value(t->scale.x), h.value(t->scale.y), h.value(t->offset.x), h.value(t->offset.y), h.value(t->clamp),
          h.value(t->channel);
  }
  for (const texture_data& t : m.textures) {
    h.value(t.width), h.value(t.height);
    h.value(t.channels);
    h.column(t.texels8);
    h.column(t.texels16);
  }
  h.vec(scene.camera.eye), h.vec(scene.camera.target), h.vec(scene.camera.up), h.value(scene.camera.fov_y_deg);
  h.value(scene.sun.enabled), h.vec(scene.sun.direction), h.vec(scene.sun.irradiance);
  h.value(scene.sun.angular_diameter_deg), h.value(scene.two_sided_emitters);
  h.begin(fp_image_size);
  h.value(p.width), h.value(p.height);
  h.begin(fp_max_depth);
  h.value(p.max_depth);
  h.begin(fp_seed);
  h.value(p.seed);
  h.begin(fp_sampler);
  h.value(int(p.sampler.kind));
  h.begin(fp_light_samples);
  h.value(p.stratify);
  if (p.light_samples != 1) h.value(p.light_samples);  // (one: the fingerprint of checkpoints from before the option)
  if (p.light_points != 1) h.value(uint64_t(0x6c69676874707473)), h.value(p.light_points);  // (0: auto)
  const sampler_kind k = p.sampler.kind;
  h.begin(fp_animation);
  if (p.frames > 1) {
    // An animation: its frame count and the sun's end (each frame's sun), and, for a learning sampler, how much of
    // its statistics a frame keeps. (A still's fingerprint is what it was before animations could be resumed.)
    h.value(p.frames), h.value(scene.sun.animated), h.vec(scene.sun.direction_end);
    // (With the learning's other weight: only the learning samplers read it, and another sampler names itself.)
    if (k == sampler_kind::bayes || k == sampler_kind::donikian) h.value_in(fp_learning_weights, p.frame_decay);
    // And its samples per frame: the frames before the checkpoint's were rendered with them, and a learning sampler's
    // later frames start from what those learned (a resume with another --spp was taken silently; a review).
    h.value(p.time_budget);
    if (!(p.time_budget > 0)) h.value(p.spp);
  }
  // Only the options of the sampler in use: a uniform render resumed with another --grid or --bayes-b0 (which
  // cannot change its image) was refused as a different render.
  const bool regions = k == sampler_kind::bound || k == sampler_kind::donikian || k == sampler_kind::bayes;
  // Nor the options the others leave without effect (as the command line's warning names them: a resume with
  // --pass-weighting 8 of a --bayes-oracle render was refused right after the warning said it was ignored; a review).
  const bool frozen = k == sampler_kind::bayes && p.sampler.bayes.oracle_spp > 0;
  h.begin(fp_learning_weights);
  if ((k == sampler_kind::donikian || k == sampler_kind::bayes) && !frozen) h.value(p.pass_weighting);  // adaptive
  h.begin(fp_regions);
  if (regions) {
    // As the render resolves them: a default given explicitly (--cut-members 128 in direct illumination, the automatic
    // pair budget) renders the same image and was refused as a different render. donikian's first hit reads only
    // its cut's options; its regions serve the vertices past it.
    const region_params r = effective_region_params(p.sampler, p.max_depth, int64_t(p.width) * p.height);
    h.value(r.max_cut), h.value(r.cut_threshold), h.value(r.coherence);
    if (k != sampler_kind::donikian || p.max_depth > 1) {
      h.value(r.grid), h.value(r.shared_cut_lights), h.value(r.min_samples), h.value(r.max_pairs), h.value(r.fine_depth);
      h.value(r.max_members), h.value(r.min_pixels);
    }
  }
  h.begin(fp_bayes);
  if (k == sampler_kind::bayes) {
    bayes_params b = p.sampler.bayes;
    const bayes_params d;
    if (!b.prior) b.a0 = d.a0, b.b0 = d.b0, b.kappa0 = d.kappa0, b.alpha0 = d.alpha0, b.c = d.c;
    if (!b.region_prior) b.orientation = d.orientation, b.bsdf_factor = d.bsdf_factor, b.control_variate = d.control_variate;
    if (!b.region_prior || !b.second_moment || !b.control_variate)
      b.cv_min_visible = d.cv_min_visible, b.cv_sun_min_visible = d.cv_sun_min_visible;
    if (!b.second_moment) b.control_variate = d.control_variate;
    if (!b.region_prior || !b.second_moment || !b.control_variate || p.max_depth == 1)
      b.cv_every_vertex = d.cv_every_vertex;
    if (!b.prior || !b.region_prior || !(b.hierarchy > 0)) b.mean_hierarchy = d.mean_hierarchy;
    h.value(b.a0), h.value(b.b0), h.value(b.kappa0), h.value(b.alpha0), h.value(b.c), h.value(b.epsilon);
    h.value(b.second_moment), h.value(b.distance_regression), h.value(b.prior), h.value(b.hierarchy);
    h.value(b.region_prior), h.value(b.control_variate), h.value(b.cv_min_visible), h.value(b.cv_sun_min_visible);
    h.value(b.oracle_spp), h.value(b.refold_tolerance), h.value(b.orientation), h.value(b.mean_hierarchy);
    h.value(b.fallback_ratio), h.value(b.fallback_window), h.value(b.fallback_stratified), h.value(b.bsdf_factor);
    h.value(b.cv_every_vertex);
    h.value(b.fallback_ratio > 0 ? b.fallback_bvh_ratio : 0.0);
    h.value(b.prior && b.region_prior ? b.unseen_cap : 0.0);
    // The early draws, where they can apply (direct illumination; one draw or no early spp: none).
    const bool early = p.max_depth == 1 && b.early_draws > std::max(1, p.light_samples) && b.early_spp > 0;
    h.value(early ? b.early_draws : 0), h.value(early ? b.early_spp : 0);
  }
  h.begin(fp_donikian);
  if (k == sampler_kind::donikian) {
    const donikian_params& d = p.sampler.donikian;
    h.value(d.block), h.value(d.pixel_half), h.value(d.min_share);
  }
  render_fingerprint_data f;
  f.total = h.total.h;
  for (int p = 0; p < fp_part_count; p++) f.parts[p] = h.parts[p].h;
  return f;
}

namespace {

// checkpoint_checksum of bytes given in pieces: the same 8-byte words across piece boundaries, then the length.
struct streaming_checksum {
  uint64_t h = hasher{}.h;
  unsigned char partial[8] = {};
  size_t held = 0, total = 0;
  void add(const unsigned char* p, size_t n) {
    total += n;
    while (n > 0) {
      size_t k = std::min(n, 8 - held);
      std::memcpy(partial + held, p, k);
      held += k, p += k, n -= k;
      if (held == 8) {
        uint64_t w;
        std::memcpy(&w, partial, 8);
        h = mix64(h ^ w);
        held = 0;
      }
    }
  }
  uint64_t finish() {
    if (held > 0) {
      uint64_t w = 0;
      std::memcpy(&w, partial, held);
      h = mix64(h ^ w);
    }
    return mix64(h ^ total);
  }
};

void writer::bytes(const void* p, size_t n) {
  constexpr size_t piece = size_t(4) << 20;
  if (n >= piece) {  // (a large column goes as it is, not through the buffer)
    flush();
    sum->add(static_cast<const unsigned char*>(p), n);
    (*sink)(static_cast<const char*>(p), n);
    return;
  }
  out.append(static_cast<const char*>(p), n);
  if (out.size() >= piece) flush();
}
void writer::flush() {
  if (out.empty()) return;
  sum->add(reinterpret_cast<const unsigned char*>(out.data()), out.size());
  (*sink)(out.data(), out.size());
  out.clear();
}

}  // namespace

// (What hasher::bytes gives for the whole body in one call.)
uint64_t checkpoint_checksum(std::string_view body) {
  streaming_checksum sum;
  sum.add(reinterpret_cast<const unsigned char*>(body.data()), body.size());
  return sum.finish();
}

uint64_t reference_hash(const image_data* reference) {
  if (!reference) return 0;
  hasher h;
  h.value(reference->width), h.value(reference->height);
  h.bytes(reference->pixels.data(), reference->pixels.size() * sizeof(float));
  return h.h == 0 ? 1 : h.h;
}

// Every field of a checkpoint but the checksum that ends it.
static void emit_checkpoint(writer& w, const render_fingerprint_data& fingerprint, uint64_t reference,
                            const render_result& result, const light_sampler& sampler, int frames) {
  w.bytes(magic, sizeof magic);
  w.value(version);
  w.value(fingerprint.total);
  w.value(uint32_t(fp_part_count));
  for (uint64_t part : fingerprint.parts) w.value(part);
  w.value(reference);
  w.value(uint32_t(sampler.index()));
  w.value(result.width), w.value(result.height);
  if (frames > 1) {  // (an animation's only)
    w.value(result.frame);
    w.value(uint8_t(result.fallback_earlier));  // (bayes fell back in an earlier frame: its summary says so)
  }
  w.value(result.passes), w.value(result.spp), w.value(result.stratum_base);
  w.value(result.seconds);
  w.value(result.stats);
  w.value(uint64_t(result.log.size()));
  for (const pass_record& p : result.log) {
    w.value(p.pass), w.value(p.spp), w.value(p.seconds), w.value(uint8_t(p.has_error));
    w.value(p.error.relmse), w.value(p.error.mse), w.value(p.error.maxabs);
  }
  w.column(result.film);
  w.value(result.film_weight);
  w.value(uint8_t(result.late_learns)), w.value(uint8_t(result.late_fallback));
  if (result.late_learns || result.late_fallback) {
    w.column(result.early_film);
    w.value(result.early_weight), w.value(result.late_ref_weight);
  }
  w.column(result.point_stats);
  write_sampler(w, sampler);
}

void write_checkpoint(const std::string& path, const render_fingerprint_data& fingerprint, uint64_t reference,
                      const render_result& result, const light_sampler& sampler, int frames) {
  write_file_atomic_stream(path, [&](const byte_sink& sink) {
    streaming_checksum sum;
    writer w;
    w.sink = &sink;
    w.sum = &sum;
    emit_checkpoint(w, fingerprint, reference, result, sampler, frames);
    w.flush();
    const uint64_t checksum = sum.finish();
    sink(reinterpret_cast<const char*>(&checksum), sizeof checksum);
  });
}

bool holds_checkpoint(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return false;  // (opening a FIFO to read would wait for a writer)
  std::ifstream f(path, std::ios::binary);
  char head[sizeof magic];
  return f.read(head, sizeof head) && std::memcmp(head, magic, sizeof magic) == 0;
}

int saved_passes(const std::string& path, int frames) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return -1;
  std::ifstream f(path, std::ios::binary);
  // (as emit_checkpoint writes them: the pass count follows the width and height, or an animation's frame and flag)
  const size_t at = checkpoint_frame_offset + (frames > 1 ? sizeof(int) + 1 : 0);
  std::string head(at + sizeof(int), '\0');
  uint32_t stored_version, parts;
  int passes;
  if (!f.read(head.data(), std::streamsize(head.size())) || std::memcmp(head.data(), magic, sizeof magic) != 0)
    return -1;
  std::memcpy(&stored_version, head.data() + sizeof magic, sizeof stored_version);
  std::memcpy(&parts, head.data() + sizeof magic + 4 + 8, sizeof parts);
  std::memcpy(&passes, head.data() + at, sizeof passes);
  return stored_version == version && parts == fp_part_count && passes >= 0 ? passes : -1;
}

uint64_t decode_checkpoint(const std::string& bytes, const std::string& path,
                           const render_fingerprint_data& fingerprint, const render_params& params,
                           render_result& result, light_sampler& sampler) {
  if (bytes.size() < sizeof magic + 8 || std::memcmp(bytes.data(), magic, sizeof magic) != 0)
    throw input_error(path, "not a bayeslight checkpoint");
  uint64_t stored;
  std::memcpy(&stored, bytes.data() + bytes.size() - 8, 8);
  if (stored != checkpoint_checksum(std::string_view(bytes).substr(0, bytes.size() - 8))) throw input_error(path, "corrupt checkpoint: checksum mismatch");
  // (A view, not a copy: the copy doubled a resume's peak memory, 180 MB for a 90 MB checkpoint.)
  const std::string_view body = std::string_view(bytes).substr(0, bytes.size() - 8);
  reader r{body, path, sizeof magic};
  if (r.value<uint32_t>() != version) throw input_error(path, "checkpoint of another bayeslight version");
  const uint64_t total = r.value<uint64_t>();
  if (r.value<uint32_t>() != fp_part_count) r.fail("fingerprint");
  render_fingerprint_data saved;
  for (uint64_t& part : saved.parts) part = r.value<uint64_t>();
  const uint64_t reference = r.value<uint64_t>();
  const uint32_t kind = r.value<uint32_t>();
  int w = r.value<int>(), hgt = r.value<int>();
  if (total != fingerprint.total) {
    // Name what differs (the parts whose hashes differ; the image size as saved, the likeliest slip). Another
    // sampler brings its own options, and the region options' automatic values follow the image size and the depth:
    // those are not named too.
    std::string which;
    auto differs = [&](int p) { return saved.parts[p] != fingerprint.parts[p]; };
    for (int p = 0; p < fp_part_count; p++) {
      if (!differs(p) || (differs(fp_sampler) && p >= fp_learning_weights) ||
          (p == fp_regions && (differs(fp_image_size) || differs(fp_max_depth))))
        continue;
      which += std::string(which.empty() ? "" : ", ") + fingerprint_part_name(p);
      if (p == fp_image_size) which += " (" + std::to_string(w) + "x" + std::to_string(hgt) + " there)";
    }
    throw input_error(path, "checkpoint was written for a different scene or different render options" +
                                (which.empty() ? std::string() : "; what differs: " + which));
  }
  if (kind != uint32_t(sampler.index())) r.fail("sampler kind");
  if (w != result.width || hgt != result.height) r.fail("image size");
  result.frame = params.frames > 1 ? r.value<int>() : 0;
  if (result.frame < 0 || result.frame >= std::max(1, params.frames)) r.fail("frame");
  result.fallback_earlier = params.frames > 1 && r.value<uint8_t>() != 0;
  result.passes = r.value<int>();
  result.spp = r.value<int>();
  result.stratum_base = r.value<int>();
  result.seconds = r.value<double>();
  result.stats = r.value<path_stats>();
  uint64_t n = r.value<uint64_t>();
  if (n > uint64_t(1) << 24) r.fail("log length");
  result.log.clear();
  for (uint64_t i = 0; i < n; i++) {
    pass_record p;
    p.pass = r.value<int>(), p.spp = r.value<int>(), p.seconds = r.value<double>();
    p.has_error = r.value<uint8_t>() != 0;
    p.error.relmse = r.value<double>(), p.error.mse = r.value<double>(), p.error.maxabs = r.value<double>();
    result.log.push_back(p);
  }
  result.film = r.column<double>(size_t(w) * size_t(hgt) * 3);
  result.film_weight = r.value<double>();
  result.late_learns = r.value<uint8_t>() != 0;
  result.late_fallback = r.value<uint8_t>() != 0;
  if (result.late_learns || result.late_fallback) {
    result.early_film = r.column<double>(size_t(w) * size_t(hgt) * 3);
    result.early_weight = r.value<double>(), result.late_ref_weight = r.value<double>();
  }
  // --light-points auto: the tiles' sums (empty before its first pass), every one finite and not negative.
  result.point_stats = r.column<double>();
  if (!(result.point_stats.empty() ||
        (params.light_points == 0 && result.point_stats.size() == point_stats_size(w, hgt))))
    r.fail("light point statistics");
  for (double x : result.point_stats)
    if (!(std::isfinite(x) && x >= 0)) r.fail("light point statistics");
  // One log record per pass, numbered from 1, each adding samples; the stratified light set starts at a pass's end
  // (or at 0).
  bool passes_ok = result.passes >= 0 && uint64_t(result.passes) == result.log.size() &&
                   std::isfinite(result.seconds) && result.seconds >= 0;
  bool base_ok = result.stratum_base == 0;
  int spp = 0;
  double seconds = 0;
  for (size_t i = 0; passes_ok && i < result.log.size(); i++) {
    const pass_record& p = result.log[i];
    bool errors_ok = !p.has_error || (std::isfinite(p.error.relmse) && std::isfinite(p.error.mse) &&
                                      std::isfinite(p.error.maxabs));
    passes_ok = p.pass == int(i) + 1 && p.spp > spp && std::isfinite(p.seconds) && p.seconds >= seconds && errors_ok;
    spp = p.spp, seconds = p.seconds;
    base_ok = base_ok || result.stratum_base == p.spp;
  }
  if (!passes_ok || spp != result.spp || !base_ok) r.fail("pass state");
  read_sampler(r, sampler, size_t(w) * size_t(hgt));  // (before the weight: a frozen oracle model does not adapt)
  // The film's weight is a function of the passes (their spp and the weighting fixed in advance): the same sum, in
  // the same order, as the render's.
  const double weighting = sampler_adapts(sampler) ? params.pass_weighting : 0.0;
  // bayes's staged weights: its first staged_spp spp, then the later passes' (their own, and their plain ones where
  // the first passes were kept apart), summed as the render sums them.
  const bool staged = std::holds_alternative<bayes_sampler>(sampler) && stages_passes(params, weighting);
  if (result.late_learns && !(staged && result.spp >= staged_spp)) r.fail("staged pass weights");
  // After a fallback (late_fallback), the passes before it are kept apart: those of the frame's first stratum_base
  // spp (the fallback's own pass the last of them).
  if (result.late_fallback) {
    const auto* b = std::get_if<bayes_sampler>(&sampler);
    if (!(b && b->fallback && weighting > 0 && !result.late_learns && result.stratum_base > 0))
      r.fail("fallback pass weights");
  }
  // A pass weighs as the first of its stratified light set (render.cpp): every pass before the set now running
  // started one of its own (the model changed after each), and every later one belongs to it.
  double weight = 0, early = 0, late_ref = 0;
  spp = 0;
  for (const pass_record& p : result.log) {
    const int set = std::min(spp, result.stratum_base);
    const double wk = staged ? staged_pass_weight(set, weighting, result.late_learns) : pass_weight(set, weighting);
    weight += wk * (p.spp - spp);
    if (result.late_learns && spp < staged_spp) early = weight;
    if (result.late_learns && spp >= staged_spp) late_ref += pass_weight(set, weighting) * (p.spp - spp);
    if (result.late_fallback && spp < result.stratum_base) early = weight;
    if (result.late_fallback && spp >= result.stratum_base)
      late_ref += plain_pass_weight(spp, weighting, staged) * (p.spp - spp);
    spp = p.spp;
  }
  if (result.film_weight != weight) r.fail("film weight");
  if (result.early_weight != early || result.late_ref_weight != late_ref) r.fail("staged pass weights");
  for (double x : result.early_film)
    if (!std::isfinite(float(x / early))) r.fail("film");
  // Every sample is a finite float, so every pixel's mean converts to a finite float as the image does it (film_image);
  // a value finite in double but beyond that (an edit) was written as an infinite pixel. Without a pass (an
  // animation's frame stopped before its first) the film is empty: all zeros.
  for (double x : result.film)
    if (weight > 0 ? !std::isfinite(float(x / weight)) : x != 0) r.fail("film");
  if (r.pos != body.size()) r.fail("trailing data");
  return reference;
}

}  // namespace bl
