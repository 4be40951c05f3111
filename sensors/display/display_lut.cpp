// Display LUT: exact OCIO samples on a log2 grid, trilinear interpolation per pixel.
#include "sensors/display/display_lut.h"

#include <emmintrin.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "scene/core/check.h"
#include "scene/core/simd_lanes.h"

namespace seasense::sensors {

DisplayLut::DisplayLut(const OcioDisplay& display, int edge, float minLog2, float maxLog2)
    : edge_(edge), minLog2_(minLog2), scale_(float(edge - 1) / (maxLog2 - minLog2)) {
    CHECK(edge >= 2 && maxLog2 > minLog2);
    Image grid(edge * edge, edge, 3);  // one row per blue index
    for (int b = 0; b < edge; ++b)
        for (int g = 0; g < edge; ++g)
            for (int r = 0; r < edge; ++r) {
                float* p = grid.At(g * edge + r, b);
                const int idx[3] = {r, g, b};
                for (int c = 0; c < 3; ++c) p[c] = std::exp2(minLog2 + float(idx[c]) / scale_);
            }
    table_ = display.ToDisplayFloat(grid, 1.0f).pixels;
    table_.push_back(0.0f);  // Apply loads four floats from the last node's three
}

void DisplayLut::Apply(const float rgb[3], float out[3]) const {
    int i0[3];
    float f[3];
    const float top = float(edge_ - 1);
    for (int c = 0; c < 3; ++c) {
        // log2 of non-positive or tiny values: clamp to the grid's lower end.
        const float x = std::max(rgb[c], 1e-30f);
        const float u = std::clamp((std::log2(x) - minLog2_) * scale_, 0.0f, top);
        i0[c] = std::min(int(u), edge_ - 2);
        f[c] = u - float(i0[c]);
    }
    Trilinear(i0, f, out);
}

void DisplayLut::Trilinear(const int i0[3], const float f[3], float out[3]) const {
    const size_t e = size_t(edge_);
    const float* node = &table_[((size_t(i0[2]) * e + size_t(i0[1])) * e + size_t(i0[0])) * 3];
    // Corner (dr, dg, db)'s weight is (w_r · w_g) · w_b, each w = f or 1 − f by the corner's
    // offset: the eight products two registers at a time, corner = dr + 2 dg + 4 db per lane.
    const __m128 wr = _mm_setr_ps(1.0f - f[0], f[0], 1.0f - f[0], f[0]);
    const __m128 wg = _mm_setr_ps(1.0f - f[1], 1.0f - f[1], f[1], f[1]);
    const __m128 rg = _mm_mul_ps(wr, wg);
    const __m128 w[2] = {_mm_mul_ps(rg, _mm_set1_ps(1.0f - f[2])),
                         _mm_mul_ps(rg, _mm_set1_ps(f[2]))};
    const size_t dg = 3 * e, db = 3 * e * e;
    const float* corner[2][4] = {{node, node + 3, node + dg, node + dg + 3},
                                 {node + db, node + db + 3, node + db + dg, node + db + dg + 3}};
    // The three components in the lanes of one SSE register (the fourth lane is dropped): per
    // component the same products and sums, corner after corner, as a scalar loop.
    __m128 sum = _mm_setzero_ps();
    for (int b = 0; b < 2; ++b) {
        sum = _mm_add_ps(sum, _mm_mul_ps(_mm_shuffle_ps(w[b], w[b], _MM_SHUFFLE(0, 0, 0, 0)),
                                         _mm_loadu_ps(corner[b][0])));
        sum = _mm_add_ps(sum, _mm_mul_ps(_mm_shuffle_ps(w[b], w[b], _MM_SHUFFLE(1, 1, 1, 1)),
                                         _mm_loadu_ps(corner[b][1])));
        sum = _mm_add_ps(sum, _mm_mul_ps(_mm_shuffle_ps(w[b], w[b], _MM_SHUFFLE(2, 2, 2, 2)),
                                         _mm_loadu_ps(corner[b][2])));
        sum = _mm_add_ps(sum, _mm_mul_ps(_mm_shuffle_ps(w[b], w[b], _MM_SHUFFLE(3, 3, 3, 3)),
                                         _mm_loadu_ps(corner[b][3])));
    }
    alignas(16) float lanes[4];
    _mm_store_ps(lanes, sum);
    out[0] = lanes[0], out[1] = lanes[1], out[2] = lanes[2];
}

namespace {

// A vector of one component of kLanes pixels to its grid coordinates: the cell (the last cell
// at most) and the fraction within it. Non-positive, tiny and NaN values clamp to the grid's
// lower end, +∞ to its top (the comparison is false for NaN, which then takes `lowest`).
struct GridCoordinates {
    GridCoordinates(float minLog2, float scale, int edge)
        : minLog2(simd::Splat(minLog2)),
          scale(simd::Splat(scale)),
          top(simd::Splat(float(edge - 1))),
          lastCell(simd::VI{} + (edge - 2)) {}
    void operator()(simd::VF x, simd::VI& i0, simd::VF& f) const {
        x = simd::Select(x > lowest, x, lowest);
        const simd::VF u = simd::Min(simd::Max((simd::Log2(x) - minLog2) * scale, zero), top);
        i0 = __builtin_convertvector(u, simd::VI);
        i0 = i0 < lastCell ? i0 : lastCell;
        f = u - __builtin_convertvector(i0, simd::VF);
    }
    simd::VF lowest = simd::Splat(1e-30f), zero = simd::Splat(0.0f);
    simd::VF minLog2, scale, top;
    simd::VI lastCell;
};

}  // namespace

#if defined(__AVX2__)
namespace {

// Eight pixels' red, green and blue (24 interleaved floats at p) in one vector each, pixel l in
// lane l: in each 128-bit half the four-pixel deinterleave by five shuffles.
inline void LoadRgb8(const float* p, __m256& r, __m256& g, __m256& b) {
    const __m256 m03 = _mm256_loadu2_m128(p + 12, p);      // r0 g0 b0 r1 | r4 g4 b4 r5
    const __m256 m14 = _mm256_loadu2_m128(p + 16, p + 4);  // g1 b1 r2 g2 | g5 b5 r6 g6
    const __m256 m25 = _mm256_loadu2_m128(p + 20, p + 8);  // b2 r3 g3 b3 | b6 r7 g7 b7
    const __m256 xy = _mm256_shuffle_ps(m14, m25, _MM_SHUFFLE(2, 1, 3, 2));  // r2 g2 r3 g3
    const __m256 yz = _mm256_shuffle_ps(m03, m14, _MM_SHUFFLE(1, 0, 2, 1));  // g0 b0 g1 b1
    r = _mm256_shuffle_ps(m03, xy, _MM_SHUFFLE(2, 0, 3, 0));
    g = _mm256_shuffle_ps(yz, xy, _MM_SHUFFLE(3, 1, 2, 0));
    b = _mm256_shuffle_ps(yz, m25, _MM_SHUFFLE(3, 0, 3, 1));
}

// The three floats at base + at[l] + offset (and one more, dropped) of eight lanes, one vector
// per component: eight 16-byte loads, transposed four lanes at a time.
inline void LoadNodes8(const float* base, const uint32_t at[8], size_t offset, __m256 out[3]) {
    const float* p = base + offset;
    const __m256 a0 = _mm256_loadu2_m128(p + at[4], p + at[0]);  // r g b · of lanes 0 | 4
    const __m256 a1 = _mm256_loadu2_m128(p + at[5], p + at[1]);
    const __m256 a2 = _mm256_loadu2_m128(p + at[6], p + at[2]);
    const __m256 a3 = _mm256_loadu2_m128(p + at[7], p + at[3]);
    const __m256 t0 = _mm256_unpacklo_ps(a0, a1), t1 = _mm256_unpacklo_ps(a2, a3);  // r r g g
    const __m256 t2 = _mm256_unpackhi_ps(a0, a1), t3 = _mm256_unpackhi_ps(a2, a3);  // b b · ·
    out[0] = _mm256_shuffle_ps(t0, t1, _MM_SHUFFLE(1, 0, 1, 0));
    out[1] = _mm256_shuffle_ps(t0, t1, _MM_SHUFFLE(3, 2, 3, 2));
    out[2] = _mm256_shuffle_ps(t2, t3, _MM_SHUFFLE(1, 0, 1, 0));
}

// Eight pixels' codes (each lane in [0, 255]) interleaved into 24 bytes at out: packed to bytes
// per 128-bit half (r0-3 g0-3 b0-3 | r4-7 g4-7 b4-7), each half's twelve bytes into pixel
// order, and the halves joined.
inline void StoreRgb8(__m256i r, __m256i g, __m256i b, std::uint8_t* out) {
    const __m256i bytes = _mm256_packus_epi16(_mm256_packus_epi32(r, g), _mm256_packus_epi32(b, b));
    const __m256i order = _mm256_setr_epi8(0, 4, 8, 1, 5, 9, 2, 6, 10, 3, 7, 11, -1, -1, -1, -1, 0,
                                           4, 8, 1, 5, 9, 2, 6, 10, 3, 7, 11, -1, -1, -1, -1);
    const __m256i rgb = _mm256_permutevar8x32_epi32(_mm256_shuffle_epi8(bytes, order),
                                                    _mm256_setr_epi32(0, 1, 2, 4, 5, 6, 7, 7));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out), _mm256_castsi256_si128(rgb));
    _mm_storel_epi64(reinterpret_cast<__m128i*>(out + 16), _mm256_extracti128_si256(rgb, 1));
}

}  // namespace
#endif

