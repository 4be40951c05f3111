// The ocean surface (FFT cascades plus Gerstner waves) against the spectrum it was made from,
// published Pierson–Moskowitz relations, linear wave theory, the law of total variance for its
// filtered lookups, and its own definitions of foam and velocity.
#include "scene/ocean/ocean_surface.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <array>
#include <bit>
#include <cmath>
#include <numbers>
#include <span>
#include <vector>

#include "scene/core/error.h"

namespace seasense::scene {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double g = kGravity_mps2;
constexpr double kRad = kPi / 180.0;

// A Beaufort-5 JONSWAP sea (fetch 100 km) plus one long Gerstner swell, as configs/ocean.yaml.
OceanSettings Beaufort5(uint64_t seed = 11, int grid = 128, bool swell = true) {
    OceanSettings o;
    o.depth_m = 60.0;
    SpectralOceanSettings s;
    s.sea.beaufort = 5;
    s.sea.spectrum.model = SpectrumModel::Jonswap;
    s.sea.spectrum.fetch_m = 1e5;
    s.sea.spectrum.windDirection_rad = 20.0 * kRad;
    s.fft.gridSize = grid;
    s.fft.seed = seed;
    o.spectral = s;
    if (swell) {
        GerstnerWaveSettings w;
        w.direction_rad = 80.0 * kRad;
        w.wavelength_m = 180.0;
        w.amplitude_m = 0.4;
        w.steepness = 0.4;
        o.waves.push_back(w);
    }
    return o;
}

OceanSettings PiersonMoskowitz(double u10, double depth_m, uint64_t seed = 1) {
    OceanSettings o;
    o.depth_m = depth_m;
    SpectralOceanSettings s;
    s.sea.windSpeed_mps = u10;
    s.sea.spectrum.model = SpectrumModel::PiersonMoskowitz;
    s.sea.spectrum.windDirection_rad = 1.1;
    s.fft.gridSize = 128;
    s.fft.seed = seed;
    o.spectral = s;
    return o;
}

TEST(OceanSurface, SynthesizedHsMatchesTheSpectrumAndPiersonMoskowitz) {
    // 4 × std of the drawn heights, averaged over seeds, within 5 % of the summary's Hs
    // (4√m0 of the synthesized modes) and of the fully developed PM sea's 0.21 U19.5²/g
    // (physics.md; the modes carry the spectrum's m0 to 2 %, tested in fft_ocean_test).
    const double u10 = 10.0;
    const int seeds = 6;
    double meanHs = 0.0, summaryHs = 0.0;
    for (int seed = 1; seed <= seeds; ++seed) {
        const OceanSurface sea(PiersonMoskowitz(u10, 1e4, uint64_t(seed)));
        summaryHs = sea.Summary().significantHeight_m;
        const auto frame = sea.At(23.0);
        const double l = sea.Fft()->Cascades()[0].patch_m;
        const int n = 160;  // not a divisor of the grid: points fall everywhere in the cells
        double sum = 0.0, sum2 = 0.0;
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j) {
                const double z = frame->Evaluate(l * (i + 0.31) / n, l * (j + 0.77) / n).position.z;
                sum += z;
                sum2 += z * z;
            }
        const double mean = sum / (n * n);
        meanHs += 4.0 * std::sqrt(sum2 / (n * n) - mean * mean) / seeds;
    }
    EXPECT_NEAR(meanHs, summaryHs, 0.05 * summaryHs);
    const double u195 = WindSpeed19_5(u10);
    EXPECT_NEAR(meanHs, 0.21 * u195 * u195 / g, 0.07 * 0.21 * u195 * u195 / g);
}

