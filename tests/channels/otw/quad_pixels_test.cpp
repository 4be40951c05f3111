// ClassifyQuadPixels makes, lane for lane, the per-pixel decisions of the OTW classification's
// scalar path (BlockClassifier::Pixels, DepthsClose, SeaTrianglePixel's sums), bit for bit, on
// synthetic visibility rows mixing sky, sea and model ids, depths on either side of the ratio
// and signed zeros, at every offset of a row segment.
#include "channels/otw/quad_pixels.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

namespace seasense::channels {
namespace {

using simd::kLanes;

constexpr uint32_t kSky = 0xffffffffu;
constexpr uint32_t kFirstModel = 1000;
constexpr float kRatio = 1.1f;

uint32_t Bits(float f) {
    uint32_t u;
    std::memcpy(&u, &f, sizeof u);
    return u;
}

// The scalar decisions of the pixel whose samples start at column x of rows 0 and 1, written
// as BlockClassifier's scalar path computes them.
struct Reference {
    bool same = true, allSea = true, sky, close;
    float b1Sum = 0.0f, b2Sum = 0.0f;
};
Reference Scalar(const std::vector<uint32_t>* prim, const std::vector<float>* depth,
                 const std::vector<float>* b1, const std::vector<float>* b2, size_t x) {
    Reference r;
    const uint32_t prim0 = prim[0][x];
    float dMin = std::numeric_limits<float>::infinity(), dMax = 0.0f;
    for (int j = 0; j < 2; ++j) {
        for (size_t i = 0; i < 2; ++i) {
            r.same &= prim[j][x + i] == prim0;
            r.allSea &= prim[j][x + i] < kFirstModel;
            dMin = std::min(dMin, depth[j][x + i]), dMax = std::max(dMax, depth[j][x + i]);
            r.b1Sum += b1[j][x + i];
            r.b2Sum += b2[j][x + i];
        }
    }
    r.sky = r.same && prim0 == kSky;
    r.close = dMax <= kRatio * dMin;
    return r;
}

TEST(QuadPixels, EqualsTheScalarDecisionsLaneForLane) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    const size_t width = 8 * kLanes + 6;  // samples per row: segments at odd offsets too
    std::vector<uint32_t> prim[2];
    std::vector<float> depth[2], b1[2], b2[2];
    int counts[6] = {};  // same, allSea, sky, close, mixed sea/model, sea over several triangles
    for (int trial = 0; trial < 400; ++trial) {
        for (int j = 0; j < 2; ++j) {
            prim[j].resize(width), depth[j].resize(width), b1[j].resize(width);
            b2[j].resize(width);
        }
        // Runs of one id (as triangles cover neighbouring samples) from a small pool of sky,
        // sea (several triangles) and model ids.
        const uint32_t pool[] = {kSky, 3, 4, 999, kFirstModel, kFirstModel + 5};
        for (size_t x = 0; x < width; ++x) {
            for (int j = 0; j < 2; ++j) {
                const bool keep = x > 0 && unit(rng) < 0.7f;
                prim[j][x] = keep ? prim[j][x - 1] : pool[rng() % 6];
                // Depths near 10 m, some pixels spread across the 10 % ratio and exactly on it.
                const float spread = unit(rng) < 0.5f ? 0.02f : 0.3f;
                depth[j][x] = 10.0f * (1.0f + spread * unit(rng));
                if (rng() % 16 == 0) depth[j][x] = 10.0f * kRatio;
                if (rng() % 16 == 0) depth[j][x] = 10.0f;
                b1[j][x] = unit(rng), b2[j][x] = (rng() % 8 == 0) ? -0.0f : unit(rng);
                if (rng() % 8 == 0) b1[j][x] = -0.0f;
            }
        }
        for (size_t x0 = 0; x0 + 2 * kLanes <= width; ++x0) {
            const QuadPixels q =
                ClassifyQuadPixels(prim[0].data() + x0, prim[1].data() + x0, depth[0].data() + x0,
                                   depth[1].data() + x0, b1[0].data() + x0, b1[1].data() + x0,
                                   b2[0].data() + x0, b2[1].data() + x0, kFirstModel, kRatio);
            for (size_t l = 0; l < kLanes; ++l) {
                const Reference r = Scalar(prim, depth, b1, b2, x0 + 2 * l);
                ASSERT_EQ(q.same[l] != 0, r.same) << x0 << " " << l;
                ASSERT_EQ(q.allSea[l] != 0, r.allSea) << x0 << " " << l;
                ASSERT_EQ(q.sky[l] != 0, r.sky) << x0 << " " << l;
                ASSERT_EQ(q.depthsClose[l] != 0, r.close) << x0 << " " << l;
                ASSERT_EQ(Bits(q.b1Sum[l]), Bits(r.b1Sum)) << x0 << " " << l;
                ASSERT_EQ(Bits(q.b2Sum[l]), Bits(r.b2Sum)) << x0 << " " << l;
                counts[0] += r.same, counts[1] += r.allSea, counts[2] += r.sky;
                counts[3] += r.close, counts[4] += !r.allSea && !r.same;
                counts[5] += r.allSea && !r.same;
            }
        }
    }
    // Every decision is met both ways.
    for (int c : counts) EXPECT_GT(c, 100);
}

}  // namespace
}  // namespace seasense::channels
