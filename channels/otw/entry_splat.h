// Writing shading entries' radiance to their samples in the OTW shading pass (OtwChannel): an
// entry is one sample, or, tagged with kPixelEntry, all N×N samples of a pixel (its key is then
// the pixel's top-left sample), shaded once (otw_channel.cpp, "Shading entries").
#pragma once

#include <immintrin.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "scene/core/simd4.h"

namespace seasense::channels {

// Keys without the tag are sample indices, below it.
inline constexpr uint32_t kPixelEntry = 1u << 30;

// Writes radiance rgb to the sample(s) of entry k; out is the block's first sample row (the
// default 2×2's pixel entries: SplatChunk).
inline void SplatEntry(float* out, uint32_t k, int sampleWidth, int n, float r, float g, float b) {
    if (!(k & kPixelEntry)) {
        float* o = out + 3 * size_t(k);
        o[0] = r, o[1] = g, o[2] = b;
        return;
    }
    k &= ~kPixelEntry;
    for (int j = 0; j < n; ++j) {
        float* o = out + 3 * (size_t(k) + size_t(j) * size_t(sampleWidth));
        for (int i = 0; i < n; ++i) o[3 * i] = r, o[3 * i + 1] = g, o[3 * i + 2] = b;
    }
}

// Whether four entries' keys (lanes 0–3) are pixel entries of four adjacent pixels of one row, left
// to right (N = 2: keys k, k + 2, k + 4, k + 6, all tagged kPixelEntry). Untagged keys are below
// kPixelEntry, so a tagged k + 6 does not wrap into another tag.
inline bool PixelRun4(__m128i keys) {
    const int32_t k0 = _mm_cvtsi128_si32(keys);
    if (!(uint32_t(k0) & kPixelEntry)) return false;
    const __m128i run = _mm_add_epi32(_mm_set1_epi32(k0), _mm_setr_epi32(0, 2, 4, 6));
    return _mm_movemask_epi8(_mm_cmpeq_epi32(keys, run)) == 0xffff;
}

// SplatEntry of count entries keys[i] with radiance (r[i], g[i], b[i]): the arrays (16-byte
// aligned, with room for count rounded up to four, as SeaChunk's kChunk floats) transposed four
// entries at a time to (r, g, b, 0) registers, written from them (the same values as SplatEntry
// writes).
inline void SplatChunk(float* out, const uint32_t* keys, size_t count, const float* r,
                       const float* g, const float* b, int sampleWidth, int n) {
    if (n != 2) {
        for (size_t i = 0; i < count; ++i)
            SplatEntry(out, keys[i], sampleWidth, n, r[i], g[i], b[i]);
        return;
    }
    for (size_t i = 0; i < count; i += 4) {
        simd4::F4 rgb[4] = {_mm_load_ps(r + i), _mm_load_ps(g + i), _mm_load_ps(b + i),
                            _mm_setzero_ps()};
        _MM_TRANSPOSE4_PS(rgb[0], rgb[1], rgb[2], rgb[3]);
        const size_t lanes = std::min<size_t>(4, count - i);
        if (lanes == 4) {
            const __m128i k = _mm_loadu_si128(reinterpret_cast<const __m128i*>(&keys[i]));
            if (PixelRun4(k)) {
                // Four adjacent pixels (most of the sky and the far sea): each of their two
                // sample rows is 24 contiguous floats, (r g b r g b) per pixel.
                const auto Two = [](simd4::F4 p, simd4::F4 q, simd4::F4* row) {
                    row[0] = _mm_shuffle_ps(p, p, _MM_SHUFFLE(0, 2, 1, 0));  // rp gp bp rp
                    row[1] = _mm_shuffle_ps(p, q, _MM_SHUFFLE(1, 0, 2, 1));  // gp bp rq gq
                    row[2] = _mm_shuffle_ps(q, q, _MM_SHUFFLE(2, 1, 0, 2));  // bq rq gq bq
                };
                simd4::F4 row[6];
                Two(rgb[0], rgb[1], row), Two(rgb[2], rgb[3], row + 3);
                float* o0 = out + 3 * size_t(keys[i] & ~kPixelEntry);
                float* o1 = o0 + 3 * size_t(sampleWidth);
#if defined(__AVX__)
                for (int v = 0; v < 3; ++v) {
                    const __m256 pair = _mm256_set_m128(row[2 * v + 1], row[2 * v]);
                    _mm256_storeu_ps(o0 + 8 * v, pair), _mm256_storeu_ps(o1 + 8 * v, pair);
                }
#else
                for (int v = 0; v < 6; ++v)
                    _mm_storeu_ps(o0 + 4 * v, row[v]), _mm_storeu_ps(o1 + 4 * v, row[v]);
#endif
                continue;
            }
            if (!_mm_movemask_ps(_mm_castsi128_ps(_mm_slli_epi32(k, 1)))) {
                // Four single samples (no key has kPixelEntry, bit 30).
                for (size_t l = 0; l < 4; ++l) {
                    float* o = out + 3 * size_t(keys[i + l]);
                    _mm_storel_pi(reinterpret_cast<__m64*>(o), rgb[l]);
                    _mm_store_ss(o + 2, _mm_movehl_ps(rgb[l], rgb[l]));
                }
                continue;
            }
        }
        for (size_t l = 0; l < lanes; ++l) {
            uint32_t k = keys[i + l];
            const simd4::F4 v = rgb[l];
            if (!(k & kPixelEntry)) {
                float* o = out + 3 * size_t(k);
                _mm_storel_pi(reinterpret_cast<__m64*>(o), v);
                _mm_store_ss(o + 2, _mm_movehl_ps(v, v));
                continue;
            }
            // Each sample row's six floats (r g b r g b) in two stores.
            k &= ~kPixelEntry;
            const simd4::F4 rgbr = _mm_shuffle_ps(v, v, _MM_SHUFFLE(0, 2, 1, 0));
            const simd4::F4 gb = _mm_shuffle_ps(v, v, _MM_SHUFFLE(3, 3, 2, 1));
            for (int j = 0; j < 2; ++j) {
                float* o = out + 3 * (size_t(k) + size_t(j) * size_t(sampleWidth));
                _mm_storeu_ps(o, rgbr);
                _mm_storel_pi(reinterpret_cast<__m64*>(o + 4), gb);
            }
        }
    }
}

}  // namespace seasense::channels
