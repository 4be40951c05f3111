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

std::vector<std::uint8_t> DisplayLut::ToDisplay8(const Image& linear, float exposureScale) const {
    CHECK(linear.channels == 3);
    std::vector<std::uint8_t> codes(linear.pixels.size());
    const size_t n = linear.pixels.size() / 3;
    using simd::kLanes;
    using simd::VF;
    using simd::VI;
    const VF lowest = simd::Splat(1e-30f), minLog2 = simd::Splat(minLog2_);
    const VF scale = simd::Splat(scale_), zero = simd::Splat(0.0f);
    const VF top = simd::Splat(float(edge_ - 1));
    const VI lastCell = VI{} + (edge_ - 2);
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
                    // Non-positive, tiny and NaN values clamp to the grid's lower end, +∞ to
                    // its top (the comparison is false for NaN, which then takes `lowest`).
                    VF x = simd::Load(comp[c]);
                    x = simd::Select(x > lowest, x, lowest);
                    const VF u = simd::Min(simd::Max((simd::Log2(x) - minLog2) * scale, zero), top);
                    VI i0 = __builtin_convertvector(u, VI);
                    i0 = i0 < lastCell ? i0 : lastCell;
                    const VF f = u - __builtin_convertvector(i0, VF);
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
