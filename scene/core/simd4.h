// Four-lane float helpers on SSE2 (the x86-64 baseline) shared by the per-sample kernels.
// Each helper matches the scalar operation it stands for, so lane results equal scalar ones.
#pragma once

#include <immintrin.h>

#include <cstddef>

namespace seasense::simd4 {

using F4 = __m128;
using I4 = __m128i;

inline F4 Set4(float v) { return _mm_set1_ps(v); }
// |v|: the sign bit cleared.
inline F4 Abs4(F4 v) { return _mm_andnot_ps(_mm_set1_ps(-0.0f), v); }
// std::max(a, b): b when a < b, else a (same NaN and ±0 behaviour).
inline F4 Max4(F4 a, F4 b) { return _mm_max_ps(b, a); }
inline F4 Select4(F4 mask, F4 a, F4 b) {
    return _mm_or_ps(_mm_and_ps(mask, a), _mm_andnot_ps(mask, b));
}
// (x + y) + z, the order of glm::dot.
inline F4 Dot4(F4 ax, F4 ay, F4 az, F4 bx, F4 by, F4 bz) {
    return _mm_add_ps(_mm_add_ps(_mm_mul_ps(ax, bx), _mm_mul_ps(ay, by)), _mm_mul_ps(az, bz));
}

// Loads and stores of count ≤ 4 lanes: a partial last group is padded with a harmless value,
// so every sample goes through the same four-wide code.
inline F4 LoadLanes(const float* p, size_t count, float pad) {
    if (count == 4) return _mm_loadu_ps(p);
    alignas(16) float tmp[4] = {pad, pad, pad, pad};
    for (size_t i = 0; i < count; ++i) tmp[i] = p[i];
    return _mm_load_ps(tmp);
}
inline void StoreLanes(float* p, size_t count, F4 v) {
    if (count == 4) return _mm_storeu_ps(p, v);
    alignas(16) float tmp[4];
    _mm_store_ps(tmp, v);
    for (size_t i = 0; i < count; ++i) p[i] = tmp[i];
}

}  // namespace seasense::simd4
