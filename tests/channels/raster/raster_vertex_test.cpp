// The rasterizer's four-lane vertex stage against its one-vertex definition, bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <glm/gtc/matrix_transform.hpp>
#include <limits>
#include <string>
#include <vector>

#include "channels/raster/rasterizer.h"
#include "scene/core/error.h"
#include "scene/core/rng.h"

namespace seasense::channels {
namespace {

using raster_detail::ClipRows;
using raster_detail::Context;
using raster_detail::ScreenVertex;

// The per-frame values Rasterizer::Prepare derives from a camera.
Context MakeContext(int width, int height, float near) {
    Context ctx;
    ctx.width = width;
    ctx.height = height;
    ctx.near = near;
    ctx.halfWidth = 0.5 * width;
    ctx.halfHeight = 0.5 * height;
    ctx.guard = 2.0 * 524288.0 / double(std::max(width, height)) - 1.0;
    return ctx;
}

ClipRows MakeRows(const glm::mat4& clipFromWorld) {
    const glm::dmat4 m(clipFromWorld);
    return {glm::dvec4(m[0][0], m[1][0], m[2][0], m[3][0]),
            glm::dvec4(m[0][1], m[1][1], m[2][1], m[3][1]),
            glm::dvec4(m[0][3], m[1][3], m[2][3], m[3][3])};
}

// Runs both forms over positions (a multiple of 4, all finite) and compares every output bit.
// Returns the union of the outcodes seen, so that callers can check which cases they reached.
uint32_t ExpectLanesMatchScalar(const ClipRows& rows, const Context& ctx,
                                const std::vector<glm::vec3>& positions) {
    EXPECT_EQ(positions.size() % 4, 0u);
    uint32_t seen = 0;
    for (size_t v = 0; v + 4 <= positions.size(); v += 4) {
        glm::vec3 clipLanes[4], clipScalar[4];
        ScreenVertex screenLanes[4], screenScalar[4];
        if (!raster_detail::TransformVertices4(rows, ctx, &positions[v], clipLanes, screenLanes)) {
            ADD_FAILURE() << "finite positions " << v << "..: lanes refused them";
            continue;
        }
        for (int l = 0; l < 4; ++l) {
            raster_detail::TransformVertex(rows, ctx, positions[v + l], clipScalar[l],
                                           screenScalar[l]);
            const ScreenVertex& a = screenLanes[l];
            const ScreenVertex& b = screenScalar[l];
            SCOPED_TRACE("vertex " + std::to_string(v + l) + " (" +
                         std::to_string(positions[v + l].x) + ", " +
                         std::to_string(positions[v + l].y) + ", " +
                         std::to_string(positions[v + l].z) + ")");
            EXPECT_EQ(std::memcmp(&clipLanes[l], &clipScalar[l], sizeof(glm::vec3)), 0);
            EXPECT_EQ(a.x, b.x);
            EXPECT_EQ(a.y, b.y);
            EXPECT_EQ(a.outcode, b.outcode);
            EXPECT_EQ(std::bit_cast<uint64_t>(a.invW), std::bit_cast<uint64_t>(b.invW));
            seen |= b.outcode;
        }
    }
    return seen;
}

float RandomIn(uint64_t stream, uint64_t& counter, float lo, float hi) {
    return float(double(lo) + (double(hi) - double(lo)) * scene::Uniform01(11, stream, counter++));
}

TEST(RasterVertexLanes, PerspectiveCameraMatchesScalarBitForBit) {
    // The demo's kind of camera (1280×960 samples) and a tiny grid, whose guard band is wide.
    const int sizes[][2] = {{1280, 960}, {64, 48}, {32768, 1}};
    for (const auto& size : sizes) {
        const float near = 0.25f;
        const glm::mat4 proj =
            glm::perspective(0.6f, float(size[0]) / float(size[1]), near, 20000.0f);
        const glm::mat4 view = glm::lookAt(glm::vec3(3.0f, 12.0f, -5.0f),
                                           glm::vec3(40.0f, 0.0f, 300.0f), glm::vec3(0, 1, 0));
        const ClipRows rows = MakeRows(proj * view);
        const Context ctx = MakeContext(size[0], size[1], near);
        std::vector<glm::vec3> positions;
        uint64_t counter = 0;
        // Around the camera (behind the eye, crossing the near plane), the scene scale, the
        // horizon scale, and sizes whose clip coordinates overflow float or double.
        const float scales[] = {1.0f, 50.0f, 5000.0f, 1e6f, 1e20f, 1e37f, 3e38f};
        for (float scale : scales)
            for (int i = 0; i < 4000; ++i)
                positions.emplace_back(RandomIn(1, counter, -scale, scale),
                                       RandomIn(1, counter, -scale, scale),
                                       RandomIn(1, counter, -scale, scale));
        // Signed zeros and the camera position itself.
        positions.emplace_back(0.0f, -0.0f, 0.0f);
        positions.emplace_back(-0.0f, -0.0f, -0.0f);
        positions.emplace_back(3.0f, 12.0f, -5.0f);
        positions.emplace_back(std::numeric_limits<float>::max(), 0.0f, 0.0f);
        positions.emplace_back(0.0f, 0.0f, -std::numeric_limits<float>::max());
        positions.emplace_back(std::numeric_limits<float>::denorm_min(), 1e-30f, -1e-38f);
        while (positions.size() % 4 != 0) positions.emplace_back(1.0f, 2.0f, 3.0f);
        const uint32_t seen = ExpectLanesMatchScalar(rows, ctx, positions);
        // The sample reached behind-the-eye, guard-band and overflowing vertices.
        EXPECT_NE(seen & (1u << 4), 0u);  // near
        EXPECT_NE(seen & (1u << 5), 0u);  // guard x+
        EXPECT_NE(seen & (1u << 8), 0u);  // guard y−
        EXPECT_NE(seen & (1u << 9), 0u);  // invalid
    }
}

TEST(RasterVertexLanes, ExactPlaneAndGuardBoundariesMatchScalar) {
    // Clip x = world x, y = world y, w = world z: the planes can be hit exactly.
    glm::mat4 m(0.0f);
    m[0][0] = 1.0f;
    m[1][1] = 1.0f;
    m[2][3] = 1.0f;
    const ClipRows rows = MakeRows(m);
    const float near = 0.25f;
    const Context ctx = MakeContext(640, 480, near);
    const float g = float(ctx.guard);  // 1637.4: not a float, so both sides of it are tried
    std::vector<glm::vec3> positions;
    const float ws[] = {near,
                        std::nextafter(near, 0.0f),
                        std::nextafter(near, 1.0f),
                        0.0f,
                        -0.0f,
                        -1.0f,
                        1.0f,
                        3.0f,
                        1e-3f,
                        1e30f,
                        -1e30f};
    for (float w : ws) {
        const float xs[] = {0.0f, -0.0f, w, -w, std::nextafter(w, 1e38f),
                            std::nextafter(-w, -1e38f), g * w, -g * w, std::nextafter(g * w, 1e38f),
                            std::nextafter(-g * w, -1e38f), std::nextafter(g * w, -1e38f), 0.5f * w,
                            -0.37f * w,
                            // Sample coordinates on and next to rounding halves.
                            (2.0f * (100.5f / 256.0f) / 640.0f - 1.0f) * w,
                            (2.0f * (333.0f + 128.5f / 256.0f) / 640.0f - 1.0f) * w};
        for (float x : xs)
            for (float y : xs) positions.emplace_back(x, y, w);
    }
    while (positions.size() % 4 != 0) positions.emplace_back(0.0f, 0.0f, 1.0f);
    const uint32_t seen = ExpectLanesMatchScalar(rows, ctx, positions);
    EXPECT_EQ(seen, (1u << 9) - 1);  // every outcode bit but invalid (clip = world here)
}

TEST(RasterVertexLanes, DotProductsKeepGlmOrder) {
    // Rows of ones: clip = (p.x + p.y) + (p.z + 1) in glm's order, and cancelling terms make
    // any other order give a different float (e.g. p = (1, 1e20, −1e20): 0 versus 1).
    glm::mat4 m(0.0f);
    for (int c = 0; c < 4; ++c) m[c][0] = m[c][1] = m[c][3] = 1.0f;
    m[3][1] = -1.0f;
    const ClipRows rows = MakeRows(m);
    const Context ctx = MakeContext(640, 480, 0.25f);
    const float values[] = {0.0f, 1.0f, -1.0f, 0.75f, 3e-8f, 1e8f, -1e8f, 1e20f, -1e20f};
    std::vector<glm::vec3> positions;
    for (float x : values)
        for (float y : values)
            for (float z : values) positions.emplace_back(x, y, z);
    while (positions.size() % 4 != 0) positions.emplace_back(1.0f, 1e20f, -1e20f);
    ExpectLanesMatchScalar(rows, ctx, positions);
}

TEST(RasterVertexLanes, NonFinitePositionWritesNothing) {
    const ClipRows rows = MakeRows(glm::perspective(0.6f, 4.0f / 3.0f, 0.25f, 1000.0f));
    const Context ctx = MakeContext(640, 480, 0.25f);
    const float bad[] = {std::numeric_limits<float>::quiet_NaN(),
                         std::numeric_limits<float>::infinity(),
                         -std::numeric_limits<float>::infinity()};
    for (float b : bad)
        for (int lane = 0; lane < 4; ++lane)
            for (int axis = 0; axis < 3; ++axis) {
                glm::vec3 p[4] = {{1, 2, -3}, {4, 5, -6}, {-7, 8, -9}, {0, 0, -1}};
                p[lane][axis] = b;
                glm::vec3 clip[4];
                ScreenVertex screen[4];
                std::memset(clip, 0x5a, sizeof clip);
                std::memset(screen, 0x5a, sizeof screen);
                EXPECT_FALSE(raster_detail::TransformVertices4(rows, ctx, p, clip, screen));
                const auto* cb = reinterpret_cast<const unsigned char*>(clip);
                const auto* sb = reinterpret_cast<const unsigned char*>(screen);
                EXPECT_TRUE(std::all_of(cb, cb + sizeof clip, [](auto c) { return c == 0x5a; }));
                EXPECT_TRUE(std::all_of(sb, sb + sizeof screen, [](auto c) { return c == 0x5a; }));
            }
}

TEST(RasterVertexLanes, RenderReportsFirstNonFiniteVertex) {
    // A non-finite position inside a four-vertex group and one in the remainder after it.
    std::vector<glm::vec3> positions(4103, glm::vec3(0.0f, 0.0f, -2.0f));
    positions[4102].x = std::numeric_limits<float>::infinity();
    positions[9].y = std::numeric_limits<float>::quiet_NaN();
    const std::vector<uint32_t> indices = {0, 1, 2};
    const RasterMesh meshes[] = {{positions, indices, true}};
    RasterCamera cam;
    cam.clipFromWorld = glm::perspective(0.6f, 4.0f / 3.0f, 0.25f, 1000.0f);
    cam.width = 64;
    cam.height = 48;
    Rasterizer r;
    VisibilityBuffer vis;
    try {
        r.Render(meshes, cam, vis);
        ADD_FAILURE() << "no InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("vertex 9 "), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace seasense::channels
