// Thermal imager against radiometric and statistical facts: NETD, FPN, NUC, lag, ADC, threads.
#include "sensors/thermal/thermal_imager.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <numbers>
#include <vector>

#include "radiometry/planck/planck.h"
#include "scene/core/error.h"
#include "scene/core/rng.h"
#include "sensors/thermal/normal_deviates.h"
#include "sensors/thermal/optics_kernel.h"

namespace seasense::sensors {
namespace {

constexpr double kPi = std::numbers::pi;

// Camera equation E = τπL/(4F² + 1) (Holst), written out independently of the imager.
double ReferenceIrradiance(double L, const ThermalImagerSettings& s) {
    return s.opticsTransmission * kPi * L / (4.0 * s.fNumber * s.fNumber + 1.0);
}

// Signal per kelvin at T: dE/dT from the exact band radiance derivative.
double ReferenceSignalPerKelvin(const ThermalImagerSettings& s, double T) {
    return ReferenceIrradiance(radiometry::BandRadianceDerivative(radiometry::Band::Lwir(), T), s);
}

ThermalImagerSettings SmallSettings(int w, int h) {
    ThermalImagerSettings s;
    s.width_px = w;
    s.height_px = h;
    s.netd_K = 0.0;
    s.agc.timeConstant_s = 0.0;
    return s;
}

Image Uniform(int w, int h, int n, double radiance) {
    Image img(w * n, h * n, 1);
    for (float& v : img.pixels) v = float(radiance);
    return img;
}

double LwirRadiance(double T) { return radiometry::BandRadiance(radiometry::Band::Lwir(), T); }

double StdDev(const std::vector<double>& v) {
    double mean = 0.0;
    for (double x : v) mean += x;
    mean /= double(v.size());
    double var = 0.0;
    for (double x : v) var += (x - mean) * (x - mean);
    return std::sqrt(var / double(v.size() - 1));
}

TEST(ThermalImager, TemporalNoiseInKelvinEqualsNetd) {
    // Lab procedure: SiTF from the mean counts of uniform blackbodies at 299 and 301 K, then
    // NETD = pooled per-pixel temporal std of 64 frames at 300 K / SiTF (physics.md: NETD =
    // σ/SiTF).
    const int w = 64, h = 48, frames = 64;
    ThermalImagerSettings s = SmallSettings(w, h);
    s.netd_K = 0.050;
    auto meanCounts = [&](double T) {
        ThermalImager imager(s, radiometry::Band::Lwir(), 1);
        const Image scene = Uniform(w, h, 1, LwirRadiance(T));
        double sum = 0.0;
        for (int f = 0; f < 16; ++f) {
            imager.Process(scene, f / 30.0);
            for (uint16_t c : imager.Counts()) sum += c;
        }
        return sum / (16.0 * w * h);
    };
    const double sitf = (meanCounts(301.0) - meanCounts(299.0)) / 2.0;  // counts/K
    // The ADC maps E(240 K) … E(340 K) onto 0 … 16383.
    const double analyticSitf =
        16383.0 * ReferenceSignalPerKelvin(s, 300.0) /
        (ReferenceIrradiance(LwirRadiance(340.0), s) - ReferenceIrradiance(LwirRadiance(240.0), s));
    EXPECT_NEAR(sitf, analyticSitf, 0.005 * analyticSitf);

    ThermalImager imager(s, radiometry::Band::Lwir(), 1);
    const Image scene = Uniform(w, h, 1, LwirRadiance(300.0));
    std::vector<double> sum(size_t(w * h), 0.0), sum2(size_t(w * h), 0.0);
    for (int f = 0; f < frames; ++f) {
        imager.Process(scene, f / 30.0);
        for (size_t i = 0; i < sum.size(); ++i) {
            const double c = imager.Counts()[i];
            sum[i] += c;
            sum2[i] += c * c;
        }
    }
    double pooled = 0.0;
    for (size_t i = 0; i < sum.size(); ++i)
        pooled += (sum2[i] - sum[i] * sum[i] / frames) / (frames - 1);
    const double netd = std::sqrt(pooled / double(sum.size())) / sitf;
    EXPECT_NEAR(netd, 0.050, 0.05 * 0.050);
}

// Spatial statistics of a noise-free uniform 300 K frame with the given pattern settings:
// the signal offsets in kelvin (signal − ideal)/(dE/dT), and the relative gains signal/ideal.
struct PatternFrame {
    std::vector<double> offset_K;
    int w, h;
};

PatternFrame PatternOf(ThermalImagerSettings s) {
    ThermalImager imager(s, radiometry::Band::Lwir(), 1);
    const double L = LwirRadiance(300.0);
    imager.Process(Uniform(s.width_px, s.height_px, 1, L), 0.0);
    const double ideal = ReferenceIrradiance(L, s);
    const double perK = ReferenceSignalPerKelvin(s, 300.0);
    PatternFrame p{{}, s.width_px, s.height_px};
    for (float v : imager.Signal().pixels) p.offset_K.push_back((v - ideal) / perK);
    return p;
}

TEST(ThermalImager, FixedPatternStatisticsMatchTheirSettings) {
    const int n = 384;  // std of a std estimate from n values: 1/√(2(n−1)) ≈ 3.6 %
    {
        ThermalImagerSettings s = SmallSettings(n, n);
        s.offsetFpn_K = 0.3;
        EXPECT_NEAR(StdDev(PatternOf(s).offset_K), 0.3, 0.02 * 0.3);  // n² values: 0.2 %
    }
    {
        ThermalImagerSettings s = SmallSettings(n, n);
        s.gainFpn = 0.04;
        const PatternFrame p = PatternOf(s);
        // Gain g on E: (g − 1)·E/(dE/dT) kelvin; E/(dE/dT) = L/(dL/dT).
        const double scale = LwirRadiance(300.0) /
                             radiometry::BandRadianceDerivative(radiometry::Band::Lwir(), 300.0);
        EXPECT_NEAR(StdDev(p.offset_K) / scale, 0.04, 0.02 * 0.04);
    }
    for (bool rows : {true, false}) {
        ThermalImagerSettings s = SmallSettings(n, n);
        (rows ? s.rowFpn_K : s.columnFpn_K) = 0.2;
        const PatternFrame p = PatternOf(s);
        std::vector<double> lineMeans(size_t(n), 0.0);
        double within = 0.0;  // a row pattern is constant along its row, and vice versa
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const double v = p.offset_K[size_t(y * n + x)];
                lineMeans[size_t(rows ? y : x)] += v / n;
            }
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x)
                within = std::max(within, std::abs(p.offset_K[size_t(y * n + x)] -
                                                   lineMeans[size_t(rows ? y : x)]));
        EXPECT_NEAR(StdDev(lineMeans), 0.2, 0.12 * 0.2) << (rows ? "rows" : "columns");
        EXPECT_LT(within, 1e-4) << (rows ? "rows" : "columns");
    }
}

