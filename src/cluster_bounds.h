// cluster_bounds: the importance of many light-tree nodes at one shading point, four at a time (SSE).
// Invariant: produces bit for bit the values of node_importance_parts (same operations in the same order on
// IEEE single precision; sqrt and division are correctly rounded in SSE as in scalar code), so vectorising
// never changes an image.
#pragma once

#include "light_tree.h"

#include <vector>

namespace bl {

// For nodes[0..count): num[j] = intensity * emitter cos bound * receiver cos bound and inv_d2[j] = 1 / d^2 at
// the point (p, n), exactly as node_importance_parts. num and inv_d2 need room for count rounded up to 4.
void eval_node_bounds(const light_tree_data& tree, const int* nodes, int count, vec3f p, vec3f n, float* num,
                      float* inv_d2);

}  // namespace bl