TEST(OceanSurface, SummaryOfAPiersonMoskowitzSeaInShallowWater) {
    // Peak ω_p = 0.877 g / U19.5 (physics.md's PM with β = 0.74), travelling with the wind;
    // the reported wave obeys ω² = g k tanh kh and c_g = dω/dk (numerical derivative).
    const double u10 = 8.0, depth = 6.0;
    const OceanSurface sea(PiersonMoskowitz(u10, depth));
    const SeaSummary& s = sea.Summary();
    const double omegaP = std::pow(4.0 * 0.74 / 5.0, 0.25) * g / WindSpeed19_5(u10);
    EXPECT_NEAR(s.peakPeriod_s, 2.0 * kPi / omegaP, 1e-3 * s.peakPeriod_s);
    EXPECT_NEAR(s.dominantDirection_rad, 1.1, 0.3 * kRad);
    const double k = 2.0 * kPi / s.peakWavelength_m, omega = 2.0 * kPi / s.peakPeriod_s;
    EXPECT_NEAR(omega * omega, g * k * std::tanh(k * depth), 1e-9 * omega * omega);
    EXPECT_NEAR(s.phaseSpeed_mps, omega / k, 1e-12);
    const double dk = 1e-6 * k;
    const double cg = (std::sqrt(g * (k + dk) * std::tanh((k + dk) * depth)) -
                       std::sqrt(g * (k - dk) * std::tanh((k - dk) * depth))) /
                      (2.0 * dk);
    EXPECT_NEAR(s.groupSpeed_mps, cg, 1e-6 * cg);
    EXPECT_GT(s.groupSpeed_mps, 0.5 * s.phaseSpeed_mps);  // shallow: c_g → c
    EXPECT_EQ(s.depth_m, depth);
    EXPECT_NEAR(s.windSpeed_mps, u10, 1e-12);
}

TEST(OceanSurface, DominantWaveIsTheSwellWhenTheSwellCarriesTheEnergy) {
    OceanSettings o = PiersonMoskowitz(3.0, 1e4);  // a light wind sea, Hs ≈ 0.2 m
    SwellSettings swell;
    swell.significantHeight_m = 2.0;
    swell.peakPeriod_s = 12.0;
    swell.direction_rad = 250.0 * kRad;
    o.spectral->sea.spectrum.swell = swell;
    const OceanSurface sea(o);
    EXPECT_NEAR(sea.Summary().peakPeriod_s, 12.0, 0.01);
    EXPECT_NEAR(sea.Summary().dominantDirection_rad, 250.0 * kRad, 0.3 * kRad);
    // Hs of the sum: variances add (swell 2 m, wind sea ≈ 0.2 m).
    EXPECT_NEAR(sea.Summary().significantHeight_m,
                std::hypot(2.0, 0.21 * std::pow(WindSpeed19_5(3.0), 2) / g), 0.05);
}

TEST(OceanSurface, GerstnerWavesAloneAreSummarizedByTheLargest) {
    OceanSettings o;
    o.depth_m = 10.0;
    for (double a : {0.2, 0.5, 0.1}) {
        GerstnerWaveSettings w;
        w.wavelength_m = 100.0 * a;
        w.amplitude_m = a;
        w.direction_rad = a;
        o.waves.push_back(w);
    }
    const OceanSurface sea(o);
    const SeaSummary& s = sea.Summary();
    EXPECT_FALSE(s.spectral);
    EXPECT_NEAR(s.significantHeight_m, 4.0 * std::sqrt(0.5 * (0.04 + 0.25 + 0.01)), 1e-12);
    EXPECT_NEAR(s.peakWavelength_m, 50.0, 1e-9);
    EXPECT_NEAR(s.dominantDirection_rad, 0.5, 1e-12);
    const double k = 2.0 * kPi / 50.0;
    EXPECT_NEAR(s.peakPeriod_s, 2.0 * kPi / std::sqrt(g * k * std::tanh(k * 10.0)), 1e-9);
    EXPECT_TRUE(std::isnan(s.windSpeed_mps));
}

