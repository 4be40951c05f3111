// The world's clock and motion: constant-velocity entities and eyepoint, wave riding against
// the sea surface's own height and slope, the ephemeris sun, and published-state composition.
#include "scene/world/world.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "scene/core/error.h"
#include "scene/scenario/scenario_loader.h"
#include "scene/sky/ephemeris.h"

namespace seasense::scene {
namespace {

Scenario BaseScenario() {
    Scenario sc;
    sc.world.latitude_deg = 33.2;
    sc.world.longitude_deg = -117.4;
    sc.world.start = *ParseIso8601("2026-06-22T02:35:00Z");
    sc.world.frameRate_hz = 25.0;
    sc.world.timeScale = 4.0;
    GerstnerWaveSettings w;
    w.direction_rad = 0.3;
    w.wavelength_m = 300.0;  // long against the 14 m boat: the hull follows the slope
    w.amplitude_m = 1.5;
    w.steepness = 0.0;
    sc.environment.ocean.waves.push_back(w);
    sc.materials = {{"grey", glm::dvec3(0.5)}};
    EntitySettings boat;
    boat.name = "boat";
    boat.model = std::string(SEASENSE_SOURCE_DIR) + "/configs/models/patrol_boat.obj";
    boat.position_m = {10.0, 50.0, 0.0};
    boat.attitude.heading_rad = 1.0;
    boat.speed_mps = 7.0;
    boat.material = "grey";
    sc.entities.push_back(boat);
    sc.eyepoint.position_m = {0.0, 0.0, 2.0};
    sc.eyepoint.attitude.heading_rad = -0.5;
    sc.eyepoint.speed_mps = 3.0;
    return sc;
}

// The observer the world uses for BaseScenario: its place and the eyepoint's height.
Observer BaseObserver() {
    Observer obs;
    obs.latitude_deg = 33.2;
    obs.longitude_deg = -117.4;
    obs.height_m = 2.0;
    return obs;
}

TEST(World, EntitiesAndEyepointMoveAtConstantVelocityAlongTheirHeading) {
    const World world(BaseScenario());
    const FrameState f = world.Advance(50);
    const double t = 50 * 4.0 / 25.0;  // frame · time_scale / frame_rate
    EXPECT_DOUBLE_EQ(f.time_s, t);
    EXPECT_EQ(f.utc, BaseScenario().world.start.PlusSeconds(t));
    const glm::dvec3 boat = f.entityPoses[0].position_m;
    EXPECT_NEAR(boat.x, 10.0 + 7.0 * t * std::sin(1.0), 1e-9);
    EXPECT_NEAR(boat.y, 50.0 + 7.0 * t * std::cos(1.0), 1e-9);
    EXPECT_NEAR(boat.z, 0.0, 1e-12);
    EXPECT_NEAR(f.eyepoint.position_m.x, 3.0 * t * std::sin(-0.5), 1e-9);
    EXPECT_NEAR(f.eyepoint.position_m.y, 3.0 * t * std::cos(-0.5), 1e-9);
    EXPECT_NEAR(f.eyepoint.position_m.z, 2.0, 1e-12);
    // Body y (forward) points along the heading.
    const glm::dvec3 fwd = f.entityPoses[0].worldFromBody[1];
    EXPECT_NEAR(fwd.x, std::sin(1.0), 1e-12);
    EXPECT_NEAR(fwd.y, std::cos(1.0), 1e-12);
}

TEST(World, RidingBoatHeavesPitchesAndRollsWithTheSurface) {
    Scenario sc = BaseScenario();
    sc.entities[0].rideWaves = true;
    const World world(sc);
    for (int64_t frame : {0, 7, 31, 90}) {
        const FrameState f = world.Advance(frame);
        const Pose& pose = f.entityPoses[0];
        const glm::dvec3 o = pose.position_m;
        // Heave: the origin sits on the drawn surface.
        EXPECT_NEAR(o.z, world.Ocean().HeightAt(o.x, o.y, f.time_s), 1e-9) << frame;
        // Pitch and roll: the hull's axes follow the surface slope, measured here by a small
        // central difference of the surface height along them (λ = 300 m ≫ 14 m hull).
        const auto slope = [&](glm::dvec3 dir) {
            dir.z = 0.0;
            dir = glm::normalize(dir);
            const double e = 0.01;
            return (world.Ocean().HeightAt(o.x + e * dir.x, o.y + e * dir.y, f.time_s) -
                    world.Ocean().HeightAt(o.x - e * dir.x, o.y - e * dir.y, f.time_s)) /
                   (2 * e);
        };
        const glm::dvec3 fwd = pose.worldFromBody[1], right = pose.worldFromBody[0];
        const double pitchSlope = fwd.z / std::hypot(fwd.x, fwd.y);
        const double rollSlope = right.z / std::hypot(right.x, right.y);
        const double kA = 2 * M_PI / 300.0 * 1.5;  // maximum slope of the wave
        EXPECT_NEAR(pitchSlope, slope(fwd), 0.02 * kA) << frame;
        EXPECT_NEAR(rollSlope, slope(right), 0.02 * kA) << frame;
    }
}

TEST(World, EphemerisSunFollowsTheClockAndSets) {
    Scenario sc = BaseScenario();
    sc.environment.sun.fromEphemeris = true;
    sc.world.timeScale = 60.0;  // a minute per frame at 1 Hz
    sc.world.frameRate_hz = 1.0;
    const World world(sc);
    const Observer obs = BaseObserver();
    double previous = M_PI;
    for (int64_t frame = 0; frame < 40; frame += 3) {
        const FrameState f = world.Advance(frame);
        const CelestialPosition p = SunPosition(f.utc, obs);
        EXPECT_NEAR(f.sun.elevation_rad, p.altitude_rad, 1e-12);
        EXPECT_NEAR(glm::length(f.sun.direction - p.direction), 0.0, 1e-12);
        EXPECT_LT(f.sun.elevation_rad, previous);  // evening: the sun sinks
        previous = f.sun.elevation_rad;
        // No direct sun once the upper limb (0.27°) is below the apparent horizon.
        EXPECT_EQ(f.sun.illuminance_lux > 0.0, p.altitude_rad > -0.2666 * M_PI / 180) << frame;
    }
}

TEST(World, MoonFollowsTheEphemerisWithItsPhaseAndLight) {
    // 2026-06-22 02:35 UTC at 33.2° N: the moon near first quarter (new moon 2026-06-15), high
    // in the south at sunset, setting about five hours later.
    Scenario sc = BaseScenario();
    sc.world.timeScale = 600.0;  // ten minutes per frame at 1 Hz
    sc.world.frameRate_hz = 1.0;
    const World world(sc);
    const Observer obs = BaseObserver();
    bool sawUp = false, sawDown = false;
    for (int64_t frame = 0; frame < 40; frame += 2) {
        const FrameState f = world.Advance(frame);
        const CelestialPosition m = MoonPosition(f.utc, obs);
        EXPECT_NEAR(f.moon.elevation_rad, m.altitude_rad, 1e-12);
        EXPECT_NEAR(glm::length(f.moon.direction - m.direction), 0.0, 1e-12);
        EXPECT_NEAR(f.moon.distance_m, m.distance_m, 1.0);
        const double k = MoonPhase(f.utc, obs).illuminatedFraction;
        EXPECT_NEAR((1.0 + std::cos(f.moon.phaseAngle_rad)) / 2.0, k, 1e-9);
        EXPECT_GT(k, 0.2);  // a week after new moon, waxing over the 6.5 h
        EXPECT_LT(k, 0.7);
        // Moonlight only while the disc is up; a crescent high up gives ~0.01–0.05 lx.
        EXPECT_EQ(f.moon.illuminance_lux > 0.0, m.altitude_rad > -0.259 * M_PI / 180) << frame;
        EXPECT_LT(f.moon.illuminance_lux, 0.1);
        (f.moon.illuminance_lux > 0.0 ? sawUp : sawDown) = true;
        // The composed scene state carries the same moon.
        EXPECT_EQ(world.Compose(f).moon.direction, f.moon.direction);
    }
    EXPECT_TRUE(sawUp);
    EXPECT_TRUE(sawDown);  // it sets during the 6.5 h
}

TEST(World, EveryShippedScenarioLoadsAndComposesItsFirstFrame) {
    // The scenarios in configs/ are what users start from: each must load, build its world
    // and compose a frame (materials.yaml is the material table, not a scenario).
    int scenarios = 0;
    for (const auto& entry : std::filesystem::directory_iterator(
             std::filesystem::path(SEASENSE_SOURCE_DIR) / "configs")) {
        if (entry.path().extension() != ".yaml" || entry.path().filename() == "materials.yaml")
            continue;
        SCOPED_TRACE(entry.path().string());
        const Scenario sc = LoadScenario(entry.path());
        const World world(sc);
        const SceneState state = world.State(0);
        EXPECT_TRUE(std::isfinite(state.sun.elevation_rad));
        EXPECT_FALSE(sc.channels.empty());
        ++scenarios;
    }
    EXPECT_GE(scenarios, 7);
}

TEST(World, ComposeRejectsAStateOfAnotherScenario) {
    const World world(BaseScenario());
    FrameState f = world.Advance(3);
    const SceneState s = world.Compose(f);
    ASSERT_EQ(s.entities.size(), 1u);
    EXPECT_EQ(s.entities[0].pose.position_m, f.entityPoses[0].position_m);
    f.entityPoses.push_back(f.entityPoses[0]);
    EXPECT_THROW(world.Compose(f), InputError);
}

}  // namespace
}  // namespace seasense::scene