TEST(ThermalImager, TwoPointNucRemovesTheFixedPattern) {
    const int w = 96, h = 72, frames = 16;
    ThermalImagerSettings s = SmallSettings(w, h);
    s.netd_K = 0.05;
    s.offsetFpn_K = 0.5;
    s.gainFpn = 0.05;
    s.rowFpn_K = 0.1;
    s.columnFpn_K = 0.1;
    // Spatial std (K) of the frame mean over `frames` frames at T.
    auto spatialStd = [&](bool nuc, double T) {
        ThermalImagerSettings t = s;
        t.nuc = nuc;
        ThermalImager imager(t, radiometry::Band::Lwir(), 1);
        const Image scene = Uniform(w, h, 1, LwirRadiance(T));
        std::vector<double> mean(size_t(w * h), 0.0);
        for (int f = 0; f < frames; ++f) {
            imager.Process(scene, f / 30.0);
            for (size_t i = 0; i < mean.size(); ++i) mean[i] += imager.Signal().pixels[i] / frames;
        }
        return StdDev(mean) / ReferenceSignalPerKelvin(s, T);
    };
    for (double T : {300.0, 330.0}) {
        const double before = spatialStd(false, T), after = spatialStd(true, T);
        EXPECT_GT(before, 0.4) << T;
        EXPECT_LT(after, 0.1 * before) << T;
    }
}