TEST(OceanSurface, QueryAnswersTheParticleDrawnAboveThePoint) {
    const OceanSurface sea(Beaufort5());
    const double t = 31.5;
    const auto frame = sea.AtWithVelocity(t);
    for (double x : {-40.0, 3.3, 250.0})
        for (double y : {7.0, -1234.5}) {
            const OceanPointQuery q = sea.Query(x, y, t);
            EXPECT_NEAR(q.surface.position.x, x, 1e-8);
            EXPECT_NEAR(q.surface.position.y, y, 1e-8);
            const OceanSample atRest = frame->Evaluate(q.rest_m.x, q.rest_m.y);
            EXPECT_EQ(q.surface.position.z, atRest.position.z);
            EXPECT_EQ(q.waterDepth_m, 60.0);
            // The geometry-only frame of the renderers answers the same height.
            EXPECT_NEAR(sea.HeightAt(x, y, t), q.surface.position.z, 1e-12);
            // The horizontal displacement is real, so the inversion is exercised.
            EXPECT_GT(glm::length(q.rest_m - glm::dvec2(x, y)), 1e-3);
        }
}

TEST(OceanSurface, VelocityIsTheTimeDerivativeOfTheParticlePosition) {
    const OceanSurface sea(Beaufort5());
    const double t = 12.0, dt = 1e-3;
    const auto a = sea.AtWithVelocity(t - dt), b = sea.AtWithVelocity(t + dt);
    for (double x : {5.0, 77.7})
        for (double y : {-3.0, 41.0}) {
            const OceanPointQuery q = sea.Query(x, y, t);
            const glm::dvec3 fd = (b->Evaluate(q.rest_m.x, q.rest_m.y).position -
                                   a->Evaluate(q.rest_m.x, q.rest_m.y).position) /
                                  (2.0 * dt);
            EXPECT_NEAR(glm::length(q.surface.velocity_mps - fd), 0.0,
                        2e-3 * (1.0 + glm::length(fd)));
            EXPECT_GT(glm::length(fd), 0.01);
        }
    // Frames made for rendering carry no velocities, and say so.
    EXPECT_TRUE(std::isnan(sea.At(t)->Evaluate(0.0, 0.0).velocity_mps.x));
}

TEST(OceanSurface, FoamCoverageFollowsTheJacobianEigenvalue) {
    // One trochoid (Q = 1, deep water): at a crest the smaller eigenvalue of the horizontal
    // Jacobian is 1 − kA, at a trough 1 + kA; coverage = clamp(1 − λ_min / τ).
    OceanSettings o;
    o.foamThreshold = 0.6;
    GerstnerWaveSettings w;
    w.direction_rad = 0.5 * kPi;  // toward east
    w.wavelength_m = 30.0;
    w.amplitude_m = 0.07 * 30.0;  // kA = 0.44, just inside the Stokes limit
    w.steepness = 1.0;
    o.waves.push_back(w);
    const OceanSurface sea(o);
    const double kA = 2.0 * kPi / 30.0 * w.amplitude_m;
    // Crest at rest x0 = 0 at t = 0 (phase 0, cos = 1); trough at x0 = λ/2.
    const OceanPointQuery crest = sea.Query(0.0, 5.0, 0.0);
    EXPECT_NEAR(crest.surface.minEigenvalue, 1.0 - kA, 1e-9);
    EXPECT_NEAR(crest.foamCoverage, 1.0 - (1.0 - kA) / 0.6, 1e-9);
    const OceanPointQuery trough = sea.Query(15.0, 5.0, 0.0);
    EXPECT_EQ(trough.foamCoverage, 0.0);
}

// Whether two frames' filtered FFT lookups at rest position (x, y) and footprint fp are the
// same bit for bit.
::testing::AssertionResult SameLookups(const OceanSurfaceFrame& a, const OceanSurfaceFrame& b,
                                       double x, double y, float fp) {
    GeometrySums sa{}, sb{};
    a.AccumulateFft(x, y, fp, sa);
    b.AccumulateFft(x, y, fp, sb);
    for (int k = 0; k < kGeometryTerms; ++k)
        if (std::bit_cast<uint32_t>(sa[size_t(k)]) != std::bit_cast<uint32_t>(sb[size_t(k)]))
            return ::testing::AssertionFailure()
                   << "term " << k << " at (" << x << ", " << y << "), footprint " << fp << ": "
                   << sa[size_t(k)] << " vs " << sb[size_t(k)];
    return ::testing::AssertionSuccess();
}

