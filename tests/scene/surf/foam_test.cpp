// Tests of surf-zone foam coverage: exponential decay behind the breaker line, streaks, purity.
#include "scene/surf/foam.h"

#include <gtest/gtest.h>

#include <cmath>

namespace seasense::scene {
namespace {

SurfPointInfo Broken(double age_s) {
    SurfPointInfo info;
    info.breaking.broken = true;
    info.breaking.timeSinceBreaking_s = age_s;
    info.direction_rad = 1.3;
    info.groupSpeed_mps = 4.0;
    return info;
}

// Along a transect behind the breaker line, where nothing breaks any more, coverage divided by
// the streak pattern is exp(−age / persistence).
TEST(Foam, ResidualDecaysExponentiallyAlongTransect) {
    FoamSettings s;
    s.persistence_s = 6.0;
    int checked = 0;
    for (int i = 0; i <= 40; ++i) {
        const double age = 0.5 * i, x0 = 100.0 + 3.1 * i, y0 = -20.0;
        const SurfPointInfo info = Broken(age);
        const double streaks =
            FoamStreaks(x0, y0, 2.0, info.direction_rad, 0.1 * info.groupSpeed_mps, s);
        const double c = SurfFoamCoverage(info, x0, y0, 2.0, s);
        if (streaks < 1e-3) {
            EXPECT_EQ(c, 0.0);
            continue;
        }
        EXPECT_NEAR(c / streaks, std::exp(-age / 6.0), 1e-12) << "age " << age;
        ++checked;
    }
    EXPECT_GT(checked, 10);
}

TEST(Foam, SeawardOfBreakerLineOnlyActiveBreaking) {
    FoamSettings s;
    SurfPointInfo info;
    info.breaking.broken = false;
    info.breaking.timeSinceBreaking_s = -3.0;
    info.breaking.intensity = 0.0;
    EXPECT_EQ(SurfFoamCoverage(info, 1.0, 2.0, 0.0, s), 0.0);
    info.breaking.intensity = 0.4;  // breaking right now: the dissipated fraction shows
    EXPECT_DOUBLE_EQ(SurfFoamCoverage(info, 1.0, 2.0, 0.0, s), 0.4);
}

// The streaks break the foam into patches with gaps: over a large area both full foam and gaps
// occur, and the pattern is a pure function of (position, time, seed).
TEST(Foam, StreaksHaveGapsAndPatchesAndAreDeterministic) {
    FoamSettings s;
    int gaps = 0, full = 0, n = 0;
    for (int i = 0; i < 100; ++i)
        for (int j = 0; j < 100; ++j, ++n) {
            const double v = FoamStreaks(0.7 * i, 0.7 * j, 1.0, 0.3, 0.5, s);
            ASSERT_GE(v, 0.0);
            ASSERT_LE(v, 1.0);
            gaps += v == 0.0;
            full += v == 1.0;
            EXPECT_EQ(v, FoamStreaks(0.7 * i, 0.7 * j, 1.0, 0.3, 0.5, s));
        }
    EXPECT_GT(gaps, n / 20);
    EXPECT_GT(full, n / 20);
    // Advected: the pattern at time t + Δt is the pattern at t shifted by drift · Δt along the
    // direction of travel (azimuth 0.3 rad from north).
    const double dx = 0.5 * 2.0 * std::sin(0.3), dy = 0.5 * 2.0 * std::cos(0.3);
    EXPECT_NEAR(FoamStreaks(10.0 + dx, 7.0 + dy, 3.0, 0.3, 0.5, s),
                FoamStreaks(10.0, 7.0, 1.0, 0.3, 0.5, s), 1e-9);
    FoamSettings other = s;
    other.seed = 2;
    int differ = 0;
    for (int i = 0; i < 50; ++i)
        differ += FoamStreaks(1.3 * i, 0.0, 0.0, 0.0, 0.0, s) !=
                  FoamStreaks(1.3 * i, 0.0, 0.0, 0.0, 0.0, other);
    EXPECT_GT(differ, 25);
}

TEST(Foam, WhitecapsFromJacobian) {
    EXPECT_EQ(WhitecapCoverage(1.0, 0.3), 0.0);
    EXPECT_EQ(WhitecapCoverage(0.3, 0.3), 0.0);
    EXPECT_DOUBLE_EQ(WhitecapCoverage(0.15, 0.3), 0.5);
    EXPECT_EQ(WhitecapCoverage(-0.2, 0.3), 1.0);
}

}  // namespace
}  // namespace seasense::scene
