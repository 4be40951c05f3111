// OTW channel geometry against analytic facts: the sea horizon's dip below the horizontal.
#include "channels/otw/otw_channel.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>

#include "scene/ocean/ocean_mesh.h"

namespace seasense::channels {
namespace {

scene::Scenario CalmSeaScenario(double eyeHeight_m, double hfov_deg) {
    scene::Scenario sc;
    sc.world.start = *scene::ParseIso8601("2026-06-21T12:00:00Z");
    sc.environment.sun.elevation_rad = 0.6;
    sc.environment.sun.illuminance_lux = 1e5;
    scene::GerstnerWaveSettings w;
    w.wavelength_m = 20.0;
    w.amplitude_m = 1e-4;  // a mirror-calm sea
    w.steepness = 0.0;
    sc.environment.ocean.waves.push_back(w);
    sc.eyepoint.position_m = {0.0, 0.0, eyeHeight_m};
    scene::ChannelSettings ch;
    ch.name = "test";
    ch.width = 64;
    ch.height = 480;
    ch.hfov_rad = hfov_deg * M_PI / 180.0;
    ch.supersampling = 1;
    ch.shadows = false;
    sc.channels.push_back(ch);
    return sc;
}

TEST(OtwChannel, SeaHorizonDipsByTheGeometricDipAngle) {
    // A spherical sea seen from height h has its horizon acos(R / (R + h)) below the
    // horizontal (no refraction): 0.556° at 300 m, 0.0454° at 2 m.
    for (double h : {300.0, 30.0}) {
        const scene::Scenario sc = CalmSeaScenario(h, 4.0);
        const scene::World world(sc);
        OtwChannel otw(world, sc.channels[0]);
        Image radiance;
        tbb::task_arena arena(2);
        arena.execute([&] { otw.Render(world.State(0), radiance); });
        const VisibilityBuffer& vis = otw.Visibility();
        const ChannelCamera& cam = otw.Camera();
        const double dip = std::acos(scene::kEarthRadius_m / (scene::kEarthRadius_m + h));
        // Row whose centre ray is at elevation −dip: y_ndc = −tan(dip) / tan(vfov/2).
        const double ndcY = -std::tan(dip) / cam.TanHalfV();
        const double expectedRow = (1.0 - ndcY) * 0.5 * cam.SampleHeight() - 0.5;
        const int x = cam.SampleWidth() / 2;
        int firstSea = -1;
        for (int y = 0; y < vis.height; ++y)
            if (vis.primitive[vis.Index(x, y)] != kNoPrimitive) {
                firstSea = y;
                break;
            }
        ASSERT_GE(firstSea, 0);
        EXPECT_NEAR(firstSea, expectedRow, 1.0) << "eye height " << h;
        // Every row below the horizon is sea, every row above is sky.
        for (int y = 0; y < vis.height; ++y)
            EXPECT_EQ(vis.primitive[vis.Index(x, y)] != kNoPrimitive, y >= firstSea) << y;
    }
}

}  // namespace
}  // namespace seasense::channels