TEST(OceanSurface, FramesAreSharedPerTimeAndIdenticalForAnyThreadCount) {
    const OceanSurface sea(Beaufort5(3, 64));
    const auto a = sea.At(4.0), b = sea.At(4.0);
    EXPECT_EQ(a.get(), b.get());
    const auto make = [](int threads) {
        tbb::task_arena arena(threads);
        return arena.execute([] {
            const OceanSurface s(Beaufort5(3, 64));
            return s.At(4.0);
        });
    };
    const auto one = make(1), two = make(2);
    for (int i = 0; i < 50; ++i) {
        const double x = 13.7 * i - 300.0, y = 0.37 * i * i;
        for (float fp : {0.0f, 3.0f, 40.0f}) ASSERT_TRUE(SameLookups(*one, *two, x, y, fp));
        ASSERT_EQ(one->HeightAt(x, y), two->HeightAt(x, y));
    }
}

// A frame adopted from another OceanSurface's encoded fields (the run's host handing its
// synthesis to a renderer) is the frame At makes, bit for bit: the filtered lookups at fine and
// coarse footprints (every mip level the textures build), heights and bounds. Adopting a time
// held already keeps the frame; fields of another time, grid or a sea without them are refused
// with nothing cached.
TEST(OceanSurface, AdoptedFieldsMakeTheFrameAtMakes) {
    const OceanSurface host(Beaufort5(3, 64)), renderer(Beaufort5(3, 64)), own(Beaufort5(3, 64));
    const auto made = host.At(4.0);
    ASSERT_NE(made->Fft(), nullptr);
    std::vector<uint8_t> fields(host.SharedFieldBytes());
    ASSERT_EQ(made->Fft()->EncodedBytes(), fields.size());
    made->Fft()->Encode(fields.data());
    renderer.Adopt(4.0, fields);
    const auto adopted = renderer.At(4.0), reference = own.At(4.0);
    EXPECT_EQ(std::bit_cast<uint64_t>(adopted->MaxHeight_m()),
              std::bit_cast<uint64_t>(reference->MaxHeight_m()));
    for (int i = 0; i < 60; ++i) {
        const double x = 17.3 * i - 400.0, y = 0.41 * i * i - 90.0;
        for (float fp : {0.0f, 2.0f, 9.0f, 60.0f, 500.0f})
            ASSERT_TRUE(SameLookups(*adopted, *reference, x, y, fp));
        ASSERT_EQ(std::bit_cast<uint64_t>(adopted->HeightAt(x, y)),
                  std::bit_cast<uint64_t>(reference->HeightAt(x, y)));
        const SurfaceBounds ba = adopted->BoundsNear(x, y, 30.0);
        const SurfaceBounds bb = reference->BoundsNear(x, y, 30.0);
        ASSERT_EQ(ba.height_m, bb.height_m);
        ASSERT_EQ(ba.horizontal_m, bb.horizontal_m);
    }
    renderer.Adopt(4.0, fields);
    EXPECT_EQ(renderer.At(4.0).get(), adopted.get());

    EXPECT_THROW(renderer.Adopt(5.0, fields), RuntimeError);  // fields of t = 4 s
    EXPECT_THROW(renderer.Adopt(5.0, std::span<const uint8_t>(fields).first(fields.size() - 1)),
                 RuntimeError);
    std::vector<uint8_t> badTag = fields;
    badTag[0] ^= 0xFF;
    EXPECT_THROW(renderer.Adopt(4.5, badTag), RuntimeError);
    const OceanSurface finer(Beaufort5(3, 128));
    EXPECT_THROW(finer.Adopt(4.0, fields), RuntimeError);
    OceanSettings gerstnerOnly = Beaufort5(3, 64);
    gerstnerOnly.spectral.reset();
    const OceanSurface waves(gerstnerOnly);
    EXPECT_EQ(waves.SharedFieldBytes(), 0u);
    EXPECT_THROW(waves.Adopt(4.0, fields), RuntimeError);
    EXPECT_NO_THROW(waves.Adopt(4.0, {}));
    // Nothing refused was cached: t = 5 s is synthesized as usual.
    EXPECT_TRUE(SameLookups(*renderer.At(5.0), *own.At(5.0), 10.0, 20.0, 0.0f));
}