// Eight pixels at a time, each lane one pixel throughout: its grid coordinates, its eight
// corners' weights, the sums per component (each the same products and sums, in the same
// order, as Trilinear's lane for that component) and the codes. QuantizeUnorm8 as
// ⌊min(max(v, 0), 1) · 255 + 0.5⌋: maxps gives 0 for NaN, so each case (NaN and v ≤ 0 → 0,
// v ≥ 1 → 255, else the same product and sum) gives QuantizeUnorm8's code. Tested equal to
// ToDisplay8Steps byte for byte.
std::vector<std::uint8_t> DisplayLut::ToDisplay8(const Image& linear, float exposureScale) const {
#if defined(__AVX2__)
    CHECK(linear.channels == 3);
    std::vector<std::uint8_t> codes(linear.pixels.size());
    const size_t n = linear.pixels.size() / 3;
    const float* in = linear.pixels.data();
    std::uint8_t* out = codes.data();
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, (n + 7) / 8, 512), [&](const tbb::blocked_range<size_t>& r) {
            using simd::VF;
            using simd::VI;
            const VF zero = simd::Splat(0.0f), one = simd::Splat(1.0f);
            const GridCoordinates grid(minLog2_, scale_, edge_);
            const int e = edge_;
            const size_t dg = 3 * size_t(e), db = 3 * size_t(e) * size_t(e);
            const size_t cornerOffset[8] = {0, 3, dg, dg + 3, db, db + 3, db + dg, db + dg + 3};
            const float* table = table_.data();
            const auto eight = [&](const float* src, std::uint8_t* dst)
                __attribute__((always_inline)) {
                __m256 rgb[3];
                LoadRgb8(src, rgb[0], rgb[1], rgb[2]);
                VF f[3];
                VI i0[3];
                for (int c = 0; c < 3; ++c) grid(VF(rgb[c]) * exposureScale, i0[c], f[c]);
                // Unsigned, so that each lane's offset needs no sign extension (they are ≥ 0).
                alignas(32) uint32_t at[8];
                const VI node = ((i0[2] * e + i0[1]) * e + i0[0]) * 3;
                std::memcpy(at, &node, sizeof at);
                // Trilinear's weights lane for lane: rg = w_r · w_g per corner of the r-g
                // square, then rg · (1 − f_b) and rg · f_b.
                const VF wr0 = one - f[0], wg0 = one - f[1], wb0 = one - f[2];
                const VF rg[4] = {wr0 * wg0, f[0] * wg0, wr0 * f[1], f[0] * f[1]};
                VF sum[3] = {zero, zero, zero};
#pragma GCC unroll 8
                for (int k = 0; k < 8; ++k) {
                    const VF w = rg[k % 4] * (k < 4 ? wb0 : f[2]);
                    __m256 corner[3];
                    LoadNodes8(table, at, cornerOffset[k], corner);
                    for (int c = 0; c < 3; ++c) sum[c] = sum[c] + w * VF(corner[c]);
                    // Each corner's sums here: GCC would otherwise load all 64 corner values
                    // first and sum one component at a time, spilling (11 % more instructions).
                    asm("" : "+x"(sum[0]), "+x"(sum[1]), "+x"(sum[2]));
                }
                VI q[3];
                for (int c = 0; c < 3; ++c) {
                    const __m256 v = _mm256_min_ps(_mm256_max_ps(sum[c], zero), one);
                    q[c] = VI(_mm256_cvttps_epi32(_mm256_add_ps(
                        _mm256_mul_ps(v, _mm256_set1_ps(255.0f)), _mm256_set1_ps(0.5f))));
                }
                StoreRgb8(__m256i(q[0]), __m256i(q[1]), __m256i(q[2]), dst);
            };
            for (size_t group = r.begin(); group < r.end(); ++group) {
                const size_t i = 8 * group;
                if (i + 8 <= n) {
                    eight(in + 3 * i, out + 3 * i);
                } else {
                    // The last partial group: zeros (the grid's lower end) pad it.
                    alignas(32) float padded[24] = {};
                    alignas(32) std::uint8_t codes8[24];
                    std::memcpy(padded, in + 3 * i, 3 * (n - i) * sizeof(float));
                    eight(padded, codes8);
                    std::memcpy(out + 3 * i, codes8, 3 * (n - i));
                }
            }
        });
    return codes;
