// Surf waves against linear wave theory computed here independently: phase speed at 2 m depth,
// shoaling by energy-flux conservation and Green's law, Snell refraction, McCowan breaking onset;
// the surface never below the seabed over 1000 frames, and deep water untouched.
#include "scene/surf/surf_waves.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <random>

#include "scene/ocean/ocean_surface.h"
#include "tests/scene/surf/linear_wave_theory.h"

namespace seasense::scene {
namespace {

using linear_waves::kG;
constexpr double kPi = std::numbers::pi;

using linear_waves::Cg;
using linear_waves::K;

// Shoreline running north at x = 0 (sea to the east), all zones at one slope, or a flat shelf.
SurfSettings Beach(double slope) {
    SurfSettings s;
    s.lowTide_m = -1.0;
    s.highTide_m = 1.0;
    s.intertidal = {slope, 0.0};
    s.supralittoral = {slope, 50.0};
    s.sublittoral = {slope, 400.0};
    s.offshoreSlope = slope;
    return s;
}

SurfComponent Wave(double amplitude, double period, double direction_deg) {
    return {amplitude, 2.0 * kPi / period, direction_deg * kPi / 180.0, 0.3};
}

// Height (max − min of η) at rest point (x, 0) over one period, 200 samples.
double Height(const SurfWaves& w, double x, double period, double y = 0.0) {
    double lo = 1e9, hi = -1e9;
    for (int i = 0; i < 200; ++i) {
        const double z = w.Terms(x, y, period * i / 200.0).displacement.z;
        lo = std::min(lo, z), hi = std::max(hi, z);
    }
    return hi - lo;
}

// x of the beach (slope, still-water line at 0, tide 0) where the depth is h.
double XAtDepth(double slope, double h) { return h / slope; }

TEST(SurfWaves, PhaseSpeedAtTwoMetresFollowsFiniteDepthDispersion) {
    SurfSettings s = Beach(0.05);
    s.lowTide_m = -2.0;  // a flat shelf 2 m deep from x = 40 m out to 2040 m
    s.sublittoral = {0.0, 2000.0};
    const Bathymetry b(s, 10.0);
    const double period = 8.0, omega = 2.0 * kPi / period;
    const SurfWaves w(b, {Wave(0.05, period, 270.0)}, 100.0);  // travelling west, to the shore
    // A zero up-crossing of η along x near x = 600 at t and t + dt; the crest pattern moves west.
    auto crossing = [&](double t) {
        double x = 600.0, prev = w.Terms(x, 0.0, t).displacement.z;
        for (; x > 500.0; x -= 0.01) {
            const double z = w.Terms(x - 0.01, 0.0, t).displacement.z;
            if (prev < 0.0 && z >= 0.0) return x - 0.01 * prev / (prev - z);
            prev = z;
        }
        return std::nan("");
    };
    const double dt = 0.5;
    const double c = (crossing(0.0) - crossing(dt)) / dt;
    const double k = K(omega, 2.0);
    EXPECT_NEAR(c, std::sqrt(kG / k * std::tanh(k * 2.0)), 0.01 * c);
}

TEST(SurfWaves, ShoalingConservesEnergyFluxAndFollowsGreensLaw) {
    const double slope = 0.02, period = 10.0, omega = 2.0 * kPi / period, a0 = 0.03;
    const Bathymetry b(Beach(slope), 30.0);
    const SurfWaves w(b, {Wave(a0, period, 270.0)}, 156.0);
    const double cg0 = Cg(omega, 30.0);
    for (const double h : {12.0, 8.0, 4.0, 2.0, 1.0}) {
        const double expected = 2.0 * a0 * std::sqrt(cg0 / Cg(omega, h));
        EXPECT_NEAR(Height(w, XAtDepth(slope, h), period), expected, 0.03 * expected) << h;
    }
    // Green's law in shallow water: H ∝ h^(−1/4).
    const double h1 = Height(w, XAtDepth(slope, 0.8), period);
    const double h2 = Height(w, XAtDepth(slope, 0.4), period);
    EXPECT_NEAR(h2 / h1, std::pow(0.5, -0.25), 0.03 * std::pow(0.5, -0.25));
}

TEST(SurfWaves, RefractionFollowsSnellsLaw) {
    const double slope = 0.02, period = 9.0, omega = 2.0 * kPi / period;
    const Bathymetry b(Beach(slope), 40.0);
    // 35° off the shore normal (travelling west-south-west).
    const SurfWaves w(b, {Wave(0.05, period, 270.0 - 35.0)}, 126.0);
    const double c0 = omega / K(omega, 40.0);
    for (const double h : {10.0, 5.0, 2.0}) {
        SurfPointInfo info;
        w.Terms(XAtDepth(slope, h), 0.0, 0.0, &info);
        const double c = omega / K(omega, h);
        const double theta = std::asin(std::sin(35.0 * kPi / 180.0) * c / c0);
        // Direction of travel from north: 270° − θ for a wave turned θ off the westward normal.
        const double expected = 270.0 - theta * 180.0 / kPi;
        EXPECT_NEAR(info.direction_rad * 180.0 / kPi, expected, 0.5) << h;
    }
}

TEST(SurfWaves, BreakingStartsWhereHeightReachesMcCowansIndex) {
    const double slope = 0.02, period = 8.0;
    const Bathymetry b(Beach(slope), 30.0);
    const SurfWaves w(b, {Wave(0.5, period, 270.0)}, 100.0);
    // Walk shoreward until the breaking intensity first rises; the unbroken height there is
    // the surface's height just seaward of that point.
    double xBreak = -1.0;
    for (double x = 600.0; x > 1.0; x -= 0.25) {
        SurfPointInfo info;
        w.Terms(x, 0.0, 0.0, &info);
        if (info.breaking.intensity > 0.0) {
            xBreak = x + 0.25;
            break;
        }
    }
    ASSERT_GT(xBreak, 0.0);
    const double h = slope * xBreak;
    EXPECT_NEAR(Height(w, xBreak, period) / h, 0.78, 0.05);
    // Shoreward of the break the height is saturated at γ h and tapers to zero with the depth.
    for (const double hs : {1.0, 0.5, 0.1, 0.02})
        EXPECT_NEAR(Height(w, XAtDepth(slope, hs), period), 0.78 * hs, 0.03 * 0.78 * hs) << hs;
}

OceanSettings SpectralBeach(bool surf) {
    OceanSettings o;
    o.depth_m = 80.0;
    SpectralOceanSettings sp;
    sp.sea.spectrum.windSpeed_mps = 10.0;
    sp.sea.spectrum.windDirection_rad = 250.0 * kPi / 180.0;
    sp.fft.gridSize = 64;
    sp.fft.seed = 7;
    o.spectral = sp;
    if (surf) {
        SurfSettings s = Beach(0.03);
        s.tide_m = 0.0;
        SurfRegionSettings r;
        r.width_m = 300.0;
        r.sandbar = SandbarSettings{20.0, 150.0, 1.0, 80.0, 15.0};
        s.regions = {r};
        o.surf = s;
    }
    return o;
}

TEST(SurfWaves, SurfaceNeverBelowTheSeabedAndTapersToZeroDepth) {
    const OceanSurface sea(SpectralBeach(true));
    ASSERT_NE(sea.Surf(), nullptr);
    const Bathymetry& b = sea.Surf()->Bathy();
    double worst = 1e9;
    for (int f = 0; f < 1000; ++f) {
        const auto frame = sea.At(f / 30.0);
        for (double x = -20.0; x < 400.0; x += 2.1) {
            for (const double y : {0.0, 150.0}) {
                const SurfaceTerms t = frame->Terms(x, y);
                const double zBed = b.SeabedZ_m(x + t.displacement.x, y + t.displacement.y);
                worst = std::min(worst, t.displacement.z - zBed);
                const double h = b.Depth_m(x, y);
                if (h > 0.0 && h < 0.2) {  // crests capped at γ h / 2 about the swash level
                    const ShorePoint p = b.Frame().ShoreFromWorld(x, y);
                    const double swash = sea.Surf()->Swash_m(p.s_m, p.u_m, f / 30.0, h);
                    if (t.displacement.z > zBed + 1e-9) {  // not lying on the seabed (run-down)
                        EXPECT_LE(std::abs(t.displacement.z - swash), 0.39 * h + 1e-9) << x;
                    }
                }
            }
        }
    }
    EXPECT_GE(worst, -1e-9);
}

// The height and reach bounds used to cull the sea near the eye hold at every point of the disc
// they are taken over (deep water, over the bar, in the surf, on the beach), over many frames;
// and near an eye in deep water they are far below the whole surface's bound (beach included).
TEST(SurfWaves, BoundsNearAPointHoldOverTheWholeDisc) {
    const OceanSurface sea(SpectralBeach(true));
    ASSERT_NE(sea.Surf(), nullptr);
    for (int f = 0; f < 60; ++f) {
        const auto frame = sea.At(0.77 * f);
        for (const double cx : {-10.0, 40.0, 100.0, 160.0, 300.0, 900.0})
            for (const double r : {0.0, 10.0, 60.0}) {
                const SurfaceBounds b = frame->BoundsNear(cx, 150.0, r);
                EXPECT_LE(b.height_m, frame->MaxHeight_m() + 1e-12);
                EXPECT_LE(b.horizontal_m, frame->MaxHorizontal_m() + 1e-12);
                for (int i = 0; i <= 12; ++i)
                    for (int j = 0; j < (i == 0 ? 1 : 36); ++j) {
                        const double rho = r * i / 12.0, a = 2.0 * kPi * j / 36.0;
                        const double x = cx + rho * std::cos(a), y = 150.0 + rho * std::sin(a);
                        const SurfaceTerms t = frame->Terms(x, y);
                        EXPECT_LE(t.displacement.z, b.height_m + 1e-9) << cx << " " << r;
                        EXPECT_LE(std::hypot(t.displacement.x, t.displacement.y),
                                  b.horizontal_m + 1e-9)
                            << cx << " " << r;
                    }
            }
    }
    // 3 km out the seabed has reached the ocean floor, 80 m down, deeper than any fade: the bound
    // there is exactly the bound of the same sea without a surf zone.
    const OceanSurface open(SpectralBeach(false));
    ASSERT_LT(sea.Surf()->FadeDeep_m(), sea.Surf()->Bathy().Depth_m(2000.0, 150.0));
    const SurfaceBounds deep = sea.At(0.0)->BoundsNear(3000.0, 150.0, 10.0);
    EXPECT_EQ(deep.height_m, open.At(0.0)->MaxHeight_m());
    EXPECT_EQ(deep.horizontal_m, open.At(0.0)->MaxHorizontal_m());
}

// The table of a frame's depth-interval bounds gives BoundAtDepths bit for bit for any
// minimum depth: negative, zero, on and between the depth samples, past the deepest fade.
TEST(SurfWaves, BoundTableEqualsTheIntervalLoop) {
    const OceanSurface sea(SpectralBeach(true));
    const SurfWaves& surf = *sea.Surf();
    const std::vector<SurfWaves::Bound> cascades = {{0.8, 0.6}, {0.3, 0.25}};
    const SurfWaves::Bound gerstner{0.45, 0.2};
    const SurfWaves::BoundTable table = surf.MakeBoundTable(cascades, gerstner);
    std::vector<double> depths = {-std::numeric_limits<double>::infinity(),
                                  -5.0,
                                  0.0,
                                  surf.FadeDeep_m(),
                                  2.0 * surf.FadeDeep_m(),
                                  1e6};
    for (int k = 0; k <= 4000; ++k) depths.push_back(1.1 * surf.FadeDeep_m() * k / 4000.0);
    for (int k = 0; k <= 400; ++k) depths.push_back(0.25 * k);  // on round depths
    for (double d : depths) {
        const SurfWaves::Bound a = surf.BoundAtDepths(d, cascades, gerstner);
        const SurfWaves::Bound b = surf.BoundAtDepths(d, table);
        ASSERT_EQ(a.height_m, b.height_m) << d;
        ASSERT_EQ(a.horizontal_m, b.horizontal_m) << d;
    }
}

// A negative (signed) Gerstner bound is weighted in each depth range by the smallest Gerstner
// weight of its depths (the deep weights grow with depth): the bound holds at every depth of
// [minDepth, maxDepth], and equals −w(minDepth) where no swash reaches.
TEST(SurfWaves, SignedGerstnerBoundTakesTheSmallestWeightOfItsDepths) {
    const OceanSurface sea(SpectralBeach(true));
    const SurfWaves& surf = *sea.Surf();
    const std::vector<SurfWaves::Bound> cascades(sea.Fft()->Cascades().size(),
                                                 SurfWaves::Bound{0.0, 0.0});
    const SurfWaves::Bound gerstner{-1.0, 0.0};
    const double fade = surf.FadeDeep_m(), swashDeep = 2.0 * surf.Swash().runup2_m;
    int checked = 0;
    for (int k = 1; k <= 300; ++k) {
        const double minDepth = 1.05 * fade * k / 300.0;
        for (const double width : {0.003, 0.2, 2.0}) {
            const double maxDepth = minDepth + width;
            const SurfWaves::Bound b = surf.BoundAtDepths(minDepth, cascades, gerstner,
                                                          SurfWaves::Bound{0.0, 0.0}, maxDepth);
            for (int i = 0; i <= 40; ++i) {
                const double h = minDepth + width * i / 40.0;
                ASSERT_GE(b.height_m, -surf.Weights(h).gerstner) << minDepth << " " << h;
                ++checked;
            }
            if (minDepth > swashDeep + 0.1 && minDepth < fade) {
                EXPECT_EQ(b.height_m, -surf.Weights(minDepth).gerstner) << minDepth;
            }
        }
    }
    EXPECT_GT(checked, 30000);
}

// The surf components' bounds over a disc (BoundNear) hold at every wet rest position in it —
// the height, Terms' vertical displacement less the swash (cap · Re Σ a e^{iψ}), and the reach,
// the length of its horizontal displacement — over the fade zone, the bar and the beach, at many
// instants and radii; over 2 m or less they are well below the sums of the amplitudes and of the
// orbits over the disc's depths (the bounds they tighten), and the height's below the envelope
// |Σ a e^{iψ}| itself in many discs of 2-6 m.
// The same surf with Gerstner steepness Q = 1 everywhere (deepSteepness 1): its horizontal
// displacement outside the breakers is the whole sum Σ P sin ψ that the reach bounds, not half
// of it, so the reach is tested without that slack.
TEST(SurfWaves, BoundNearHoldsOverTheDisc) {
    const OceanSurface sea(SpectralBeach(true));
    const SurfWaves& own = *sea.Surf();
    SurfWaveSettings fullSteepness;
    fullSteepness.deepSteepness = 1.0;
    const SurfWaves steep(own.Bathy(), own.Components(), sea.Summary().peakWavelength_m,
                          own.Cascades(), fullSteepness);
    const Bathymetry& bathy = own.Bathy();
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    int checked = 0, discs = 0, tighter = 0, narrower = 0, wide = 0, belowEnvelope = 0;
    const std::vector<SurfWaves::Bound> noDeepSea(own.Cascades().size());
    double worstSlack = std::numeric_limits<double>::infinity(), worstReachSlack = worstSlack;
    for (int f = 0; f < 80; ++f) {
        const SurfWaves& surf = f % 2 == 0 ? own : steep;
        const double t = 0.77 * (f / 2);
        for (double s = 5.0; s < 1.05 * surf.FadeDeep_m() / 0.03; s += 23.0) {
            const glm::dvec2 c = bathy.Frame().WorldFromShore(s, 40.0 + 3.0 * (f / 2));
            for (const double radius : {0.0, 0.5, 2.0, 6.0}) {
                const double shallow = bathy.Tide_m() - bathy.MaxSeabedZWithin_m(c.x, c.y, radius);
                const double deep = bathy.Tide_m() - bathy.MinSeabedZWithin_m(c.x, c.y, radius);
                const SurfWaves::Bound near = surf.BoundNear(c.x, c.y, t, radius, shallow, deep);
                const double bound = near.height_m;
                if (!std::isfinite(bound)) continue;
                ASSERT_TRUE(std::isfinite(near.horizontal_m));
                // The surf's reach over the disc's depths without it (the sums of the orbits).
                const double orbits = surf.BoundAtDepths(shallow, noDeepSea, SurfWaves::Bound{},
                                                         SurfWaves::kNoCap, deep)
                                          .horizontal_m;
                if (radius <= 2.0 && near.horizontal_m < 0.7 * orbits) ++narrower;
                ++discs;
                // Σ a at the shallowest depth: what the interval bound takes for the surf.
                SurfPointInfo at;
                surf.Terms(c.x, c.y, t, &at);
                double sum = 0.0;
                const SurfWeights w = surf.Weights(std::max(shallow, 0.0));
                for (const SurfComponent& k : surf.Components())
                    sum += k.amplitude_m * (k.spectral ? w.spectralSurf : w.gerstnerSurf);
                if (radius <= 0.5 && bound < 0.7 * sum) ++tighter;
                double envelopeMax = 0.0;
                for (int k = 0; k < 60; ++k) {
                    const double r = radius * std::sqrt(u01(rng)), a = 6.2832 * u01(rng);
                    const double x = c.x + r * std::cos(a), y = c.y + r * std::sin(a);
                    SurfPointInfo info;
                    const SurfaceTerms terms = surf.Terms(x, y, t, &info);
                    if (!(info.depth_m > 0.0)) continue;
                    ASSERT_GE(info.depth_m, shallow - 1e-9);
                    ASSERT_LE(info.depth_m, deep + 1e-9);
                    const ShorePoint p = bathy.Frame().ShoreFromWorld(x, y);
                    const double height =
                        terms.displacement.z - surf.Swash_m(p.s_m, p.u_m, t, info.depth_m);
                    EXPECT_LE(height, bound) << "s " << s << " radius " << radius << " t " << t;
                    EXPECT_LE(std::hypot(terms.displacement.x, terms.displacement.y),
                              near.horizontal_m)
                        << "s " << s << " radius " << radius << " t " << t;
                    worstReachSlack = std::min(
                        worstReachSlack,
                        near.horizontal_m - std::hypot(terms.displacement.x, terms.displacement.y));
                    worstSlack = std::min(worstSlack, bound - height);
                    envelopeMax = std::max(envelopeMax, 0.5 * info.unbrokenHeight_m);
                    ++checked;
                }
                if (radius >= 2.0) {
                    ++wide;
                    if (bound < envelopeMax) ++belowEnvelope;
                }
            }
        }
    }
    EXPECT_GT(checked, 20000);
    EXPECT_GT(tighter, discs / 8) << discs;
    EXPECT_GT(narrower, discs / 8) << discs;
    // A bound on the height, not on the envelope |Σ a e^{iψ}|: below the envelope's sampled
    // maximum in some wide discs (where the sum's real part stays below its modulus).
    EXPECT_GT(belowEnvelope, 0) << wide;
    std::printf(
        "BoundNear: %d points in %d discs, least slack %.4f m (reach %.4f m); below 0.7 of the "
        "sums in %d (height) and %d (reach) discs; %d of %d discs of 2-6 m below the envelope's "
        "maximum\n",
        checked, discs, worstSlack, worstReachSlack, tighter, narrower, belowEnvelope, wide);
}

TEST(SurfWaves, ChopKeepsItsWeightWhereItIsDeepWaterForItsWavelength) {
    const OceanSurface sea(SpectralBeach(true));
    const SurfWaves& w = *sea.Surf();
    const std::vector<SurfCascade>& cascades = w.Cascades();
    ASSERT_EQ(cascades.size(), 2u);
    const double lp = sea.Summary().peakWavelength_m;
    // The long cascade holds the peak: it fades over ½–¼ L_p. The chop cascade's waves are far
    // shorter than the peak's.
    EXPECT_DOUBLE_EQ(cascades[0].wavelength_m, lp);
    const double lc = cascades[1].wavelength_m;
    ASSERT_LT(lc, 0.5 * lp);
    for (double h = 0.0; h < 1.2 * w.FadeDeep_m(); h += 0.05) {
        const SurfWeights sw = w.Weights(h);
        // Deep water for the chop's wavelength (tanh kh ≥ tanh π = 0.996): full weight.
        if (std::tanh(2.0 * kPi / lc * h) >= std::tanh(kPi)) {
            EXPECT_EQ(sw.cascade[1], 1.0) << h;
        }
        if (h <= 0.25 * lp) {
            EXPECT_EQ(sw.cascade[0], 0.0) << h;
        }
        if (h >= 0.5 * lp) {
            EXPECT_TRUE(sw.AllDeep()) << h;
        }
    }
    // Where the long waves are gone and the chop is not, the surf components carry exactly the
    // long cascade's variance.
    const double h = std::max(0.55 * lc, 0.2 * lp);
    const SurfWeights sw = w.Weights(h);
    EXPECT_EQ(sw.cascade[1], 1.0);
    const double total = cascades[0].variance_m2 + cascades[1].variance_m2;
    EXPECT_NEAR(sw.spectralSurf * sw.spectralSurf * total, cascades[0].variance_m2, 1e-12 * total);
}

TEST(SurfWaves, HsIsConservedThroughThePerCascadeFade) {
    const OceanSurface sea(SpectralBeach(true));
    const SurfWaves& w = *sea.Surf();
    const std::vector<SurfCascade>& cascades = w.Cascades();
    double total = 0.0;
    for (const SurfCascade& c : cascades) total += c.variance_m2;
    // Variance bookkeeping at every depth: what the cascades lose the components gain.
    for (double h = 0.0; h < 1.1 * w.FadeDeep_m(); h += 0.01) {
        const SurfWeights sw = w.Weights(h);
        double kept = 0.0;
        for (size_t c = 0; c < cascades.size(); ++c)
            kept += sw.cascade[c] * sw.cascade[c] * cascades[c].variance_m2;
        EXPECT_NEAR(kept + sw.spectralSurf * sw.spectralSurf * total, total, 1e-12 * total) << h;
        EXPECT_NEAR(sw.gerstner * sw.gerstner + sw.gerstnerSurf * sw.gerstnerSurf, 1.0, 1e-12);
    }
    // The drawn surface: the height variance over time at a point in the fade equals the kept
    // share of each cascade's variance (as realized at that point: a random-phase sea of finite
    // modes differs from its expected variance by several %) plus the surf components' shoaled
    // and refracted variance (energy flux and Snell's law computed here).
    const double slope = 0.03;
    const double lp = sea.Summary().peakWavelength_m;
    const double h = 0.4 * lp;  // inside the long cascade's fade, below any breaking
    const SurfWeights sw = w.Weights(h);
    ASSERT_GT(sw.cascade[0], 0.05);
    ASSERT_LT(sw.cascade[0], 0.95);
    double expected = 0.0;
    const double depth0 = 80.0;
    for (const SurfComponent& c : w.Components()) {
        const double k0 = K(c.omega_radps, depth0), k = K(c.omega_radps, h);
        // Angle to the shore normal (travel toward 270°); Snell: k sin θ is conserved.
        const double th0 = c.direction_rad - 1.5 * kPi;
        const double th = std::asin(k0 * std::sin(th0) / k);
        const double a = c.amplitude_m * sw.spectralSurf *
                         std::sqrt(Cg(c.omega_radps, depth0) / Cg(c.omega_radps, h)) *
                         std::sqrt(std::cos(th0) / std::cos(th));
        expected += 0.5 * a * a;
    }
    const std::array<std::array<double, 2>, 2> only{{{1.0, 0.0}, {0.0, 1.0}}};
    std::array<double, 3> sum{}, sum2{};
    int n = 0;
    for (int f = 0; f < 1500; ++f) {
        const auto frame = sea.At(f * 1.0 + 0.37);
        for (const double y : {0.0, 57.0, 131.0, 213.0}) {
            const double x = h / slope;
            const std::array<double, 3> z{frame->Terms(x, y).displacement.z,
                                          frame->Fft()->Terms(x, y, only[0].data()).displacement.z,
                                          frame->Fft()->Terms(x, y, only[1].data()).displacement.z};
            for (size_t i = 0; i < 3; ++i) sum[i] += z[i], sum2[i] += z[i] * z[i];
            ++n;
        }
    }
    const auto var = [&](size_t i) { return sum2[i] / n - (sum[i] / n) * (sum[i] / n); };
    for (size_t c = 0; c < 2; ++c) expected += sw.cascade[c] * sw.cascade[c] * var(c + 1);
    EXPECT_NEAR(var(0), expected, 0.05 * expected);
}

TEST(SurfWaves, DeepWaterIsTheSeaWithoutSurf) {
    const OceanSurface plain(SpectralBeach(false)), surf(SpectralBeach(true));
    const double fadeDeep = surf.Surf()->FadeDeep_m();
    const Bathymetry& b = surf.Surf()->Bathy();
    const auto a = plain.At(12.5), c = surf.At(12.5);
    int checked = 0;
    for (double x = 0.0; x < 5000.0; x += 37.0) {
        if (b.Depth_m(x, 0.0) < fadeDeep + 1.0) continue;
        const SurfaceTerms p = a->Terms(x, 10.0), q = c->Terms(x, 10.0);
        EXPECT_EQ(p.displacement.z, q.displacement.z);
        EXPECT_EQ(p.displacement.x, q.displacement.x);
        ++checked;
    }
    EXPECT_GT(checked, 10);
}

// Each part fades as cos of the angle (π/2)(deep − h)/(deep − deep/2) between its depths deep =
// ½ L and ¼ L; a cascade holding the peak (Weights takes the Gerstner waves' weight for it, the
// same fade) and a shorter one that fades on its own.
TEST(SurfWaves, CascadeWeightsFollowTheirOwnFades) {
    const Bathymetry b(Beach(0.05), 10.0);
    const double peak_m = 16.0, chop_m = 6.0;
    const SurfWaves w(b, {Wave(0.2, 3.2, 270.0)}, peak_m, {{1.0, peak_m}, {0.3, chop_m}});
    const auto fade = [](double h, double wavelength_m) {
        const double deep = 0.5 * wavelength_m, shallow = 0.5 * deep;
        if (h >= deep) return 1.0;
        if (h <= shallow) return 0.0;
        return std::cos(0.5 * kPi * (deep - h) / (deep - shallow));
    };
    for (int i = 0; i <= 1000; ++i) {
        const double h = 0.01 * i;
        const SurfWeights sw = w.Weights(h);
        ASSERT_NEAR(sw.gerstner, fade(h, peak_m), 1e-14) << h;
        ASSERT_EQ(sw.cascade[0], sw.gerstner) << h;
        ASSERT_NEAR(sw.cascade[1], fade(h, chop_m), 1e-14) << h;
    }
}

// Terms runs its component loops eight float lanes wide in the AVX2 build (four double lanes for
// the phases): per lane the four-lane loops' operations, their products added to the four-lane
// sums low half then high half. So it must give TermsFourLanes' bits (the SSE2 build's loops)
// everywhere: component counts that fill the wide lanes, leave a four-lane tail, or fit only the
// tail; with and without velocity; on land, in the surf and past the fades.
TEST(SurfWaves, WideLanesGiveTheFourLaneBits) {
    const Bathymetry b(Beach(0.05), 10.0);
    const auto bits = [](double v) { return std::bit_cast<uint64_t>(v); };
    for (const size_t count : {1u, 5u, 8u, 13u, 19u}) {
        std::vector<SurfComponent> components;
        for (size_t j = 0; j < count; ++j) {
            SurfComponent c = Wave(0.05 + 0.03 * double(j % 5), 5.0 + 0.7 * double(j),
                                   270.0 + 50.0 * std::sin(1.3 * double(j)));
            c.phase_rad = 0.9 * double(j);
            c.spectral = j % 3 != 0;
            components.push_back(c);
        }
        const SurfWaves w(b, components, 60.0);
        size_t surfPoints = 0;
        for (int i = 0; i < 4000; ++i) {
            const double x = -15.0 + 0.16 * i, y = 40.0 * std::sin(0.11 * i);
            const double t = 1e3 * std::sin(0.07 * i) + 0.013 * i;
            for (const bool velocity : {true, false}) {
                SurfWaves::TermsOptions options;
                options.velocity = velocity;
                SurfPointInfo wideInfo, fourInfo;
                const SurfaceTerms wide = w.Terms(x, y, t, &wideInfo, options);
                const SurfaceTerms four = w.TermsFourLanes(x, y, t, &fourInfo, options);
                ASSERT_EQ(std::memcmp(&wide, &four, sizeof wide), 0) << count << " " << x;
                for (const auto field :
                     {&SurfPointInfo::envelope_m, &SurfPointInfo::unbrokenHeight_m,
                      &SurfPointInfo::direction_rad, &SurfPointInfo::phaseSpeed_mps,
                      &SurfPointInfo::groupSpeed_mps, &SurfPointInfo::phase_rad})
                    ASSERT_EQ(bits(wideInfo.*field), bits(fourInfo.*field)) << count << " " << x;
                ASSERT_EQ(bits(wideInfo.breaking.intensity), bits(fourInfo.breaking.intensity));
                if (velocity && wideInfo.surfWeight > 0.0 && wideInfo.depth_m > 0.0) ++surfPoints;
            }
        }
        EXPECT_GT(surfPoints, 1000u) << count;  // the sums ran, not only the early returns
    }
}

// Terms writes the point's information in place (the mesh hands its own, reused vertex after
// vertex): reset first, the weights filled in where they lie, so it must be the information of
// a fresh struct whatever the struct held, the weights must be Weights(depth) with the spectral
// weight the cascades' lost variance, the breaking state the breaker line's, and the terms the
// same bits with and without the information. Points on land, through the surf and both fades
// and past them; a struct filled with junk before each call.
TEST(SurfWaves, PointInformationInPlaceIsAFreshPointsWeightsAndBreaking) {
    const Bathymetry b(Beach(0.05), 10.0);
    std::vector<SurfComponent> components;
    for (size_t j = 0; j < 13; ++j) {
        SurfComponent c = Wave(0.1 + 0.02 * double(j % 4), 4.0 + 0.6 * double(j),
                               270.0 + 30.0 * std::sin(1.7 * double(j)));
        c.phase_rad = 0.5 * double(j);
        c.spectral = j != 0;
        components.push_back(c);
    }
    const std::vector<SurfCascade> cascades{{0.4, 16.0}, {0.1, 6.0}};
    const SurfWaves w(b, components, 16.0, cascades);
    ASSERT_TRUE(std::isfinite(w.BreakerLine_m()));
    const auto bits = [](double v) { return std::bit_cast<uint64_t>(v); };
    const auto sameInfo = [&](const SurfPointInfo& a, const SurfPointInfo& c) {
        for (const auto field : {&SurfPointInfo::depth_m, &SurfPointInfo::seabedZ_m,
                                 &SurfPointInfo::deepWeight, &SurfPointInfo::surfWeight,
                                 &SurfPointInfo::envelope_m, &SurfPointInfo::unbrokenHeight_m,
                                 &SurfPointInfo::direction_rad, &SurfPointInfo::phaseSpeed_mps,
                                 &SurfPointInfo::groupSpeed_mps, &SurfPointInfo::phase_rad})
            if (bits(a.*field) != bits(c.*field)) return false;
        for (size_t k = 0; k < kMaxSurfCascades; ++k)
            if (bits(a.weights.cascade[k]) != bits(c.weights.cascade[k])) return false;
        return bits(a.weights.gerstner) == bits(c.weights.gerstner) &&
               bits(a.weights.spectralSurf) == bits(c.weights.spectralSurf) &&
               bits(a.weights.gerstnerSurf) == bits(c.weights.gerstnerSurf) &&
               bits(a.breaking.intensity) == bits(c.breaking.intensity) &&
               a.breaking.broken == c.breaking.broken &&
               bits(a.breaking.timeSinceBreaking_s) == bits(c.breaking.timeSinceBreaking_s);
    };
    SurfPointInfo junk;
    junk.depth_m = junk.seabedZ_m = junk.deepWeight = junk.surfWeight = 7.0;
    junk.weights.cascade.fill(-3.0);
    junk.weights.gerstner = junk.weights.spectralSurf = junk.weights.gerstnerSurf = 5.0;
    junk.envelope_m = junk.unbrokenHeight_m = junk.direction_rad = 9.0;
    junk.phaseSpeed_mps = junk.groupSpeed_mps = junk.phase_rad = 11.0;
    junk.breaking = {0.5, true, 42.0};
    size_t inFade = 0, broken = 0, deep = 0;
    for (int i = 0; i < 3000; ++i) {
        const double x = -20.0 + 0.1 * i, y = 30.0 * std::sin(0.13 * i), t = 0.37 * i;
        for (const auto dominant :
             {SurfWaves::Dominant::kEverywhere, SurfWaves::Dominant::kWhereBroken}) {
            for (const bool share : {true, false}) {
                SurfWaves::TermsOptions options;
                options.velocity = i % 2 == 0;
                options.dominant = dominant;
                options.shareWeights = share;
                SurfPointInfo fresh, reused = junk;
                const SurfaceTerms a = w.Terms(x, y, t, &fresh, options);
                const SurfaceTerms c = w.Terms(x, y, t, &reused, options);
                const SurfaceTerms none = w.Terms(x, y, t, nullptr, options);
                ASSERT_EQ(std::memcmp(&a, &c, sizeof a), 0) << x;
                ASSERT_EQ(std::memcmp(&a, &none, sizeof a), 0) << x;
                ASSERT_TRUE(sameInfo(fresh, reused)) << x;
                const SurfWeights expected = w.Weights(fresh.depth_m);
                for (size_t k = 0; k < cascades.size(); ++k)
                    ASSERT_EQ(bits(fresh.weights.cascade[k]), bits(expected.cascade[k])) << x;
                ASSERT_EQ(bits(fresh.weights.gerstner), bits(expected.gerstner)) << x;
                ASSERT_EQ(bits(fresh.weights.gerstnerSurf), bits(expected.gerstnerSurf)) << x;
                ASSERT_EQ(bits(fresh.weights.spectralSurf), bits(expected.spectralSurf)) << x;
                // The spectral surf weight carries the variance the cascades give up (not the
                // Gerstner waves' weight, as without cascades).
                double lost = 0.0, total = 0.0;
                for (size_t k = 0; k < cascades.size(); ++k) {
                    const double f = fresh.weights.cascade[k];
                    lost += cascades[k].variance_m2 * (1.0 - f * f);
                    total += cascades[k].variance_m2;
                }
                ASSERT_EQ(bits(fresh.weights.spectralSurf),
                          bits(std::sqrt(std::clamp(lost / total, 0.0, 1.0))))
                    << x;
                const double s = b.Frame().ShoreFromWorld(x, y).s_m;
                ASSERT_EQ(fresh.breaking.broken, s <= w.BreakerLine_m()) << x;
                if (fresh.breaking.broken) {
                    ASSERT_GE(fresh.breaking.timeSinceBreaking_s, 0.0) << x;
                    ++broken;
                }
                if (fresh.weights.cascade[1] > 0.0 && fresh.weights.cascade[1] < 1.0) ++inFade;
                if (fresh.weights.AllDeep()) ++deep;
            }
        }
    }
    EXPECT_GT(inFade, 100u);
    EXPECT_GT(broken, 100u);
    EXPECT_GT(deep, 100u);
}

// The mesh's batches (TermsBatch, up to four points a call, one point a double lane) must give
// Terms' bits at each point with the mesh's options: the terms and every field of the point's
// information. A turned shoreline with a sandbar region (shelter behind the bar) and the swash,
// two cascades (one fading with the peak, one with its own wavelength), points from the dry
// beach through the breakers and both fades (either half of each: Fade's cosine in both
// quadrants) to past the deepest fade, batches of every size.
TEST(SurfWaves, BatchesGiveEachPointsTermsBitForBit) {
    SurfSettings settings = Beach(0.05);
    settings.shoreline = {{13.0, -7.0}, 0.7};
    SurfRegionSettings bar, plain;
    bar.width_m = plain.width_m = 200.0;
    bar.sandbar = SandbarSettings{20.0, 120.0, 0.6, 40.0, 15.0};
    settings.regions = {bar, plain};
    const Bathymetry b(settings, 12.0);
    std::vector<SurfComponent> components;
    for (size_t j = 0; j < 13; ++j) {
        SurfComponent c = Wave(0.12 + 0.02 * double(j % 4), 4.0 + 0.5 * double(j),
                               40.0 + 25.0 * std::sin(1.3 * double(j)));
        c.phase_rad = 0.7 * double(j);
        c.spectral = j != 0;
        components.push_back(c);
    }
    const double peak = 16.0;
    const SurfWaves w(b, components, peak, {{0.4, peak}, {0.1, 6.0}});
    ASSERT_TRUE(std::isfinite(w.BreakerLine_m()));
    ASSERT_TRUE(w.Swash().active);
    const auto bits = [](double v) { return std::bit_cast<uint64_t>(v); };
    const auto sameInfo = [&](const SurfPointInfo& a, const SurfPointInfo& c) {
        for (const auto field : {&SurfPointInfo::depth_m, &SurfPointInfo::seabedZ_m,
                                 &SurfPointInfo::deepWeight, &SurfPointInfo::surfWeight,
                                 &SurfPointInfo::envelope_m, &SurfPointInfo::unbrokenHeight_m,
                                 &SurfPointInfo::direction_rad, &SurfPointInfo::phaseSpeed_mps,
                                 &SurfPointInfo::groupSpeed_mps, &SurfPointInfo::phase_rad})
            if (bits(a.*field) != bits(c.*field)) return false;
        for (size_t k = 0; k < kMaxSurfCascades; ++k)
            if (bits(a.weights.cascade[k]) != bits(c.weights.cascade[k])) return false;
        return bits(a.weights.gerstner) == bits(c.weights.gerstner) &&
               bits(a.weights.spectralSurf) == bits(c.weights.spectralSurf) &&
               bits(a.weights.gerstnerSurf) == bits(c.weights.gerstnerSurf) &&
               bits(a.breaking.intensity) == bits(c.breaking.intensity) &&
               a.breaking.broken == c.breaking.broken &&
               bits(a.breaking.timeSinceBreaking_s) == bits(c.breaking.timeSinceBreaking_s);
    };
    const double peakDeep = w.PeakFadeDeep_m(), chopDeep = 3.0;
    size_t dry = 0, swash = 0, broken = 0, breaking = 0, deep = 0;
    size_t peakHalves[2] = {0, 0}, chopHalves[2] = {0, 0};
    int point = 0;
    for (int group = 0; group < 2400; ++group) {
        const size_t count = 1 + size_t(group) % SurfWaves::kBatch;
        std::array<double, SurfWaves::kBatch> x{}, y{}, z{};
        for (size_t l = 0; l < count; ++l, ++point) {
            const double s = -15.0 + 0.11 * point, u = 400.0 * std::sin(0.017 * point);
            const glm::dvec2 p = b.Frame().WorldFromShore(s, u);
            x[l] = p.x, y[l] = p.y;
            const ShorePoint sp = b.Frame().ShoreFromWorld(p.x, p.y);
            z[l] = b.SeabedZAtShore_m(sp.s_m, sp.u_m);
        }
        const double t = 0.61 * group;
        std::array<SurfPointInfo, SurfWaves::kBatch> infos;
        std::array<SurfaceTerms, SurfWaves::kBatch> terms;
        w.TermsBatch(x.data(), y.data(), z.data(), count, t, infos.data(), terms.data());
        for (size_t l = 0; l < count; ++l) {
            SurfWaves::TermsOptions options;
            options.velocity = false;
            options.dominant = SurfWaves::Dominant::kWhereBroken;
            options.shareWeights = false;
            options.seabedZ_m = z[l];
            SurfPointInfo info;
            const SurfaceTerms one = w.Terms(x[l], y[l], t, &info, options);
            ASSERT_EQ(std::memcmp(&one, &terms[l], sizeof one), 0) << group << " " << l;
            ASSERT_TRUE(sameInfo(info, infos[l])) << group << " " << l;
            const double h = info.depth_m;
            dry += h <= 0.0;
            swash += w.SwashReaches(h) && one.displacement.z != 0.0;
            broken += info.breaking.broken;
            breaking += info.breaking.intensity > 0.0;
            deep += h >= w.FadeDeep_m();
            if (h > 0.5 * peakDeep && h < peakDeep) ++peakHalves[h > 0.75 * peakDeep];
            if (h > 0.5 * chopDeep && h < chopDeep) ++chopHalves[h > 0.75 * chopDeep];
        }
    }
    EXPECT_GT(dry, 50u);
    EXPECT_GT(swash, 50u);
    EXPECT_GT(broken, 150u);
    EXPECT_GT(breaking, 50u);
    EXPECT_GT(deep, 200u);
    for (const size_t n : {peakHalves[0], peakHalves[1], chopHalves[0], chopHalves[1]})
        EXPECT_GT(n, 50u);
}

}  // namespace
}  // namespace seasense::scene