TEST(OceanSurface, FilteredLookupIsTheFieldAtFineFootprintsAndLosesVarianceAsItGrows) {
    const OceanSurface sea(Beaufort5(5, 64, false));
    const auto frame = sea.At(9.0);
    const FftOceanFrame& fft = *frame->Fft();
    // At or below the finest grid spacing: the unfiltered surface.
    const double fine = fft.PatchSize_m(1) / fft.GridSize();
    for (int i = 0; i < 40; ++i) {
        const double x = 7.1 * i - 90.0, y = 2.9 * i;
        GeometrySums s{};
        frame->AccumulateFft(x, y, float(0.5 * fine), s);
        const SurfaceTerms t = fft.Terms(x, y);
        EXPECT_NEAR(s[kTermHeight], t.displacement.z, 2e-5);
        EXPECT_NEAR(s[kTermDispX], t.displacement.x, 2e-5);
        EXPECT_NEAR(s[kTermSlopeY], t.sy, 2e-5);
        EXPECT_NEAR(s[kTermDispXY], t.dxy, 2e-5);
    }
    // Law of total variance: averaging 2×2 blocks never increases the variance over the tile,
    // so the variance of cascade 0 read at its level-l texel centres falls with l; the whole
    // tile's mean (the top level) is the DC term, which the spectrum leaves at zero. Cascade 1
    // is filtered far more at these footprints, so its part shrinks too.
    const double l0 = fft.PatchSize_m(0), d0 = l0 / fft.GridSize();
    double previous = 1e30;
    for (int level = 0; level <= 6; ++level) {
        const int m = fft.GridSize() >> level;
        const double texel = d0 * (1 << level);
        double sum = 0.0, sum2 = 0.0;
        for (int i = 0; i < m; ++i)
            for (int j = 0; j < m; ++j) {
                GeometrySums s{};
                // Texel centres of level l: (i 2^l + (2^l − 1)/2) Δ.
                frame->AccumulateFft((i + 0.5) * texel - 0.5 * d0, (j + 0.5) * texel - 0.5 * d0,
                                     float(texel), s);
                sum += s[kTermHeight];
                sum2 += double(s[kTermHeight]) * s[kTermHeight];
            }
        const double variance = sum2 / (m * m) - (sum / (m * m)) * (sum / (m * m));
        EXPECT_LE(variance, previous * (1.0 + 1e-5)) << level;
        previous = variance;
        if (level == 6) {
            EXPECT_NEAR(sum, 0.0, 1e-4);
        }
    }
    EXPECT_LT(previous, 1e-6);
}

// FilterLevels holds every level the filter of any footprint in the range reads (level[c], and
// level[c] + 1 where it blends it in), starts at the smallest footprint's and ends at most one
// past the largest's.
TEST(OceanSurface, FilterLevelsHoldEveryLevelTheFootprintsRead) {
    const OceanSurface sea(Beaufort5(5, 64, false));
    const auto frame = sea.At(9.0);
    const size_t cascades = frame->Fft()->CascadeCount();
    int ranges = 0, blended = 0;
    for (int a = 0; a < 60; ++a)
        for (const double ratio : {1.0, 1.3, 3.0, 40.0}) {
            const double lo = 0.01 * std::pow(1.17, a), hi = lo * ratio;
            for (size_t c = 0; c < cascades; ++c) {
                int first = -1, last = -1;
                frame->FilterLevels(c, lo, hi, first, last);
                EXPECT_EQ(first, frame->Filter(float(lo)).level[c]) << lo;
                EXPECT_LE(last, frame->Filter(float(hi)).level[c] + 1) << hi;
                for (int k = 0; k <= 50; ++k) {
                    const float f = float(lo * std::pow(ratio, k / 50.0));
                    const FftFilter filter = frame->Filter(f);
                    EXPECT_GE(filter.level[c], first) << f;
                    EXPECT_LE(filter.level[c] + (filter.frac[c] > 0.0f ? 1 : 0), last) << f;
                    if (filter.frac[c] > 0.0f) ++blended;
                }
                ++ranges;
            }
        }
    EXPECT_GT(ranges, 400);
    EXPECT_GT(blended, ranges * 15);
}

