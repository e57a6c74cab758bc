// cluster_bounds: SSE evaluation of node importance (x86-64 baseline: SSE2 only, no FMA).
#include "cluster_bounds.h"

#include <emmintrin.h>
#include <xmmintrin.h>

namespace bl {

namespace {

// Lane-wise select: mask ? a : b.
inline __m128 select(__m128 mask, __m128 a, __m128 b) {
  return _mm_or_ps(_mm_and_ps(mask, a), _mm_andnot_ps(mask, b));
}
// sqrt(max(v, 0)) as safe_sqrt does.
inline __m128 safe_sqrt4(__m128 v) { return _mm_sqrt_ps(_mm_max_ps(v, _mm_setzero_ps())); }

}  // namespace

void eval_node_bounds(const light_tree_data& tree, const int* nodes, int count, vec3f p,
                      vec3f n, float* num, float* inv_d2) {
  const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f), minus_one = _mm_set1_ps(-1.0f);
  const __m128 abs_mask = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
  const __m128 sign_mask = _mm_castsi128_ps(_mm_set1_epi32(int(0x80000000u)));
  for (int j0 = 0; j0 < count; j0 += 4) {
    // Four nodes as two 4x4 transposes of their packs (missing lanes repeat the last node; their results are
    // never read), rows (cx, cy, cz, r) and (ax, ay, az, cos_o), and the (sin_o, intensity) pairs as two shuffles.
    const float* q[4];
    for (int k = 0; k < 4; k++) q[k] = &tree.packed[size_t(nodes[std::min(j0 + k, count - 1)])].cx;
    __m128 cx = _mm_loadu_ps(q[0]), cy = _mm_loadu_ps(q[1]), cz = _mm_loadu_ps(q[2]), r = _mm_loadu_ps(q[3]);
    _MM_TRANSPOSE4_PS(cx, cy, cz, r);
    __m128 ax = _mm_loadu_ps(q[0] + 4), ay = _mm_loadu_ps(q[1] + 4), az = _mm_loadu_ps(q[2] + 4),
           co = _mm_loadu_ps(q[3] + 4);
    _MM_TRANSPOSE4_PS(ax, ay, az, co);
    __m128 s01 = _mm_loadh_pi(_mm_loadl_pi(zero, reinterpret_cast<const __m64*>(q[0] + 8)),
                              reinterpret_cast<const __m64*>(q[1] + 8));  // so0, in0, so1, in1
    __m128 s23 = _mm_loadh_pi(_mm_loadl_pi(zero, reinterpret_cast<const __m64*>(q[2] + 8)),
                              reinterpret_cast<const __m64*>(q[3] + 8));  // so2, in2, so3, in3
    __m128 so = _mm_shuffle_ps(s01, s23, _MM_SHUFFLE(2, 0, 2, 0));
    __m128 inten = _mm_shuffle_ps(s01, s23, _MM_SHUFFLE(3, 1, 3, 1));
    __m128 tx = _mm_sub_ps(_mm_set1_ps(p.x), cx);
    __m128 ty = _mm_sub_ps(_mm_set1_ps(p.y), cy);
    __m128 tz = _mm_sub_ps(_mm_set1_ps(p.z), cz);
    // d2 = (x*x + y*y) + z*z, as dot() evaluates it.
    __m128 d2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(tx, tx), _mm_mul_ps(ty, ty)), _mm_mul_ps(tz, tz));
    // max(d2, r*r): std::max(a, b) returns a unless a < b.
    __m128 rr = _mm_mul_ps(r, r);
    __m128 clamped = select(_mm_cmplt_ps(d2, rr), rr, d2);
    _mm_storeu_ps(inv_d2 + j0, _mm_div_ps(one, clamped));
    __m128 d = _mm_sqrt_ps(d2);
    __m128 outside = _mm_cmpgt_ps(d, r);
    __m128 sin_b_o = _mm_div_ps(r, d);
    __m128 cos_b_o = safe_sqrt4(_mm_sub_ps(one, _mm_mul_ps(sin_b_o, sin_b_o)));
    __m128 sin_b = select(outside, sin_b_o, zero), cos_b = select(outside, cos_b_o, minus_one);
    __m128 pos = _mm_cmpgt_ps(d, zero);
    __m128 wx = select(pos, _mm_div_ps(tx, d), zero);
    __m128 wy = select(pos, _mm_div_ps(ty, d), zero);
    __m128 wz = select(pos, _mm_div_ps(tz, d), one);
    // Emitter side.
    __m128 cos_w = _mm_add_ps(_mm_add_ps(_mm_mul_ps(ax, wx), _mm_mul_ps(ay, wy)), _mm_mul_ps(az, wz));
    if (tree.two_sided) cos_w = _mm_and_ps(cos_w, abs_mask);
    __m128 sin_w = safe_sqrt4(_mm_sub_ps(one, _mm_mul_ps(cos_w, cos_w)));
    __m128 inside_cone = _mm_cmpge_ps(cos_w, co);
    __m128 cos_wo = select(inside_cone, one, _mm_add_ps(_mm_mul_ps(cos_w, co), _mm_mul_ps(sin_w, so)));
    __m128 sin_wo = select(inside_cone, zero, _mm_sub_ps(_mm_mul_ps(sin_w, co), _mm_mul_ps(cos_w, so)));
    __m128 ce = select(_mm_cmpge_ps(cos_wo, cos_b), one,
                       _mm_add_ps(_mm_mul_ps(cos_wo, cos_b), _mm_mul_ps(sin_wo, sin_b)));
    ce = select(_mm_cmpgt_ps(ce, zero), ce, zero);
    // Receiver side: cos_i = dot(n, -w).
    __m128 cos_i = _mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_set1_ps(n.x), _mm_xor_ps(wx, sign_mask)),
                                         _mm_mul_ps(_mm_set1_ps(n.y), _mm_xor_ps(wy, sign_mask))),
                              _mm_mul_ps(_mm_set1_ps(n.z), _mm_xor_ps(wz, sign_mask)));
    __m128 sin_i = safe_sqrt4(_mm_sub_ps(one, _mm_mul_ps(cos_i, cos_i)));
    __m128 cr = select(_mm_cmpge_ps(cos_i, cos_b), one, _mm_add_ps(_mm_mul_ps(cos_i, cos_b), _mm_mul_ps(sin_i, sin_b)));
    cr = select(_mm_cmpgt_ps(cr, zero), cr, zero);
    __m128 v = _mm_mul_ps(_mm_mul_ps(inten, ce), cr);
    // A zero emitter bound gives exactly 0 (the scalar code returns before multiplying).
    _mm_storeu_ps(num + j0, select(_mm_cmpgt_ps(ce, zero), v, zero));
  }
}

}  // namespace bl
