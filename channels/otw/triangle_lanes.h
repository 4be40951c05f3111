// Lane helpers of the OTW classification (BlockClassifier in otw_channel.cpp) for a cached
// triangle's vertices: a vertex's position and normal side by side in eight float lanes
// (CachedTriangle::PN), interpolated at once, and the min / max of a pixel's cosines in order.
// Every lane does the four-lane or scalar form's operations in the same order, so the results
// are the same bits.
#pragma once

#include <limits>

#include "scene/core/simd4.h"

namespace seasense::channels::triangle_lanes {

using simd4::F4;

// Eight float lanes (GCC vector extension: AVX where the build targets it, else two SSE
// halves).
using F8 = float __attribute__((vector_size(32)));

// v in all eight lanes, bit for bit.
inline F8 Set8(float v) { return F8{v, v, v, v, v, v, v, v}; }
// The (x, y, z, ·) vectors in lanes 0–3 (Low) and 4–7 (High) of v.
inline F4 Low(F8 v) { return __builtin_shufflevector(v, v, 0, 1, 2, 3); }
inline F4 High(F8 v) { return __builtin_shufflevector(v, v, 4, 5, 6, 7); }
// v in lanes 0–3 and again in 4–7.
inline F8 Twice(F4 v) { return __builtin_shufflevector(v, v, 0, 1, 2, 3, 0, 1, 2, 3); }
// Lane c of v in lanes 0–3 and lane 4 + c in lanes 4–7 (component c of a position and a
// normal side by side).
template <int c>
F8 Spread(F8 v) {
    return __builtin_shufflevector(v, v, c, c, c, c, c + 4, c + 4, c + 4, c + 4);
}

// b0·a0 + b1·a1 + b2·a2 per lane in glm's order, (b0 a0 + b1 a1) + b2 a2.
inline F8 Interpolate8(F8 b0, F8 b1, F8 b2, F8 a0, F8 a1, F8 a2) {
    return (b0 * a0 + b1 * a1) + b2 * a2;
}

// std::min and std::max of the values taken one by one (lane 0), from +∞ and −∞: minss and
// maxss make std::min's and std::max's comparisons (c < lo ? c : lo and hi < c ? c : hi, NaN
// and ties included), one instruction each even for the first value.
struct MinMax {
    F4 lo = simd4::Set4(std::numeric_limits<float>::infinity()),
       hi = simd4::Set4(-std::numeric_limits<float>::infinity());
    void Take(F4 c) { lo = _mm_min_ss(c, lo), hi = _mm_max_ss(c, hi); }
    float Min() const { return _mm_cvtss_f32(lo); }
    float Max() const { return _mm_cvtss_f32(hi); }
};

}  // namespace seasense::channels::triangle_lanes
