// Lane-generic float vectors (GCC vector extensions) for shading loops written once for the
// widest vectors the build targets: eight lanes where it generates AVX, else four (SSE2). Each
// operation is the IEEE operation per lane, so a loop gives the same bits at either width.
#pragma once

#include <immintrin.h>

#include <cstddef>
#include <cstdint>
#include <cstring>

namespace seasense::simd {

#if defined(__AVX__)
inline constexpr size_t kLanes = 8;
#else
inline constexpr size_t kLanes = 4;
#endif

using VF = float __attribute__((vector_size(kLanes * sizeof(float))));
using VI = int32_t __attribute__((vector_size(kLanes * sizeof(int32_t))));

inline VF Splat(float v) { return VF{} + v; }
// v in every lane, bit for bit (Splat's 0 + v turns −0 into +0).
inline VF Broadcast(float v) {
#if defined(__AVX__)
    return _mm256_set1_ps(v);
#else
    return _mm_set1_ps(v);
#endif
}

// count ≤ kLanes lanes from p, the rest pad (a partial last group goes through the same code).
inline VF Load(const float* p, size_t count = kLanes, float pad = 0.0f) {
    VF v;
    if (count >= kLanes) {  // one unaligned vector load
        std::memcpy(&v, p, sizeof v);
        return v;
    }
    v = Splat(pad);
    for (size_t i = 0; i < count; ++i) v[i] = p[i];
    return v;
}
// Stores the first count ≤ kLanes lanes (all of them by default: the caller's array has room).
inline void Store(float* p, VF v, size_t count = kLanes) {
    if (count >= kLanes) {
        std::memcpy(p, &v, sizeof v);
        return;
    }
    for (size_t i = 0; i < count; ++i) p[i] = v[i];
}

// base[index[l]] in lane l of lo and base[index[l] + 1] in lane l of hi: each lane's adjacent
// pair by one 8-byte load, split four lanes at a time. On the AMD cores this project runs on,
// two eight-lane gather instructions are slower than these loads (BM_UniformTableLanes).
inline void GatherPair(const float* base, VI index, VF& lo, VF& hi) {
    // Unsigned, so that each lane's offset needs no sign extension (the indices are ≥ 0).
    alignas(32) uint32_t at[kLanes];
    std::memcpy(at, &index, sizeof at);
    const auto Pair = [&](size_t l) { return reinterpret_cast<const __m64*>(base + at[l]); };
    __m128 even[kLanes / 4], odd[kLanes / 4];
    for (size_t q = 0; q < kLanes; q += 4) {
        const __m128 a = _mm_loadh_pi(_mm_loadl_pi(_mm_setzero_ps(), Pair(q)), Pair(q + 1));
        const __m128 b = _mm_loadh_pi(_mm_loadl_pi(_mm_setzero_ps(), Pair(q + 2)), Pair(q + 3));
        even[q / 4] = _mm_shuffle_ps(a, b, _MM_SHUFFLE(2, 0, 2, 0));
        odd[q / 4] = _mm_shuffle_ps(a, b, _MM_SHUFFLE(3, 1, 3, 1));
    }
#if defined(__AVX__)
    lo = _mm256_set_m128(even[1], even[0]);
    hi = _mm256_set_m128(odd[1], odd[0]);
#else
    lo = even[0];
    hi = odd[0];
#endif
}

// a where mask (a comparison's result) is set, else b.
inline VF Select(VI mask, VF a, VF b) { return mask ? a : b; }
// _mm_max_ps(b, a) / _mm_min_ps(b, a) lane for lane: a when either is NaN or both are zeros.
inline VF Max(VF a, VF b) { return b > a ? b : a; }
inline VF Min(VF a, VF b) { return b < a ? b : a; }
inline VF Abs(VF v) { return (VF)((VI)v & 0x7fffffff); }
// a + (b − a)·f.
inline VF Lerp(VF a, VF b, VF f) { return a + (b - a) * f; }
// (x + y) + z, the order of glm::dot.
inline VF Dot(VF ax, VF ay, VF az, VF bx, VF by, VF bz) { return (ax * bx + ay * by) + az * bz; }

inline VF Sqrt(VF v) {
#if defined(__AVX__)
    return _mm256_sqrt_ps(v);
#else
    return _mm_sqrt_ps(v);
#endif
}

// Bit l set where lane l of a comparison's result is.
inline unsigned LaneBits(VI mask) {
#if defined(__AVX__)
    return unsigned(_mm256_movemask_ps(reinterpret_cast<__m256>(mask)));
#else
    return unsigned(_mm_movemask_ps(reinterpret_cast<__m128>(mask)));
#endif
}

// Whether any lane of a comparison's result is set.
inline bool Any(VI mask) {
#if defined(__AVX__)
    return _mm256_movemask_ps(reinterpret_cast<__m256>(mask)) != 0;
#else
    return _mm_movemask_ps(reinterpret_cast<__m128>(mask)) != 0;
#endif
}

// Whether every lane of a comparison's result is set.
inline bool All(VI mask) {
#if defined(__AVX__)
    return _mm256_movemask_ps(reinterpret_cast<__m256>(mask)) == 0xff;
#else
    return _mm_movemask_ps(reinterpret_cast<__m128>(mask)) == 0xf;
#endif
}

// Round to the nearest integer, ties to even (as cvtps2dq in the default rounding mode), for
// |x| < 2^22: adding and subtracting 1.5·2^23 leaves x's integer part in the units place.
inline VI RoundToInt(VF x) {
    constexpr float kMagic = 12582912.0f;  // 1.5 · 2^23
    return __builtin_convertvector((x + kMagic) - kMagic, VI);
}

// log2 x per lane for positive normal x: x = 2^e · m with m in [√½, √2), and
// ln m = 2 atanh s = 2 (s + s³/3 + s⁵/5 + s⁷/7 + s⁹/9 + …), s = (m − 1) / (m + 1), |s| ≤ 0.1716
// (Abramowitz & Stegun, "Handbook of Mathematical Functions" (1964) 4.1.27); the series'
// remainder is below 1e-10, so the float rounding of the steps is the error: measured
// 1.7e-8 near x = 1 and 2.0e-7 · |log2 x| elsewhere (half an ulp of the result; tested). Zero,
// negative, subnormal, infinite and NaN lanes give finite garbage rather than the IEEE results:
// callers clamp the input first.
inline VF Log2(VF x) {
    VI bits;
    std::memcpy(&bits, &x, sizeof bits);
    VI e = ((bits >> 23) & 0xFF) - 127;
    const VI mantissaBits = (bits & 0x7FFFFF) | 0x3F800000;
    VF m;
    std::memcpy(&m, &mantissaBits, sizeof m);  // [1, 2)
    const VI high = m > 1.41421356f;           // −1 where m ≥ √2: halve it, one more octave
    m = Select(high, m * 0.5f, m);
    e -= high;
    const VF s = (m - 1.0f) / (m + 1.0f), s2 = s * s;
    const VF lnM =
        s *
        (2.0f + s2 * (2.0f / 3.0f + s2 * (2.0f / 5.0f + s2 * (2.0f / 7.0f + s2 * (2.0f / 9.0f)))));
    return __builtin_convertvector(e, VF) + lnM * 1.44269504088896341f;  // 1 / ln 2
}
}  // namespace seasense::simd
