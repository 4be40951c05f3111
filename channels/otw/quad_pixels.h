// The per-pixel decisions of the OTW shading pass's classification (OtwChannel, BlockClassifier)
// for 2×2-supersampled pixels, simd::kLanes pixels at a time: they read only the visibility
// buffer's two sample rows of a pixel row, so a row segment of 2·kLanes samples gives one
// pixel per lane once its samples are paired (the even and odd samples of each row). Every
// lane does the scalar per-pixel operations in the same order, so the results are the same bits.
#pragma once

#include <cstdint>
#include <cstring>

#include "channels/raster/rasterizer.h"
#include "scene/core/simd_lanes.h"

namespace seasense::channels {

// A row segment's kLanes pixels, lane l the pixel of samples 2l and 2l + 1 of both rows.
struct QuadPixels {
    simd::VI same;         // all four primitive ids equal
    simd::VI allSea;       // all four ids below the first model primitive (sea, not sky)
    simd::VI sky;          // all four ids kNoPrimitive
    simd::VI depthsClose;  // largest depth ≤ maxDepthRatio × smallest
    // The barycentrics summed sample by sample from 0 in sample order (row 0, then row 1).
    simd::VF b1Sum, b2Sum;
};

namespace quad_pixels_detail {
using VU = uint32_t __attribute__((vector_size(simd::kLanes * sizeof(uint32_t))));

// Samples 2l (Even) and 2l + 1 (Odd) of the 2·kLanes values from p, lane l.
template <typename V, typename T>
void EvenOdd(const T* p, V& even, V& odd) {
    V lo, hi;
    std::memcpy(&lo, p, sizeof lo);
    std::memcpy(&hi, p + simd::kLanes, sizeof hi);
#if defined(__AVX2__)
    // Within each 128-bit half (lo0 lo2 hi0 hi2 | lo4 lo6 hi4 hi6), then the 64-bit pairs into
    // order: two instructions an output, where the generic shuffle costs three and a constant.
    const __m256 l = reinterpret_cast<__m256>(lo), h = reinterpret_cast<__m256>(hi);
    const auto order = [](__m256 v) {
        return reinterpret_cast<V>(
            _mm256_castpd_ps(_mm256_permute4x64_pd(_mm256_castps_pd(v), _MM_SHUFFLE(3, 1, 2, 0))));
    };
    even = order(_mm256_shuffle_ps(l, h, _MM_SHUFFLE(2, 0, 2, 0)));
    odd = order(_mm256_shuffle_ps(l, h, _MM_SHUFFLE(3, 1, 3, 1)));
#elif defined(__AVX__)
    even = __builtin_shufflevector(lo, hi, 0, 2, 4, 6, 8, 10, 12, 14);
    odd = __builtin_shufflevector(lo, hi, 1, 3, 5, 7, 9, 11, 13, 15);
#else
    even = __builtin_shufflevector(lo, hi, 0, 2, 4, 6);
    odd = __builtin_shufflevector(lo, hi, 1, 3, 5, 7);
#endif
}
}  // namespace quad_pixels_detail

// The decisions for the kLanes pixels whose samples start at the given pointers into the
// primitive, depth, b1 and b2 planes, row 0 and row 1 (2·kLanes samples read from each).
inline QuadPixels ClassifyQuadPixels(const uint32_t* prim0, const uint32_t* prim1,
                                     const float* depth0, const float* depth1, const float* b10,
                                     const float* b11, const float* b20, const float* b21,
                                     uint32_t firstModelPrimitive, float maxDepthRatio) {
    using namespace simd;
    using quad_pixels_detail::EvenOdd;
    using quad_pixels_detail::VU;
    QuadPixels q;
    VU a, b, c, d;  // the ids of samples (0, 0), (0, 1), (1, 0), (1, 1) (row, column)
    EvenOdd(prim0, a, b);
    EvenOdd(prim1, c, d);
    q.same = (a == b) & (a == c) & (a == d);
    q.allSea = (a < firstModelPrimitive) & (b < firstModelPrimitive) & (c < firstModelPrimitive) &
               (d < firstModelPrimitive);
    q.sky = q.same & (a == kNoPrimitive);
    // std::min / std::max from +∞ and 0, sample by sample.
    VF s0, s1, s2, s3;
    EvenOdd(depth0, s0, s1);
    EvenOdd(depth1, s2, s3);
    VF dMin = Splat(__builtin_inff()), dMax = Splat(0.0f);
    dMin = Min(Min(Min(Min(dMin, s0), s1), s2), s3);
    dMax = Max(Max(Max(Max(dMax, s0), s1), s2), s3);
    q.depthsClose = dMax <= maxDepthRatio * dMin;
    EvenOdd(b10, s0, s1);
    EvenOdd(b11, s2, s3);
    q.b1Sum = ((((Splat(0.0f) + s0) + s1) + s2) + s3);
    EvenOdd(b20, s0, s1);
    EvenOdd(b21, s2, s3);
    q.b2Sum = ((((Splat(0.0f) + s0) + s1) + s2) + s3);
    return q;
}

}  // namespace seasense::channels