#else
    return ToDisplay8Steps(linear, exposureScale);
#endif
}

std::vector<std::uint8_t> DisplayLut::ToDisplay8Steps(const Image& linear,
                                                      float exposureScale) const {
    CHECK(linear.channels == 3);
    std::vector<std::uint8_t> codes(linear.pixels.size());
    const size_t n = linear.pixels.size() / 3;
    using simd::kLanes;
    using simd::VF;
    using simd::VI;
    const GridCoordinates grid(minLog2_, scale_, edge_);
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& r) {
            // The grid coordinates of kLanes pixels at a time (one vector per component, the
            // log2 by simd::Log2 instead of one libm call per value), then each pixel's
            // trilinear look-up.
            for (size_t i = r.begin(); i < r.end(); i += kLanes) {
                const size_t count = std::min(kLanes, r.end() - i);
                alignas(32) float comp[3][kLanes] = {};
                for (size_t l = 0; l < count; ++l)
                    for (int c = 0; c < 3; ++c)
                        comp[c][l] = linear.pixels[3 * (i + l) + size_t(c)] * exposureScale;
                alignas(32) int cell[3][kLanes];
                alignas(32) float frac[3][kLanes];
                for (int c = 0; c < 3; ++c) {
                    VI i0;
                    VF f;
                    grid(simd::Load(comp[c]), i0, f);
                    std::memcpy(cell[c], &i0, sizeof i0);
                    simd::Store(frac[c], f);
                }
                for (size_t l = 0; l < count; ++l) {
                    const int i0[3] = {cell[0][l], cell[1][l], cell[2][l]};
                    const float f[3] = {frac[0][l], frac[1][l], frac[2][l]};
                    float out[3];
                    Trilinear(i0, f, out);
                    for (int c = 0; c < 3; ++c)
                        codes[3 * (i + l) + size_t(c)] = QuantizeUnorm8(out[c]);
                }
            }
        });
    return codes;
}

