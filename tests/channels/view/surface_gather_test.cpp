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

// Deep-water records: a sea mesh whose vertices are mostly deep (column ≥ kDeep, also exactly
// kDeep, +∞ or NaN; foam ±0; wet finite or NaN) and otherwise just too shallow, foamed (also by
// 1e-30 or NaN) or with a wet value of −∞; barycentrics mostly inside the triangle, now and then
// −0, NaN, +∞, slightly negative or past the triangle.
struct DeepSea {
    static constexpr float kDeep = 0.04f;
    static constexpr uint32_t kBase = 3, kTriangles = 24;
    std::vector<glm::vec3> positions, normals;
    std::vector<glm::vec4> attributes;
    std::vector<uint32_t> indices;
    std::vector<uint32_t> prims;
    std::vector<float> b1, b2;

    explicit DeepSea(int width) {
        std::mt19937 rng(29);
        std::uniform_real_distribution<float> coord(-50.0f, 50.0f), unit(0.0f, 1.0f);
        const float inf = std::numeric_limits<float>::infinity();
        const float nan = std::numeric_limits<float>::quiet_NaN();
        for (int i = 0; i < 40; ++i) {
            positions.emplace_back(coord(rng), coord(rng), 0.1f * coord(rng));
            normals.emplace_back(0.02f * coord(rng), 0.02f * coord(rng), 1.0f);
            const float deepColumns[] = {inf, 1.0e5f, kDeep, nan, kDeep + 50.0f * unit(rng)};
            glm::vec4 a(deepColumns[rng() % 5], rng() % 6 == 0 ? nan : unit(rng),
                        rng() % 2 ? 0.0f : -0.0f, 0.0f);
            // One vertex in four is not deep.
            if (i % 16 == 1) a.x = std::nextafter(kDeep, 0.0f);
            if (i % 16 == 5) a.x = 0.25f * kDeep * unit(rng);
            if (i % 16 == 9) a.z = i % 32 < 16 ? 1.0e-30f : nan;
            if (i % 16 == 13) a.y = -inf;
            attributes.push_back(a);
        }
        for (uint32_t t = 0; t < kTriangles; ++t)
            for (uint32_t k = 0; k < 3; ++k) indices.push_back(rng() % 40);
        while (int(prims.size()) < width) {
            const uint32_t run = 1 + rng() % 11;
            const uint32_t prim = rng() % 10 == 0 ? kNoPrimitive : kBase + rng() % kTriangles;
            for (uint32_t s = 0; s < run && int(prims.size()) < width; ++s) {
                float u = unit(rng), v = unit(rng) * (1.0f - u);
                const uint32_t odd = rng() % 300;
                if (odd == 0) u = -0.0f;
                if (odd == 1) v = nan;
                if (odd == 2) u = inf;
                if (odd == 3) v = -1.0e-3f;
                if (odd == 4) u = 1.25f;
                if (odd == 5) u = -30.0f, v = 20.0f;
                prims.push_back(prim), b1.push_back(u), b2.push_back(v);
            }
        }
    }
    MeshArrays Mesh() const {
        return {positions.data(), normals.data(), indices.data(), attributes.data()};
    }
    // Triangle prim's clamped vertex attribute c (0 depth, 1 wet, 2 foam) of vertex k.
    float Clamped(uint32_t prim, int k, int c) const {
        const float a = attributes[indices[3 * (prim - kBase) + uint32_t(k)]][c];
        return a < kMaxVertexAttribute ? a : kMaxVertexAttribute;
    }
    // SeaGather's definition of a deep triangle.
    bool Deep(uint32_t prim) const {
        for (int k = 0; k < 3; ++k)
            if (!(Clamped(prim, k, 0) >= kDeep && Clamped(prim, k, 1) >= -kMaxVertexAttribute &&
                  Clamped(prim, k, 2) == 0.0f))
                return false;
        return true;
    }
    // Attribute c of sample x: the barycentric sum of the clamped vertex attributes.
    float Sum(int x, int c) const {
        const uint32_t prim = prims[size_t(x)];
        const float u = b1[size_t(x)], v = b2[size_t(x)], w0 = 1.0f - u - v;
        return (w0 * Clamped(prim, 0, c) + u * Clamped(prim, 1, c)) + v * Clamped(prim, 2, c);
    }
};

