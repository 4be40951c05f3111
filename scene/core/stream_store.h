// Copies to frame-sized buffers with non-temporal stores, which write whole cache lines
// without first reading them.
#pragma once

#include <emmintrin.h>

#include <cstddef>
#include <cstdint>

namespace seasense::simd {

// dst[i] = src[i] for i < n (4-byte values). A frame's targets are far larger than the caches:
// ordinary stores first read each line they write (read for ownership), streaming stores do
// not (Intel 64 and IA-32 Architectures Optimization Reference Manual, "Non-temporal stores";
// AMD64 Architecture Programmer's Manual vol. 1, "Streaming store"). Where dst is not 64-byte
// aligned, the part before the first line boundary, and the part after the last, use ordinary
// stores: those lines may be shared with a neighbouring block. Call StreamFence before another
// thread reads dst. Streaming stores also evict the lines from the caches: they pay where the
// stores would otherwise read lines from memory and the next reader is not the next pass
// (the rasterizer's targets: run +15 % against memcpy); the OTW and FLIR radiance images, read
// again at once by the overlays, plumes and sensors, ran 2-8 % slower with them.
template <class T>
void StreamCopy(T* __restrict dst, const T* __restrict src, size_t n) {
    static_assert(sizeof(T) == 4);
    size_t i = 0;
    for (; i < n && (reinterpret_cast<uintptr_t>(dst + i) & 63) != 0; ++i) dst[i] = src[i];
    for (; i + 16 <= n; i += 16) {
        __m128i* d = reinterpret_cast<__m128i*>(dst + i);
        const __m128i* q = reinterpret_cast<const __m128i*>(src + i);
        _mm_stream_si128(d, _mm_loadu_si128(q));
        _mm_stream_si128(d + 1, _mm_loadu_si128(q + 1));
        _mm_stream_si128(d + 2, _mm_loadu_si128(q + 2));
        _mm_stream_si128(d + 3, _mm_loadu_si128(q + 3));
    }
    for (; i < n; ++i) dst[i] = src[i];
}

// Streaming stores are weakly ordered: this orders them before the thread's later stores, so
// that a task finishing after it publishes them.
inline void StreamFence() { _mm_sfence(); }

}  // namespace seasense::simd
