// Embree occlusion: box shadow length h/tan(e), segment line of sight, bounds, refit, packets.
#include "channels/occlusion/occlusion.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "scene/core/check.h"
#include "scene/core/error.h"
#include "scene/core/rng.h"
#include "tests/support/meshes.h"

namespace seasense::channels {
namespace {

using TestMesh = seasense::testing::SimpleMesh;
using seasense::testing::MakeBox;

// Square ground plane z = 0 of half-size halfSize_m around the origin (2 triangles).
TestMesh MakeGround(float halfSize_m) {
    TestMesh mesh;
    mesh.positions = {{-halfSize_m, -halfSize_m, 0.0f},
                      {halfSize_m, -halfSize_m, 0.0f},
                      {halfSize_m, halfSize_m, 0.0f},
                      {-halfSize_m, halfSize_m, 0.0f}};
    mesh.indices = {0, 1, 2, 0, 2, 3};
    return mesh;
}

TestMesh Translated(TestMesh mesh, const glm::vec3& offset) {
    for (glm::vec3& p : mesh.positions) p += offset;
    return mesh;
}

uint32_t Add(OcclusionScene& scene, const TestMesh& mesh) {
    return scene.AddMesh(mesh.positions, mesh.indices);
}

double Radians(double deg) { return deg * std::numbers::pi / 180.0; }

// Unit vector toward a light at azimuth (from north, clockwise) and elevation, world ENU.
glm::vec3 SunDirection(double azimuth_deg, double elevation_deg) {
    const double az = Radians(azimuth_deg), el = Radians(elevation_deg);
    return glm::normalize(glm::vec3(float(std::sin(az) * std::cos(el)),
                                    float(std::cos(az) * std::cos(el)), float(std::sin(el))));
}

constexpr float kBoxHeight_m = 4.0f;
constexpr float kPixel_m = 0.02f;
constexpr float kShadowTNear_m = 1e-3f;

// Shadow length of the 2 m × 2 m × h box centred at (centre.x, centre.y) on the ground, measured
// on a line of ground samples of spacing kPixel_m that starts at the footprint's far edge and
// runs in the anti-sun direction: distance from that edge to the last occluded sample.
// Also requires the shadow along the line to be one unbroken run (the shadow of a convex box
// is convex).
float MeasureShadowLength(const OcclusionScene& scene, const glm::vec2& centre, double azimuth_deg,
                          double elevation_deg) {
    const glm::vec3 sun = SunDirection(azimuth_deg, elevation_deg);
    const glm::vec2 away = -glm::normalize(glm::vec2(sun.x, sun.y));
    // Distance from the footprint centre to its edge along `away` (half-width 1 m).
    const float edge_m = 1.0f / std::max(std::abs(away.x), std::abs(away.y));
    const float expected_m = kBoxHeight_m / float(std::tan(Radians(elevation_deg)));
    const int count = int(std::ceil((1.5f * expected_m + 2.0f) / kPixel_m));
    std::vector<glm::vec3> origins;
    for (int k = 1; k <= count; ++k) {
        const glm::vec2 p = centre + (edge_m + float(k) * kPixel_m) * away;
        origins.emplace_back(p.x, p.y, 0.0f);
    }
    std::vector<uint8_t> visible(origins.size(), 7);
    scene.DirectionalVisibility(origins, sun, kShadowTNear_m, visible);
    int last = 0;
    for (int k = 1; k <= count; ++k) {
        EXPECT_TRUE(visible[k - 1] == 0 || visible[k - 1] == 1);
        if (visible[k - 1] == 0) last = k;
    }
    for (int k = 1; k <= last; ++k) EXPECT_EQ(visible[k - 1], 0) << "gap in shadow at " << k;
    EXPECT_LT(last, count) << "shadow reaches the end of the sample line";
    return float(last) * kPixel_m;
}

struct SunCase {
    double azimuth_deg;
    double elevation_deg;
};

class BoxShadow : public ::testing::TestWithParam<SunCase> {};

// Shadow of a vertical box edge of height h on flat ground under a sun at elevation e has
// length h / tan(e) (similar triangles); the measurement must agree within one pixel.
TEST_P(BoxShadow, LengthIsHeightOverTanElevationWithinOnePixel) {
    const SunCase sun = GetParam();
    OcclusionScene scene;
    Add(scene, MakeGround(60.0f));
    Add(scene, MakeBox({-1.0f, -1.0f, 0.0f}, {1.0f, 1.0f, kBoxHeight_m}));
    scene.Commit();
    const float expected_m = kBoxHeight_m / float(std::tan(Radians(sun.elevation_deg)));
    const float measured_m =
        MeasureShadowLength(scene, {0.0f, 0.0f}, sun.azimuth_deg, sun.elevation_deg);
    EXPECT_NEAR(measured_m, expected_m, kPixel_m)
        << "azimuth " << sun.azimuth_deg << "°, elevation " << sun.elevation_deg << "°";
}

INSTANTIATE_TEST_SUITE_P(SunPositions, BoxShadow,
                         ::testing::Values(SunCase{90, 20}, SunCase{90, 35}, SunCase{90, 60},
                                           SunCase{200, 20}, SunCase{200, 35}, SunCase{200, 60},
                                           SunCase{305, 20}, SunCase{305, 35}, SunCase{305, 60}));

class BoxScene : public ::testing::Test {
  protected:
    void SetUp() override {
        Add(scene_, MakeBox({-1.0f, -1.0f, 0.0f}, {1.0f, 1.0f, kBoxHeight_m}));
        scene_.Commit();
    }
    OcclusionScene scene_;
};

TEST_F(BoxScene, BoundsAreTheBoxExtents) {
    EXPECT_FALSE(scene_.Empty());
    EXPECT_EQ(scene_.BoundsMin(), glm::vec3(-1.0f, -1.0f, 0.0f));
    EXPECT_EQ(scene_.BoundsMax(), glm::vec3(1.0f, 1.0f, kBoxHeight_m));
}

TEST_F(BoxScene, SegmentsThroughBesideAndShortOfTheBox) {
    // Through the middle, both ways.
    EXPECT_TRUE(scene_.Occluded({-5, 0, 2}, {5, 0, 2}));
    EXPECT_TRUE(scene_.Occluded({5, 0, 2}, {-5, 0, 2}));
    // Diagonal through the volume.
    EXPECT_TRUE(scene_.Occluded({-3, -3, 0.5f}, {3, 3, 3.5f}));
    // Beside (0.5 m clear of the y = 1 face) and above the top (z = 4).
    EXPECT_FALSE(scene_.Occluded({-5, 1.5f, 2}, {5, 1.5f, 2}));
    EXPECT_FALSE(scene_.Occluded({-5, 0, 4.5f}, {5, 0, 4.5f}));
    // Stops 0.5 m short of the x = −1 face, and starts 0.5 m beyond the x = +1 face.
    EXPECT_FALSE(scene_.Occluded({-5, 0, 2}, {-1.5f, 0, 2}));
    EXPECT_FALSE(scene_.Occluded({1.5f, 0, 2}, {5, 0, 2}));
    // Ends inside the box: crosses the x = −1 face.
    EXPECT_TRUE(scene_.Occluded({-5, 0, 2}, {0, 0, 2}));
    // Starts on the x = +1 face and leaves it: the face itself is excluded by the epsilon.
    EXPECT_FALSE(scene_.Occluded({1, 0, 2}, {5, 0, 2}));
    // Ends on the x = −1 face: the open segment does not include its end point.
    EXPECT_FALSE(scene_.Occluded({-5, 0, 2}, {-1, 0, 2}));
    // Starts on the +1 face and goes through the box: leaves through the −1 face.
    EXPECT_TRUE(scene_.Occluded({1, 0, 2}, {-5, 0, 2}));
    // Degenerate segment.
    EXPECT_FALSE(scene_.Occluded({-5, 0, 2}, {-5, 0, 2}));
}

TEST_F(BoxScene, MayOccludeFollowsTheBoundingBox) {
    const glm::vec3 west(-1, 0, 0), east(1, 0, 0), up(0, 0, 1);
    EXPECT_TRUE(scene_.MayOcclude({5, 0, 2}, west, 10.0f));
    EXPECT_TRUE(scene_.MayOcclude({5, 0, 2}, west, INFINITY));
    EXPECT_FALSE(scene_.MayOcclude({5, 0, 2}, west, 3.0f));  // box starts 4 m away
    EXPECT_FALSE(scene_.MayOcclude({5, 0, 2}, east, INFINITY));
    EXPECT_FALSE(scene_.MayOcclude({0, 0, 5}, up, INFINITY));
    EXPECT_TRUE(scene_.MayOcclude({0, 0, -5}, up, INFINITY));
    // Parallel to the y slabs but outside them: the zero direction component must not
    // produce NaN.
    EXPECT_FALSE(scene_.MayOcclude({5, 5, 2}, west, INFINITY));
    EXPECT_TRUE(scene_.MayOcclude({5, 0.99f, 2}, west, INFINITY));
    // Inside the box.
    EXPECT_TRUE(scene_.MayOcclude({0, 0, 2}, east, 0.0f));
    EXPECT_FALSE(scene_.MayOcclude({5, 0, 2}, west, -1.0f));
}

TEST_F(BoxScene, MayOccludeIsConservative) {
    // Every occluded segment must pass the cheap test, or shading would lose shadows.
    int occludedCount = 0;
    for (uint64_t i = 0; i < 4000; ++i) {
        auto u = [&](uint64_t stream) { return float(scene::Uniform01(11, stream, i)); };
        const glm::vec3 origin(8 * u(0) - 4, 8 * u(1) - 4, 6 * u(2) - 1);
        const float cosTheta = 2 * u(3) - 1, phi = 2 * float(std::numbers::pi) * u(4);
        const float sinTheta = std::sqrt(std::max(0.0f, 1 - cosTheta * cosTheta));
        const glm::vec3 direction(sinTheta * std::cos(phi), sinTheta * std::sin(phi), cosTheta);
        const float range_m = 10 * u(5);
        if (scene_.Occluded(origin, origin + range_m * direction)) {
            ++occludedCount;
            EXPECT_TRUE(scene_.MayOcclude(origin, direction, range_m)) << "ray " << i;
        }
    }
    EXPECT_GT(occludedCount, 200);
}

TEST(OcclusionScene, EmptySceneOccludesNothing) {
    OcclusionScene scene;
    scene.Commit();
    EXPECT_TRUE(scene.Empty());
    EXPECT_GT(scene.BoundsMin().x, scene.BoundsMax().x);
    EXPECT_FALSE(scene.Occluded({-5, 0, 2}, {5, 0, 2}));
    EXPECT_FALSE(scene.MayOcclude({0, 0, 0}, {0, 0, 1}, INFINITY));
    std::vector<glm::vec3> origins(3000, glm::vec3(0.0f));
    std::vector<uint8_t> visible(origins.size(), 7);
    scene.DirectionalVisibility(origins, {0, 0, 1}, 0.0f, visible);
    for (uint8_t v : visible) ASSERT_EQ(v, 1);
    scene.DirectionalVisibility({}, {0, 0, 1}, 0.0f, {});
}

TEST(OcclusionScene, UpdateMeshMovesTheShadow) {
    OcclusionScene scene;
    Add(scene, MakeGround(60.0f));
    const TestMesh box = MakeBox({-1.0f, -1.0f, 0.0f}, {1.0f, 1.0f, kBoxHeight_m});
    const uint32_t boxId = Add(scene, box);
    // A second, static box far away keeps casting while the first one moves.
    Add(scene, Translated(box, {0.0f, 30.0f, 0.0f}));
    scene.Commit();

    const double azimuth_deg = 90, elevation_deg = 35;  // sun in the east: shadow to the west
    const glm::vec3 sun = SunDirection(azimuth_deg, elevation_deg);
    const float expected_m = kBoxHeight_m / float(std::tan(Radians(elevation_deg)));
    const glm::vec3 inOldShadow(-1.0f - 0.5f * expected_m, 0.0f, 0.0f);
    const glm::vec3 offset(20.0f, 5.0f, 0.0f);
    const glm::vec3 inStaticShadow(-1.0f - 0.5f * expected_m, 30.0f, 0.0f);
    auto shadowed = [&](const glm::vec3& p) { return scene.Occluded(p, p + 100.0f * sun); };
    ASSERT_TRUE(shadowed(inOldShadow));
    ASSERT_FALSE(shadowed(inOldShadow + offset));

    scene.UpdateMesh(boxId, Translated(box, offset).positions);
    scene.Commit();
    EXPECT_FALSE(shadowed(inOldShadow));
    EXPECT_TRUE(shadowed(inOldShadow + offset));
    EXPECT_TRUE(shadowed(inStaticShadow));
    EXPECT_NEAR(MeasureShadowLength(scene, {offset.x, offset.y}, azimuth_deg, elevation_deg),
                expected_m, kPixel_m);
    EXPECT_EQ(scene.BoundsMin(), glm::vec3(-60.0f, -60.0f, 0.0f));

    // Second refit: raise the box by 50 %, so the shadow grows by the same factor.
    const glm::vec3 beyondOldTip(offset.x - 1.0f - 1.25f * expected_m, offset.y, 0.0f);
    EXPECT_FALSE(shadowed(beyondOldTip));
    TestMesh taller = Translated(box, offset);
    for (glm::vec3& p : taller.positions) p.z *= 1.5f;
    scene.UpdateMesh(boxId, taller.positions);
    scene.Commit();
    EXPECT_TRUE(shadowed(beyondOldTip));
    EXPECT_TRUE(shadowed(inStaticShadow));

    // A mesh added after the scene went dynamic is traced too.
    Add(scene, MakeBox({-1.0f, -11.0f, 0.0f}, {1.0f, -9.0f, kBoxHeight_m}));
    scene.Commit();
    EXPECT_TRUE(shadowed(inOldShadow + glm::vec3(0.0f, -10.0f, 0.0f)));
}

// Random origins around several boxes: the packet path must give exactly what one
// Occluded() call per ray gives over the same interval.
TEST(OcclusionScene, DirectionalVisibilityAgreesWithOccluded) {
    OcclusionScene scene;
    const TestMesh box = MakeBox({-1.0f, -1.0f, 0.0f}, {1.0f, 1.0f, kBoxHeight_m});
    Add(scene, box);
    Add(scene, Translated(box, {4.0f, 1.0f, 0.0f}));
    Add(scene, Translated(box, {-3.0f, 5.0f, 1.0f}));
    Add(scene, Translated(box, {2.0f, -5.0f, 0.5f}));
    scene.Commit();

    // Four full blocks of 1024 origins and a ragged fifth, so the parallel path runs.
    const size_t count = 4 * 1024 + 777;
    std::vector<glm::vec3> origins(count);
    for (size_t i = 0; i < count; ++i) {
        auto u = [&](uint64_t stream) { return float(scene::Uniform01(2024, stream, i)); };
        origins[i] = glm::vec3(14 * u(0) - 7, 14 * u(1) - 7, 6 * u(2) - 1);
    }
    const float range_m = 200.0f;
    const float tNear_m = OcclusionScene::kSegmentEpsilon * range_m;
    const glm::vec3 directions[] = {SunDirection(90, 30), SunDirection(200, 15),
                                    glm::normalize(glm::vec3(1.0f, 0.0f, 1.0f)),
                                    glm::vec3(0.0f, 0.0f, 1.0f)};
    for (const glm::vec3& direction : directions) {
        std::vector<uint8_t> visible(count, 7);
        scene.DirectionalVisibility(origins, direction, tNear_m, visible);
        size_t shadowed = 0;
        for (size_t i = 0; i < count; ++i) {
            const bool occluded = scene.Occluded(origins[i], origins[i] + range_m * direction);
            ASSERT_EQ(visible[i], occluded ? 0 : 1) << "origin " << i;
            shadowed += occluded;
        }
        // Enough of both outcomes for the comparison to mean something.
        EXPECT_GT(shadowed, count / 20);
        EXPECT_LT(shadowed, count - count / 20);

        // Every span length 0..40 (all packet tails) gives the same per-ray answers.
        for (size_t n = 0; n <= 40; ++n) {
            std::vector<uint8_t> part(n, 7);
            scene.DirectionalVisibility(std::span(origins).first(n), direction, tNear_m, part);
            for (size_t i = 0; i < n; ++i) ASSERT_EQ(part[i], visible[i]) << n << " " << i;
        }
        // Same bits with one and two threads.
        for (int threads : {1, 2}) {
            std::vector<uint8_t> again(count, 7);
            tbb::task_arena(threads).execute(
                [&] { scene.DirectionalVisibility(origins, direction, tNear_m, again); });
            ASSERT_EQ(again, visible) << threads << " threads";
        }
    }
}

// The prepared bounds test gives MayOcclude's answer for every origin, direction (also along
// the axes, where slabs are parallel) and distance; DirectionalVisibility of origins that pass
// it gives the same visibility whether it tests them again or not.
TEST(OcclusionScene, BoundsTestEqualsMayOccludeAndPrefilteredOriginsTraceTheSame) {
    OcclusionScene empty;
    empty.Commit();
    EXPECT_FALSE(empty.BoundsTest(glm::vec3(0.0f, 0.0f, 1.0f), 1e30f).MayOcclude(glm::vec3(0.0f)));

    OcclusionScene scene;
    const TestMesh box = MakeBox({-1.0f, -1.0f, 0.0f}, {1.0f, 1.0f, kBoxHeight_m});
    Add(scene, box);
    Add(scene, Translated(box, {6.0f, 2.0f, 0.5f}));
    scene.Commit();
    const size_t count = 3000;
    std::vector<glm::vec3> origins(count);
    for (size_t i = 0; i < count; ++i) {
        auto u = [&](uint64_t stream) { return float(scene::Uniform01(77, stream, i)); };
        origins[i] = glm::vec3(30 * u(0) - 15, 30 * u(1) - 15, 8 * u(2) - 2);
    }
    const glm::vec3 directions[] = {SunDirection(250, 4.4), SunDirection(30, 60),
                                    glm::vec3(0.0f, 0.0f, 1.0f), glm::vec3(1.0f, 0.0f, 0.0f),
                                    glm::normalize(glm::vec3(-1.0f, 1e-21f, 0.5f))};
    size_t hits = 0, misses = 0;
    for (const glm::vec3& direction : directions) {
        for (float maxDistance_m : {1e30f, 6.0f, 0.0f, -1.0f}) {
            const OccluderBoundsTest test = scene.BoundsTest(direction, maxDistance_m);
            const RayBoxesTest boxes(scene.MeshBoxes(), direction, maxDistance_m);
            for (const glm::vec3& o : origins) {
                const bool may = scene.MayOcclude(o, direction, maxDistance_m);
                ASSERT_EQ(test.MayOcclude(o), may) << maxDistance_m;
                hits += may, misses += !may;
            }
        }
        std::vector<glm::vec3> kept;
        for (const glm::vec3& o : origins)
            if (scene.MayOcclude(o, direction, 1e30f)) kept.push_back(o);
        std::vector<uint8_t> tested(kept.size(), 7), trusted(kept.size(), 7);
        scene.DirectionalVisibility(kept, direction, kShadowTNear_m, tested);
        scene.DirectionalVisibility(kept, direction, kShadowTNear_m, trusted, true);
        EXPECT_EQ(tested, trusted);
        EXPECT_GT(std::count(tested.begin(), tested.end(), 0), 0);
    }
    EXPECT_GT(hits, count / 10);
    EXPECT_GT(misses, count);
}

// Each mesh's box in MeshBoxes: its vertices' bounds enlarged by 1e-5 of the largest coordinate
// of any mesh plus 0.1 mm (the documented margin, computed here from the meshes themselves).
std::vector<AxisBox> ExpectedMeshBoxes(const std::vector<TestMesh>& meshes) {
    std::vector<AxisBox> boxes;
    float largest = 0.0f;
    for (const TestMesh& mesh : meshes) {
        AxisBox box{glm::vec3(INFINITY), glm::vec3(-INFINITY)};
        for (const glm::vec3& p : mesh.positions) {
            box.min = glm::min(box.min, p), box.max = glm::max(box.max, p);
            largest = std::max({largest, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
        }
        boxes.push_back(box);
    }
    for (AxisBox& box : boxes)
        box.min -= 1e-5f * largest + 1e-4f, box.max += 1e-5f * largest + 1e-4f;
    return boxes;
}

// Three boxes hundreds of metres apart, 10 m tall, as the five-channel scene's boats.
std::vector<TestMesh> ThreeCasters() {
    return {MakeBox({-126, 255, 0}, {-114, 265, 10}), MakeBox({144, 245, 0}, {156, 255, 8}),
            Translated(MakeBox({-6, -5, -1}, {6, 5, 9}), {232, 386, 0})};
}

// The prepared test (and RayBoxesTest of the scene's boxes, grown) is the per-mesh slab test,
// mesh by mesh, for many random origins around and between the casters and several directions (a
// low sun among them).
TEST(OcclusionScene, BoundsTestIsTheSlabTestOfEachMeshsOwnBox) {
    const std::vector<TestMesh> meshes = ThreeCasters();
    OcclusionScene scene;
    for (const TestMesh& mesh : meshes) Add(scene, mesh);
    scene.Commit();
    const std::vector<AxisBox> expected = ExpectedMeshBoxes(meshes);
    ASSERT_EQ(scene.MeshBoxes().size(), expected.size());
    for (size_t m = 0; m < expected.size(); ++m) {
        EXPECT_EQ(scene.MeshBoxes()[m].min, expected[m].min) << m;
        EXPECT_EQ(scene.MeshBoxes()[m].max, expected[m].max) << m;
    }
    const glm::vec3 directions[] = {SunDirection(290, 4.0), SunDirection(250, 1.0),
                                    SunDirection(30, 60), glm::vec3(1.0f, 0.0f, 0.0f),
                                    glm::vec3(0.0f, 0.0f, 1.0f)};
    size_t hits = 0, grownHits = 0;
    const size_t count = 20000;
    for (const glm::vec3& direction : directions) {
        const glm::vec3 inverse = occlusion_detail::InverseDirection(direction);
        for (float maxDistance_m : {1e30f, 150.0f}) {
            const OccluderBoundsTest test = scene.BoundsTest(direction, maxDistance_m);
            const RayBoxesTest boxes(scene.MeshBoxes(), direction, maxDistance_m);
            for (size_t i = 0; i < count; ++i) {
                auto u = [&](uint64_t stream) { return float(scene::Uniform01(78, stream, i)); };
                const glm::vec3 o(700 * u(0) - 300, 400 * u(1) + 100, 12 * u(2) - 1);
                const glm::vec3 grow(2 * u(3), 2 * u(4), 0.5f * u(5));
                bool any = false, anyGrown = false;
                for (const AxisBox& box : expected) {
                    any |= occlusion_detail::SlabHit(box.min, box.max, o, direction, inverse,
                                                     maxDistance_m);
                    anyGrown |= occlusion_detail::SlabHit(box.min - grow, box.max + grow, o,
                                                          direction, inverse, maxDistance_m);
                }
                ASSERT_EQ(test.MayOcclude(o), any) << i;
                ASSERT_EQ(scene.MayOcclude(o, direction, maxDistance_m), any) << i;
                ASSERT_EQ(boxes.MayHit(o, grow), anyGrown) << i;
                hits += any, grownHits += anyGrown;
            }
        }
    }
    EXPECT_GT(hits, count / 20);
    EXPECT_GT(grownHits, hits);
    EXPECT_LT(grownHits, 5 * count);
}

// Where the prepared test says a ray cannot be occluded, Embree finds nothing on it either
// (Occluded over a long segment, and DirectionalVisibility without the prefilter's promise):
// no false negatives, on random rays aimed near the casters.
TEST(OcclusionScene, RaysTheBoundsTestRejectsAreNotOccluded) {
    const std::vector<TestMesh> meshes = ThreeCasters();
    OcclusionScene scene;
    for (const TestMesh& mesh : meshes) Add(scene, mesh);
    scene.Commit();
    const glm::vec3 sun = SunDirection(290, 4.0);
    const OccluderBoundsTest test = scene.BoundsTest(sun, 1e30f);
    std::vector<glm::vec3> origins;
    for (size_t i = 0; i < 30000; ++i) {
        auto u = [&](uint64_t stream) { return float(scene::Uniform01(79, stream, i)); };
        // Back from a random point of a caster's box (a little larger) along the sun: a
        // ray from there toward the sun passes through or by that caster.
        const TestMesh& mesh = meshes[i % meshes.size()];
        const glm::vec3 lo = mesh.positions[0] - 0.5f, hi = mesh.positions[7] + 0.5f;
        const glm::vec3 target = lo + (hi - lo) * glm::vec3(u(0), u(1), u(2));
        origins.push_back(target - (20.0f + 200.0f * u(3)) * sun);
    }
    std::vector<uint8_t> visible(origins.size(), 7);
    scene.DirectionalVisibility(origins, sun, 0.0f, visible);
    size_t rejected = 0, occluded = 0;
    for (size_t i = 0; i < origins.size(); ++i) {
        const bool blocked = scene.Occluded(origins[i], origins[i] + 1e4f * sun);
        EXPECT_EQ(visible[i] == 0, blocked) << i;
        if (!test.MayOcclude(origins[i])) {
            ++rejected;
            ASSERT_FALSE(blocked) << i;
        }
        occluded += blocked;
    }
    EXPECT_GT(rejected, origins.size() / 30);  // near the boxes, where false negatives would be
    EXPECT_GT(occluded, origins.size() / 2);
}

// The case the per-mesh boxes are for: a low sun's ray between two boxes far apart meets
// their union box but neither box, so it is rejected; the union box (the old test) let it in.
TEST(OcclusionScene, ARayBetweenTwoDistantBoxesIsRejected) {
    OcclusionScene scene;
    Add(scene, MakeBox({-101, -1, 0}, {-99, 1, 10}));
    Add(scene, MakeBox({99, -1, 0}, {101, 1, 10}));
    scene.Commit();
    const glm::vec3 sun = SunDirection(0, 4.0);  // north, 4° up
    const glm::vec3 between(0.0f, -50.0f, 0.0f);
    const OccluderBoundsTest test = scene.BoundsTest(sun, 1e30f);
    EXPECT_FALSE(test.MayOcclude(between));
    EXPECT_FALSE(scene.MayOcclude(between, sun, 1e30f));
    EXPECT_FALSE(scene.Occluded(between, between + 1e3f * sun));
    const glm::vec3 lo = glm::min(scene.MeshBoxes()[0].min, scene.MeshBoxes()[1].min);
    const glm::vec3 hi = glm::max(scene.MeshBoxes()[0].max, scene.MeshBoxes()[1].max);
    EXPECT_TRUE(occlusion_detail::SlabHit(lo, hi, between, sun,
                                          occlusion_detail::InverseDirection(sun), 1e30f));
    // Behind either box the ray is still let in, and occluded.
    for (const float x : {-100.0f, 100.0f}) {
        const glm::vec3 behind(x, -50.0f, 0.0f);
        EXPECT_TRUE(test.MayOcclude(behind)) << x;
        EXPECT_TRUE(scene.Occluded(behind, behind + 1e3f * sun)) << x;
    }
    // Grown by 99 m along x, the boxes reach the ray between them.
    const RayBoxesTest boxes(scene.MeshBoxes(), sun, 1e30f);
    EXPECT_FALSE(boxes.MayHit(between, glm::vec3(98.0f, 0.0f, 0.0f)));
    EXPECT_TRUE(boxes.MayHit(between, glm::vec3(99.5f, 0.0f, 0.0f)));
}

// UpdateMesh + Commit moves that mesh's box (and only its): the prefilter follows the mesh.
TEST(OcclusionScene, UpdateMeshMovesItsBox) {
    std::vector<TestMesh> meshes = ThreeCasters();
    OcclusionScene scene;
    std::vector<uint32_t> ids;
    for (const TestMesh& mesh : meshes) ids.push_back(Add(scene, mesh));
    scene.Commit();
    const glm::vec3 sun = SunDirection(290, 4.0);
    const glm::vec3 offset(30.0f, -40.0f, 0.5f);
    const glm::vec3 centre = 0.5f * (meshes[1].positions[0] + meshes[1].positions[7]);
    const glm::vec3 behindOld = centre - 100.0f * sun, behindNew = behindOld + offset;
    EXPECT_TRUE(scene.BoundsTest(sun, 1e30f).MayOcclude(behindOld));
    EXPECT_FALSE(scene.BoundsTest(sun, 1e30f).MayOcclude(behindNew));

    meshes[1] = Translated(meshes[1], offset);
    scene.UpdateMesh(ids[1], meshes[1].positions);
    scene.Commit();
    const std::vector<AxisBox> expected = ExpectedMeshBoxes(meshes);
    for (size_t m = 0; m < expected.size(); ++m) {
        EXPECT_EQ(scene.MeshBoxes()[m].min, expected[m].min) << m;
        EXPECT_EQ(scene.MeshBoxes()[m].max, expected[m].max) << m;
    }
    EXPECT_FALSE(scene.BoundsTest(sun, 1e30f).MayOcclude(behindOld));
    EXPECT_TRUE(scene.BoundsTest(sun, 1e30f).MayOcclude(behindNew));
    EXPECT_TRUE(scene.Occluded(behindNew, behindNew + 1e3f * sun));
}

TEST(OcclusionScene, BadMeshesAreInputErrors) {
    OcclusionScene scene;
    const TestMesh box = MakeBox({0, 0, 0}, {1, 1, 1});
    std::vector<uint32_t> ragged(box.indices.begin(), box.indices.end() - 1);
    EXPECT_THROW(scene.AddMesh(box.positions, ragged), InputError);
    std::vector<uint32_t> outOfRange = box.indices;
    outOfRange[5] = 8;
    EXPECT_THROW(scene.AddMesh(box.positions, outOfRange), InputError);
    std::vector<glm::vec3> nan = box.positions;
    nan[3].y = NAN;
    EXPECT_THROW(scene.AddMesh(nan, box.indices), InputError);
    EXPECT_THROW(scene.AddMesh({}, {}), InputError);
    EXPECT_TRUE(scene.Empty());

    const uint32_t id = Add(scene, box);
    std::vector<glm::vec3> fewer(box.positions.begin(), box.positions.end() - 1);
    EXPECT_THROW(scene.UpdateMesh(id, fewer), InputError);
    std::vector<glm::vec3> infinite = box.positions;
    infinite[0].z = INFINITY;
    EXPECT_THROW(scene.UpdateMesh(id, infinite), InputError);
    EXPECT_THROW(scene.UpdateMesh(id + 1, box.positions), InternalError);
    // The failed calls left the mesh intact.
    scene.Commit();
    EXPECT_TRUE(scene.Occluded({-1, 0.5f, 0.5f}, {2, 0.5f, 0.5f}));
}

TEST(OcclusionScene, QueriesBeforeCommitAreInternalErrors) {
    OcclusionScene scene;
    Add(scene, MakeBox({0, 0, 0}, {1, 1, 1}));
    EXPECT_THROW(scene.Occluded({-1, 0.5f, 0.5f}, {2, 0.5f, 0.5f}), InternalError);
    scene.Commit();
    EXPECT_TRUE(scene.Occluded({-1, 0.5f, 0.5f}, {2, 0.5f, 0.5f}));
    std::vector<glm::vec3> origins(4, glm::vec3(0.0f));
    std::vector<uint8_t> tooFew(3);
    EXPECT_THROW(scene.DirectionalVisibility(origins, {0, 0, 1}, 0.0f, tooFew), InternalError);
    std::vector<uint8_t> visible(4);
    EXPECT_THROW(scene.DirectionalVisibility(origins, {0, 0, 2}, 0.0f, visible), InternalError);
}

TEST(OcclusionScene, EmbreeErrorsBecomeRuntimeErrors) {
    // An acceleration structure name Embree does not know fails inside Embree when the scene
    // is built; it must surface as RuntimeError carrying Embree's message, not abort.
    try {
        OcclusionScene scene("tri_accel=no_such_accel");
        Add(scene, MakeBox({0, 0, 0}, {1, 1, 1}));
        scene.Commit();
        FAIL() << "expected RuntimeError";
    } catch (const RuntimeError& e) {
        EXPECT_NE(std::string(e.what()).find("no_such_accel"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace seasense::channels
