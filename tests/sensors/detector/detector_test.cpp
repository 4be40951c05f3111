// Detector footprint integration against the discrete box-filter transfer function.
#include "sensors/detector/detector.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

namespace seasense::sensors {
namespace {

TEST(Detector, BoxFootprintAttenuatesASineByTheDiscreteSinc) {
    // The mean of n point samples at offsets (k + ½)/n of sin(2π f x + φ) is a sine of the
    // same phase scaled by sin(π f) / (n sin(π f / n)) (sum of a geometric series); n → ∞
    // gives the detector-footprint MTF |sinc(π a f)| of physics.md.
    const int n = 8, width = 64;
    for (double f : {0.05, 0.2, 0.37, 0.5}) {
        Image s(width * n, n, 1);  // one row of pixels, n sample rows of the same signal
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < width * n; ++i)
                s.At(i, j)[0] = float(std::sin(2.0 * M_PI * f * (i + 0.5) / n + 0.3));
        const Image p = IntegrateFootprint(s, n);
        const double gain = std::sin(M_PI * f) / (n * std::sin(M_PI * f / n));
        for (int x = 0; x < width; ++x)
            EXPECT_NEAR(p.At(x, 0)[0], gain * std::sin(2.0 * M_PI * f * (x + 0.5) + 0.3), 2e-6);
    }
}

TEST(Detector, EachPixelIsTheMeanOfItsSamplesAndTheImageMeanIsConserved) {
    for (int n : {2, 3}) {
        for (int c : {1, 3}) {
            Image s(12 * n, 6 * n, c);
            for (size_t i = 0; i < s.pixels.size(); ++i) s.pixels[i] = float((i * 7919) % 101);
            const Image p = IntegrateFootprint(s, n);
            ASSERT_EQ(p.width, 12);
            ASSERT_EQ(p.height, 6);
            double a = 0, b = 0;
            for (float v : s.pixels) a += v;
            for (float v : p.pixels) b += v;
            EXPECT_NEAR(a / double(s.pixels.size()), b / double(p.pixels.size()), 1e-4);
            for (int y = 0; y < 6; ++y)
                for (int x = 0; x < 12; ++x)
                    for (int k = 0; k < c; ++k) {
                        double mean = 0;
                        for (int sy = 0; sy < n; ++sy)
                            for (int sx = 0; sx < n; ++sx) mean += s.At(x * n + sx, y * n + sy)[k];
                        EXPECT_NEAR(p.At(x, y)[k], mean / (n * n), 1e-4);
                    }
        }
    }
}

TEST(Detector, AutoExposureMapsGeometricMeanLuminanceToKey) {
    // Half the pixels at 10 cd/m², half at 1000: the geometric mean is 100 cd/m².
    Image img(4, 2, 3);
    for (int x = 0; x < 4; ++x)
        for (int y = 0; y < 2; ++y)
            for (int c = 0; c < 3; ++c) img.At(x, y)[c] = (x + y) % 2 ? 10.0f : 1000.0f;
    EXPECT_NEAR(LogAverageLuminance(img), 100.0, 1e-3);
    EXPECT_NEAR(AutoExposureEv(img, 0.18), std::log2(0.18 / 100.0), 1e-5);
}

TEST(Detector, LogAverageLuminanceIsTheGeometricMeanOverTwentyDecades) {
    // Luminances from 1e-6 to 1e13 cd/m² (below δ, night sky, day, the sun's disc), with
    // black and a row width that is not a multiple of the blocks LogAverageLuminance uses:
    // exp of the mean of ln(δ + Y), summed here one logarithm per pixel in long double.
    Image img(37, 5, 3);
    long double sum = 0.0L;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            const int k = y * img.width + x;
            const float Y =
                k % 11 == 0 ? 0.0f : float(std::pow(10.0, -6.0 + 19.0 * (k % 97) / 96.0));
            for (int c = 0; c < 3; ++c) img.At(x, y)[c] = Y;  // grey: luminance Y
            sum += std::log(1e-4L + (long double)(img.At(x, y)[0]) * 0.2126L +
                            (long double)(img.At(x, y)[1]) * 0.7152L +
                            (long double)(img.At(x, y)[2]) * 0.0722L);
        }
    const double expected = double(std::exp(sum / (img.width * img.height)));
    EXPECT_NEAR(LogAverageLuminance(img) / expected, 1.0, 1e-12);
}

TEST(Detector, LogAverageLuminanceOfANonFiniteImageIsNotFinite) {
    Image img(20, 2, 3);
    std::fill(img.pixels.begin(), img.pixels.end(), 5.0f);
    img.At(17, 1)[1] = std::numeric_limits<float>::infinity();
    EXPECT_TRUE(std::isinf(LogAverageLuminance(img)));
    img.At(3, 0)[0] = std::numeric_limits<float>::quiet_NaN();
    EXPECT_TRUE(std::isnan(LogAverageLuminance(img)));
    // A NaN with its sign bit set (x86's default NaN, e.g. of 0 · ∞), in a group of four and
    // among the last pixels of a row.
    for (const int x : {5, 21}) {
        Image row(22, 2, 3);
        std::fill(row.pixels.begin(), row.pixels.end(), 5.0f);
        row.At(x, 1)[2] = -std::numeric_limits<float>::quiet_NaN();
        EXPECT_TRUE(std::isnan(LogAverageLuminance(row))) << x;
    }
}

