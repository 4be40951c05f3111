// The rasterizer's row loops (small triangles' box rows on int32 lanes, the others' spans)
// against the per-sample definition of coverage, depth, primitive and barycentrics, bit for bit.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "channels/raster/depth_test.h"
#include "channels/raster/rasterizer.h"
#include "scene/core/rng.h"

namespace seasense::channels {
namespace {

using raster_detail::ClipRows;
using raster_detail::Context;
using raster_detail::ScreenVertex;

// A camera at the origin looking down −z, y up: clip = (x / tanH, y / tanV, ·, −z).
RasterCamera LookDown(int width, int height, double tanH, double tanV) {
    glm::mat4 m(0.0f);
    m[0][0] = float(1.0 / tanH);
    m[1][1] = float(1.0 / tanV);
    m[2][3] = -1.0f;
    m[3][2] = 0.25f;
    RasterCamera cam;
    cam.clipFromWorld = m;
    cam.near_m = 0.25f;
    cam.width = width;
    cam.height = height;
    return cam;
}

// The world point that the camera above sees at sample-grid point (sx, sy), view depth w.
glm::vec3 Unproject(const RasterCamera& cam, double tanH, double tanV, double sx, double sy,
                    double w) {
    const double xNdc = 2.0 * sx / cam.width - 1.0, yNdc = 1.0 - 2.0 * sy / cam.height;
    return glm::vec3(float(xNdc * tanH * w), float(yNdc * tanV * w), float(-w));
}

// The vertex stage's values for one vertex (the one-vertex form, tested against the lanes
// elsewhere): fixed-point position and 1 / w.
ScreenVertex Screen(const RasterCamera& cam, const glm::vec3& p) {
    Context ctx;
    ctx.width = cam.width;
    ctx.height = cam.height;
    ctx.near = cam.near_m;
    ctx.halfWidth = 0.5 * cam.width;
    ctx.halfHeight = 0.5 * cam.height;
    ctx.guard = 2.0 * 524288.0 / double(std::max(cam.width, cam.height)) - 1.0;
    const glm::dmat4 m(cam.clipFromWorld);
    const ClipRows rows{glm::dvec4(m[0][0], m[1][0], m[2][0], m[3][0]),
                        glm::dvec4(m[0][1], m[1][1], m[2][1], m[3][1]),
                        glm::dvec4(m[0][3], m[1][3], m[2][3], m[3][3])};
    glm::vec3 clip;
    ScreenVertex s;
    raster_detail::TransformVertex(rows, ctx, p, clip, s);
    return s;
}

struct Expected {
    std::vector<float> depth, b1, b2;
    std::vector<uint32_t> primitive;
};

// Every triangle's samples by the straightforward per-sample form: int64 edge functions E_k
// with the top-left rule, depth near/w as k0 + E_1 Δc_1 + E_2 Δc_2 (c_k = near / (w_k·|2·area|)),
// b_k = E_k c_k / depth, and the depth test keeping the nearer sample, at equal depth the lower
// primitive id. Triangles must not need clipping. Counts the samples each triangle shows.
Expected Reference(const RasterCamera& cam, const std::vector<ScreenVertex>& sv,
                   const std::vector<uint32_t>& indices, std::vector<int>& won) {
    const size_t n = size_t(cam.width) * size_t(cam.height);
    Expected e{std::vector<float>(n, 0.0f), std::vector<float>(n, 0.0f),
               std::vector<float>(n, 0.0f), std::vector<uint32_t>(n, kNoPrimitive)};
    won.assign(indices.size() / 3, 0);
    for (uint32_t t = 0; t < indices.size() / 3; ++t) {
        int64_t fx[3], fy[3];
        double invW[3];
        for (int v = 0; v < 3; ++v) {
            const ScreenVertex& s = sv[indices[3 * t + v]];
            fx[v] = s.x, fy[v] = s.y, invW[v] = s.invW;
        }
        const int64_t area2 = (fx[1] - fx[0]) * (fy[2] - fy[0]) - (fy[1] - fy[0]) * (fx[2] - fx[0]);
        if (area2 == 0) continue;
        const bool positive = area2 > 0;
        const int64_t absArea2 = positive ? area2 : -area2;
        const double nearPerArea = double(cam.near_m) / double(absArea2);
        const double c[3] = {nearPerArea * invW[0], nearPerArea * invW[1], nearPerArea * invW[2]};
        const double k0 = double(absArea2) * c[0], dc1 = c[1] - c[0], dc2 = c[2] - c[0];
        const int64_t minX = std::min({fx[0], fx[1], fx[2]}),
                      maxX = std::max({fx[0], fx[1], fx[2]});
        const int64_t minY = std::min({fy[0], fy[1], fy[2]}),
                      maxY = std::max({fy[0], fy[1], fy[2]});
        const int i0 = int(std::max<int64_t>(minX / 256 - 1, 0));
        const int i1 = int(std::min<int64_t>(maxX / 256 + 1, cam.width - 1));
        const int j0 = int(std::max<int64_t>(minY / 256 - 1, 0));
        const int j1 = int(std::min<int64_t>(maxY / 256 + 1, cam.height - 1));
        for (int j = j0; j <= j1; ++j) {
            for (int i = i0; i <= i1; ++i) {
                const int64_t px = int64_t(i) * 256 + 128, py = int64_t(j) * 256 + 128;
                int64_t edge[3];
                bool inside = true;
                for (int k = 0; k < 3; ++k) {
                    int a = k == 2 ? 0 : k + 1, b = k == 0 ? 2 : k - 1;
                    if (!positive) std::swap(a, b);
                    const int64_t ex = fy[a] - fy[b], ey = fx[b] - fx[a];
                    edge[k] = ex * (px - fx[a]) + ey * (py - fy[a]);
                    const bool topLeft = ex > 0 || (ex == 0 && ey > 0);
                    inside &= edge[k] - (topLeft ? 0 : 1) >= 0;
                }
                if (!inside) continue;
                const double f1 = double(edge[1]), f2 = double(edge[2]);
                const double d = k0 + f1 * dc1 + f2 * dc2;
                const float depth = float(d);
                const size_t s = size_t(j) * size_t(cam.width) + size_t(i);
                if (depth > 0.0f &&
                    (depth > e.depth[s] || (depth == e.depth[s] && t < e.primitive[s]))) {
                    const double inv = 1.0 / d;
                    e.depth[s] = depth;
                    e.primitive[s] = t;
                    e.b1[s] = float(f1 * c[1] * inv);
                    e.b2[s] = float(f2 * c[2] * inv);
                }
            }
        }
    }
    for (uint32_t p : e.primitive)
        if (p != kNoPrimitive) ++won[p];
    return e;
}

// Renders meshes {positions, indices} and a copy {positions, indices} (which ties in depth
// everywhere and must never win) with tile sizes 16 and 64, one and two threads, and expects
// every sample to equal the per-sample form bit for bit. Returns the samples each triangle
// of the first mesh shows.
std::vector<int> ExpectRowsMatchReference(const RasterCamera& cam,
                                          const std::vector<glm::vec3>& positions,
                                          const std::vector<uint32_t>& indices) {
    std::vector<ScreenVertex> sv;
    for (const glm::vec3& p : positions) sv.push_back(Screen(cam, p));
    std::vector<uint32_t> twice = indices;
    twice.insert(twice.end(), indices.begin(), indices.end());
    std::vector<int> won;
    const Expected ref = Reference(cam, sv, twice, won);
    const size_t numTriangles = indices.size() / 3;
    int fromCopy = 0;
    for (size_t p = numTriangles; p < won.size(); ++p) fromCopy += won[p];
    EXPECT_EQ(fromCopy, 0);
    won.resize(numTriangles);

    const RasterMesh meshes[] = {{positions, indices, false}, {positions, indices, false}};
    for (int tileSize : {16, 64}) {
        for (int threads : {1, 2}) {
            SCOPED_TRACE("tile size " + std::to_string(tileSize) + ", " + std::to_string(threads) +
                         " threads");
            Rasterizer r(tileSize);
            VisibilityBuffer vis;
            tbb::task_arena arena(threads);
            arena.execute([&] { r.Render(meshes, cam, vis); });
            EXPECT_EQ(r.Stats().trianglesClipped, 0u);
            int mismatches = 0;
            std::string first;
            for (size_t s = 0; s < ref.depth.size(); ++s) {
                const bool same = std::memcmp(&ref.depth[s], &vis.depth[s], 4) == 0 &&
                                  ref.primitive[s] == vis.primitive[s] &&
                                  std::memcmp(&ref.b1[s], &vis.b1[s], 4) == 0 &&
                                  std::memcmp(&ref.b2[s], &vis.b2[s], 4) == 0;
                if (!same && mismatches++ == 0)
                    first = "sample (" + std::to_string(s % size_t(cam.width)) + ", " +
                            std::to_string(s / size_t(cam.width)) + "): primitive " +
                            std::to_string(vis.primitive[s]) + " expected " +
                            std::to_string(ref.primitive[s]);
            }
            EXPECT_EQ(mismatches, 0) << first;
        }
    }
    return won;
}

// Largest |x_i − x_j|, |y_i − y_j| of a triangle's fixed-point vertices (1/256 sample).
int64_t FixedExtent(const RasterCamera& cam, const std::vector<glm::vec3>& positions,
                    const std::vector<uint32_t>& indices, size_t t) {
    int64_t extent = 0;
    for (int v = 0; v < 3; ++v) {
        const ScreenVertex a = Screen(cam, positions[indices[3 * t + v]]);
        const ScreenVertex b = Screen(cam, positions[indices[3 * t + (v + 1) % 3]]);
        extent = std::max({extent, std::abs(int64_t(a.x) - b.x), std::abs(int64_t(a.y) - b.y)});
    }
    return extent;
}

// Random triangles of every size the rows distinguish — a sample or two, up to and past the
// box rows' 16 samples, slivers long in x or y, extents around 64 samples (the int32 lanes'
// bound) and far beyond it with a narrow box — across tile borders and the frame's edges
// (partial tiles at its right and bottom), at view depths 1 to 60 with each vertex at its own
// depth, overlapping. Every sample shown must be the per-sample form's.
TEST(RasterRows, BoxAndSpanRowsEqualThePerSampleFormBitForBit) {
    const double tanH = 0.9, tanV = 0.7;
    const RasterCamera cam = LookDown(200, 136, tanH, tanV);
    std::vector<glm::vec3> positions;
    std::vector<uint32_t> indices;
    uint64_t counter = 0;
    const auto uniform = [&](double lo, double hi) {
        return lo + (hi - lo) * scene::Uniform01(23, 0, counter++);
    };
    for (int t = 0; t < 2800; ++t) {
        double ex = 0.0, ey = 0.0;  // extents in samples
        switch (t % 7) {
            case 0:
                ex = uniform(0.3, 8.0), ey = uniform(0.3, 8.0);
                break;
            case 1:
                ex = uniform(8.0, 24.0), ey = uniform(1.0, 20.0);
                break;
            case 2:
                ex = uniform(0.5, 3.0), ey = uniform(20.0, 90.0);
                break;
            case 3:
                ex = uniform(20.0, 90.0), ey = uniform(0.5, 3.0);
                break;
            case 4:
                ex = uniform(62.0, 66.0), ey = uniform(2.0, 66.0);
                break;
            case 5:
                ex = uniform(2.0, 66.0), ey = uniform(62.0, 66.0);
                break;
            default:  // far past the frame's top and bottom: E beyond int32 in its box
                ex = uniform(2.0, 14.0), ey = uniform(4000.0, 40000.0);
                break;
        }
        const double cx = uniform(-20.0, cam.width + 20.0), cy = uniform(-20.0, cam.height + 20.0);
        // The smaller triangles nearer, so that they show.
        const double w = std::exp(t % 7 < 2 ? uniform(0.0, std::log(4.0))
                                            : uniform(std::log(4.0), std::log(60.0)));
        const double corners[3][2] = {
            {-0.5, -0.5}, {0.5, uniform(-0.5, 0.5)}, {uniform(-0.5, 0.5), 0.5}};
        for (int v = 0; v < 3; ++v) {
            const double sx = cx + ex * corners[v][0], sy = cy + ey * corners[v][1];
            positions.push_back(Unproject(cam, tanH, tanV, sx, sy, w * uniform(0.7, 1.4)));
        }
        // Each vertex first in turn, both windings: every edge takes every role.
        const uint32_t base = uint32_t(positions.size() - 3), rot = uint32_t(t / 7 % 3);
        const bool reverse = t / 21 % 2 == 1;
        for (uint32_t v = 0; v < 3; ++v)
            indices.push_back(base + (rot + (reverse ? 3 - v : v)) % 3);
    }
    const std::vector<int> shown = ExpectRowsMatchReference(cam, positions, indices);

    // Both row loops must show plenty: triangles within 15 samples each way (sample box at
    // most 16 wide, every extent below 2^14) take the box rows in every tile; those with an
    // extent beyond 2^14 take the spans.
    int boxSamples = 0, spanSamples = 0;
    for (size_t t = 0; t < shown.size(); ++t) {
        const int64_t extent = FixedExtent(cam, positions, indices, t);
        if (extent > (int64_t(1) << 14)) spanSamples += shown[t];
        if (extent < 15 * 256) boxSamples += shown[t];
    }
    EXPECT_GT(boxSamples, 2000);
    EXPECT_GT(spanSamples, 4000);
}

// Vertices at view depth 1 on a 1/64-sample grid of a camera whose clip coordinates and
// fixed-point snapping are exact there: edges exactly ±64 samples long in x or y (∂E/∂y or
// ∂E/∂x = ±2^14: −2^14 is the last the int32 lanes take, +2^14 the first they leave to the
// spans) and a sample longer, drawn in 16-sample tiles so that their boxes fit the box rows.
TEST(RasterRows, EdgesAtTheLanesBoundEqualThePerSampleFormBitForBit) {
    const RasterCamera cam = LookDown(256, 128, 1.0, 1.0);
    std::vector<glm::vec3> positions;
    std::vector<uint32_t> indices;
    uint64_t counter = 0;
    const auto onGrid = [&](double lo, double hi) {
        return std::round(64.0 * (lo + (hi - lo) * scene::Uniform01(29, 0, counter++))) / 64.0;
    };
    int at[3] = {0, 0, 0};  // triangles of fixed-point extent below 2^14, 2^14, beyond
    for (int t = 0; t < 240; ++t) {
        const double len = t % 4 == 0 ? 64.0 : t % 4 == 1 ? -64.0 : t % 4 == 2 ? 65.0 : 63.984375;
        const double x = onGrid(70.0, 186.0), y = onGrid(0.0, 128.0), off = onGrid(0.5, 6.0);
        const double along = onGrid(-3.0, 3.0);
        const bool inX = t % 8 < 4;
        const double p[3][2] = {
            {x, y}, {x + (inX ? len : along), y + (inX ? along : len)}, {x + off, y + off}};
        for (int v = 0; v < 3; ++v) {
            positions.push_back(Unproject(cam, 1.0, 1.0, p[v][0], p[v][1], 1.0));
            indices.push_back(uint32_t(positions.size() - 1));
        }
        const int64_t extent = FixedExtent(cam, positions, indices, size_t(t));
        at[extent < (int64_t(1) << 14) ? 0 : extent == (int64_t(1) << 14) ? 1 : 2] += 1;
    }
    EXPECT_GT(at[0], 30);
    EXPECT_GT(at[1], 50);
    EXPECT_GT(at[2], 30);
    const std::vector<int> shown = ExpectRowsMatchReference(cam, positions, indices);
    int drawn = 0;
    for (int n : shown) drawn += n;
    EXPECT_GT(drawn, 5000);
}

// The lanes' depth test without its depth > 0 term against the straightforward one, on every
// pairing of new depths (negative, ±0, subnormal, NaN, ties) and ids (0, around 2^31, the last
// id below kNoPrimitive) with targets that are empty or hold depth > 0 and an id below
// kNoPrimitive: the only targets the rasterizer's tiles hold.
TEST(RasterRows, DepthTestWithoutItsPositiveTermEqualsTheStraightforwardOne) {
    using raster_detail::DepthLanes;
    using raster_detail::IdLanes;
    const float inf = std::numeric_limits<float>::infinity();
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float tiny = std::numeric_limits<float>::denorm_min();
    const float depths[] = {-inf, -1.0f, -tiny, -0.0f, 0.0f, tiny, 1e-30f, 0.25f, 0.5f, 1.0f, nan};
    const uint32_t ids[] = {0u,          1u,          2u,          0x7ffffffeu, 0x7fffffffu,
                            0x80000000u, 0x80000001u, 0xfffffffdu, 0xfffffffeu};
    // Targets: empty, or a positive depth with an id.
    std::vector<std::pair<float, uint32_t>> targets = {{0.0f, kNoPrimitive}};
    for (float d : depths)
        if (d > 0.0f)
            for (uint32_t id : ids) targets.push_back({d, id});
    int checked = 0, won = 0, tiesWon = 0;
    for (float depth : depths) {
        for (uint32_t id : ids) {
            for (size_t k = 0; k < targets.size(); k += 4) {
                // Four targets on the lanes (the last group repeats its first where short).
                DepthLanes old, newDepth;
                IdLanes oldPrim, prim;
                for (int l = 0; l < 4; ++l) {
                    const auto& target = targets[k + l < targets.size() ? k + l : k];
                    old[l] = target.first;
                    oldPrim[l] = int32_t(target.second);
                    newDepth[l] = depth;
                    prim[l] = int32_t(id);
                }
                const IdLanes wins = raster_detail::DepthTestWins(
                    newDepth, raster_detail::DepthTestKey(prim), old, oldPrim);
                for (int l = 0; l < 4; ++l) {
                    const float o = old[l];
                    const uint32_t op = uint32_t(oldPrim[l]);
                    const bool expected = depth > 0.0f && (depth > o || (depth == o && id < op));
                    EXPECT_EQ(wins[l], expected ? -1 : 0)
                        << "depth " << depth << " id " << id << " old " << o << " id " << op;
                    ++checked;
                    won += expected;
                    tiesWon += expected && depth == o;
                }
            }
        }
    }
    EXPECT_GT(checked, 3000);
    EXPECT_GT(won, 300);
    EXPECT_GT(tiesWon, 100);
}

// The same cases on eight lanes (the box rows test an 8-sample group at once where both of its
// halves hold covered samples): every lane must be the straightforward test's decision.
TEST(RasterRows, EightLaneDepthTestEqualsTheStraightforwardOne) {
    using raster_detail::DepthLanes8;
    using raster_detail::IdLanes8;
    const float inf = std::numeric_limits<float>::infinity();
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float tiny = std::numeric_limits<float>::denorm_min();
    const float depths[] = {-inf, -1.0f, -tiny, -0.0f, 0.0f, tiny, 1e-30f, 0.25f, 0.5f, 1.0f, nan};
    const uint32_t ids[] = {0u,          1u,          2u,          0x7ffffffeu, 0x7fffffffu,
                            0x80000000u, 0x80000001u, 0xfffffffdu, 0xfffffffeu};
    std::vector<std::pair<float, uint32_t>> targets = {{0.0f, kNoPrimitive}};
    for (float d : depths)
        if (d > 0.0f)
            for (uint32_t id : ids) targets.push_back({d, id});
    int checked = 0, won = 0, tiesWon = 0;
    for (float depth : depths) {
        for (uint32_t id : ids) {
            // Each target on every lane in turn: the groups start one target further each time.
            for (size_t k = 0; k < targets.size(); ++k) {
                DepthLanes8 old, newDepth;
                IdLanes8 oldPrim, prim;
                for (int l = 0; l < 8; ++l) {
                    const auto& target = targets[(k + size_t(l)) % targets.size()];
                    old[l] = target.first;
                    oldPrim[l] = int32_t(target.second);
                    newDepth[l] = depth;
                    prim[l] = int32_t(id);
                }
                const IdLanes8 wins = raster_detail::DepthTestWins(
                    newDepth, raster_detail::DepthTestKey(prim), old, oldPrim);
                for (int l = 0; l < 8; ++l) {
                    const float o = old[l];
                    const uint32_t op = uint32_t(oldPrim[l]);
                    const bool expected = depth > 0.0f && (depth > o || (depth == o && id < op));
                    EXPECT_EQ(wins[l], expected ? -1 : 0)
                        << "lane " << l << " depth " << depth << " id " << id << " old " << o
                        << " id " << op;
                    ++checked;
                    won += expected;
                    tiesWon += expected && depth == o;
                }
            }
        }
    }
    EXPECT_GT(checked, 20000);
    EXPECT_GT(won, 2000);
    EXPECT_GT(tiesWon, 600);
}

}  // namespace
}  // namespace seasense::channels