TEST(ThermalImager, BolometerLagFollowsTheExponentialStepResponse) {
    const int w = 16, h = 12;
    for (double tau : {0.010, 0.0}) {
        ThermalImagerSettings s = SmallSettings(w, h);
        s.timeConstant_s = tau;
        ThermalImager imager(s, radiometry::Band::Lwir(), 2);
        const double L1 = LwirRadiance(280.0), L2 = LwirRadiance(320.0);
        imager.Process(Uniform(w, h, 2, L1), 0.0);
        const Image hot = Uniform(w, h, 2, L2);
        // Uneven frame intervals: the response depends on elapsed time only.
        double t = 0.0;
        for (double dt : {1.0 / 60, 1.0 / 30, 1.0 / 120, 1.0 / 60, 1.0 / 60}) {
            t += dt;
            imager.Process(hot, t);
            const double fraction = tau > 0 ? 1.0 - std::exp(-t / tau) : 1.0;
            const double expected = s.opticsTransmission * (L1 + (L2 - L1) * fraction);
            for (int y = 0; y < h; y += 5)
                for (int x = 0; x < w; x += 5)
                    EXPECT_NEAR(
                        (imager.Radiance().At(x, y)[0] - s.opticsTransmission * L1) /
                            (s.opticsTransmission * (L2 - L1)),
                        (expected - s.opticsTransmission * L1) / (s.opticsTransmission * (L2 - L1)),
                        1e-6)
                        << "tau " << tau << " t " << t;
        }
    }
}

// After Restart the next frame starts settled (the bolometer at the scene's radiance, the AGC
// taking its mapping directly), as a new imager's first frame does, bit for bit; time may start
// over.
TEST(ThermalImager, RestartForgetsTheLagAndTheAgc) {
    const int w = 16, h = 12;
    ThermalImagerSettings s = SmallSettings(w, h);
    s.timeConstant_s = 0.010;
    ThermalImager used(s, radiometry::Band::Lwir(), 2), fresh(s, radiometry::Band::Lwir(), 2);
    used.Process(Uniform(w, h, 2, LwirRadiance(280.0)), 0.0, 0);
    used.Process(Uniform(w, h, 2, LwirRadiance(290.0)), 1.0 / 30, 1);
    used.Restart();
    EXPECT_EQ(used.FramesProcessed(), 0);
    const Image hot = Uniform(w, h, 2, LwirRadiance(320.0));
    used.Process(hot, 0.0, 1);
    fresh.Process(hot, 0.0, 1);
    for (int y = 0; y < h; y += 5)
        for (int x = 0; x < w; x += 5)
            EXPECT_NEAR(used.Radiance().At(x, y)[0] / (s.opticsTransmission * LwirRadiance(320.0)),
                        1.0, 1e-6);
    EXPECT_TRUE(used.Radiance().pixels == fresh.Radiance().pixels);
    EXPECT_TRUE(std::equal(used.Counts().begin(), used.Counts().end(), fresh.Counts().begin(),
                           fresh.Counts().end()));
    EXPECT_TRUE(std::equal(used.Display().begin(), used.Display().end(), fresh.Display().begin(),
                           fresh.Display().end()));
}

