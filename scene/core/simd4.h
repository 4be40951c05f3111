// Four-lane float helpers on SSE2 (the x86-64 baseline) shared by the per-sample kernels.
// Each helper matches the scalar operation it stands for, so lane results equal scalar ones.
#pragma once

#include <immintrin.h>

#include <cstddef>
#include <cstdint>
#include <iterator>

namespace seasense::simd4 {

using F4 = __m128;
using I4 = __m128i;

inline F4 Set4(float v) { return _mm_set1_ps(v); }

// Four doubles on lanes (a GCC vector type: one AVX register, or two SSE2 ones).
typedef double Double4 __attribute__((vector_size(32)));
// The four lanes of v as doubles (exact): one AVX conversion, where GCC's generic conversion
// takes two halves.
inline Double4 ToDouble4(F4 v) {
#if defined(__AVX__)
    return Double4(_mm256_cvtps_pd(v));
#else
    typedef float Float4 __attribute__((vector_size(16)));
    return __builtin_convertvector(Float4(v), Double4);
#endif
}
// |v|: the sign bit cleared.
inline F4 Abs4(F4 v) { return _mm_andnot_ps(_mm_set1_ps(-0.0f), v); }
// std::max(a, b): b when a < b, else a (same NaN and ±0 behaviour).
inline F4 Max4(F4 a, F4 b) { return _mm_max_ps(b, a); }
// std::min(a, b): b when b < a, else a.
inline F4 Min4(F4 a, F4 b) { return _mm_min_ps(b, a); }
inline F4 Clamp4(F4 v, F4 lo, F4 hi) { return Min4(Max4(v, lo), hi); }
inline F4 Select4(F4 mask, F4 a, F4 b) {
    return _mm_or_ps(_mm_and_ps(mask, a), _mm_andnot_ps(mask, b));
}
// (x + y) + z, the order of glm::dot.
inline F4 Dot4(F4 ax, F4 ay, F4 az, F4 bx, F4 by, F4 bz) {
    return _mm_add_ps(_mm_add_ps(_mm_mul_ps(ax, bx), _mm_mul_ps(ay, by)), _mm_mul_ps(az, bz));
}

// e^x, four lanes, for x in [−87, 88] (clamped to it: e^−87 < 1.7e-38, e^88 < FLT_MAX):
// x = n ln 2 + r with |r| ≤ ln 2 / 2 (ln 2 split in two so that n ln 2 is exact, Cody & Waite,
// "Software Manual for the Elementary Functions" (1980) ch. 6), e^r by its degree-6 Taylor
// polynomial (remainder ≤ (ln 2 / 2)^7 / 7! · √2 < 1.7e-7 relative), 2^n by the exponent bits.
// The polynomial's coefficients, highest degree first (Horner's scheme).
inline constexpr float kExpTaylor6[] = {1.0f / 720.0f, 1.0f / 120.0f, 1.0f / 24.0f, 1.0f / 6.0f,
                                        0.5f,          1.0f,          1.0f};
inline F4 Exp4(F4 x) {
    x = _mm_min_ps(_mm_max_ps(x, _mm_set1_ps(-87.0f)), _mm_set1_ps(88.0f));
    const __m128i n = _mm_cvtps_epi32(_mm_mul_ps(x, _mm_set1_ps(1.44269504f)));  // round
    const F4 fn = _mm_cvtepi32_ps(n);
    F4 r = _mm_sub_ps(x, _mm_mul_ps(fn, _mm_set1_ps(0.693359375f)));
    r = _mm_sub_ps(r, _mm_mul_ps(fn, _mm_set1_ps(-2.12194440e-4f)));
    F4 p = _mm_set1_ps(kExpTaylor6[0]);
    for (size_t i = 1; i < std::size(kExpTaylor6); ++i)
        p = _mm_add_ps(_mm_mul_ps(p, r), _mm_set1_ps(kExpTaylor6[i]));
    const F4 scale = _mm_castsi128_ps(_mm_slli_epi32(_mm_add_epi32(n, _mm_set1_epi32(127)), 23));
    return _mm_mul_ps(p, scale);
}

// acos x, four lanes, x clamped to [−1, 1]: Abramowitz & Stegun 4.4.46,
// acos|x| = √(1 − |x|) Σ a_k |x|^k with |error| ≤ 2e-8 rad (plus float rounding), and
// acos x = π − acos|x| for x < 0.
inline F4 Acos4(F4 x) {
    const F4 ax = _mm_min_ps(Abs4(x), _mm_set1_ps(1.0f));
    F4 p = _mm_set1_ps(-0.0012624911f);
    p = _mm_add_ps(_mm_mul_ps(p, ax), _mm_set1_ps(0.0066700901f));
    p = _mm_add_ps(_mm_mul_ps(p, ax), _mm_set1_ps(-0.0170881256f));
    p = _mm_add_ps(_mm_mul_ps(p, ax), _mm_set1_ps(0.0308918810f));
    p = _mm_add_ps(_mm_mul_ps(p, ax), _mm_set1_ps(-0.0501743046f));
    p = _mm_add_ps(_mm_mul_ps(p, ax), _mm_set1_ps(0.0889789874f));
    p = _mm_add_ps(_mm_mul_ps(p, ax), _mm_set1_ps(-0.2145988016f));
    p = _mm_add_ps(_mm_mul_ps(p, ax), _mm_set1_ps(1.5707963050f));
    const F4 r = _mm_mul_ps(_mm_sqrt_ps(_mm_sub_ps(_mm_set1_ps(1.0f), ax)), p);
    return Select4(_mm_cmplt_ps(x, _mm_setzero_ps()), _mm_sub_ps(_mm_set1_ps(3.14159265f), r), r);
}

// sin x and cos x per lane, for |x| ≤ 4 (e.g. phases already reduced to [−π, π]), to about
// 2e-7 absolute: x = n π/2 + r with |r| ≤ π/4, π/2 in three parts of which the first two have
// short mantissas so that n times them is exact (Cody & Waite's reduction as in Cephes' sinf,
// S. L. Moshier 1989), then the Taylor series of sin r to r⁹ and cos r to r¹⁰ (truncation
// < 3e-9 at π/4); the quadrant n mod 4 swaps and signs the pair with masks, no branches.
// Written once for any float vector F (four or eight lanes, with RoundToInt for its width):
// every lane does the same IEEE operations, so both widths give the same bits per lane.
// Integer lanes of a float vector's width (the attribute cannot take a template's size).
template <size_t kBytes>
struct IntLanes;
template <>
struct IntLanes<16> {
    using Type = int32_t __attribute__((vector_size(16)));
};
template <>
struct IntLanes<32> {
    using Type = int32_t __attribute__((vector_size(32)));
};
inline I4 RoundToInt(F4 v) { return _mm_cvtps_epi32(v); }  // nearest, ties to even
#if defined(__AVX2__)
using F8 = __m256;
inline __m256i RoundToInt(F8 v) { return _mm256_cvtps_epi32(v); }
#endif
template <class F>
inline void SinCosLanes(F x, F& sinX, F& cosX) {
    using I = typename IntLanes<sizeof(F)>::Type;
    const I n = (I)RoundToInt(x * 0.63661977236f);  // round(x 2/π)
    const F fn = __builtin_convertvector(n, F);
    F r = x - fn * 1.5703125f;
    r = r - fn * 4.837512969970703125e-4f;
    r = r - fn * 7.54978995489188216e-8f;
    const F r2 = r * r;
    F ps = F{} + 1.0f / 362880.0f;
    ps = ps * r2 + -1.0f / 5040.0f;
    ps = ps * r2 + 1.0f / 120.0f;
    ps = ps * r2 + -1.0f / 6.0f;
    const F s = r + r * r2 * ps;
    F pc = F{} + -1.0f / 3628800.0f;
    pc = pc * r2 + 1.0f / 40320.0f;
    pc = pc * r2 + -1.0f / 720.0f;
    pc = pc * r2 + 1.0f / 24.0f;
    pc = pc * r2 + -0.5f;
    const F c = pc * r2 + 1.0f;
    // Quadrant q: sin x = (s, c, −s, −c)[q], cos x = (c, −s, −c, s)[q]; bit 1 of q (of q + 1
    // for the cosine) moved to the sign bit.
    const I swap = (n & 1) == 1;
    const I sinSign = (n & 2) << 30;
    const I cosSign = ((n + 1) & 2) << 30;
    sinX = (F)((I)(swap ? c : s) ^ sinSign);
    cosX = (F)((I)(swap ? s : c) ^ cosSign);
}
inline void SinCos4(F4 x, F4& sinX, F4& cosX) { SinCosLanes(x, sinX, cosX); }

// Lane 0 of v.
inline float Lane0(F4 v) { return _mm_cvtss_f32(v); }

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