// A pixel's three sums in one SSE2 register: its fourth lane, the next pixel's first value, is
// overwritten by the next pixel, and the last pixel is summed without reading past the row.
void HalveRgb(const Image& src, Image& dst) {
    CHECK(src.channels == 3 && dst.channels == 3 && src.width == 2 * dst.width &&
          src.height == 2 * dst.height);
    tbb::parallel_for(0, dst.height, [&](int y) {
        const float* r0 = src.At(0, 2 * y);
        const float* r1 = src.At(0, 2 * y + 1);
        float* out = dst.At(0, y);
        const __m128 quarter = _mm_set1_ps(0.25f);
        int x = 0;
        for (; x + 1 < dst.width; ++x) {
            const size_t i = size_t(6 * x);
            const __m128 sum =
                _mm_add_ps(_mm_add_ps(_mm_add_ps(_mm_loadu_ps(r0 + i), _mm_loadu_ps(r0 + i + 3)),
                                      _mm_loadu_ps(r1 + i)),
                           _mm_loadu_ps(r1 + i + 3));
            _mm_storeu_ps(out + 3 * x, _mm_mul_ps(sum, quarter));
        }
        for (; x < dst.width; ++x)
            for (int c = 0; c < 3; ++c) {
                const size_t i = size_t(6 * x + c);
                out[3 * x + c] = (((r0[i] + r0[i + 3]) + r1[i]) + r1[i + 3]) * 0.25f;
            }
    });
}

}  // namespace seasense::sensors
