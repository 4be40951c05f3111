// Display LUT: exact OCIO samples on a log2 grid, trilinear interpolation per pixel.
#include "sensors/display/display_lut.h"

#include <emmintrin.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "scene/core/check.h"

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
    const size_t e = size_t(edge_);
    // The three components in the lanes of one SSE register (the fourth lane is dropped): per
    // component the same products and sums, corner after corner, as a scalar loop.
    __m128 sum = _mm_setzero_ps();
    for (int corner = 0; corner < 8; ++corner) {
        const int dr = corner & 1, dg = (corner >> 1) & 1, db = corner >> 2;
        const float w =
            (dr ? f[0] : 1.0f - f[0]) * (dg ? f[1] : 1.0f - f[1]) * (db ? f[2] : 1.0f - f[2]);
        const float* v =
            &table_[((size_t(i0[2] + db) * e + size_t(i0[1] + dg)) * e + size_t(i0[0] + dr)) * 3];
        sum = _mm_add_ps(sum, _mm_mul_ps(_mm_set1_ps(w), _mm_loadu_ps(v)));
    }
    alignas(16) float lanes[4];
    _mm_store_ps(lanes, sum);
    out[0] = lanes[0], out[1] = lanes[1], out[2] = lanes[2];
}

std::vector<std::uint8_t> DisplayLut::ToDisplay8(const Image& linear, float exposureScale) const {
    CHECK(linear.channels == 3);
    std::vector<std::uint8_t> codes(linear.pixels.size());
    const size_t n = linear.pixels.size() / 3;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096),
                      [&](const tbb::blocked_range<size_t>& r) {
                          for (size_t i = r.begin(); i < r.end(); ++i) {
                              const float in[3] = {linear.pixels[3 * i] * exposureScale,
                                                   linear.pixels[3 * i + 1] * exposureScale,
                                                   linear.pixels[3 * i + 2] * exposureScale};
                              float out[3];
                              Apply(in, out);
                              for (int c = 0; c < 3; ++c)
                                  codes[3 * i + size_t(c)] = QuantizeUnorm8(out[c]);
                          }
                      });
    return codes;
}

}  // namespace seasense::sensors