TEST(ThermalImager, AdcRoundsAndClampsToFourteenBits) {
    const int w = 4, h = 4;
    ThermalImagerSettings s = SmallSettings(w, h);
    s.timeConstant_s = 0.0;  // each frame settles at once
    const double e240 = ReferenceIrradiance(LwirRadiance(240.0), s);
    const double e340 = ReferenceIrradiance(LwirRadiance(340.0), s);
    const double gain = 16383.0 / (e340 - e240);
    // Scene radiance whose signal lands on `count` counts exactly.
    auto radianceFor = [&](double count) {
        return (count / gain + e240) * (4.0 * s.fNumber * s.fNumber + 1.0) /
               (s.opticsTransmission * kPi);
    };
    ThermalImager imager(s, radiometry::Band::Lwir(), 1);
    struct Probe {
        double radiance;
        int expected;
    };
    const Probe probes[] = {{radianceFor(1234.3), 1234},   {radianceFor(1234.7), 1235},
                            {radianceFor(9000.2), 9000},   {radianceFor(16382.3), 16382},
                            {radianceFor(16382.8), 16383}, {LwirRadiance(339.0), -1},
                            {radianceFor(-0.7), 0},        {LwirRadiance(200.0), 0},
                            {LwirRadiance(400.0), 16383},  {LwirRadiance(2000.0), 16383}};
    double t = 0.0;
    for (const Probe& p : probes) {
        imager.Process(Uniform(w, h, 1, p.radiance), t += 0.01);
        const int expected =
            p.expected >= 0 ? p.expected
                            : int(std::lround(gain * (ReferenceIrradiance(p.radiance, s) - e240)));
        for (uint16_t c : imager.Counts()) EXPECT_EQ(int(c), expected) << p.radiance;
    }
}

TEST(ThermalImager, BlackbodyPlateReadsItsTemperature) {
    const int w = 64, h = 48, n = 2;
    for (double tau : {1.0, 0.9}) {
        ThermalImagerSettings s = SmallSettings(w, h);
        s.opticsTransmission = tau;
        ThermalImager imager(s, radiometry::Band::Lwir(), n);
        // A 305.37 K plate over the middle, 280 K around it; pixels farther than the kernel
        // radius from the plate edge see only the plate.
        Image scene = Uniform(w, h, n, LwirRadiance(280.0));
        for (int y = 8 * n; y < 40 * n; ++y)
            for (int x = 12 * n; x < 52 * n; ++x) scene.At(x, y)[0] = float(LwirRadiance(305.37));
        imager.Process(scene, 0.0);
        const Image T = imager.ApparentTemperature();
        const int r = imager.Kernel().size / (2 * n) + 1;
        for (int y = 8 + r; y < 40 - r; ++y)
            for (int x = 12 + r; x < 52 - r; ++x) EXPECT_NEAR(T.At(x, y)[0], 305.37, 0.05);
        EXPECT_NEAR(T.At(1, 1)[0], 280.0, 0.05);
    }
}

TEST(ThermalImager, PathCorrectedApparentTemperatureInvertsTheRadianceEquation) {
    const radiometry::BandRadianceTable table(radiometry::Band::Lwir());
    for (double T : {250.0, 290.0, 310.0, 600.0})
        for (double tauPath : {1.0, 0.8, 0.35})
            for (double air : {270.0, 300.0}) {
                const double L = tauPath * LwirRadiance(T) + (1.0 - tauPath) * LwirRadiance(air);
                EXPECT_NEAR(ApparentTemperature(table, L, tauPath, air), T, 0.1);
            }
    EXPECT_THROW(ApparentTemperature(table, 30.0, 0.0, 290.0), InputError);
    EXPECT_THROW(ApparentTemperature(table, 30.0, 1.2, 290.0), InputError);
    // A measurement darker than the path alone has no target temperature.
    EXPECT_THROW(ApparentTemperature(table, 0.4 * LwirRadiance(290.0), 0.5, 290.0), InputError);
}

TEST(ThermalImager, RejectsBadSettings) {
    ThermalImagerSettings s = SmallSettings(8, 8);
    s.opticsTransmission = 0.0;
    EXPECT_THROW(ThermalImager(s, radiometry::Band::Lwir(), 2), InputError);
    s = SmallSettings(8, 8);
    s.adcMax_K = 200.0;
    EXPECT_THROW(ThermalImager(s, radiometry::Band::Lwir(), 2), InputError);
    s = SmallSettings(0, 8);
    EXPECT_THROW(ThermalImager(s, radiometry::Band::Lwir(), 2), InputError);
}

