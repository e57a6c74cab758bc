// triangulate: ear clipping, the monotone sweep and the choice between them (see triangulate.h).
#include "triangulate.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <set>
#include <utility>

namespace bl {

// Twice the signed area of 2D triangle (a, b, c): positive when it turns counter-clockwise.
static double cross2(const double* x, const double* y, int a, int b, int c) {
  return (x[b] - x[a]) * (y[c] - y[a]) - (y[b] - y[a]) * (x[c] - x[a]);
}

// True when point q lies inside or on triangle (a, b, c) (counter-clockwise) in 2D.
static bool in_triangle(const double* x, const double* y, int a, int b, int c, int q) {
  return cross2(x, y, a, b, q) >= 0 && cross2(x, y, b, c, q) >= 0 && cross2(x, y, c, a, q) >= 0;
}

// Ear clipping of a simple counter-clockwise 2D polygon into n-2 triangles of local corner indices.
// Only reflex corners can lie inside an ear, so only they are tested. When no ear is found in a full turn
// (self-intersecting or degenerate input) or the budget runs out, the current corner is clipped anyway.
static void ear_clip(const std::vector<double>& x, const std::vector<double>& y, triangulate_state& st,
                     std::vector<int>& tris) {
  int n = int(x.size());
  std::vector<int> prev(n), next(n);
  std::vector<char> reflex(n), alive(n, 1);
  std::vector<int> reflex_list;
  for (int i = 0; i < n; i++) {
    prev[i] = (i + n - 1) % n;
    next[i] = (i + 1) % n;
    reflex[i] = cross2(x.data(), y.data(), prev[i], i, next[i]) < 0;
    if (reflex[i]) reflex_list.push_back(i);
  }
  bool out_of_budget = false;
  int remaining = n, i = 0, misses = 0;
  while (remaining > 3) {
    int a = prev[i], b = next[i];
    bool ear = false;
    if (!out_of_budget && misses <= remaining && cross2(x.data(), y.data(), a, i, b) > 0) {
      ear = true;
      for (int r : reflex_list) {
        st.budget--;
        if (!alive[r] || !reflex[r] || r == a || r == i || r == b) continue;
        bool same_point =
            (x[r] == x[a] && y[r] == y[a]) || (x[r] == x[b] && y[r] == y[b]) || (x[r] == x[i] && y[r] == y[i]);
        if (!same_point && in_triangle(x.data(), y.data(), a, i, b, r)) {
          ear = false;
          break;
        }
      }
      if (st.budget < 0 && !out_of_budget) out_of_budget = true, st.fan_fallbacks++;
    }
    if (!ear && !out_of_budget && misses <= remaining) {
      misses++;
      i = b;
      continue;
    }
    tris.insert(tris.end(), {a, i, b});
    alive[i] = 0;
    next[a] = b;
    prev[b] = a;
    remaining--;
    for (int v : {a, b}) {
      bool was = reflex[v];
      reflex[v] = cross2(x.data(), y.data(), prev[v], v, next[v]) < 0;
      if (reflex[v] && !was) reflex_list.push_back(v);
    }
    misses = 0;
    i = a;
  }
  tris.insert(tris.end(), {prev[i], i, next[i]});
}

// Monotone sweep triangulation (the decomposition into y-monotone pieces of de Berg et al., Computational Geometry,
// ch. 3, then each piece by its two chains): O(n log n) steps whatever the shape, for the polygons whose ear clipping
// would cost too much; weakly simple outlines too (corners at one point, as where a bridge to a hole is written twice).
// It returns false, leaving tris as it found it, when a step finds what such a polygon cannot have (a dead end: two
// edges out and back along one line; crossing edges) or a triangle comes out turned over; the caller then sweeps the
// polygon without its dead ends, or ear-clips.
namespace {

struct sweep_triangulator {
  const double* x = nullptr;
  const double* y = nullptr;
  int n = 0;

  // a comes before b in the downward sweep: higher y, then smaller x, then the smaller index.
  bool above(int a, int b) const { return y[a] != y[b] ? y[a] > y[b] : x[a] != x[b] ? x[a] < x[b] : a < b; }
  double turn(int a, int b, int c) const { return cross2(x, y, a, b, c); }

