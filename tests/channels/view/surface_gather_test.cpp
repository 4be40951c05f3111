// SeaGather's samples against the one-sample forms they must equal bit for bit: TriangleCache's
// position and normal, and the same barycentric sums of the clamped vertex attributes.
#include "channels/view/surface_gather.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

namespace seasense::channels {
namespace {

// Bit for bit, or both NaN.
bool Same(float a, float b) {
    return std::memcmp(&a, &b, sizeof a) == 0 || (std::isnan(a) && std::isnan(b));
}

TEST(SeaGather, SamplesEqualTheOneSampleInterpolationAcrossRunsRowEndsAndFullChunks) {
    // A sea mesh of 12 triangles over 20 vertices, with attributes above kMaxVertexAttribute
    // (the +∞ column of open water) on some vertices; the sea's primitives start at 7.
    std::mt19937 rng(17);
    std::uniform_real_distribution<float> coord(-50.0f, 50.0f), unit(0.0f, 1.0f);
    std::vector<glm::vec3> positions, normals;
    std::vector<glm::vec4> attributes;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (int i = 0; i < 20; ++i) {
        // z = −0 at the vertices 2 mod 5, all three vertices of the triangles below that share
        // that residue: their sums keep the sign only if the vertex values are used as they are.
        positions.emplace_back(coord(rng), coord(rng), i % 5 == 2 ? -0.0f : 0.1f * coord(rng));
        normals.emplace_back(0.02f * coord(rng), 0.02f * coord(rng), 1.0f);
        const float depth = i % 3 == 0 ? std::numeric_limits<float>::infinity() : unit(rng);
        attributes.emplace_back(depth, i % 7 == 3 ? nan : unit(rng),
                                i % 4 == 1 ? 3.0e4f : unit(rng), 0.0f);
    }
    std::vector<uint32_t> indices;
    for (int t = 0; t < 12; ++t)
        for (int k = 0; k < 3; ++k) indices.push_back(uint32_t((t * 7 + k * 5 + t / 3) % 20));
    const MeshArrays sea{positions.data(), normals.data(), indices.data(), attributes.data()};
    constexpr uint32_t kBase = 7, kTriangles = 12;
    const std::vector<uint32_t> primitiveBase{kBase, kBase + kTriangles};
    const std::vector<MeshArrays> meshes{sea, sea};

    // One row: runs of one to eleven samples on a triangle, now and then a sample that is not
    // sea (sky, a primitive below the sea's or of the next mesh); some barycentrics −0, NaN or
    // outside the triangle, and vertex attributes NaN, which the sums must carry as the
    // one-sample forms do.
    constexpr int kWidth = 600;
    std::vector<uint32_t> prims;
    std::vector<float> b1, b2;
    while (int(prims.size()) < kWidth) {
        const uint32_t run = 1 + rng() % 11;
        uint32_t prim = kBase + rng() % kTriangles;
        const uint32_t other = rng() % 9;
        if (other == 0) prim = kNoPrimitive;
        if (other == 1) prim = kBase - 1 - rng() % kBase;
        if (other == 2) prim = kBase + kTriangles + rng() % 5;
        for (uint32_t s = 0; s < run && int(prims.size()) < kWidth; ++s) {
            float u = unit(rng), v = unit(rng) * (1.0f - u);
            const uint32_t odd = rng() % 40;
            if (odd == 0) u = -0.0f;
            if (odd == 1) v = nan;
            if (odd == 2) u = 1.25f;
            prims.push_back(prim), b1.push_back(u), b2.push_back(v);
        }
    }

    // Gathered as the FLIR's shading pass does, in chunks of kCapacity (small, so that chunks
    // fill inside runs), checking each chunk's records as it fills.
    constexpr size_t kCapacity = 13;
    SeaSamples<kCapacity> out;
    SeaGather gather(sea, kBase, kTriangles);
    TriangleCache cache;
    size_t records = 0, checked = 0;
    std::vector<int> pending;  // the samples of the chunk being gathered
    const auto Check = [&] {
        ASSERT_EQ(pending.size(), records);
        for (size_t r = 0; r < records; ++r) {
            const int x = pending[r];
            alignas(16) float p[4], n[4];
            int mesh = -1;
            cache.Surface(primitiveBase, meshes, prims[size_t(x)], b1[size_t(x)], b2[size_t(x)], p,
                          n, mesh);
            for (int c = 0; c < 3; ++c) {
                EXPECT_TRUE(Same(out.c[kSeaPx + c][r], p[c]))
                    << "sample " << x << " position " << c;
                EXPECT_TRUE(Same(out.c[kSeaNx + c][r], n[c])) << "sample " << x << " normal " << c;
            }
            const uint32_t* i = indices.data() + 3 * (prims[size_t(x)] - kBase);
            const float w0 = 1.0f - b1[size_t(x)] - b2[size_t(x)];
            for (int c = 0; c < 3; ++c) {
                // _mm_min_ps(a, top): top where a is NaN.
                const auto Clamped = [&](int k) {
                    const float a = attributes[i[k]][c];
                    return a < kMaxVertexAttribute ? a : kMaxVertexAttribute;
                };
                const float expected =
                    (w0 * Clamped(0) + b1[size_t(x)] * Clamped(1)) + b2[size_t(x)] * Clamped(2);
                EXPECT_TRUE(Same(out.c[kSeaDepth + c][r], expected))
                    << "sample " << x << " attribute " << c;
            }
        }
        checked += records;
        records = 0;
        pending.clear();
    };
    size_t seaSamples = 0;
    for (int x = 0; x < kWidth;) {
        if (!gather.IsSea(prims[size_t(x)])) {
            ++x;
            continue;
        }
        const size_t before = records;
        const int next = gather.Gather(prims.data(), b1.data(), b2.data(), x, kWidth, out, records);
        // Up to the first sample that is not sea, the row's end or a full chunk.
        int end = x;
        while (end < kWidth && gather.IsSea(prims[size_t(end)]) &&
               size_t(end - x) < kCapacity - before)
            ++end;
        ASSERT_EQ(next, end) << "from " << x;
        for (int s = x; s < next; ++s) pending.push_back(s);
        seaSamples += size_t(next - x);
        x = next;
        if (records == kCapacity) Check();
    }
    Check();
    EXPECT_EQ(checked, seaSamples);
    EXPECT_GT(seaSamples, 400u);
}

}  // namespace
}  // namespace seasense::channels
