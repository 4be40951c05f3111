// The surf zone's seabed: plane-beach depths from the slopes, the shore frame's orientation,
// sandbar crest and flanks, region repetition, and a depth grid read from a float TIFF.
#include "scene/surf/bathymetry.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "scene/core/error.h"

namespace seasense::scene {
namespace {

namespace fs = std::filesystem;
constexpr double kDeg = std::numbers::pi / 180.0;

// A beach facing east (shoreline runs north, land to the west): intertidal 0.05 between −1 and
// +1 m, 40 m of supralittoral at 0.08, 200 m of sublittoral at 0.02, then 0.05 to 20 m depth.
SurfSettings EastFacingBeach() {
    SurfSettings s;
    s.shoreline.azimuth_rad = 0.0;
    s.tide_m = 0.5;
    s.lowTide_m = -1.0;
    s.highTide_m = 1.0;
    s.supralittoral = {0.08, 40.0};
    s.intertidal = {0.05, 0.0};
    s.sublittoral = {0.02, 200.0};
    s.offshoreSlope = 0.05;
    return s;
}

TEST(Bathymetry, PlaneBeachDepthsFollowTheZoneSlopes) {
    const Bathymetry b(EastFacingBeach(), 20.0);
    // Seabed elevations worked by hand from the slopes: the still-water line (z = 0) at x = 0,
    // low water (−1 m) 20 m out, high water (+1 m) 20 m in.
    struct Point {
        double x, z;
    };
    for (const Point p : std::vector<Point>{{0.0, 0.0},
                                            {10.0, -0.5},
                                            {20.0, -1.0},
                                            {120.0, -1.0 - 0.02 * 100.0},
                                            {220.0, -5.0},
                                            {320.0, -5.0 - 0.05 * 100.0},
                                            {520.0, -20.0},
                                            {5000.0, -20.0},
                                            {-20.0, 1.0},
                                            {-40.0, 1.0 + 0.08 * 20.0},
                                            {-60.0, 1.0 + 0.08 * 40.0},
                                            {-900.0, 4.2}}) {
        for (const double y : {-1234.0, 0.0, 777.0}) {  // no alongshore variation
            EXPECT_NEAR(b.SeabedZ_m(p.x, y), p.z, 1e-12) << "x = " << p.x;
            EXPECT_NEAR(b.Depth_m(p.x, y), 0.5 - p.z, 1e-12) << "x = " << p.x;
        }
    }
    EXPECT_LT(b.Depth_m(-15.0, 0.0), 0.0);  // dry above the tide's waterline at x = -10
    EXPECT_NEAR(b.Depth_m(-10.0, 0.0), 0.0, 1e-12);
    EXPECT_EQ(b.ZoneAt(-50.0), LittoralZone::Supralittoral);
    EXPECT_EQ(b.ZoneAt(-70.0), LittoralZone::Land);
    EXPECT_EQ(b.ZoneAt(5.0), LittoralZone::Intertidal);
    EXPECT_EQ(b.ZoneAt(100.0), LittoralZone::Sublittoral);
    EXPECT_EQ(b.ZoneAt(300.0), LittoralZone::Offshore);
    EXPECT_NEAR(b.OceanFloor_m(), 520.0, 1e-9);
}

TEST(Bathymetry, ShoreFrameOfCampPendletonPutsLandOnTheLeft) {
    SurfSettings s = EastFacingBeach();
    // Seed 003: the shoreline at 125.518° counter-clockwise from the x (east) axis, which is the
    // azimuth 90° − 125.518° from north, clockwise.
    const double azimuth_deg = 90.0 - 125.518;
    s.shoreline.azimuth_rad = azimuth_deg * kDeg;
    s.shoreline.origin_m = {350.0, -120.0};
    const Bathymetry b(s, 20.0);
    const ShoreFrame& f = b.Frame();
    // The shoreline direction at 125.518° from east, the seaward normal 90° clockwise from it.
    const glm::dvec2 along{std::cos(125.518 * kDeg), std::sin(125.518 * kDeg)};
    const glm::dvec2 seaward{along.y, -along.x};
    EXPECT_NEAR(glm::length(f.Alongshore() - along), 0.0, 1e-12);
    EXPECT_NEAR(glm::length(f.Seaward() - seaward), 0.0, 1e-12);
    for (const double u : {-300.0, 0.0, 45.0}) {
        for (const double sd : {-60.0, 10.0, 120.0}) {
            const glm::dvec2 p = s.shoreline.origin_m + sd * seaward + u * along;
            const ShorePoint q = f.ShoreFromWorld(p.x, p.y);
            EXPECT_NEAR(q.s_m, sd, 1e-9);
            EXPECT_NEAR(q.u_m, u, 1e-9);
            const glm::dvec2 back = f.WorldFromShore(q.s_m, q.u_m);
            EXPECT_NEAR(glm::length(back - p), 0.0, 1e-9);
        }
    }
    // Facing along the shoreline, the left hand (90° counter-clockwise) points to dry land.
    const glm::dvec2 left{-along.y, along.x};
    const glm::dvec2 land = s.shoreline.origin_m + 30.0 * left;
    const glm::dvec2 sea = s.shoreline.origin_m - 30.0 * left;
    EXPECT_NEAR(b.SeabedZ_m(land.x, land.y), 1.0 + 0.08 * 10.0, 1e-9);
    EXPECT_NEAR(b.SeabedZ_m(sea.x, sea.y), -1.0 - 0.02 * 10.0, 1e-9);
}

// One 400 m region with a bar (crest 1 m below the tide, 30 m wide, 200 m long, centred 100 m
// out, 20 m flanks) and one 300 m region without.
SurfSettings BarredBeach() {
    SurfSettings s = EastFacingBeach();
    SurfRegionSettings barred;
    barred.width_m = 400.0;
    barred.sandbar = SandbarSettings{30.0, 200.0, 1.0, 100.0, 20.0};
    SurfRegionSettings plain;
    plain.width_m = 300.0;
    s.regions = {barred, plain};
    return s;
}

TEST(Bathymetry, SandbarCrestLiesAtItsDepthBelowTheTideAndBlendsOverItsFlanks) {
    const Bathymetry b(BarredBeach(), 20.0);
    // The sublittoral plane beach beyond x = 20.
    auto plane = [](double x) { return -1.0 - 0.02 * (x - 20.0); };
    // Region 0 spans u (= y here) ∈ [0, 400): the bar is centred at y = 200.
    for (const double x : {85.0, 100.0, 115.0})
        for (const double y : {100.0, 200.0, 300.0}) EXPECT_NEAR(b.Depth_m(x, y), 1.0, 1e-12);
    // Beyond the flanks (20 m past the crest rectangle) the plane beach is untouched.
    EXPECT_NEAR(b.SeabedZ_m(135.0, 200.0), plane(135.0), 1e-12);
    EXPECT_NEAR(b.SeabedZ_m(100.0, 320.0), plane(100.0), 1e-12);
    EXPECT_NEAR(b.SeabedZ_m(60.0, 200.0), plane(60.0), 1e-12);
    // Halfway down the seaward flank the smoothstep weight is 1/2: midway between crest and beach.
    const double zCrest = 0.5 - 1.0;
    EXPECT_NEAR(b.SeabedZ_m(125.0, 200.0), 0.5 * (zCrest + plane(125.0)), 1e-12);
    // A quarter of the way (5 m from the crest): weight t²(3 − 2t) at t = 3/4 is 27/32.
    EXPECT_NEAR(b.SeabedZ_m(120.0, 200.0), plane(120.0) + 27.0 / 32.0 * (zCrest - plane(120.0)),
                1e-12);
    // The seabed never falls below the plane beach and the flank is monotone.
    double last = b.SeabedZ_m(115.0, 200.0);
    for (double x = 115.0; x <= 140.0; x += 0.5) {
        const double z = b.SeabedZ_m(x, 200.0);
        EXPECT_GE(z, plane(x) - 1e-12);
        EXPECT_LE(z, last + 1e-12);
        last = z;
    }
    // A bar crest below the plane beach (near shore) does not dig a trench.
    SurfSettings deep = BarredBeach();
    deep.regions[0].sandbar->distance_m = 10.0;
    deep.regions[0].sandbar->crestDepth_m = 3.0;
    const Bathymetry d(deep, 20.0);
    EXPECT_NEAR(d.SeabedZ_m(10.0, 200.0), -0.5, 1e-12);
}

// The seabed bound over a disc (view culling) holds at every point of the disc, and off the bar
// it is the plane beach at the disc's landward edge, where the monotone profile is highest.
TEST(Bathymetry, SeabedBoundOverADiscHoldsEverywhereInIt) {
    const Bathymetry b(BarredBeach(), 20.0);
    for (const double cx : {-30.0, 10.0, 60.0, 100.0, 180.0, 400.0})
        for (const double cy : {0.0, 200.0, 550.0})
            for (const double r : {0.0, 5.0, 40.0, 150.0}) {
                const double bound = b.MaxSeabedZWithin_m(cx, cy, r);
                for (int i = 0; i <= 24; ++i)
                    for (int j = 0; j < 48; ++j) {
                        const double rho = r * i / 24.0, a = 2.0 * M_PI * j / 48.0;
                        EXPECT_LE(b.SeabedZ_m(cx + rho * std::cos(a), cy + rho * std::sin(a)),
                                  bound + 1e-12)
                            << cx << " " << cy << " " << r;
                    }
            }
    // Far from the bar (it spans s ∈ [65, 135] with its flanks): the profile at s − r.
    EXPECT_NEAR(b.MaxSeabedZWithin_m(300.0, 0.0, 50.0), b.ProfileZ_m(250.0), 1e-12);
    EXPECT_NEAR(b.MaxSeabedZWithin_m(30.0, 0.0, 10.0), b.ProfileZ_m(20.0), 1e-12);
    // Reaching the bar: its crest level, 1 m below the tide.
    EXPECT_NEAR(b.MaxSeabedZWithin_m(200.0, 0.0, 70.0), b.Tide_m() - 1.0, 1e-12);
    // The whole bed: the level ground behind the beach.
    EXPECT_NEAR(b.MaxSeabedZWithin_m(0.0, 0.0, std::numeric_limits<double>::infinity()),
                b.ProfileZ_m(b.LandwardEdge_m() - 1.0), 1e-12);
}

// Seaward of DeepSeawardOf_m(h) the still water is at least h deep everywhere, bars included,
// and a metre landward of it (off the bar) it is shallower: the bound is the profile's own.
TEST(Bathymetry, DeepSeawardOfBoundsTheDepthEverywhereSeawardOfIt) {
    const Bathymetry barred(BarredBeach(), 20.0), plane(EastFacingBeach(), 20.0);
    for (const Bathymetry* b : {&barred, &plane}) {
        for (const double h : {0.2, 0.5, 1.2, 3.0, 7.5, 15.0, 20.4}) {
            const double s = b->DeepSeawardOf_m(h);
            ASSERT_TRUE(std::isfinite(s)) << h;
            for (double ds = 0.0; ds < 800.0; ds += 0.0625) {
                for (const double u : {0.0, 180.0, 200.0, 333.0}) {
                    ASSERT_GE(b->DepthAtShore_m(s + ds, u), h) << h << " " << ds << " " << u;
                }
            }
            // Off the bar (its flanks end at s = 135 + 1 mm) the profile sets it to within 1 m.
            if (s > 136.0) {
                EXPECT_LT(b->DepthAtShore_m(s - 1.0, 0.0), h) << h;
            }
        }
        // Never that deep (the floor lies 20 m below mean sea level): no such distance.
        EXPECT_EQ(b->DeepSeawardOf_m(b->Tide_m() + 20.0 + 0.01),
                  std::numeric_limits<double>::infinity());
    }
    // On the barred beach a depth the bar's crest (1 m) rises above is found seaward of it.
    EXPECT_GT(barred.DeepSeawardOf_m(1.2), 135.0);
    EXPECT_LT(plane.DeepSeawardOf_m(1.2), 80.0);
}

TEST(Bathymetry, RegionsRepeatAlongTheShore) {
    const Bathymetry b(BarredBeach(), 20.0);
    EXPECT_DOUBLE_EQ(b.RegionPeriod_m(), 700.0);
    auto plane = [](double x) { return -1.0 - 0.02 * (x - 20.0); };
    for (int k = -3; k <= 3; ++k) {
        const double y0 = 700.0 * k;
        EXPECT_NEAR(b.Depth_m(100.0, y0 + 200.0), 1.0, 1e-9) << "period " << k;
        EXPECT_NEAR(b.SeabedZ_m(100.0, y0 + 550.0), plane(100.0), 1e-12) << "period " << k;
        for (double y = 0.0; y < 700.0; y += 37.0)
            EXPECT_NEAR(b.SeabedZ_m(110.0, y0 + y), b.SeabedZ_m(110.0, y), 1e-9);
        double offset = 0.0;
        EXPECT_EQ(b.RegionAt(y0 + 420.0, &offset), 1);
        EXPECT_NEAR(offset, 20.0, 1e-9);
        EXPECT_EQ(b.RegionAt(y0 + 10.0, &offset), 0);
    }
    // Both regions' bars are centred: the bar of region 0 is symmetric about u = 200.
    for (double du = 0.0; du < 150.0; du += 7.0)
        EXPECT_NEAR(b.SeabedZ_m(128.0, 200.0 + du), b.SeabedZ_m(128.0, 200.0 - du), 1e-12);
}

class DepthGridTest : public ::testing::Test {
  protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        folder_ = fs::path(::testing::TempDir()) / (std::string("seasense_grid_") + info->name());
        fs::remove_all(folder_);
        fs::create_directories(folder_);
    }
    void TearDown() override { fs::remove_all(folder_); }

