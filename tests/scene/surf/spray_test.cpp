// Breaking-wave spray: the analytic drag trajectory against a numerical integration of
// dv/dt = g + (w − v)/τ (and its ballistic and terminal limits), the pool bound, statelessness
// (the same set for any thread count; a particle at t + dt is the one at t moved along its
// trajectory) and emission only from breaking water.
#include "scene/surf/spray.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <map>
#include <numbers>

namespace seasense::scene {
namespace {

constexpr double kG = 9.80665;
constexpr double kPi = std::numbers::pi;

// Classical fourth-order Runge-Kutta on (p, v), 1e-4 s steps.
SprayState Integrate(glm::dvec3 p, glm::dvec3 v, const glm::dvec3& w, double tau, double age) {
    const int steps = int(std::ceil(age / 1e-4));
    const double dt = age / steps;
    const auto acc = [&](const glm::dvec3& vel) {
        return glm::dvec3(0.0, 0.0, -kG) + (w - vel) / tau;
    };
    for (int i = 0; i < steps; ++i) {
        const glm::dvec3 k1v = acc(v), k1p = v;
        const glm::dvec3 k2v = acc(v + 0.5 * dt * k1v), k2p = v + 0.5 * dt * k1v;
        const glm::dvec3 k3v = acc(v + 0.5 * dt * k2v), k3p = v + 0.5 * dt * k2v;
        const glm::dvec3 k4v = acc(v + dt * k3v), k4p = v + dt * k3v;
        p += dt / 6.0 * (k1p + 2.0 * k2p + 2.0 * k3p + k4p);
        v += dt / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
    }
    return {p, v};
}

TEST(Spray, TrajectorySolvesGravityAndLinearDrag) {
    const glm::dvec3 p0(3.0, -2.0, 1.0), v0(4.0, 1.0, 3.5), wind(-6.0, 2.0, 0.0);
    for (const double tau : {0.1, 0.41, 2.0}) {
        for (const double age : {0.05, 0.6, 1.7}) {
            const SprayState a = SprayTrajectory(p0, v0, wind, tau, age);
            const SprayState n = Integrate(p0, v0, wind, tau, age);
            EXPECT_NEAR(glm::length(a.position_m - n.position_m), 0.0, 1e-9) << tau << " " << age;
            EXPECT_NEAR(glm::length(a.velocity_mps - n.velocity_mps), 0.0, 1e-9);
        }
    }
    // Without drag (τ → ∞) the ballistic parabola; long after launch the terminal velocity
    // w + g τ (1 mm drops: 4.0 m/s for τ = 0.41 s, Gunn & Kinzer 1949).
    const SprayState b = SprayTrajectory(p0, v0, wind, 1e9, 0.8);
    const glm::dvec3 ballistic = p0 + v0 * 0.8 + glm::dvec3(0.0, 0.0, -0.5 * kG * 0.64);
    EXPECT_NEAR(glm::length(b.position_m - ballistic), 0.0, 1e-6);
    const SprayState t = SprayTrajectory(p0, v0, wind, 0.41, 30.0);
    EXPECT_NEAR(t.velocity_mps.z, -4.02, 0.01);
    EXPECT_NEAR(t.velocity_mps.x, wind.x, 1e-9);
}

// A plane beach (shore along y at x = 0, sea to the east, slope 0.02) and a 1 m, 8 s sea
// spread ±10° about westward.
SurfWaves Beach() {
    SurfSettings s;
    s.intertidal = {0.02, 0.0};
    s.supralittoral = {0.02, 50.0};
    s.sublittoral = {0.02, 400.0};
    s.offshoreSlope = 0.02;
    std::vector<SurfComponent> c;
    const double a = std::sqrt(2.0 * 0.0625 / 12.0);
    for (int j = 0; j < 12; ++j)
        c.push_back({a, 2.0 * kPi / 8.0 * (0.85 + 0.3 * (j + 0.5) / 12.0),
                     1.5 * kPi + (j % 5 - 2) * 0.087, std::fmod(2.39996 * j * j, 2.0 * kPi)});
    return SurfWaves(Bathymetry(s, 30.0), c, 100.0);
}

const glm::dvec3 kEye(60.0, 0.0, 3.0), kWind(-5.0, 1.0, 0.0);

TEST(Spray, ParticlesComeFromBreakingWaterAndFlyTheirTrajectories) {
    const SurfWaves w = Beach();
    SpraySettings set;
    set.maxParticles = 1000000;
    const SprayField field(w, set, kWind);
    // The emission gate is sound: no breaking deeper than it, at any point or instant sampled.
    const double hMax = field.MaxBreakingDepth_m();
    ASSERT_GT(hMax, 1.0);
    for (double x = 0.0; x < 600.0; x += 0.5) {
        const double h = 0.02 * x;
        if (h <= hMax) continue;
        for (int i = 0; i < 50; ++i) {
            SurfPointInfo info;
            w.Terms(x, 7.0 * i, 3.1 * i, &info);
            ASSERT_EQ(info.breaking.intensity, 0.0) << x;
        }
    }
    const double t = 100.0, dt = 0.1;
    SprayStats stats;
    const std::vector<SprayParticle> now = field.Particles(kEye, t, &stats);
    const std::vector<SprayParticle> later = field.Particles(kEye, t + dt);
    ASSERT_GT(now.size(), 100u);
    EXPECT_GT(stats.bursts, 10u);
    std::map<uint64_t, SprayParticle> byId;
    for (const SprayParticle& p : now) {
        // Launched from the surf zone (x < the deepest breaking), within the radius plus the
        // flight (at most ~ 8 m/s × lifetime).
        EXPECT_LT(p.position_m.x, hMax / 0.02 + 15.0);
        EXPECT_LT(glm::length(glm::dvec2(p.position_m - kEye)), set.radius_m + 15.0);
        EXPECT_GE(p.age_s, 0.0);
        EXPECT_LE(p.age_s, set.lifetime_s);
        byId[p.id] = p;
    }
    int followed = 0;
    for (const SprayParticle& q : later) {
        const auto it = byId.find(q.id);
        if (it == byId.end()) continue;
        const SprayState moved = SprayTrajectory(it->second.position_m, it->second.velocity_mps,
                                                 kWind, set.dragTime_s, dt);
        EXPECT_NEAR(glm::length(moved.position_m - q.position_m), 0.0, 1e-9);
        EXPECT_NEAR(q.age_s - it->second.age_s, dt, 1e-9);
        ++followed;
    }
    EXPECT_GT(followed, 50);
}

TEST(Spray, PoolIsBoundedToTheNearestAndIndependentOfThreads) {
    const SurfWaves w = Beach();
    SpraySettings set;
    set.maxParticles = 1000000;
    const std::vector<SprayParticle> all = SprayField(w, set, kWind).Particles(kEye, 57.3);
    ASSERT_GT(all.size(), 300u);
    set.maxParticles = 200;
    SprayStats stats;
    const SprayField bounded(w, set, kWind);
    std::vector<SprayParticle> one, two;
    tbb::task_arena(1).execute([&] { one = bounded.Particles(kEye, 57.3, &stats); });
    tbb::task_arena(2).execute([&] { two = bounded.Particles(kEye, 57.3); });
    ASSERT_EQ(one.size(), 200u);
    EXPECT_EQ(stats.alive, all.size());
    ASSERT_EQ(two.size(), one.size());
    for (size_t i = 0; i < one.size(); ++i) {
        EXPECT_EQ(one[i].id, two[i].id);
        EXPECT_EQ(one[i].position_m, two[i].position_m);
        EXPECT_EQ(one[i].id, all[i].id);  // the nearest 200 of the whole set
    }
    for (size_t i = 1; i < one.size(); ++i)
        EXPECT_LE(glm::length(one[i - 1].position_m - kEye), glm::length(one[i].position_m - kEye));
}

TEST(Spray, NoneWhenDisabledOrCalm) {
    const SurfWaves w = Beach();
    SpraySettings off;
    off.enabled = false;
    EXPECT_TRUE(SprayField(w, off, kWind).Particles(kEye, 10.0).empty());
    SurfSettings s;
    const SurfWaves calm(Bathymetry(s, 30.0), {{0.01, 2.0 * kPi / 8.0, 1.5 * kPi, 0.0}}, 100.0);
    SpraySettings on;
    // 2 cm waves break only in the last 2.6 cm of water: a few cells at most, and the emission
    // needs breaking there.
    const std::vector<SprayParticle> p = SprayField(calm, on, kWind).Particles({0, 0, 2}, 10.0);
    for (const SprayParticle& q : p) EXPECT_LT(calm.Bathy().Depth_m(q.position_m.x, 0.0), 0.5);
}

}  // namespace
}  // namespace seasense::scene