  // Edge e runs from corner e to corner e + 1; edge n is the probe, a point-sized edge at corner `probe`.
  int probe = 0;
  int upper(int e) const { return e == n ? probe : above(e, (e + 1) % n) ? e : (e + 1) % n; }
  int lower(int e) const { return e == n ? probe : above(e, (e + 1) % n) ? (e + 1) % n : e; }

  // Sweep status order of two edges that both cross the sweep line: the one that starts later is placed by the side
  // of the other on which its upper corner lies; ties (a shared upper corner) by the lower corners, then by index.
  bool west_of(int a, int b) const {
    if (a == b) return false;
    // The probe stands for the polygon's inside just west of its corner, so an edge through the corner's point lies
    // east of it. (Only in weakly simple outlines, where another corner has the same point — a bridge to a hole
    // written twice — does an edge of the sweep status touch the corner queried.)
    if (a == n || b == n) {
      int e = a == n ? b : a;
      bool e_west = turn(upper(e), lower(e), probe) > 0;
      return a == n ? !e_west : e_west;
    }
    int ua = upper(a), ub = upper(b);
    if (ua != ub) {
      double t = above(ub, ua) ? turn(ub, lower(b), ua) : -turn(ua, lower(a), ub);
      if (t != 0) return t < 0;
    }
    double t = turn(ua, lower(a), lower(b));
    if (t != 0) return t > 0;
    return a < b;
  }
  struct order {
    const sweep_triangulator* s;
    bool operator()(int a, int b) const { return s->west_of(a, b); }
  };

  std::vector<std::pair<int, int>> diagonals;

  // Adds the diagonals that cut the polygon into y-monotone pieces. False on what a simple polygon cannot have.
  bool split_monotone() {
    enum kind : char { start, end, split, merge, regular_down, regular_up };
    std::vector<int> sweep(size_t(n), 0);
    for (int i = 0; i < n; i++) sweep[size_t(i)] = i;
    std::sort(sweep.begin(), sweep.end(), [&](int a, int b) { return above(a, b); });
    std::vector<char> type(static_cast<size_t>(n));
    for (int v = 0; v < n; v++) {
      int p = (v + n - 1) % n, q = (v + 1) % n;
      bool pa = above(p, v), qa = above(q, v);
      double t = turn(p, v, q);
      if (pa == qa && t == 0) return false;  // a spike: both edges along one line
      type[size_t(v)] = !pa && !qa ? (t > 0 ? start : split)
                        : pa && qa ? (t > 0 ? end : merge)
                        : pa       ? regular_down
                                   : regular_up;
    }
    std::set<int, order> status(order{this});
    std::vector<std::set<int, order>::iterator> where(static_cast<size_t>(n));
    std::vector<char> in_status(size_t(n), 0);
    std::vector<int> helper(size_t(n), -1);
    auto insert = [&](int e, int v) {
      auto [it, fresh] = status.insert(e);
      if (!fresh) return false;
      where[size_t(e)] = it, in_status[size_t(e)] = 1, helper[size_t(e)] = v;
      return true;
    };
    // Ends edge e at corner v, joining v to the edge's helper when that is a merge corner.
    auto finish = [&](int e, int v) {
      if (!in_status[size_t(e)]) return false;
      if (type[size_t(helper[size_t(e)])] == merge) diagonals.push_back({v, helper[size_t(e)]});
      status.erase(where[size_t(e)]);
      in_status[size_t(e)] = 0;
      return true;
    };
    // The edge directly west of corner v (-1 when there is none).
    auto west_edge = [&](int v) {
      probe = v;
      auto it = status.lower_bound(n);
      return it == status.begin() ? -1 : *std::prev(it);
    };
    for (int v : sweep) {
      int before = (v + n - 1) % n;  // the edge ending at v
      switch (type[size_t(v)]) {
        case start:
          if (!insert(v, v)) return false;
          break;
        case end:
          if (!finish(before, v)) return false;
          break;
        case split: {
          int w = west_edge(v);
          if (w < 0) return false;
          diagonals.push_back({v, helper[size_t(w)]});
          helper[size_t(w)] = v;
          if (!insert(v, v)) return false;
          break;
        }
        case merge: {
          if (!finish(before, v)) return false;
          int w = west_edge(v);
          if (w < 0) return false;
          if (type[size_t(helper[size_t(w)])] == merge) diagonals.push_back({v, helper[size_t(w)]});
          helper[size_t(w)] = v;
          break;
        }
        case regular_down:  // the polygon's interior lies east of v
          if (!finish(before, v) || !insert(v, v)) return false;
          break;
        default: {  // regular_up: the interior lies west of v
          int w = west_edge(v);
          if (w < 0) return false;
          if (type[size_t(helper[size_t(w)])] == merge) diagonals.push_back({v, helper[size_t(w)]});
          helper[size_t(w)] = v;
        }
      }
    }
    return status.empty();
  }

