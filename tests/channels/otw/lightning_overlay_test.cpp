// Lightning drawn in the OTW channel: the light the drawn bolt sends to the eye equals the
// exact line-source illuminance of the scene model, and nearer geometry hides it.
#include "channels/otw/lightning_overlay.h"

#include <gtest/gtest.h>

#include <cmath>

#include "channels/otw/celestial.h"

namespace seasense::channels {
namespace {

scene::LightningSettings StormNorth() {
    scene::LightningSettings s;
    scene::StormCellSettings cell;
    cell.center_m = {0.0, 8000.0, 0.0};
    cell.radius_m = 800.0;
    cell.cloudBase_m = 1500.0;
    cell.flashRate_perMin = 30.0;
    s.cells.push_back(cell);
    return s;
}

ChannelCamera NorthCamera() {
    ChannelCamera cam;
    cam.worldFromCamera = scene::PoseFrom(glm::dvec3(0.0, 0.0, 2.0), scene::Attitude{});
    cam.hfov_rad = 60.0 * M_PI / 180.0;
    cam.width = 320;
    cam.height = 240;
    cam.supersampling = 2;
    return cam;
}

VisibilityBuffer Empty(const ChannelCamera& cam, float depth) {
    VisibilityBuffer vis;
    vis.width = cam.SampleWidth();
    vis.height = cam.SampleHeight();
    vis.depth.assign(size_t(vis.width) * size_t(vis.height), depth);
    vis.primitive.assign(vis.depth.size(), depth > 0.0f ? 0u : kNoPrimitive);
    return vis;
}

TEST(LightningOverlay, DrawnBoltSendsTheLineSourceIlluminanceToTheEye) {
    const scene::Lightning lightning(StormNorth(), 7);
    const std::vector<scene::Flash> flashes = lightning.FlashesBetween(0.0, 120.0);
    ASSERT_FALSE(flashes.empty());
    const scene::Flash& flash = flashes.front();
    const double t0 = flash.start_s, t1 = flash.start_s + 0.04;  // one 25 Hz frame
    const ChannelCamera cam = NorthCamera();
    for (double beta : {0.0, 3.912 / 20000.0}) {
        Image radiance(cam.SampleWidth(), cam.SampleHeight(), 3);
        const LitFlashes lit = FindLitFlashes(lightning, t0, t1);
        DrawLightning(cam, Empty(cam, 0.0f), lightning, lit, beta, radiance);
        const glm::dvec3 eye = cam.worldFromCamera.position_m;
        const FlashLight light = FlashLightAt(lightning, lit, eye, beta);
        ASSERT_GE(light.flashes, 1);
        double E = 0.0;
        for (int y = 0; y < radiance.height; ++y)
            for (int x = 0; x < radiance.width; ++x)
                E += radiance.At(x, y)[1] * SampleSolidAngle_sr(cam, x, y);
        // Exact line-source integral (Lightning::MeanIlluminance_lux, extinction at each
        // segment's midpoint) against the drawn elements: within 1 %.
        EXPECT_NEAR(E, light.illuminance_lux, 0.01 * light.illuminance_lux) << beta;
        EXPECT_NEAR(light.illuminance_lux, lightning.SceneIlluminance_lux(eye, t0, t1, beta),
                    1e-9 * light.illuminance_lux);
        EXPECT_GT(light.direction.y, 0.99);  // toward the storm, north
    }
}

TEST(LightningOverlay, NearerGeometryHidesTheBoltAndNoFlashDrawsNothing) {
    const scene::Lightning lightning(StormNorth(), 7);
    const scene::Flash flash = lightning.FlashesBetween(0.0, 120.0).front();
    const ChannelCamera cam = NorthCamera();
    // A wall 100 m in front of the camera everywhere: depth = near / 100 m.
    Image radiance(cam.SampleWidth(), cam.SampleHeight(), 3);
    DrawLightning(cam, Empty(cam, float(cam.near_m / 100.0)), lightning,
                  FindLitFlashes(lightning, flash.start_s, flash.start_s + 0.04), 0.0, radiance);
    for (float v : radiance.pixels) EXPECT_EQ(v, 0.0f);
    // A frame in which no flash is lit draws nothing and sheds no light.
    double quiet = 0.0;
    while (!lightning.FlashesBetween(quiet, quiet + 0.04).empty()) quiet += 0.04;
    Image dark(cam.SampleWidth(), cam.SampleHeight(), 3);
    const LitFlashes unlit = FindLitFlashes(lightning, quiet, quiet + 0.04);
    DrawLightning(cam, Empty(cam, 0.0f), lightning, unlit, 0.0, dark);
    const FlashLight none = FlashLightAt(lightning, unlit, cam.worldFromCamera.position_m, 0.0);
    EXPECT_EQ(none.flashes, 0);
    EXPECT_EQ(none.illuminance_lux, 0.0);
    for (float v : dark.pixels) EXPECT_EQ(v, 0.0f);
}

}  // namespace
}  // namespace seasense::channels
