// Spray clumps drawn into a channel: the covered area equals the clump's projected disc (by
// geometry, sub-sample clumps by their area), fading with age, and nearer geometry in the
// visibility buffer hides them.
#include "channels/otw/spray_overlay.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace seasense::channels {
namespace {

ChannelCamera NorthCamera() {
    ChannelCamera cam;
    cam.worldFromCamera = scene::PoseFrom(glm::dvec3(0.0, 0.0, 2.0), scene::Attitude{});
    cam.hfov_rad = 60.0 * std::numbers::pi / 180.0;
    cam.width = 320;
    cam.height = 240;
    cam.supersampling = 2;
    return cam;
}

VisibilityBuffer Wall(const ChannelCamera& cam, double distance_m) {
    VisibilityBuffer vis;
    vis.width = cam.SampleWidth();
    vis.height = cam.SampleHeight();
    // Depth is near / view depth (0: sky).
    const float d = distance_m > 0.0 ? float(cam.near_m / distance_m) : 0.0f;
    vis.depth.assign(size_t(vis.width) * size_t(vis.height), d);
    vis.primitive.assign(vis.depth.size(), d > 0.0f ? 0u : kNoPrimitive);
    return vis;
}

// Σ coverage over the image of one clump straight ahead at range y (m).
double Coverage(const scene::SpraySettings& s, double y, double lifeFraction, double wall_m) {
    const ChannelCamera cam = NorthCamera();
    scene::SprayParticle p;
    p.position_m = {0.0, y, 2.0};
    p.lifeFraction = lifeFraction;
    Image image(cam.SampleWidth(), cam.SampleHeight(), 1);
    DrawSprayClumps(
        {p}, s, cam, Wall(cam, wall_m), [](double, float alpha, float* px) { *px += alpha; },
        image);
    double sum = 0.0;
    for (int j = 0; j < image.height; ++j)
        for (int i = 0; i < image.width; ++i) sum += *image.At(i, j);
    return sum;
}

TEST(SprayOverlay, CoveredAreaIsTheProjectedDisc) {
    const ChannelCamera cam = NorthCamera();
    scene::SpraySettings s;
    s.opacity = 0.8;
    const double samplesPerTan = 0.5 * cam.SampleWidth() / std::tan(0.5 * cam.hfov_rad);
    for (const double radius : {0.01, 0.2, 0.5}) {
        s.clumpRadius_m = radius;
        const double y = 20.0;
        const double rs = radius / y * samplesPerTan;  // radius in samples
        // The soft edge (a linear ramp one sample wide about r) adds π/12 sample² to π r².
        const double expected =
            s.opacity * 0.75 * std::numbers::pi * (rs >= 0.5 ? rs * rs + 1.0 / 12.0 : rs * rs);
        EXPECT_NEAR(Coverage(s, y, 0.25, 0.0), expected, 0.03 * expected) << radius;
    }
}

TEST(SprayOverlay, NearerGeometryHidesTheClump) {
    scene::SpraySettings s;
    s.clumpRadius_m = 0.5;
    EXPECT_EQ(Coverage(s, 20.0, 0.0, 10.0), 0.0);  // a wall at 10 m in front of it
    EXPECT_GT(Coverage(s, 20.0, 0.0, 30.0), 1.0);  // the wall behind it
    EXPECT_EQ(Coverage(s, 20.0, 1.0, 0.0), 0.0);   // at the end of its life
}

}  // namespace
}  // namespace seasense::channels