  // Triangulates one y-monotone piece (corners counter-clockwise) by its two chains; false when it is not monotone.
  bool triangulate_monotone(const std::vector<int>& piece, std::vector<int>& tris) const {
    int m = int(piece.size());
    int top = 0, bottom = 0;
    for (int i = 1; i < m; i++) {
      if (above(piece[size_t(i)], piece[size_t(top)])) top = i;
      if (above(piece[size_t(bottom)], piece[size_t(i)])) bottom = i;
    }
    // Counter-clockwise from the top corner runs down the west chain; clockwise, down the east chain. Merge them.
    std::vector<std::pair<int, bool>> order;  // (corner, on the west chain)
    order.reserve(size_t(m));
    order.push_back({piece[size_t(top)], true});
    int w = (top + 1) % m, e = (top + m - 1) % m;
    while (int(order.size()) < m) {
      bool take_west = w != bottom && (e == bottom || above(piece[size_t(w)], piece[size_t(e)]));
      if (int(order.size()) == m - 1) take_west = true;  // the bottom corner (on both chains)
      int c = take_west ? piece[size_t(w)] : piece[size_t(e)];
      if (!above(order.back().first, c)) return false;  // not monotone
      order.push_back({c, take_west});
      if (take_west)
        w = (w + 1) % m;
      else
        e = (e + m - 1) % m;
    }
    // A triangle of corner c and the stacked edge (s, t), s above t, wound counter-clockwise: a west chain runs down
    // counter-clockwise, an east chain up.
    auto emit = [&](int c, int s, int t, bool west) {
      if (west)
        tris.insert(tris.end(), {s, t, c});
      else
        tris.insert(tris.end(), {c, t, s});
    };
    std::vector<std::pair<int, bool>> stack = {order[0], order[1]};
    for (int j = 2; j < m - 1; j++) {
      auto [c, west] = order[size_t(j)];
      if (west != stack.back().second) {
        for (size_t k = 0; k + 1 < stack.size(); k++) emit(c, stack[k].first, stack[k + 1].first, stack[k + 1].second);
        stack = {order[size_t(j - 1)], order[size_t(j)]};
      } else {
        auto last = stack.back();
        stack.pop_back();
        while (!stack.empty()) {
          int s = stack.back().first;
          double t = west ? turn(s, last.first, c) : turn(c, last.first, s);
          if (!(t > 0)) break;
          emit(c, s, last.first, west);
          last = stack.back();
          stack.pop_back();
        }
        stack.push_back(last);
        stack.push_back(order[size_t(j)]);
      }
    }
    int c = order[size_t(m - 1)].first;
    for (size_t k = 0; k + 1 < stack.size(); k++) emit(c, stack[k].first, stack[k + 1].first, stack[k + 1].second);
    return true;
  }

