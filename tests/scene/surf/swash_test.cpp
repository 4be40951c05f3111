// Swash run-up: the waterline measured on the drawn surface (where the water meets the sand)
// against Stockdon et al. (2006): setup η̄ = 0.35 β √(H0 L0), significant swash height
// S = √(H0 L0 (0.563 β² + 0.004)), R2 = 1.1 (η̄ + S/2); it moves with the wave groups (surf
// beat) and runs farther into the cusp bays than onto the horns.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <numbers>
#include <vector>

#include "scene/surf/surf_waves.h"

namespace seasense::scene {
namespace {

constexpr double kG = 9.80665;
constexpr double kPi = std::numbers::pi;
constexpr double kBeta = 0.05, kPeriod_s = 8.0, kH0_m = 1.0;
constexpr double kCusp_m = 40.0, kCuspAmplitude = 0.5;

// 13 components about the peak (the middle one largest), ±8° about westward, Σ A²/2 = (H0/4)².
SurfWaves Beach() {
    SurfSettings s;
    s.intertidal = {kBeta, 0.0};
    s.supralittoral = {kBeta, 50.0};
    s.sublittoral = {kBeta, 400.0};
    s.offshoreSlope = kBeta;
    s.swash.cuspSpacing_m = kCusp_m;
    s.swash.cuspAmplitude = kCuspAmplitude;
    std::vector<SurfComponent> c;
    double sum = 0.0;
    for (int j = 0; j < 13; ++j) {
        const double a = std::exp(-(j - 6) * (j - 6) / 8.0);
        sum += 0.5 * a * a;
        c.push_back({a, 2.0 * kPi / kPeriod_s * (1.0 + 0.025 * (j - 6)),
                     1.5 * kPi + 0.14 * std::sin(1.7 * j), std::fmod(2.39996 * j * j, 2.0 * kPi)});
    }
    for (SurfComponent& x : c) x.amplitude_m *= kH0_m / 4.0 / std::sqrt(sum);
    return SurfWaves(Bathymetry(s, 40.0), c, 100.0);
}

// Elevation above the tide of the waterline at alongshore y, time t: the landward end of the
// water, by bisection on "surface above the sand".
double Runup(const SurfWaves& w, double y, double t) {
    const Bathymetry& b = w.Bathy();
    const auto wet = [&](double x) {
        return b.Tide_m() + w.Terms(x, y, t).displacement.z > b.SeabedZ_m(x, y) + 1e-4;
    };
    double lo = -40.0, hi = 15.0;  // dry, wet
    if (wet(lo) || !wet(hi)) return std::nan("");
    for (int i = 0; i < 40; ++i) {
        const double mid = 0.5 * (lo + hi);
        (wet(mid) ? hi : lo) = mid;
    }
    return b.SeabedZ_m(hi, y) - b.Tide_m();
}

struct Stats {
    double mean = 0.0, sigma = 0.0, r2 = 0.0;  // r2: 2 % exceedance
};
Stats Measure(const SurfWaves& w, const std::vector<double>& ys) {
    std::vector<double> r;
    for (const double y : ys)
        for (int i = 0; i < 800; ++i) r.push_back(Runup(w, y, 3.3 * i + 0.1 * y));
    Stats s;
    for (const double v : r) {
        EXPECT_TRUE(std::isfinite(v));
        s.mean += v / r.size();
    }
    for (const double v : r) s.sigma += (v - s.mean) * (v - s.mean) / r.size();
    s.sigma = std::sqrt(s.sigma);
    std::sort(r.begin(), r.end());
    s.r2 = r[size_t(0.98 * r.size())];
    return s;
}

double StockdonSetup() {
    const double l0 = kG * kPeriod_s * kPeriod_s / (2.0 * kPi);
    return 0.35 * kBeta * std::sqrt(kH0_m * l0);
}
double StockdonSwash() {
    const double l0 = kG * kPeriod_s * kPeriod_s / (2.0 * kPi);
    return std::sqrt(kH0_m * l0 * (0.563 * kBeta * kBeta + 0.004));
}

TEST(Swash, RunupFollowsStockdon2006) {
    const SurfWaves w = Beach();
    // Alongshore positions spread over the cusps (their mean square modulation is 1).
    std::vector<double> ys;
    for (int i = 0; i < 16; ++i) ys.push_back(i * kCusp_m / 16.0 + 137.0 * i);
    const Stats s = Measure(w, ys);
    const double eta = StockdonSetup(), S = StockdonSwash(), r2 = 1.1 * (eta + 0.5 * S);
    std::printf("run-up: mean %.3f m (η̄ %.3f), 4σ %.3f m (S %.3f), 2%% %.3f m (R2 %.3f)\n", s.mean,
                eta, 4.0 * s.sigma, S, s.r2, r2);
    EXPECT_NEAR(s.mean, eta, 0.15 * eta);
    EXPECT_NEAR(4.0 * s.sigma, S, 0.15 * S);
    EXPECT_NEAR(s.r2, r2, 0.2 * r2);
}

TEST(Swash, RunsFartherIntoCuspBaysThanOntoHorns) {
    const SurfWaves w = Beach();
    std::vector<double> bays, horns;
    for (int i = 0; i < 8; ++i) {
        bays.push_back(kCusp_m * (3 * i));  // cos 2πu/λ = 1
        horns.push_back(kCusp_m * (3 * i + 0.5));
    }
    const Stats bay = Measure(w, bays), horn = Measure(w, horns);
    EXPECT_NEAR(bay.sigma / horn.sigma, (1.0 + kCuspAmplitude) / (1.0 - kCuspAmplitude), 0.5);
    EXPECT_GT(bay.r2, horn.r2 + 0.1);
}

TEST(Swash, WaterlineMovesWithTheWaveGroups) {
    const SurfWaves w = Beach();
    // Over a few surf-beat periods (2π/Δω = 40 T) the waterline rises and falls by about S.
    double lo = 1e9, hi = -1e9;
    for (int i = 0; i < 400; ++i) {
        const double r = Runup(w, 0.0, 2.0 * i);
        lo = std::min(lo, r), hi = std::max(hi, r);
    }
    EXPECT_GT(hi - lo, 0.5 * StockdonSwash());
    // The published bound on ζ (for surface bounds) holds.
    EXPECT_LE(hi, w.Swash().max_m);
    // No swash: the waterline stays at the still-water line (waves taper to zero height there).
    SurfSettings s = w.Bathy().Settings();
    s.swash.enabled = false;
    const SurfWaves still(Bathymetry(s, 40.0), w.Components(), 100.0);
    for (int i = 0; i < 50; ++i) EXPECT_NEAR(Runup(still, 0.0, 7.0 * i), 0.0, 0.01);
}

// Terms skips Swash_m where SwashReaches says it is +0: there it must be +0 bit for bit at
// every s, u and t (depths from the beach through 2 R2 and beyond, the bound itself, −0 and 0),
// and it must reach just shallower than 2 R2 (a tighter skip, at R2, fails this).
TEST(Swash, ReachesNoDeeperThanTwiceTheRunup) {
    const SurfWaves w = Beach();
    ASSERT_TRUE(w.Swash().active);
    const double edge = 2.0 * w.Swash().runup2_m;
    std::vector<double> depths{0.0, -0.0, edge, std::nextafter(edge, 0.0),
                               std::nextafter(edge, 1e9)};
    for (int i = -200; i <= 400; ++i) depths.push_back(edge * i / 200.0);
    int skipped = 0, reached = 0;
    for (const double h : depths) {
        const bool reaches = w.SwashReaches(h);
        (reaches ? reached : skipped) += 1;
        for (int k = 0; k < 40; ++k) {
            const double s = -30.0 + 3.1 * k, u = 17.0 * k, t = 2.3 * k * k;
            const double zeta = w.Swash_m(s, u, t, h);
            if (!reaches) {
                ASSERT_EQ(std::bit_cast<uint64_t>(zeta), 0u) << h << " " << s;
            }
        }
        if (h > 0.0 && h < edge) {
            EXPECT_TRUE(reaches) << h;
        }
    }
    EXPECT_GT(skipped, 150);
    EXPECT_GT(reached, 300);
    // Inactive: nowhere.
    SurfSettings st = w.Bathy().Settings();
    st.swash.enabled = false;
    const SurfWaves still(Bathymetry(st, 40.0), w.Components(), 100.0);
    for (const double h : depths) EXPECT_FALSE(still.SwashReaches(h));
}

}  // namespace
}  // namespace seasense::scene
