// Seed 003's sandbar rule for a random sea: depth over the bar > 2 Hb: crests peak, no breaking;
// 1–2 Hb: some waves break on the bar, the rest shoreward; < Hb: breaking on the seaward side.
// Hb, the significant breaker height of the plane beach, is computed here independently: energy
// flux conservation of each component (linear theory) until Hs = 4σ reaches McCowan's 0.78 h.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "scene/surf/surf_waves.h"
#include "tests/scene/surf/linear_wave_theory.h"

namespace seasense::scene {
namespace {

using linear_waves::kG;
constexpr double kPi = std::numbers::pi;
constexpr double kGamma = 0.78;  // McCowan (1894)
constexpr double kSlope = 0.02;  // plane beach
constexpr double kOceanDepth_m = 30.0;
constexpr double kPeriod_s = 8.0;
constexpr int kComponents = 12;
constexpr double kHs0_m = 1.0;  // deep-water significant height 4σ
constexpr double kBarDistance_m = 250.0, kBarWidth_m = 30.0, kBarSide_m = 30.0;
constexpr double kBarU_m = 150.0, kPlainU_m = 450.0;  // centre of the bar, the bar-less region

using linear_waves::Cg;
using linear_waves::K;

// A narrow-band random sea travelling west (to the shore at x = 0): equal amplitudes, fixed
// incommensurate phases; Σ A²/2 = (Hs0/4)².
std::vector<SurfComponent> Sea() {
    const double a = std::sqrt(2.0 * (kHs0_m / 4.0) * (kHs0_m / 4.0) / kComponents);
    std::vector<SurfComponent> c;
    for (int j = 0; j < kComponents; ++j) {
        const double omega = 2.0 * kPi / kPeriod_s * (0.85 + 0.3 * (j + 0.5) / kComponents);
        c.push_back({a, omega, 1.5 * kPi, std::fmod(2.39996 * j * j + 0.7, 2.0 * kPi)});
    }
    return c;
}

// Shoaled variance of the sea at depth h: each component's energy flux E cg is conserved.
double Variance(double h) {
    double v = 0.0;
    for (const SurfComponent& c : Sea())
        v += 0.5 * c.amplitude_m * c.amplitude_m * Cg(c.omega_radps, kOceanDepth_m) /
             Cg(c.omega_radps, h);
    return v;
}

// Significant breaker height: Hs(h) = γ h, walking shoreward.
double BreakerHeight() {
    double lo = 0.05, hi = 20.0;  // 4σ(h) − γh: positive at lo, negative at hi
    for (int i = 0; i < 100; ++i) {
        const double mid = 0.5 * (lo + hi);
        (4.0 * std::sqrt(Variance(mid)) > kGamma * mid ? lo : hi) = mid;
    }
    return kGamma * 0.5 * (lo + hi);
}

// A plane beach (shore along y at x = 0, sea to the east) with two 300 m regions: a bar with
// its crest crestDepth_m below the still water, then none.
SurfSettings Beach(double crestDepth_m) {
    SurfSettings s;
    s.intertidal = {kSlope, 0.0};
    s.supralittoral = {kSlope, 50.0};
    s.sublittoral = {kSlope, 400.0};
    s.offshoreSlope = kSlope;
    SurfRegionSettings bar, plain;
    bar.width_m = plain.width_m = 300.0;
    bar.sandbar = SandbarSettings{kBarWidth_m, 150.0, crestDepth_m, kBarDistance_m, kBarSide_m};
    s.regions = {bar, plain};
    return s;
}

// Statistics over time at cross-shore points x (every 2 m from 330 m to 2 m) on line y.
struct Profile {
    std::vector<double> x, breaking, rms, maxHeight;  // fraction of instants, σ of η, max 2A
};
Profile Measure(const SurfWaves& w, double y) {
    Profile p;
    constexpr int kTimes = 1500;
    for (double x = 330.0; x > 1.0; x -= 2.0) {
        int broken = 0;
        double sum = 0.0, sum2 = 0.0, maxH = 0.0;
        for (int i = 0; i < kTimes; ++i) {
            SurfPointInfo info;
            const double z = w.Terms(x, y, 3.7 * i, &info).displacement.z;
            broken += info.breaking.intensity > 0.0;
            sum += z, sum2 += z * z;
            maxH = std::max(maxH, 2.0 * info.envelope_m);
        }
        p.x.push_back(x);
        p.breaking.push_back(double(broken) / kTimes);
        p.rms.push_back(std::sqrt(sum2 / kTimes - (sum / kTimes) * (sum / kTimes)));
        p.maxHeight.push_back(maxH);
    }
    return p;
}

double At(const Profile& p, const std::vector<double>& v, double x) {
    size_t best = 0;
    for (size_t i = 0; i < p.x.size(); ++i)
        if (std::abs(p.x[i] - x) < std::abs(p.x[best] - x)) best = i;
    return v[best];
}

const double kSeawardFoot_m = kBarDistance_m + 0.5 * kBarWidth_m + kBarSide_m;
const double kSeawardCrest_m = kBarDistance_m + 0.5 * kBarWidth_m;
const double kLandwardCrest_m = kBarDistance_m - 0.5 * kBarWidth_m;
const double kLandwardFoot_m = kBarDistance_m - 0.5 * kBarWidth_m - kBarSide_m;

TEST(Sandbar, BreakerHeightIsOnThePlaneBeachSeawardOfTheBarsTrough) {
    const double hb = BreakerHeight();
    // A 1 m, 8 s sea breaks in about 1.5 m of water (H_b/H_0 ≈ 1.2 on a mild slope; Komar 1998,
    // Fig. 7-6): the bar at 5 m plane depth stands well seaward of the plane beach's breakers.
    EXPECT_GT(hb, 1.0);
    EXPECT_LT(hb, 1.6);
    EXPECT_GT(kSlope * kLandwardFoot_m, 2.0 * hb / kGamma);
}

TEST(Sandbar, DeeperThanTwiceTheBreakerHeightCrestsPeakWithoutBreaking) {
    const double hb = BreakerHeight(), d = 2.5 * hb;
    const SurfWaves w(Bathymetry(Beach(d), kOceanDepth_m), Sea(), 100.0);
    const Profile bar = Measure(w, kBarU_m), plain = Measure(w, kPlainU_m);
    for (size_t i = 0; i < bar.x.size(); ++i)
        if (bar.x[i] >= kLandwardFoot_m) {
            EXPECT_EQ(bar.breaking[i], 0.0) << bar.x[i];
        }
    // The crests peak: σ over the crest is the shoaled σ at its depth, above the plain's.
    const double ratio = At(bar, bar.rms, kBarDistance_m) / At(plain, plain.rms, kBarDistance_m);
    const double expected = std::sqrt(Variance(d) / Variance(kSlope * kBarDistance_m));
    std::printf("Hb %.3f m, bar at %.3f m: σ ratio over the crest %.3f (energy flux %.3f)\n", hb, d,
                ratio, expected);
    EXPECT_GT(expected, 1.05);
    EXPECT_NEAR(ratio, expected, 0.05 * expected);
    // The waves still break on the beach, shoreward.
    EXPECT_GT(*std::max_element(bar.breaking.begin(), bar.breaking.end()), 0.2);
}

TEST(Sandbar, BetweenOneAndTwoBreakerHeightsSomeBreakOnTheBarTheRestShoreward) {
    const double hb = BreakerHeight(), d = 1.5 * hb;
    const SurfWaves w(Bathymetry(Beach(d), kOceanDepth_m), Sea(), 100.0);
    const Profile bar = Measure(w, kBarU_m);
    double onBar = 0.0, seaward = 0.0, shoreward = 0.0;
    for (size_t i = 0; i < bar.x.size(); ++i) {
        if (bar.x[i] > kSeawardFoot_m) seaward = std::max(seaward, bar.breaking[i]);
        if (bar.x[i] >= kLandwardCrest_m && bar.x[i] <= kSeawardCrest_m)
            onBar = std::max(onBar, bar.breaking[i]);
        if (bar.x[i] < kLandwardFoot_m) shoreward = std::max(shoreward, bar.breaking[i]);
    }
    std::printf("bar at %.3f m: breaking seaward %.3f, on the bar %.3f, shoreward %.3f\n", d,
                seaward, onBar, shoreward);
    EXPECT_EQ(seaward, 0.0);
    EXPECT_GT(onBar, 0.01);  // some waves break on the bar ...
    EXPECT_LT(onBar, 0.5);   // ... not most
    EXPECT_GT(shoreward, 0.2);
}

TEST(Sandbar, ShallowerThanTheBreakerHeightWavesBreakOnItsSeawardSide) {
    const double hb = BreakerHeight(), d = 0.7 * hb;
    const SurfWaves w(Bathymetry(Beach(d), kOceanDepth_m), Sea(), 100.0);
    const Profile bar = Measure(w, kBarU_m);
    // Breaking begins on the seaward flank, before the crest ...
    double onset = -1.0;
    for (size_t i = 0; i < bar.x.size() && onset < 0.0; ++i)
        if (bar.breaking[i] >= 0.01) onset = bar.x[i];
    std::printf(
        "bar at %.3f m: breaking onset at x = %.1f m (crest %.1f-%.1f m), %.3f at its edge\n", d,
        onset, kLandwardCrest_m, kSeawardCrest_m, At(bar, bar.breaking, kSeawardCrest_m));
    EXPECT_GT(onset, kSeawardCrest_m);
    EXPECT_LT(onset, kSeawardFoot_m);
    EXPECT_GT(At(bar, bar.breaking, kSeawardCrest_m), 0.3);
    // ... and the trough behind it gets only the energy flux the crest lets through: heights at
    // most γ d shoaled (by energy flux) from the crest depth to the trough's, and no breaking.
    const double omega = 2.0 * kPi / kPeriod_s;
    for (const double x : {kLandwardFoot_m - 10.0, kLandwardFoot_m - 40.0}) {
        const double h = kSlope * x;
        const double bound = kGamma * d * std::sqrt(Cg(omega, d) / Cg(omega, h));
        EXPECT_LE(At(bar, bar.maxHeight, x), 1.03 * bound) << x;
        EXPECT_EQ(At(bar, bar.breaking, x), 0.0) << x;
    }
}

}  // namespace
}  // namespace seasense::scene