    fs::path WriteTiff(int width, int height, int channels, const std::vector<float>& v) const {
        const fs::path file = folder_ / "grid.tif";
        auto out = OIIO::ImageOutput::create(file.string());
        EXPECT_TRUE(out);
        const OIIO::ImageSpec spec(width, height, channels, OIIO::TypeDesc::FLOAT);
        EXPECT_TRUE(out->open(file.string(), spec));
        EXPECT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, v.data()));
        out->close();
        return file;
    }
    fs::path folder_;
};

TEST_F(DepthGridTest, GridReadFromAFloatTiffIsSampledBilinearly) {
    // 3 columns × 2 rows of depths below mean sea level.
    const std::vector<float> depth = {1.0f, 2.0f, 4.0f,  //
                                      3.0f, 5.0f, 9.0f};
    const fs::path file = WriteTiff(3, 2, 1, depth);
    SurfSettings s = EastFacingBeach();
    DepthGridSettings g;
    g.file = file;
    g.origin_m = {100.0, 50.0};  // pixel (0, 0) centre; rows run south
    g.cell_m = 10.0;
    g.values = DepthGridValues::Depth;
    g.grid = std::make_shared<const DepthGrid>(DepthGrid::Load(file));
    s.depthGrid = g;
    const Bathymetry b(s, 6.0);
    EXPECT_NEAR(b.SeabedZ_m(100.0, 50.0), -1.0, 1e-6);
    EXPECT_NEAR(b.SeabedZ_m(120.0, 50.0), -4.0, 1e-6);
    EXPECT_NEAR(b.SeabedZ_m(110.0, 40.0), -5.0, 1e-6);
    EXPECT_NEAR(b.Depth_m(110.0, 40.0), 5.5, 1e-6);  // tide 0.5
    // Centre of the four left cells: their mean; a point a quarter along the top edge.
    EXPECT_NEAR(b.SeabedZ_m(105.0, 45.0), -(1.0 + 2.0 + 3.0 + 5.0) / 4.0, 1e-6);
    EXPECT_NEAR(b.SeabedZ_m(102.5, 50.0), -(0.75 * 1.0 + 0.25 * 2.0), 1e-6);
    // Outside the grid the border extends; deeper than the ocean's depth is floored at it.
    EXPECT_NEAR(b.SeabedZ_m(0.0, 500.0), -1.0, 1e-6);
    EXPECT_NEAR(b.SeabedZ_m(500.0, -500.0), -6.0, 1e-6);  // 9 m floored at 6 m

    g.values = DepthGridValues::Elevation;
    s.depthGrid = g;
    const Bathymetry e(s, 6.0);
    EXPECT_NEAR(e.SeabedZ_m(110.0, 50.0), 2.0, 1e-6);
    EXPECT_NEAR(e.Depth_m(110.0, 50.0), -1.5, 1e-6);
}

TEST_F(DepthGridTest, MultiChannelOrNonFiniteGridsAreRejected) {
    const fs::path rgb = WriteTiff(2, 2, 3, std::vector<float>(12, 1.0f));
    EXPECT_THROW(DepthGrid::Load(rgb), InputError);
    const fs::path nan = WriteTiff(2, 2, 1, {1.0f, std::nanf(""), 1.0f, 1.0f});
    try {
        DepthGrid::Load(nan);
        ADD_FAILURE() << "a NaN grid loaded";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("column 1, row 0"), std::string::npos) << e.what();
    }
    EXPECT_THROW(DepthGrid::Load(folder_ / "missing.tif"), InputError);
}

}  // namespace
}  // namespace seasense::scene