TEST(SeaGather, DeepRecordsOnlyWhereTheTriangleIsDeepAndTheWeightsAreNonNegative) {
    constexpr int kWidth = 6000;
    const DeepSea sea(kWidth);
    const MeshArrays mesh = sea.Mesh();
    constexpr size_t kCapacity = 29;
    SeaSamples<kCapacity> out;
    SeaGather gather(mesh, DeepSea::kBase, DeepSea::kTriangles, DeepSea::kDeep);
    const std::vector<uint32_t> primitiveBase{DeepSea::kBase, DeepSea::kBase + DeepSea::kTriangles};
    const std::vector<MeshArrays> meshes{mesh, mesh};
    TriangleCache cache;
    size_t records = 0, deepRecords = 0, summed = 0, summedOnDeep = 0;
    std::vector<int> pending;
    const auto Check = [&] {
        ASSERT_EQ(pending.size(), records);
        for (size_t r = 0; r < records; ++r) {
            const int x = pending[r];
            alignas(16) float p[4], n[4];
            int m = -1;
            cache.Surface(primitiveBase, meshes, sea.prims[size_t(x)], sea.b1[size_t(x)],
                          sea.b2[size_t(x)], p, n, m);
            for (int c = 0; c < 3; ++c) {
                EXPECT_TRUE(Same(out.c[kSeaPx + c][r], p[c])) << "sample " << x;
                EXPECT_TRUE(Same(out.c[kSeaNx + c][r], n[c])) << "sample " << x;
            }
            const float record[3] = {out.c[kSeaDepth][r], out.c[kSeaWet][r], out.c[kSeaFoam][r]};
            const float sums[3] = {sea.Sum(x, 0), sea.Sum(x, 1), sea.Sum(x, 2)};
            const uint32_t prim = sea.prims[size_t(x)];
            const float u = sea.b1[size_t(x)], v = sea.b2[size_t(x)], w0 = 1.0f - u - v;
            if (Same(record[0], sums[0]) && Same(record[1], sums[1]) && Same(record[2], sums[2])) {
                ++summed;
                summedOnDeep += sea.Deep(prim) && w0 >= 0.0f && u >= 0.0f && v >= 0.0f;
                continue;
            }
            // Not the sums: the deep record, on a deep triangle with weights ≥ 0, whose sums have
            // the column ≥ kDeep·(1 − 2^-22), foam ±0 and a finite wet value.
            ++deepRecords;
            EXPECT_TRUE(Same(record[0], kMaxVertexAttribute) && Same(record[1], 0.0f) &&
                        Same(record[2], 0.0f))
                << "sample " << x;
            EXPECT_TRUE(sea.Deep(prim)) << "sample " << x << " triangle " << prim;
            EXPECT_TRUE(w0 >= 0.0f && u >= 0.0f && v >= 0.0f)
                << "sample " << x << " weights " << w0 << " " << u << " " << v;
            EXPECT_GE(sums[0], DeepSea::kDeep * (1.0f - 0x1p-22f)) << "sample " << x;
            EXPECT_TRUE(std::isfinite(sums[1])) << "sample " << x;
            EXPECT_EQ(sums[2], 0.0f) << "sample " << x;
        }
        records = 0;
        pending.clear();
    };
    for (int x = 0; x < kWidth;) {
        if (!gather.IsSea(sea.prims[size_t(x)])) {
            ++x;
            continue;
        }
        const int next =
            gather.Gather(sea.prims.data(), sea.b1.data(), sea.b2.data(), x, kWidth, out, records);
        for (int s = x; s < next; ++s) pending.push_back(s);
        x = next;
        if (records == kCapacity) Check();
    }
    Check();
    // Most samples on deep triangles with weights ≥ 0 take the deep record (the rest share a
    // lane group with odd weights); the others keep their sums.
    EXPECT_GT(deepRecords, 3 * summedOnDeep);
    EXPECT_GT(deepRecords, 1000u);
    EXPECT_GT(summed, 1000u);
}