TEST(OceanSurface, LookupsFourAtATimeAreTheLookupsOneByOneBitForBit) {
    // AccumulateFft computes the lookups' texel coordinates, wraps and weights four at a time:
    // the same sums as one lookup at a time, bit for bit, at footprints from below the finest
    // texel to beyond the coarsest mip (one and two levels per cascade), at points near and far
    // (negative and 1e6 m coordinates wrap too), without and with cascade weights (0 skips a
    // cascade), over one, two and three cascades.
    for (const int cascades : {1, 2, 3}) {
        OceanSettings o = Beaufort5(7, 64, false);
        o.spectral->fft.cascadeCount = cascades;
        const OceanSurface sea(o);
        const auto frame = sea.At(3.25);
        uint64_t state = 0x9e3779b97f4a7c15ULL;
        const auto uniform = [&] {
            state = state * 6364136223846793005ULL + 1442695040888963407ULL;
            return double(state >> 11) * 0x1.0p-53;
        };
        int compared = 0;
        for (const float footprint : {0.0f, 0.07f, 0.4f, 1.0f, 3.3f, 17.0f, 250.0f, 1e5f}) {
            const FftFilter filter = frame->Filter(footprint);
            for (int i = 0; i < 400; ++i) {
                const double range = i % 4 == 0 ? 1e6 : i % 4 == 1 ? 50.0 : 3000.0;
                const double x = (2.0 * uniform() - 1.0) * range,
                             y = (2.0 * uniform() - 1.0) * range;
                const std::array<double, 3> w{uniform(), i % 3 == 0 ? 0.0 : 1.0, uniform()};
                for (const double* weights : {static_cast<const double*>(nullptr), w.data()}) {
                    GeometrySums a{}, b{};
                    frame->AccumulateFft(x, y, filter, a, weights);
                    frame->AccumulateFftOneByOne(x, y, filter, b, weights);
                    for (int k = 0; k < kGeometryTerms; ++k)
                        ASSERT_EQ(std::bit_cast<uint32_t>(a[size_t(k)]),
                                  std::bit_cast<uint32_t>(b[size_t(k)]))
                            << cascades << " " << footprint << " " << x << " " << y << " " << k;
                    ++compared;
                }
            }
        }
        EXPECT_EQ(compared, 8 * 400 * 2);
    }
}

TEST(OceanSurface, DetailNormalIsTheSurfaceNormalAtFineFootprints) {
    const OceanSurface sea(Beaufort5());
    const auto frame = sea.At(2.0);
    for (int i = 0; i < 30; ++i) {
        const double x0 = 5.3 * i, y0 = -2.1 * i;
        const glm::dvec3 n(frame->DetailNormal(x0, y0, 0.01f));
        EXPECT_NEAR(glm::dot(n, frame->Evaluate(x0, y0).normal), 1.0, 1e-6);
    }
    // A footprint as large as the longest patch averages each periodic cascade over its whole
    // tile, where the mean slope of a periodic surface is zero: the normal is vertical.
    const OceanSurface calm(Beaufort5(11, 128, false));
    const double l0 = calm.Fft()->Cascades()[0].patch_m;
    const glm::vec3 up = calm.At(2.0)->DetailNormal(10.0, 20.0, float(2.0 * l0));
    EXPECT_NEAR(up.z, 1.0, 1e-6);
}

TEST(OceanSurface, RejectsAHeightWithoutWind) {
    OceanSettings o = PiersonMoskowitz(0.0, 50.0);
    o.spectral->sea.windSpeed_mps = 0.0;
    o.spectral->sea.spectrum.significantHeight_m = 2.0;
    EXPECT_THROW(OceanSurface{o}, InputError);
}

}  // namespace
}  // namespace seasense::scene
