// triangulate: an OBJ face's polygon into triangles of its corners, for load_obj. Convex polygons split along a
// diagonal or fan; concave ones are ear-clipped in the plane of their Newell normal, or, where ear clipping would take
// long (thousands of concave corners), swept into y-monotone pieces in O(n log n) steps; only polygons that cross
// themselves and exceed the file's ear-clipping budget are fanned (counted, for a warning).
// Invariants: triangles keep the polygon's winding; a polygon and its reverse, from any first corner, give exact
// reversed twins; the result depends only on the corner positions (double maths of float inputs, no hashing).
#pragma once

#include <vector>

#include "math.h"

namespace bl {

// Inner-loop steps ear clipping may spend on one file before falling back to fans (bounds hostile input).
constexpr long long ear_clip_budget = 200'000'000;

// Triangulation work left for this file, and how many polygons ran out of it.
struct triangulate_state {
  long long budget = ear_clip_budget;
  int fan_fallbacks = 0;
};

// Triangulates one polygon with corner positions p into triangles of local corner indices (winding kept): n-2 of
// them, or fewer where corners repeat in a row or a dead end is left out. Spends st's budget on ear clipping.
void triangulate_polygon(const std::vector<vec3f>& p, triangulate_state& st, std::vector<int>& tris);

// The monotone sweep triangulate_polygon uses for large concave polygons (its ear clipping would take too long): the
// corners (x[i], y[i]) of a simple counter-clockwise polygon give n-2 counter-clockwise triangles of corner indices,
// appended to tris, in O(n log n) steps; so do weakly simple ones with corners at one point (a bridge to a hole
// written twice). False, tris untouched, when it meets what such a polygon cannot have: crossing edges, or a dead end
// (two edges along one line, out and back: triangulate_polygon sweeps the polygon without them). Some self-crossing
// polygons are triangulated all the same, covering where the outline winds twice twice, as ear clipping does.
bool sweep_triangulate(const std::vector<double>& x, const std::vector<double>& y, std::vector<int>& tris);

}  // namespace bl