TEST(SeaGather, SumsFlagIsClearOnlyWhereEveryRecordIsTheDeepRecord) {
    // Chunks of 8 records over DeepSea's row, the flag cleared after each as ShadeSea does: a
    // chunk whose flag stays clear must hold the deep record (kMaxVertexAttribute, +0, +0) in
    // every record, since its consumer then reads none of them; both kinds of chunk occur.
    constexpr int kWidth = 6000;
    const DeepSea sea(kWidth);
    const MeshArrays mesh = sea.Mesh();
    constexpr size_t kCapacity = 8;
    SeaSamples<kCapacity> out;
    SeaGather gather(mesh, DeepSea::kBase, DeepSea::kTriangles, DeepSea::kDeep);
    size_t records = 0, deepChunks = 0, summedChunks = 0;
    const auto Check = [&] {
        if (out.sums) {
            ++summedChunks;
        } else {
            ++deepChunks;
            for (size_t r = 0; r < records; ++r)
                EXPECT_TRUE(Same(out.c[kSeaDepth][r], kMaxVertexAttribute) &&
                            Same(out.c[kSeaWet][r], 0.0f) && Same(out.c[kSeaFoam][r], 0.0f))
                    << "chunk " << deepChunks + summedChunks << " record " << r;
        }
        out.sums = false;
        records = 0;
    };
    for (int x = 0; x < kWidth;) {
        if (!gather.IsSea(sea.prims[size_t(x)])) {
            ++x;
            continue;
        }
        x = gather.Gather(sea.prims.data(), sea.b1.data(), sea.b2.data(), x, kWidth, out, records);
        if (records == kCapacity) Check();
    }
    if (records > 0) Check();
    EXPECT_GT(deepChunks, 20u) << summedChunks;
    EXPECT_GT(summedChunks, 20u) << deepChunks;
}

TEST(SeaGather, DeepVertexFlagsGiveEachTrianglesTestAndTheSameRecords) {
    // DeepSea's vertices flagged once: the three flags of a triangle are its deep test, and a
    // gather given the flags writes the records (and the sums flag) of one that tests each
    // triangle's attributes, bit for bit.
    constexpr int kWidth = 6000;
    const DeepSea sea(kWidth);
    const MeshArrays mesh = sea.Mesh();
    std::vector<uint8_t> flags(sea.attributes.size(), 2);
    SeaGather::DeepVertices(sea.attributes.data(), flags.size(), DeepSea::kDeep, flags.data());
    size_t deepTriangles = 0;
    for (uint32_t t = 0; t < DeepSea::kTriangles; ++t) {
        const uint32_t* i = sea.indices.data() + 3 * t;
        const bool flagged = flags[i[0]] && flags[i[1]] && flags[i[2]];
        EXPECT_EQ(flagged, sea.Deep(DeepSea::kBase + t)) << "triangle " << t;
        deepTriangles += flagged;
    }
    EXPECT_GT(deepTriangles, 2u);
    EXPECT_LT(deepTriangles, DeepSea::kTriangles - 2);
    for (uint8_t f : flags) EXPECT_LE(f, 1);

    constexpr size_t kCapacity = 29;
    SeaSamples<kCapacity> tested, flagged;
    SeaGather byTriangle(mesh, DeepSea::kBase, DeepSea::kTriangles, DeepSea::kDeep);
    SeaGather byVertex(mesh, DeepSea::kBase, DeepSea::kTriangles, DeepSea::kDeep, flags.data());
    size_t records = 0, recordsFlagged = 0, compared = 0;
    const auto Compare = [&] {
        ASSERT_EQ(records, recordsFlagged);
        EXPECT_EQ(tested.sums, flagged.sums);
        for (int c = 0; c < kSeaComponents; ++c)
            for (size_t r = 0; r < records; ++r)
                EXPECT_EQ(std::memcmp(&tested.c[c][r], &flagged.c[c][r], sizeof(float)), 0)
                    << "component " << c << " record " << r;
        compared += records;
        records = recordsFlagged = 0;
        tested.sums = flagged.sums = false;
    };
    for (int x = 0; x < kWidth;) {
        if (!byTriangle.IsSea(sea.prims[size_t(x)])) {
            ++x;
            continue;
        }
        const int next = byTriangle.Gather(sea.prims.data(), sea.b1.data(), sea.b2.data(), x,
                                           kWidth, tested, records);
        ASSERT_EQ(byVertex.Gather(sea.prims.data(), sea.b1.data(), sea.b2.data(), x, kWidth,
                                  flagged, recordsFlagged),
                  next);
        x = next;
        if (records == kCapacity) Compare();
    }
    Compare();
    EXPECT_GT(compared, 4000u);
}

}  // namespace
}  // namespace seasense::channels