  // The pieces the diagonals cut the polygon into, each counter-clockwise: at each corner the edges are sorted by
  // angle, and a piece's boundary turns at every corner onto the next edge clockwise from the one it came along.
  bool pieces(std::vector<std::vector<int>>& out) const {
    std::vector<int> first(size_t(n) + 1, 0);
    for (int v = 0; v < n; v++) first[size_t(v) + 1] = 2;
    for (auto [a, b] : diagonals) first[size_t(a) + 1]++, first[size_t(b) + 1]++;
    for (int v = 0; v < n; v++) first[size_t(v) + 1] += first[size_t(v)];
    std::vector<int> to(static_cast<size_t>(first[size_t(n)])), fill(first.begin(), first.end() - 1);
    for (int v = 0; v < n; v++) {
      to[size_t(fill[size_t(v)]++)] = (v + 1) % n;
      to[size_t(fill[size_t((v + 1) % n)]++)] = v;
    }
    for (auto [a, b] : diagonals) to[size_t(fill[size_t(a)]++)] = b, to[size_t(fill[size_t(b)]++)] = a;
    for (int v = 0; v < n; v++) {
      // Counter-clockwise from the east: the upper half-plane (and east) first, then by turn.
      auto half = [&](int u) {
        double dy = y[u] - y[v];
        return dy > 0 || (dy == 0 && x[u] > x[v]) ? 0 : 1;
      };
      std::sort(to.begin() + first[size_t(v)], to.begin() + first[size_t(v) + 1], [&](int a, int b) {
        int ha = half(a), hb = half(b);
        if (ha != hb) return ha < hb;
        double t = turn(v, a, b);
        return t > 0 || (t == 0 && a < b);
      });
      // Two edges of one corner along one ray (or a diagonal twice): not a subdivision a simple polygon gives.
      for (int h = first[size_t(v)]; h + 1 < first[size_t(v) + 1]; h++) {
        int a = to[size_t(h)], b = to[size_t(h) + 1];
        if (a == b || (half(a) == half(b) && turn(v, a, b) == 0)) return false;
      }
    }
    // Half-edge h leaves corner owner[h] for corner to[h]; twin[h] is the half-edge back (found by sorting them).
    std::vector<int> owner(to.size()), twin(to.size()), by_ends(to.size());
    for (int v = 0; v < n; v++)
      for (int h = first[size_t(v)]; h < first[size_t(v) + 1]; h++) owner[size_t(h)] = v;
    for (size_t h = 0; h < to.size(); h++) by_ends[h] = int(h);
    auto ends_less = [&](int a, int b) {
      return owner[size_t(a)] != owner[size_t(b)] ? owner[size_t(a)] < owner[size_t(b)] : to[size_t(a)] < to[size_t(b)];
    };
    std::sort(by_ends.begin(), by_ends.end(), ends_less);
    for (size_t h = 0; h < to.size(); h++) {
      int v = owner[h], u = to[h];
      auto it = std::lower_bound(by_ends.begin(), by_ends.end(), u, [&](int g, int) {
        return owner[size_t(g)] != u ? owner[size_t(g)] < u : to[size_t(g)] < v;
      });
      if (it == by_ends.end() || owner[size_t(*it)] != u || to[size_t(*it)] != v) return false;
      twin[h] = *it;
    }
    std::vector<char> used(to.size(), 0);
    for (int v = 0; v < n; v++)  // the outside: each edge taken backward
      for (int h = first[size_t(v)]; h < first[size_t(v) + 1]; h++)
        if (to[size_t(h)] == (v + n - 1) % n) used[size_t(h)] = 1;
    for (size_t h0 = 0; h0 < to.size(); h0++) {
      if (used[h0]) continue;
      std::vector<int> piece;
      size_t h = h0;
      while (!used[h]) {
        used[h] = 1;
        piece.push_back(owner[h]);
        int u = to[h], back = twin[h];
        int lo = first[size_t(u)], deg = first[size_t(u) + 1] - lo;
        h = size_t(lo + (back - lo + deg - 1) % deg);
      }
      if (h != h0 || piece.size() < 3) return false;  // the boundary ran into another piece's or the outside
      out.push_back(std::move(piece));
    }
    return true;
  }
};

}  // namespace

bool sweep_triangulate(const std::vector<double>& x, const std::vector<double>& y, std::vector<int>& tris) {
  if (x.size() < 3 || x.size() != y.size() || x.size() > size_t(INT_MAX / 3)) return false;
  sweep_triangulator s;
  s.x = x.data(), s.y = y.data(), s.n = int(x.size());
  std::vector<std::vector<int>> parts;
  if (!s.split_monotone() || !s.pieces(parts)) return false;
  std::vector<int> out;
  out.reserve(3 * (x.size() - 2));
  for (const auto& piece : parts)
    if (!s.triangulate_monotone(piece, out)) return false;
  if (out.size() != 3 * (x.size() - 2)) return false;
  // The pieces' triangles have signed areas adding up to the outline's (by construction; checked as a guard), so with
  // n-2 of them none turned over (up to rounding) means none overlaps another: an exact triangulation.
  int n = int(x.size());
  double area = 0, scale = 0;
  for (int i = 1; i + 1 < n; i++) area += cross2(x.data(), y.data(), 0, i, i + 1);
  double sum = 0;
  for (size_t t = 0; t < out.size(); t += 3) {
    int a = out[t], b = out[t + 1], c = out[t + 2];
    double ab = (x[b] - x[a]) * (y[c] - y[a]), ba = (y[b] - y[a]) * (x[c] - x[a]);
    double turn = ab - ba, size = std::fabs(ab) + std::fabs(ba);
    if (turn < -1e-12 * size) return false;
    sum += turn;
    scale += size;
  }
  if (!(std::fabs(sum - area) <= 1e-9 * scale)) return false;
  tris.insert(tris.end(), out.begin(), out.end());
  return true;
}

// Ear clipping tests each candidate ear against the reflex corners, in about n times their number of steps for the
// polygons of real files, but walks round and round some shapes (a comb of 4096 teeth spent the file's budget of 2e8
// steps). It is tried where n times the reflex corners is at most ear_clip_max_work, for at most ear_clip_max_steps;
// the monotone sweep (n log n) takes over beyond that, and ear clipping within the file's budget only when the sweep
// refuses the polygon (one that crosses itself).
constexpr long long ear_clip_max_work = 1 << 24;
constexpr long long ear_clip_max_steps = 1 << 26;

// The corners of a polygon without its dead ends: where the outline runs out along a line and straight back (a slit
// cut into the surface, or a hair sticking out of it) its far end is left out, and so is a corner at the point of the
// one before; repeated until none is left. That is the same surface (a dead end has no area), but one the monotone
// sweep can order (it refuses any dead end: its two edges lie along one line). False, kept untouched, when there is
// none.
static bool without_dead_ends(const std::vector<double>& x, const std::vector<double>& y, std::vector<int>& kept) {
  int n = int(x.size());
  auto same = [&](int a, int b) { return x[a] == x[b] && y[a] == y[b]; };
  auto dead_end = [&](int a, int b, int c) {  // b is the far end of a run a -> b -> c out and back
    return cross2(x.data(), y.data(), a, b, c) == 0 &&
           (x[b] - x[a]) * (x[c] - x[b]) + (y[b] - y[a]) * (y[c] - y[b]) < 0;
  };
  bool any = false;
  for (int i = 0; i < n && !any; i++) any = dead_end((i + n - 1) % n, i, (i + 1) % n);
  if (!any) return false;
  std::vector<int> stack;  // stack[head..] is the polygon (corners leave the front where it closes)
  for (int c = 0; c < n; c++) {
    bool drop = !stack.empty() && same(stack.back(), c);
    while (!drop && stack.size() >= 2 && dead_end(stack[stack.size() - 2], stack.back(), c)) {
      stack.pop_back();
      drop = same(stack.back(), c);
    }
    if (!drop) stack.push_back(c);
  }
  size_t head = 0;
  for (bool changed = true; changed && stack.size() - head >= 3;) {  // where the polygon closes
    size_t m = stack.size();
    changed = true;
    if (same(stack[m - 1], stack[head]))
      stack.pop_back();
    else if (dead_end(stack[m - 2], stack[m - 1], stack[head]))
      stack.pop_back();
    else if (dead_end(stack[m - 1], stack[head], stack[head + 1]))
      head++;
    else
      changed = false;
  }
  kept.assign(stack.begin() + long(head), stack.end());
  return true;
}

// The sweep of the polygon, or of what is left of it without its dead ends.
static bool sweep_with_dead_ends(const std::vector<double>& x, const std::vector<double>& y, std::vector<int>& tris) {
  std::vector<int> kept;
  if (!without_dead_ends(x, y, kept)) return sweep_triangulate(x, y, tris);
  if (kept.size() < 3) return false;  // nothing but dead ends: no area
  std::vector<double> kx, ky;
  for (int k : kept) kx.push_back(x[size_t(k)]), ky.push_back(y[size_t(k)]);
  std::vector<int> sub;
  if (!sweep_triangulate(kx, ky, sub)) return false;
  for (int t : sub) tris.push_back(kept[size_t(t)]);
  return true;
}

static void triangulate_concave(const std::vector<double>& x, const std::vector<double>& y, triangulate_state& st,
                                std::vector<int>& tris) {
  long long n = (long long)x.size(), reflex = 0;
  for (long long i = 0; i < n; i++)
    reflex += cross2(x.data(), y.data(), int((i + n - 1) % n), int(i), int((i + 1) % n)) < 0;
  if (n * reflex <= ear_clip_max_work) {
    triangulate_state trial;
    bool file_limited = st.budget <= ear_clip_max_steps;
    trial.budget = file_limited ? st.budget : ear_clip_max_steps;
    ear_clip(x, y, trial, tris);
    st.budget -= (file_limited ? st.budget : ear_clip_max_steps) - trial.budget;
    if (trial.fan_fallbacks == 0) return;
    if (file_limited) {
      // The file's budget, not the trial's cap, ran out: what ear clipping gives now, partly fanned, stands unless
      // the sweep does better (clipping again would only fan more).
      std::vector<int> sweep;
      if (sweep_with_dead_ends(x, y, sweep)) return tris.swap(sweep);
      st.fan_fallbacks++;
      return;
    }
    tris.clear();
  }
  if (sweep_with_dead_ends(x, y, tris)) return;
  ear_clip(x, y, st, tris);
}

// The polygon corner with the smallest position (x, then y, then z; the first of equal ones): a choice that does
// not depend on where the corner list starts or which way it runs.
static bool corner_less(vec3f a, vec3f b) {
  return a.x != b.x ? a.x < b.x : a.y != b.y ? a.y < b.y : a.z < b.z;
}
static int smallest_corner(const std::vector<vec3f>& p) {
  int m = 0;
  for (int i = 1; i < int(p.size()); i++)
    if (corner_less(p[size_t(i)], p[size_t(m)])) m = i;
  return m;
}

// Triangulates one polygon with corner positions p into n-2 triangles of local corner indices (winding kept; fewer
// where corners repeat or dead ends are left out). Convex quads split along the shorter diagonal (as tinyobjloader
// does; of equal ones, the one through the smallest corner), other convex polygons fan from their smallest corner,
// concave ones are ear-clipped or swept (triangulate_concave) in the plane of their Newell normal.
void triangulate_polygon(const std::vector<vec3f>& p, triangulate_state& st, std::vector<int>& tris) {
  int n = int(p.size());
  tris.clear();
  if (n == 3) return tris.assign({0, 1, 2});
  // Corners at the position of the corner before them (a vertex written twice in a row, or two vertices at one point)
  // are left out: their zero-length edge made both copies look straight (cross product 0), which hid a reflex corner
  // from the convexity and ear tests (an L with its inner corner written twice was fanned over its notch: a triangle
  // of negative area, the sum 1.4 times the outline).
  auto same = [&](int a, int b) { return p[a].x == p[b].x && p[a].y == p[b].y && p[a].z == p[b].z; };
  bool repeats = false;  // (checked first: most polygons have none, and load time should not pay for a list)
  for (int i = 0; i < n && !repeats; i++) repeats = same(i, (i + 1) % n);
  if (repeats) {
    std::vector<int> keep;
    for (int i = 0; i < n; i++)
      if (keep.empty() || !same(i, keep.back())) keep.push_back(i);
    while (keep.size() > 1 && same(keep.back(), keep.front())) keep.pop_back();
    if (keep.size() < 3) return;  // a point or a segment: no area
    std::vector<vec3f> q;
    for (int k : keep) q.push_back(p[size_t(k)]);
    std::vector<int> sub;
    triangulate_polygon(q, st, sub);
    for (int t : sub) tris.push_back(keep[size_t(t)]);
    return;
  }
  // Newell normal (twice the vector area) relative to corner 0, in double for robust signs.
  double nx = 0, ny = 0, nz = 0;
  for (int i = 1; i + 1 < n; i++) {
    double ax = double(p[i].x) - p[0].x, ay = double(p[i].y) - p[0].y, az = double(p[i].z) - p[0].z;
    double bx = double(p[i + 1].x) - p[0].x, by = double(p[i + 1].y) - p[0].y, bz = double(p[i + 1].z) - p[0].z;
    nx += ay * bz - az * by;
    ny += az * bx - ax * bz;
    nz += ax * by - ay * bx;
  }
  bool flat = !(std::fabs(nx) + std::fabs(ny) + std::fabs(nz) > 0) || !std::isfinite(nx + ny + nz);
  // Project by dropping the dominant axis k, keeping the cyclic order of the other two (counter-clockwise).
  int k =
      std::fabs(nx) >= std::fabs(ny) && std::fabs(nx) >= std::fabs(nz) ? 0 : (std::fabs(ny) >= std::fabs(nz) ? 1 : 2);
  double sign = (k == 0 ? nx : k == 1 ? ny : nz) < 0 ? -1.0 : 1.0;
  std::vector<double> x(n), y(n);
  for (int i = 0; i < n; i++) {
    x[i] = sign * (double(p[i][(k + 1) % 3]) - p[0][(k + 1) % 3]);
    y[i] = double(p[i][(k + 2) % 3]) - p[0][(k + 2) % 3];
  }
  bool convex = true;
  for (int i = 0; i < n && convex && !flat; i++)
    convex = cross2(x.data(), y.data(), (i + n - 1) % n, i, (i + 1) % n) >= 0;
  if (flat || convex) {
    if (n == 4) {
      float d02 = length_sq(p[2] - p[0]), d13 = length_sq(p[3] - p[1]);
      bool split02 = d02 < d13;
      if (d02 == d13) {
        // Equal diagonals (every rectangle): the one through the smallest corner (x, then y, then z), whatever the
        // corners' order, so that the two faces of a sheet written as a quad and its reverse are exact reversed twins
        // (scene.h): a ray then meets the face turned toward it.
        split02 = smallest_corner(p) % 2 == 0;
      }
      if (split02) return tris.assign({0, 1, 2, 0, 2, 3});
      return tris.assign({0, 1, 3, 1, 2, 3});
    }
    // A fan from the smallest corner: a polygon and its reverse give exact reversed twins, as quads do.
    int m = smallest_corner(p);
    for (int i = 1; i + 1 < n; i++) tris.insert(tris.end(), {m, (m + i) % n, (m + i + 1) % n});
    return;
  }
  // Ear clipping depends on where it starts and which way it goes: it runs on the corners from the smallest one on,
  // toward its smaller neighbour, so a polygon and its reverse clip the same sequence and give exact reversed twins
  // (the triangles of the reverse get their winding back).
  int m = smallest_corner(p);
  bool forward = !corner_less(p[size_t((m + n - 1) % n)], p[size_t((m + 1) % n)]);
  if (m == 0 && forward) return triangulate_concave(x, y, st, tris);
  std::vector<vec3f> q(static_cast<size_t>(n));
  std::vector<int> from(static_cast<size_t>(n)), canonical;
  for (int i = 0; i < n; i++) {
    from[size_t(i)] = forward ? (m + i) % n : (m - i + n) % n;
    q[size_t(i)] = p[size_t(from[size_t(i)])];
  }
  triangulate_polygon(q, st, canonical);  // (q starts at its smallest corner and goes toward the smaller neighbour)
  for (size_t t = 0; t + 2 < canonical.size(); t += 3) {
    int a = from[size_t(canonical[t])], b = from[size_t(canonical[t + 1])], c = from[size_t(canonical[t + 2])];
    if (forward)
      tris.insert(tris.end(), {a, b, c});
    else
      tris.insert(tris.end(), {a, c, b});
  }
}

}  // namespace bl
