// The sea mesh as the channels rasterize it: watertight (every view ray that must meet the sea
// does, in any attitude and as the eye moves), and contiguous channels share their vertices.
#include "channels/view/view_geometry.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <string>
#include <vector>

namespace seasense::channels {
namespace {

constexpr double kRad = std::numbers::pi / 180.0;

scene::Scenario SpectralSea(double eyeHeight_m, double pitch_deg, double roll_deg) {
    scene::Scenario sc;
    sc.world.start = *scene::ParseIso8601("2026-06-21T12:00:00Z");
    sc.world.seed = 5;
    sc.environment.sun.elevation_rad = 0.6;
    sc.environment.ocean.depth_m = 60.0;
    scene::SpectralOceanSettings s;
    s.sea.beaufort = 4;
    s.sea.spectrum.windDirection_rad = 0.3;
    s.fft.gridSize = 128;
    s.fft.seed = 5;
    sc.environment.ocean.spectral = s;
    sc.eyepoint.position_m = {0.0, 0.0, eyeHeight_m};
    sc.eyepoint.attitude.heading_rad = 0.4;
    sc.eyepoint.attitude.pitch_rad = pitch_deg * kRad;
    sc.eyepoint.attitude.roll_rad = roll_deg * kRad;
    sc.eyepoint.speed_mps = 7.0;
    scene::ChannelSettings ch;
    ch.name = "view";
    ch.width = 320;
    ch.height = 240;
    ch.hfov_rad = 60.0 * kRad;
    ch.supersampling = 1;
    sc.channels.push_back(ch);
    return sc;
}

// Samples of view's last frame (only those of the pixels in spans, one per pixel row, when
// given) that look below the horizon of the highest crest by more than two samples: each must
// meet the sea (a sphere of mean radius R whose surface lies within ±MaxHeight); one that sees
// nothing looks through a crack. Returns how many it checked.
int CheckNoGapBelowTheHorizon(const ViewGeometry& view, const std::vector<PixelSpan>& spans,
                              const std::string& what) {
    const ChannelCamera& cam = view.Camera();
    const VisibilityBuffer& vis = view.Visibility();
    const double crest = view.OceanFrame().MaxHeight_m();
    const glm::dvec3 eye = cam.worldFromCamera.position_m;
    const double h = eye.z;
    // The eye is above the water (below it, the sea is seen from underneath: culled).
    EXPECT_GT(h, view.OceanFrame().HeightAt(eye.x, eye.y) + 0.3) << what;
    // Dip of the horizon of a point at height h + crest above a trough-level sphere.
    const double dip = std::acos(scene::kEarthRadius_m / (scene::kEarthRadius_m + h + crest));
    const double margin = 2.0 * cam.hfov_rad / cam.SampleWidth();  // two samples
    const int n = cam.supersampling;
    int checked = 0;
    for (int y = 0; y < cam.SampleHeight(); ++y)
        for (int x = 0; x < cam.SampleWidth(); ++x) {
            if (!spans.empty() &&
                (x / n < spans[size_t(y / n)].begin || x / n >= spans[size_t(y / n)].end))
                continue;
            const glm::dvec3 d = cam.SampleDirection(x, y);
            if (d.z > -std::sin(dip + margin)) continue;
            ++checked;
            EXPECT_NE(vis.primitive[vis.Index(x, y)], kNoPrimitive)
                << what << " sample " << x << "," << y;
            if (vis.primitive[vis.Index(x, y)] == kNoPrimitive) return checked;
        }
    return checked;
}

struct ViewCase {
    double height, pitch, roll;
};
constexpr ViewCase kViewCases[] = {
    {2.0, -2.0, 0.0}, {2.0, -30.0, 25.0}, {40.0, -10.0, -40.0}, {300.0, -89.0, 0.0}};

TEST(ViewGeometry, SeaMeshLeavesNoGapBelowTheHorizon) {
    // Several attitudes, eye heights and frames.
    for (const ViewCase c : kViewCases) {
        const scene::Scenario sc = SpectralSea(c.height, c.pitch, c.roll);
        const scene::World world(sc);
        ViewGeometry view(world, sc.channels[0]);
        tbb::task_arena arena(2);
        int checked = 0;
        for (int64_t frame : {0, 17}) {
            arena.execute([&] { view.Update(world.State(frame)); });
            checked += CheckNoGapBelowTheHorizon(
                view, {},
                "height " + std::to_string(c.height) + " pitch " + std::to_string(c.pitch) +
                    " roll " + std::to_string(c.roll) + " frame " + std::to_string(frame));
        }
        EXPECT_GT(checked, 10000) << c.height;
    }
}

// Pixels whose centres lie within radius_px of the image centre, row by row (an NVG channel's
// circular field stop).
std::vector<PixelSpan> DiscSpans(int width, int height, double radius_px) {
    std::vector<PixelSpan> spans(static_cast<size_t>(height));
    for (int y = 0; y < height; ++y) {
        const double dy = y + 0.5 - 0.5 * height;
        if (std::abs(dy) > radius_px) continue;
        const double half = std::sqrt(radius_px * radius_px - dy * dy);
        // Pixel x is inside when |x + ½ − width/2| ≤ half.
        spans[size_t(y)].begin = std::max(0, int(std::ceil(0.5 * width - half - 0.5)));
        spans[size_t(y)].end = std::min(width, int(std::floor(0.5 * width + half - 0.5)) + 1);
    }
    return spans;
}

TEST(ViewGeometry, SeaMeshLimitedToRenderSpansLeavesNoGapInThem) {
    // A disc of pixels filling the frame's height (an NVG field stop): the sea mesh asked only
    // for their azimuths still meets every ray through them that must meet the sea, in the
    // attitudes above; and its sector is the disc's.
    for (const ViewCase c : kViewCases) {
        const scene::Scenario sc = SpectralSea(c.height, c.pitch, c.roll);
        const scene::ChannelSettings& ch = sc.channels[0];
        const std::vector<PixelSpan> spans = DiscSpans(ch.width, ch.height, 0.5 * ch.height);
        const scene::World world(sc);
        ViewGeometry view(world, ch);
        view.SetRenderSpans(spans);
        tbb::task_arena arena(2);
        int checked = 0;
        for (int64_t frame : {0, 17}) {
            arena.execute([&] { view.Update(world.State(frame)); });
            checked += CheckNoGapBelowTheHorizon(
                view, spans,
                "spans: height " + std::to_string(c.height) + " pitch " + std::to_string(c.pitch) +
                    " roll " + std::to_string(c.roll) + " frame " + std::to_string(frame));
        }
        EXPECT_GT(checked, 5000) << c.height;
    }
}

TEST(ViewGeometry, RenderSpansSectorOfALevelDiscIsItsAngularRadius) {
    // A level camera (pitch 0, roll 0, heading 0.4 rad): the cone of directions within ρ of
    // the axis reaches azimuths heading ± ρ exactly (at elevation 0); the disc of pixels within
    // the radius r_px = (W/2) tan ρ / tan(hfov/2) of the centre reaches that within ½ pixel and
    // the rounding of its rim (its outermost pixels' outer edges). A whole-frame span gives the
    // frustum's sector.
    scene::Scenario sc = SpectralSea(2.0, 0.0, 0.0);
    const ChannelCamera cam = MakeChannelCamera(
        scene::Pose{sc.eyepoint.position_m, scene::WorldFromBodyRotation(sc.eyepoint.attitude)},
        sc.channels[0]);
    const double rho = 20.0 * kRad;
    const double tanPerPixel = std::tan(0.5 * cam.hfov_rad) / (0.5 * cam.width);
    const std::vector<PixelSpan> spans =
        DiscSpans(cam.width, cam.height, std::tan(rho) / tanPerPixel);
    double lo = 0.0, hi = 0.0;
    SpansAzimuthSector(cam, spans, lo, hi);
    const double pixel = std::atan(tanPerPixel);
    EXPECT_NEAR(0.5 * (lo + hi), 0.4, 1e-9);
    EXPECT_GE(0.5 * (hi - lo), rho - 0.6 * pixel);
    EXPECT_LE(0.5 * (hi - lo), rho + 0.6 * pixel);
    std::vector<PixelSpan> all(size_t(cam.height), PixelSpan{0, cam.width});
    double flo = 0.0, fhi = 0.0;
    FrustumAzimuthSector(cam, 0.0, flo, fhi);
    SpansAzimuthSector(cam, all, lo, hi);
    EXPECT_NEAR(lo, flo, 1e-12);
    EXPECT_NEAR(hi, fhi, 1e-12);
    EXPECT_NEAR(0.5 * (fhi - flo), std::atan(std::tan(0.5 * cam.hfov_rad)), 1e-9);
}

// The steepest view ray, against brute force: the lowest unit z over 2000 directions per image
// edge and 2000 inside the image, for random attitudes and fields of view, among them views
// 60-89° down with the nadir just outside the image (where the steepest ray lies inside an edge,
// between corners). The exact value is never above any sampled ray's z (no ray is steeper than
// it says) and is within the sampling's resolution of the lowest sample (it is attained); the
// nearest visible range then keeps every ray's crossing of the crest plane outside it.
TEST(ViewGeometry, SteepestViewDirectionIsTheLowestOfAllRays) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    int nearNadir = 0;
    for (int trial = 0; trial < 400; ++trial) {
        const bool steep = trial % 2 == 0;
        scene::Attitude a;
        a.heading_rad = 6.28 * u01(rng);
        a.pitch_rad = (steep ? -60.0 - 29.0 * u01(rng) : -30.0 + 40.0 * u01(rng)) * kRad;
        a.roll_rad = (60.0 * u01(rng) - 30.0) * kRad;
        scene::ChannelSettings ch;
        ch.width = 640;
        ch.height = 480;
        ch.hfov_rad = (10.0 + 100.0 * u01(rng)) * kRad;
        ch.supersampling = 1;
        const ChannelCamera cam =
            MakeChannelCamera(scene::PoseFrom(glm::dvec3(0.0, 0.0, 2.0), a), ch);
        const double sw = cam.SampleWidth(), sh = cam.SampleHeight();
        // Nadir inside the frustum: the function's answer is not meaningful (the range is 0).
        const glm::dvec3 nadirInCamera =
            glm::transpose(cam.worldFromCamera.worldFromBody) * glm::dvec3(0.0, 0.0, -1.0);
        if (nadirInCamera.y > 0.0 &&
            std::abs(nadirInCamera.x / nadirInCamera.y) <= cam.TanHalfH() &&
            std::abs(nadirInCamera.z / nadirInCamera.y) <= cam.TanHalfV())
            continue;
        double lowest = 1.0;
        constexpr int kSteps = 2000;
        for (int i = 0; i <= kSteps; ++i) {
            const double t = double(i) / kSteps;
            for (const glm::dvec2& s :
                 {glm::dvec2(t * sw, 0.0), glm::dvec2(sw, t * sh), glm::dvec2(t * sw, sh),
                  glm::dvec2(0.0, t * sh), glm::dvec2(u01(rng) * sw, u01(rng) * sh)})
                lowest = std::min(lowest, cam.SampleDirection(s.x - 0.5, s.y - 0.5).z);
        }
        const double z = SteepestViewDirectionZ(cam);
        EXPECT_LE(z, lowest + 1e-12) << trial;
        // Between boundary samples (≤ 110°/2000 apart) a ray's z differs by under 1e-3.
        EXPECT_GE(z, lowest - 1e-3) << trial;
        if (steep && lowest < -0.9) ++nearNadir;
        if (z < 0.0) {
            const double slope = -lowest / std::sqrt(1.0 - lowest * lowest);
            // (2 − 0.5) m above the crests; a positive range leaves the reach 0.25 m inside it.
            const double range = NearestVisibleSeaRange_m(cam, 0.5, 0.25);
            if (range > 0.0) {
                EXPECT_LE(range + 0.25, 1.5 / slope) << trial;
            }
        }
    }
    EXPECT_GT(nearNadir, 50);
}

TEST(ViewGeometry, ContiguousChannelsShareTheirSeaVertices) {
    // Vertices sit at world-fixed azimuths, so the left and centre channels of a row (equal
    // resolution and field of view) build the same vertices where their sectors overlap.
    scene::Scenario sc = SpectralSea(2.0, -1.0, 0.0);
    scene::ChannelSettings left = sc.channels[0];
    left.name = "left";
    left.attitude.heading_rad = -60.0 * kRad;
    sc.channels.push_back(left);
    const scene::World world(sc);
    ViewGeometry centre(world, sc.channels[0]), side(world, sc.channels[1]);
    const scene::SceneState state = world.State(3);
    centre.Update(state);
    side.Update(state);
    const scene::OceanMesh &a = centre.Ocean(), &b = side.Ocean();
    ASSERT_EQ(a.circleSegments, b.circleSegments);
    // The rings are one fixed sequence, each mesh from its own nearest visible range (the two
    // frusta dip differently, the eyepoint's pitch being partly roll for the side channel): one
    // mesh's radii are the other's from some ring k on.
    const bool aFirst = a.radii_m.size() >= b.radii_m.size();
    const scene::OceanMesh &outer = aFirst ? a : b, &inner = aFirst ? b : a;
    const size_t k = outer.radii_m.size() - inner.radii_m.size();
    ASSERT_EQ(std::vector<double>(outer.radii_m.begin() + std::ptrdiff_t(k), outer.radii_m.end()),
              inner.radii_m);
    ASSERT_EQ(
        std::vector<int>(outer.ringStride.begin() + std::ptrdiff_t(k), outer.ringStride.end()),
        inner.ringStride);
    // World column c of ring j, or nullptr where that ring has no such column.
    const auto at = [](const scene::OceanMesh& m, int j, int c) -> const glm::vec3* {
        const int n = int(m.ringStart[size_t(j) + 1] - m.ringStart[size_t(j)]);
        const int s = m.ringStride[size_t(j)];
        const int col = n * s == m.circleSegments
                            ? ((c % m.circleSegments) + m.circleSegments) % m.circleSegments
                            : c - m.ringFirstColumn[size_t(j)];
        if (col < 0 || col % s != 0 || col / s >= n) return nullptr;
        return &m.positions[m.ringStart[size_t(j)] + size_t(col / s)];
    };
    int shared = 0;
    for (int j = 0; j < inner.rings; ++j) {
        const int n = int(inner.ringStart[size_t(j) + 1] - inner.ringStart[size_t(j)]);
        for (int i = 0; i < n; ++i) {
            const int c = inner.ringFirstColumn[size_t(j)] + i * inner.ringStride[size_t(j)];
            const glm::vec3* po = at(outer, j + int(k), c);
            if (!po) continue;
            ASSERT_EQ(*at(inner, j, c), *po) << "ring " << j << " column " << c;
            ++shared;
        }
    }
    EXPECT_GT(shared, 1000);  // the overlap holds the widened margins of both sectors
}

// The per-triangle shadow prefilter's boxes: one per entity, holding that entity's vertices and
// the occlusion scene's (enlarged) box of it, so that passing the per-sample test implies
// passing this one, caster by caster; a moving entity's box follows it. Two boats 300 m apart
// keep boxes apart (the union of them would hold the sea between).
TEST(ViewGeometry, CasterBoxesHoldEachEntityAndItsOcclusionBox) {
    const std::filesystem::path obj =
        std::filesystem::temp_directory_path() /
        ("seasense_caster_boxes_" + std::to_string(::getpid()) + ".obj");
    {
        std::ofstream out(obj);  // a 4 × 3 × 6 m block (glTF axes: y up)
        for (int c = 0; c < 8; ++c)
            out << "v " << (c & 1 ? 2 : -2) << " " << (c & 2 ? 3 : -3) << " "
                << (c & 4 ? 1.5 : -1.5) << "\n";
        out << "f 1 2 4\nf 1 4 3\nf 5 6 8\nf 5 8 7\nf 1 5 6\nf 1 6 2\n";
    }
    scene::Scenario sc = SpectralSea(3.0, -2.0, 0.0);
    sc.materials = {{"grey", glm::dvec3(0.5)}};
    sc.entities.push_back({"a", obj, {-150, 200, 0}, {}, 1.0, "grey"});
    sc.entities.push_back({"b", obj, {150, 250, 0}, {}, 1.0, "grey", 5.0});
    const scene::World world(sc);
    ViewGeometry view(world, sc.channels[0]);
    const AxisBox a0 = view.CasterBoxes()[0], b0 = view.CasterBoxes()[1];
    const glm::vec3 bVertex0 = view.EntityMeshes()[1].positions[0];
    for (int frame : {0, 30}) {
        if (frame > 0) tbb::task_arena(2).execute([&] { view.Update(world.State(frame)); });
        const std::span<const AxisBox> casters = view.CasterBoxes();
        const std::span<const AxisBox> meshes = view.Occlusion().MeshBoxes();
        ASSERT_EQ(casters.size(), 2u);
        ASSERT_EQ(meshes.size(), 2u);
        for (size_t i = 0; i < 2; ++i) {
            for (int axis = 0; axis < 3; ++axis) {
                EXPECT_LT(casters[i].min[axis], meshes[i].min[axis]) << frame << " " << i;
                EXPECT_GT(casters[i].max[axis], meshes[i].max[axis]) << frame << " " << i;
            }
            for (const glm::vec3& p : view.EntityMeshes()[i].positions) {
                EXPECT_TRUE(glm::all(glm::lessThan(meshes[i].min, p)) &&
                            glm::all(glm::lessThan(p, meshes[i].max)))
                    << frame << " " << i;
            }
        }
        EXPECT_LT(casters[0].max.x, casters[1].min.x - 250.0f) << frame;
    }
    // Boat b moved at 5 m/s along its heading, and its box with it; a's stayed. (Both boxes'
    // margins grow by 1e-3 of the change in the largest coordinate: the tolerance.)
    const glm::vec3 moved = view.EntityMeshes()[1].positions[0] - bVertex0;
    EXPECT_GT(glm::length(moved), 1.0f);
    for (int axis = 0; axis < 3; ++axis) {
        EXPECT_NEAR(view.CasterBoxes()[1].min[axis] - b0.min[axis], moved[axis], 0.02f) << axis;
        EXPECT_NEAR(view.CasterBoxes()[1].max[axis] - b0.max[axis], moved[axis], 0.02f) << axis;
        EXPECT_NEAR(view.CasterBoxes()[0].min[axis], a0.min[axis], 0.02f) << axis;
        EXPECT_NEAR(view.CasterBoxes()[0].max[axis], a0.max[axis], 0.02f) << axis;
    }
    std::filesystem::remove(obj);
}

}  // namespace
}  // namespace seasense::channels
