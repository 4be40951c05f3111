// The small triangles' edge set-up on int32 lanes (computed modulo 2^32) against the int64 set-up
// that the spans use, bit for bit, and its choice of which triangles it takes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>

#include "channels/raster/rasterizer.h"
#include "scene/core/rng.h"

namespace seasense::channels {
namespace {

using raster_detail::EdgeSetUp;

constexpr int64_t kLimit = int64_t(1) << 14;  // the lanes take ∂E/∂x, ∂E/∂y in [−kLimit, kLimit)

struct Reference {
    EdgeSetUp edges[3];
    int64_t absArea2;
    bool small;  // every edge's a, b in [−kLimit, kLimit)
};

// The rasterizer's int64 set-up, written out: edge k from vertex i = k + 1 to j = k − 1 (mod 3),
// swapped where 2·area < 0, and the top-left rule.
Reference Int64SetUp(const int32_t (&x)[3], const int32_t (&y)[3], int64_t px, int64_t py) {
    const int64_t area2 = (int64_t(x[1]) - x[0]) * (int64_t(y[2]) - y[0]) -
                          (int64_t(y[1]) - y[0]) * (int64_t(x[2]) - x[0]);
    Reference r{};
    r.absArea2 = area2 < 0 ? -area2 : area2;
    r.small = true;
    for (int k = 0; k < 3; ++k) {
        int i = (k + 1) % 3, j = (k + 2) % 3;
        if (area2 < 0) std::swap(i, j);
        const int64_t a = int64_t(y[i]) - y[j], b = int64_t(x[j]) - x[i];
        const bool topLeft = a > 0 || (a == 0 && b > 0);
        r.edges[k].unbias = topLeft ? 0 : 1;
        r.edges[k].row = a * (px - x[i]) + b * (py - y[i]) - r.edges[k].unbias;
        r.edges[k].stepX = a * 256;
        r.edges[k].stepY = b * 256;
        r.small = r.small && a >= -kLimit && a < kLimit && b >= -kLimit && b < kLimit;
    }
    return r;
}

// Expects the lanes to take exactly the small triangles and to set those up as the int64 form.
// px, py: a sample centre (256·i + 128) inside the vertices' bounding box, as the rasterizer
// passes. Counts the triangles taken.
void ExpectLanesMatch(const int32_t (&x)[3], const int32_t (&y)[3], int64_t px, int64_t py,
                      int& taken) {
    const Reference ref = Int64SetUp(x, y, px, py);
    ASSERT_NE(ref.absArea2, 0);
    EdgeSetUp lanes[3];
    int64_t absArea2 = -1;
    const bool took = raster_detail::BoxEdgesAt(x, y, px, py, lanes, absArea2);
    const std::string where = "vertices (" + std::to_string(x[0]) + ", " + std::to_string(y[0]) +
                              ") (" + std::to_string(x[1]) + ", " + std::to_string(y[1]) + ") (" +
                              std::to_string(x[2]) + ", " + std::to_string(y[2]) + ")";
    ASSERT_EQ(took, ref.small) << where;
    if (!took) return;
    ++taken;
    EXPECT_EQ(absArea2, ref.absArea2) << where;
    for (int k = 0; k < 3; ++k) {
        EXPECT_EQ(lanes[k].row, ref.edges[k].row) << where << " edge " << k;
        EXPECT_EQ(lanes[k].stepX, ref.edges[k].stepX) << where << " edge " << k;
        EXPECT_EQ(lanes[k].stepY, ref.edges[k].stepY) << where << " edge " << k;
        EXPECT_EQ(lanes[k].unbias, ref.edges[k].unbias) << where << " edge " << k;
    }
}

// A sample centre inside the bounding box of x (nudged from t ∈ [0, 1) along it), or false.
bool CentreIn(const int32_t (&x)[3], double t, int64_t& centre) {
    const int64_t lo = std::min({x[0], x[1], x[2]}), hi = std::max({x[0], x[1], x[2]});
    const int64_t first = (lo - 128 + 255) >> 8, last = (hi - 128) >> 8;
    if (first > last) return false;
    centre = (first + int64_t(t * double(last - first + 1))) * 256 + 128;
    return true;
}

// Random triangles of every extent around the lanes' bound (a few fixed-point units to 2^15,
// vertices snapped to whole and half samples and quarter units so that edges are often
// axis-aligned or pass through sample centres), both windings, anywhere in a 32768-sample grid,
// and large ones up to 2^28 units, whose int32 products wrap around.
TEST(RasterBoxEdges, LanesEqualTheInt64SetUpBitForBit) {
    uint64_t counter = 0;
    const auto uniform = [&](double lo, double hi) {
        return lo + (hi - lo) * scene::Uniform01(31, 0, counter++);
    };
    int taken = 0, left = 0;
    for (int n = 0; n < 60000; ++n) {
        const double extent = n % 5 == 4 ? uniform(1.0, 268435456.0) : uniform(2.0, 33000.0);
        const double snap = n % 3 == 0 ? 128.0 : n % 3 == 1 ? 1.0 : 64.0;
        const double cx = uniform(0.0, 32768.0 * 256.0), cy = uniform(0.0, 32768.0 * 256.0);
        int32_t x[3], y[3];
        for (int v = 0; v < 3; ++v) {
            const double ex = n % 7 == 0 ? 0.0 : uniform(-0.5, 0.5) * extent;
            const double ey = n % 11 == 0 ? 0.0 : uniform(-0.5, 0.5) * extent;
            x[v] =
                int32_t(std::clamp(std::round((cx + ex) / snap) * snap, -134217728.0, 134217728.0));
            y[v] =
                int32_t(std::clamp(std::round((cy + ey) / snap) * snap, -134217728.0, 134217728.0));
        }
        if ((int64_t(x[1]) - x[0]) * (int64_t(y[2]) - y[0]) ==
            (int64_t(y[1]) - y[0]) * (int64_t(x[2]) - x[0]))
            continue;  // degenerate: never set up
        int64_t px = 0, py = 0;
        if (!CentreIn(x, uniform(0.0, 1.0), px) || !CentreIn(y, uniform(0.0, 1.0), py)) continue;
        const int tookBefore = taken;
        ExpectLanesMatch(x, y, px, py, taken);
        left += taken == tookBefore;
        if (HasFatalFailure()) return;
    }
    EXPECT_GT(taken, 10000);
    EXPECT_GT(left, 10000);
}

// Edges whose a or b is exactly −2^14 (the last the lanes take), 2^14 − 1, 2^14 and −2^14 − 1
// (the first they leave), with the triangle on either side, in both windings and with every
// vertex first, and right triangles with legs of 2^16 and more, whose 2·area wraps around in
// int32 (to 0 for legs of 2^16 and 2^20).
TEST(RasterBoxEdges, LanesTakeExactlyTheEdgesWithinTheBound) {
    int taken = 0;
    const int64_t base = 4000 * 256;
    for (const int64_t len : {kLimit, kLimit - 1, -kLimit, -kLimit - 1, kLimit + 1, 1 - kLimit}) {
        for (const int64_t off : {int64_t(0), int64_t(77), int64_t(-300), int64_t(5000)}) {
            for (int axisSide = 0; axisSide < 4; ++axisSide) {
                // The edge from vertex 0 to 1 along x or y, the third vertex on either side.
                const bool alongX = axisSide < 2;
                const int64_t side = axisSide % 2 == 0 ? 3000 : -3000;
                const int64_t p[3][2] = {{0, 0},
                                         {alongX ? len : off, alongX ? off : len},
                                         {alongX ? off / 2 : side, alongX ? side : off / 2}};
                for (int rot = 0; rot < 3; ++rot) {
                    for (bool reverse : {false, true}) {
                        int32_t x[3], y[3];
                        for (int v = 0; v < 3; ++v) {
                            const int src = (rot + (reverse ? 3 - v : v)) % 3;
                            x[v] = int32_t(base + p[src][0]);
                            y[v] = int32_t(base + p[src][1]);
                        }
                        int64_t px = 0, py = 0;
                        ASSERT_TRUE(CentreIn(x, 0.5, px) && CentreIn(y, 0.5, py));
                        ExpectLanesMatch(x, y, px, py, taken);
                    }
                }
            }
        }
    }
    for (const int64_t s : {int64_t(1) << 16, int64_t(3) << 15, int64_t(1) << 20}) {
        const int32_t x[3] = {int32_t(base), int32_t(base + s), int32_t(base)};
        const int32_t y[3] = {int32_t(base), int32_t(base + s), int32_t(base + s)};
        int none = 0;
        ExpectLanesMatch(x, y, base + 128, base + 128, none);
        const int32_t xr[3] = {x[0], x[2], x[1]}, yr[3] = {y[0], y[2], y[1]};
        ExpectLanesMatch(xr, yr, base + 128, base + 128, none);
        EXPECT_EQ(none, 0);
    }
    EXPECT_GT(taken, 100);
}

}  // namespace
}  // namespace seasense::channels