TEST(Detector, FusedFootprintAndLogAverageEqualTheTwoPassesBitForBit) {
    // Random radiances over many decades (some negative, some zero), with odd and even widths,
    // widths below a block and not a multiple of four, 2×2 RGB (the SSE2 path) and the
    // general path (n = 1, 3; four channels), and a row with an inf.
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> decade(-6.0f, 6.0f), unit(0.0f, 1.0f);
    struct Case {
        int width, height, n, channels;
    };
    for (const Case& k : {Case{1, 1, 2, 3}, Case{3, 2, 2, 3}, Case{17, 5, 2, 3}, Case{64, 4, 2, 3},
                          Case{101, 7, 2, 3}, Case{640, 3, 2, 3}, Case{21, 3, 1, 3},
                          Case{19, 4, 3, 3}, Case{13, 3, 2, 4}}) {
        Image s(k.width * k.n, k.height * k.n, k.channels);
        for (float& v : s.pixels) {
            const float u = unit(rng);
            v = u < 0.05f ? 0.0f : (u < 0.1f ? -unit(rng) : std::pow(10.0f, decade(rng)));
        }
        for (const bool inf : {false, true}) {
            if (inf) s.At(s.width - 1, s.height - 1)[0] = std::numeric_limits<float>::infinity();
            const Image twoPass = IntegrateFootprint(s, k.n);
            const double expected = LogAverageLuminance(twoPass);
            Image fused(1, 1, 1);  // resized by the call
            const double lavg = IntegrateFootprintLogAverage(s, k.n, fused);
            EXPECT_EQ(std::bit_cast<uint64_t>(lavg), std::bit_cast<uint64_t>(expected))
                << k.width << "×" << k.height << " n " << k.n << " c " << k.channels << " inf "
                << inf;
            ASSERT_EQ(fused.width, twoPass.width);
            ASSERT_EQ(fused.height, twoPass.height);
            ASSERT_EQ(fused.channels, twoPass.channels);
            for (size_t i = 0; i < fused.pixels.size(); ++i)
                ASSERT_EQ(std::bit_cast<uint32_t>(fused.pixels[i]),
                          std::bit_cast<uint32_t>(twoPass.pixels[i]))
                    << i;
            EXPECT_EQ(std::bit_cast<uint64_t>(ExposureEv(lavg, 0.18)),
                      std::bit_cast<uint64_t>(AutoExposureEv(twoPass, 0.18)));
            EXPECT_EQ(std::bit_cast<uint64_t>(ExposureEv(lavg, AdaptedKey(lavg))),
                      std::bit_cast<uint64_t>(AdaptedExposureEv(twoPass)));
        }
    }
}

TEST(Detector, AdaptedExposureKeepsNightDarkerThanDay) {
    // Krawczyk et al. 2005, eq. 11: α(L) = 1.03 − 2 / (2 + log10(L + 1)). At L = 99 cd/m²
    // log10(L + 1) = 2 and α = 0.53; at L = 0 α = 0.03 (the formula's floor); α rises with L.
    EXPECT_NEAR(AdaptedKey(99.0), 0.53, 1e-12);
    EXPECT_NEAR(AdaptedKey(0.0), 0.03, 1e-12);
    // A uniform daylight scene (100 cd/m²) and the same scene a million times dimmer
    // (moonlight): auto exposure shows both as mid-grey, adaptation shows the night darker,
    // with display values α(L) each.
    Image day(2, 2, 3), night(2, 2, 3);
    for (size_t i = 0; i < day.pixels.size(); ++i) day.pixels[i] = 100.0f;
    for (size_t i = 0; i < night.pixels.size(); ++i) night.pixels[i] = 1e-4f;
    const auto display = [](const Image& img, double ev) {
        return LogAverageLuminance(img) * std::exp2(ev);
    };
    EXPECT_NEAR(display(day, AutoExposureEv(day, 0.18)),
                display(night, AutoExposureEv(night, 0.18)), 1e-6);
    const double dayKey = display(day, AdaptedExposureEv(day));
    const double nightKey = display(night, AdaptedExposureEv(night));
    EXPECT_NEAR(dayKey, 1.03 - 2.0 / (2.0 + std::log10(100.0 + 1e-4 + 1.0)), 1e-6);
    EXPECT_LT(nightKey, 0.05);
    EXPECT_GT(dayKey, 10.0 * nightKey);
}

}  // namespace
}  // namespace seasense::sensors