// The per-pixel chain written out in scalars from its definition (ThermalImager::Process):
// L = τ·blurred, lagged = y + α(L − y) (L when settled), E = kE·lagged, s = E + float(σ·z),
// counts = clamp(⌊adcGain·s + adcOffset + ½⌋, 0, 16383) (NaN → 0), for an ideal response; the
// deviates z of pixels (x, x + 1), x even, from one hash of (seed, frame, pixel pair).
struct ChainReference {
    std::vector<float> radiance, signal;
    std::vector<uint16_t> counts;
};
ChainReference ReferenceChain(const ThermalImager& imager, const Image& samples,
                              const std::vector<float>& previous, double alpha, int64_t frame) {
    const ThermalImagerSettings& s = imager.Settings();
    const double tau = s.opticsTransmission;
    const double kE = FocalPlaneIrradiance(1.0, tau, s.fNumber) / tau;
    const float sigma = float(imager.NoiseSigma());
    const Image blurred = ApplySamplingKernel(samples, imager.Kernel());
    ChainReference r;
    for (int y = 0; y < s.height_px; ++y)
        for (int x = 0; x < s.width_px; ++x) {
            const size_t i = size_t(y) * size_t(s.width_px) + size_t(x);
            float z[2];
            NormalPair(scene::HashBits(s.seed, (uint64_t(1) << 40) + uint64_t(frame),
                                       (uint64_t(y) << 32) | uint64_t(x / 2)),
                       z[0], z[1]);
            const double L = tau * double(blurred.pixels[i]);
            const double lagged =
                alpha == 1.0 ? L : double(previous[i]) + alpha * (L - double(previous[i]));
            const double E = kE * lagged;
            const double signal = E + double(sigma * z[x % 2]);
            double v = imager.AdcGain() * signal + imager.AdcOffset();
            v = v > 0.0 ? v : 0.0;
            v = v < 16383.0 ? v : 16383.0;
            r.radiance.push_back(float(lagged));
            r.signal.push_back(float(signal));
            r.counts.push_back(uint16_t(int(v + 0.5)));
        }
    return r;
}

TEST(ThermalImager, PixelChainEqualsItsScalarDefinitionBitForBit) {
    // Radiance, signal and counts of a settled first frame and two lagged frames, noise on,
    // a width that is not a multiple of four (the partial last pixel group), and scene values
    // that clip the ADC at both ends.
    const int w = 23, h = 5, n = 2;
    ThermalImagerSettings s = SmallSettings(w, h);
    s.netd_K = 0.05;
    ThermalImager imager(s, radiometry::Band::Lwir(), n);
    Image scene(w * n, h * n, 1);
    std::vector<float> previous;
    double t = 0.0;
    for (int f = 0; f < 3; ++f) {
        for (int y = 0; y < h * n; ++y)
            for (int x = 0; x < w * n; ++x)
                scene.At(x, y)[0] =
                    float(LwirRadiance(220.0 + 5.0 * x + 30.0 * std::sin(0.7 * y + f)));
        const double dt = f == 0 ? 0.0 : 0.004 * f;
        const double alpha = f == 0 ? 1.0 : 1.0 - std::exp(-dt / s.timeConstant_s);
        t += dt;
        const ChainReference ref = ReferenceChain(imager, scene, previous, alpha, f);
        imager.Process(scene, t);
        for (size_t i = 0; i < ref.counts.size(); ++i) {
            ASSERT_EQ(std::bit_cast<uint32_t>(imager.Radiance().pixels[i]),
                      std::bit_cast<uint32_t>(ref.radiance[i]))
                << "frame " << f << " pixel " << i;
            ASSERT_EQ(std::bit_cast<uint32_t>(imager.Signal().pixels[i]),
                      std::bit_cast<uint32_t>(ref.signal[i]))
                << "frame " << f << " pixel " << i;
            ASSERT_EQ(imager.Counts()[i], ref.counts[i]) << "frame " << f << " pixel " << i;
        }
        EXPECT_NE(std::count(ref.counts.begin(), ref.counts.end(), 0), 0);
        EXPECT_NE(std::count(ref.counts.begin(), ref.counts.end(), 16383), 0);
        previous = imager.Radiance().pixels;
    }
}

TEST(ThermalImager, PixelChainOfACalibratedResponseEqualsTheIdealOneBitForBit) {
    // A noiseless one-frame NUC of a pattern-free detector calibrates every pixel to gain 1 and
    // offset 0 exactly, so the per-pixel response path (gain·E + offset + noise) must give the
    // ideal path's bits: loads of the wrong arrays or a different order would not.
    const int w = 23, h = 5, n = 2;
    ThermalImagerSettings s = SmallSettings(w, h);
    ThermalImager ideal(s, radiometry::Band::Lwir(), n);
    s.nuc = true;
    s.nucFrames = 1;
    ThermalImager calibrated(s, radiometry::Band::Lwir(), n);
    Image scene(w * n, h * n, 1);
    for (int f = 0; f < 2; ++f) {
        for (int y = 0; y < h * n; ++y)
            for (int x = 0; x < w * n; ++x)
                scene.At(x, y)[0] = float(LwirRadiance(250.0 + 2.0 * x + 9.0 * y + 7.0 * f));
        ideal.Process(scene, 0.01 * f);
        calibrated.Process(scene, 0.01 * f);
        for (size_t i = 0; i < size_t(w * h); ++i) {
            ASSERT_EQ(std::bit_cast<uint32_t>(calibrated.Radiance().pixels[i]),
                      std::bit_cast<uint32_t>(ideal.Radiance().pixels[i]));
            ASSERT_EQ(std::bit_cast<uint32_t>(calibrated.Signal().pixels[i]),
                      std::bit_cast<uint32_t>(ideal.Signal().pixels[i]));
            ASSERT_EQ(calibrated.Counts()[i], ideal.Counts()[i]);
        }
    }
}

TEST(ThermalImager, OneAndTwoThreadsGiveBitIdenticalFrames) {
    const int w = 80, h = 60, n = 2;
    ThermalImagerSettings s = SmallSettings(w, h);
    s.netd_K = 0.05;
    s.offsetFpn_K = 0.2;
    s.gainFpn = 0.02;
    s.rowFpn_K = 0.05;
    s.nuc = true;
    s.nucFrames = 4;
    s.agc.timeConstant_s = 0.3;
    s.agc.palette = Palette::Ironbow;
    Image scene(w * n, h * n, 1);
    for (int y = 0; y < h * n; ++y)
        for (int x = 0; x < w * n; ++x)
            scene.At(x, y)[0] = float(LwirRadiance(270.0 + 0.3 * x + 20.0 * std::sin(0.1 * y)));
    struct Result {
        std::vector<float> radiance, signal, temperature;
        std::vector<uint16_t> counts;
        std::vector<uint8_t> display;
    };
    auto run = [&](int threads) {
        Result r;
        tbb::task_arena arena(threads);
        arena.execute([&] {
            ThermalImager imager(s, radiometry::Band::Lwir(), n);
            for (int f = 0; f < 3; ++f) imager.Process(scene, f / 30.0);
            r.radiance = imager.Radiance().pixels;
            r.signal = imager.Signal().pixels;
            r.temperature = imager.ApparentTemperature().pixels;
            r.counts.assign(imager.Counts().begin(), imager.Counts().end());
            r.display.assign(imager.Display().begin(), imager.Display().end());
        });
        return r;
    };
    const Result a = run(1), b = run(2);
    auto same = [](const auto& x, const auto& y) {
        return x.size() == y.size() &&
               std::memcmp(x.data(), y.data(), x.size() * sizeof(x[0])) == 0;
    };
    EXPECT_TRUE(same(a.radiance, b.radiance));
    EXPECT_TRUE(same(a.signal, b.signal));
    EXPECT_TRUE(same(a.temperature, b.temperature));
    EXPECT_TRUE(same(a.counts, b.counts));
    EXPECT_TRUE(same(a.display, b.display));
    EXPECT_EQ(a.display.size(), size_t(w * h * 3));
}

}  // namespace
}  // namespace seasense::sensors
