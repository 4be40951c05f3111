// The sampling kernel's measured MTF against analytic diffraction × aberration × footprint.
#include "sensors/thermal/optics_kernel.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "radiometry/bands/band.h"
#include "scene/core/error.h"

namespace seasense::sensors {
namespace {

constexpr double kPi = std::numbers::pi;

// A 0.01 %-wide band at 10 µm: effectively monochromatic, so the reference MTF is the
// single-wavelength Goodman formula.
radiometry::Band MonochromaticBand() {
    return radiometry::Band::Flat("mono10um", 9.9995e-6, 10.0005e-6);
}

// Goodman, "Introduction to Fourier Optics", eq. 6-32, written out again here.
double ReferenceDiffraction(double nu_per_m, double lambda_m, double fNumber) {
    const double x = nu_per_m * lambda_m * fNumber;
    if (x >= 1.0) return 0.0;
    return 2.0 / kPi * (std::acos(x) - x * std::sqrt(1.0 - x * x));
}

double ReferenceSinc(double x) { return x == 0.0 ? 1.0 : std::sin(x) / x; }

// Images 1 + ½cos(2π(fx·X + fy·Y)) (X, Y in pixels on the focal plane, point-sampled at the
// supersample centres), applies the kernel and fits a·cos + b·sin + c at the pixel centres
// away from the border; returns the modulation √(a² + b²)/½.
double MeasuredMtf(const SamplingKernel& kernel, double fx, double fy, int w, int h) {
    const int n = kernel.supersamples;
    Image s(w * n, h * n, 1);
    for (int j = 0; j < h * n; ++j)
        for (int i = 0; i < w * n; ++i) {
            const double X = (i + 0.5) / n, Y = (j + 0.5) / n;
            s.At(i, j)[0] = float(1.0 + 0.5 * std::cos(2.0 * kPi * (fx * X + fy * Y)));
        }
    const Image p = ApplySamplingKernel(s, kernel);
    // Normal equations of the three-term least-squares fit.
    double A[3][3] = {}, r[3] = {};
    const int margin = kernel.size / n + 2;
    for (int y = margin; y < h - margin; ++y)
        for (int x = margin; x < w - margin; ++x) {
            const double ph = 2.0 * kPi * (fx * (x + 0.5) + fy * (y + 0.5));
            const double basis[3] = {std::cos(ph), std::sin(ph), 1.0};
            for (int a = 0; a < 3; ++a) {
                r[a] += basis[a] * p.At(x, y)[0];
                for (int b = 0; b < 3; ++b) A[a][b] += basis[a] * basis[b];
            }
        }
    // Gaussian elimination (the system is well conditioned: many pixels, non-zero frequency).
    for (int c = 0; c < 3; ++c)
        for (int rr = c + 1; rr < 3; ++rr) {
            const double f = A[rr][c] / A[c][c];
            for (int k = c; k < 3; ++k) A[rr][k] -= f * A[c][k];
            r[rr] -= f * r[c];
        }
    double sol[3];
    for (int c = 2; c >= 0; --c) {
        double v = r[c];
        for (int k = c + 1; k < 3; ++k) v -= A[c][k] * sol[k];
        sol[c] = v / A[c][c];
    }
    return std::hypot(sol[0], sol[1]) / 0.5;
}

struct Case {
    double fNumber, fill, sigma_px;
    int n;
};

TEST(OpticsKernel, MeasuredMtfMatchesAnalyticDiffractionAberrationFootprintProduct) {
    const double pitch = 17e-6, lambda = 10e-6;
    for (const Case& c : {Case{1.0, 1.0, 0.0, 2}, Case{1.0, 1.0, 0.0, 4}, Case{2.0, 0.64, 0.3, 3},
                          Case{1.4, 0.8, 0.0, 2}}) {
        OpticsGeometry g;
        g.fNumber = c.fNumber;
        g.pitch_m = pitch;
        g.fillFactor = c.fill;
        g.aberrationSigma_m = c.sigma_px * pitch;
        const SamplingKernel kernel = BuildSamplingKernel(
            MonochromaticBand(), g, c.n, SamplingKernelRadius_px(MonochromaticBand(), g, 4));
        // Frequencies (cycles/pixel) chosen off the kernel's DFT bins (multiples of 1/8).
        const double freqs[][2] = {{0.07, 0.0}, {0.19, 0.0},  {0.0, 0.31},
                                   {0.45, 0.0}, {0.21, 0.21}, {0.33, -0.17}};
        for (const auto& f : freqs) {
            const double nx = f[0] / pitch, ny = f[1] / pitch;
            const double nu = std::hypot(nx, ny);
            const double a = pitch * std::sqrt(c.fill);
            const double expected =
                ReferenceDiffraction(nu, lambda, c.fNumber) *
                std::exp(-2.0 * kPi * kPi * std::pow(g.aberrationSigma_m * nu, 2)) *
                ReferenceSinc(kPi * a * nx) * ReferenceSinc(kPi * a * ny);
            const double measured = MeasuredMtf(kernel, f[0], f[1], 96, 64);
            EXPECT_NEAR(measured, expected, 0.02)
                << "F/" << c.fNumber << " fill " << c.fill << " N " << c.n << " f (" << f[0] << ", "
                << f[1] << ") cy/px";
        }
    }
}

// The plain definition of the sampling: out(x, y) = Σ_ij taps[i][j]·S(clamp(n·x + o + j),
// clamp(n·y + o + i)), o = (n − K)/2, summed in double over the full K×K taps.
Image ReferenceSampling(const Image& s, const SamplingKernel& k) {
    const int n = k.supersamples, K = k.size, o = (n - K) / 2;
    Image out(s.width / n, s.height / n, 1);
    for (int y = 0; y < out.height; ++y)
        for (int x = 0; x < out.width; ++x) {
            double sum = 0.0;
            for (int i = 0; i < K; ++i)
                for (int j = 0; j < K; ++j) {
                    const int sx = std::clamp(n * x + o + j, 0, s.width - 1);
                    const int sy = std::clamp(n * y + o + i, 0, s.height - 1);
                    sum += double(k.taps[size_t(i * k.padded + j)]) * s.At(sx, sy)[0];
                }
            out.At(x, y)[0] = float(sum);
        }
    return out;
}

TEST(OpticsKernel, FoldedPhaseSamplingEqualsTheDirectConvolution) {
    // Odd and even N (odd and even K), image widths that are not a multiple of the 16-pixel
    // step, kernels wider than the image: every path of SampleKernelRow against the definition.
    OpticsGeometry g;
    g.fNumber = 1.2;
    g.fillFactor = 0.8;
    g.aberrationSigma_m = 4e-6;
    for (int n : {1, 2, 3})
        for (int w : {5, 23, 40}) {
            const SamplingKernel k = BuildSamplingKernel(radiometry::Band::Lwir(), g, n, 4);
            const int h = 7;
            Image s(w * n, h * n, 1);
            for (int y = 0; y < s.height; ++y)
                for (int x = 0; x < s.width; ++x)
                    s.At(x, y)[0] =
                        float(30.0 + 10.0 * std::sin(0.7 * x + 1.3 * y) + (x * 7 + y * 3) % 11);
            const Image fast = ApplySamplingKernel(s, k), ref = ReferenceSampling(s, k);
            for (size_t i = 0; i < ref.pixels.size(); ++i)
                ASSERT_NEAR(fast.pixels[i], ref.pixels[i], 2e-6 * ref.pixels[i])
                    << "N " << n << " w " << w << " pixel " << i;
        }
}

TEST(OpticsKernel, WidePathEqualsTheFourLanePathBitForBit) {
    // The AVX path (eight pixels to a lane group) against the SSE2 path: the same operations per
    // pixel in the same order, so equal bits, for odd and even K, widths that are not a multiple
    // of either step, and kernels wider than the image.
    if (!SamplingKernelWidePath()) GTEST_SKIP() << "no AVX on this CPU";
    OpticsGeometry g;
    g.fNumber = 1.2;
    g.aberrationSigma_m = 4e-6;
    for (int n : {1, 2, 3})
        for (int w : {5, 23, 40, 77}) {
            const SamplingKernel k = BuildSamplingKernel(radiometry::Band::Lwir(), g, n, 4);
            Image s(w * n, 9 * n, 1);
            for (int y = 0; y < s.height; ++y)
                for (int x = 0; x < s.width; ++x)
                    s.At(x, y)[0] = float(20.0 + 15.0 * std::sin(0.9 * x - 0.4 * y) + (x * y) % 7);
            const Image wide = ApplySamplingKernel(s, k, true);
            const Image narrow = ApplySamplingKernel(s, k, false);
            ASSERT_EQ(wide.pixels.size(), narrow.pixels.size());
            for (size_t i = 0; i < wide.pixels.size(); ++i)
                ASSERT_EQ(std::bit_cast<uint32_t>(wide.pixels[i]),
                          std::bit_cast<uint32_t>(narrow.pixels[i]))
                    << "N " << n << " w " << w << " pixel " << i;
        }
}

// The folded sum SampleKernelRow documents, in float, pixel by pixel: per folded row i (sample
// rows i and K − 1 − i summed, the centre row of an odd K alone), per column pair p (columns p
// and K − 1 − p of the folded row summed), acc += (0 + tap(i, p))·pair, then the centre column
// of an odd K; edges clamp.
Image FoldedSampling(const Image& s, const SamplingKernel& k) {
    const int n = k.supersamples, K = k.size, o = (n - K) / 2;
    Image out(s.width / n, s.height / n, 1);
    for (int y = 0; y < out.height; ++y)
        for (int x = 0; x < out.width; ++x) {
            float acc = 0.0f;
            for (int i = 0; i < (K + 1) / 2; ++i) {
                const int ya = std::clamp(n * y + o + i, 0, s.height - 1);
                const int yb = std::clamp(n * y + o + K - 1 - i, 0, s.height - 1);
                const auto folded = [&](int j) {
                    const int c = std::clamp(n * x + o + j, 0, s.width - 1);
                    return 2 * i + 1 == K ? s.At(c, ya)[0] : s.At(c, ya)[0] + s.At(c, yb)[0];
                };
                const auto tap = [&](int j) { return 0.0f + k.taps[size_t(i * k.padded + j)]; };
                for (int p = 0; p < K / 2; ++p)
                    acc = acc + tap(p) * (folded(p) + folded(K - 1 - p));
                if (K % 2 == 1) acc = acc + tap(K / 2) * folded(K / 2);
            }
            out.At(x, y)[0] = acc;
        }
    return out;
}

TEST(OpticsKernel, SamplingEqualsTheFoldedFloatSumBitForBit) {
    // Both lane widths against the folded order written out pixel by pixel: odd and even K,
    // widths below, at and between multiples of the 40- and 80-pixel steps, kernels wider than
    // the image, so the steps, the partial last step and the clamped edges all agree bit for
    // bit.
    OpticsGeometry g;
    g.fNumber = 1.0;
    g.fillFactor = 0.8;
    for (int n : {1, 2, 3})
        for (int w : {3, 23, 40, 80, 81, 163}) {
            const SamplingKernel k = BuildSamplingKernel(radiometry::Band::Lwir(), g, n, 4);
            Image s(w * n, 6 * n, 1);
            for (int y = 0; y < s.height; ++y)
                for (int x = 0; x < s.width; ++x)
                    s.At(x, y)[0] = float(25.0 + 12.0 * std::sin(0.37 * x + 0.81 * y) +
                                          (x * 13 + y * 5) % 17 * 0.1);
            const Image ref = FoldedSampling(s, k);
            for (bool wide : {false, true}) {
                const Image fast = ApplySamplingKernel(s, k, wide);
                ASSERT_EQ(fast.pixels.size(), ref.pixels.size());
                for (size_t i = 0; i < ref.pixels.size(); ++i)
                    ASSERT_EQ(std::bit_cast<uint32_t>(fast.pixels[i]),
                              std::bit_cast<uint32_t>(ref.pixels[i]))
                        << "N " << n << " w " << w << " wide " << wide << " pixel " << i;
            }
        }
}

TEST(OpticsKernel, TapsAreEvenInBothAxesBitForBit) {
    OpticsGeometry g;
    g.fillFactor = 0.7;
    for (int n : {1, 2, 3}) {
        const SamplingKernel k = BuildSamplingKernel(radiometry::Band::Lwir(), g, n, 3);
        const int K = k.size;
        for (int i = 0; i < K; ++i)
            for (int j = 0; j < K; ++j) {
                const float t = k.taps[size_t(i * k.padded + j)];
                EXPECT_EQ(t, k.taps[size_t((K - 1 - i) * k.padded + j)]);
                EXPECT_EQ(t, k.taps[size_t(i * k.padded + K - 1 - j)]);
            }
    }
}

TEST(OpticsKernel, UniformSceneKeepsItsRadiance) {
    OpticsGeometry g;
    const SamplingKernel kernel = BuildSamplingKernel(radiometry::Band::Lwir(), g, 2, 4);
    Image s(40, 30, 1);
    for (float& v : s.pixels) v = 38.5f;
    const Image p = ApplySamplingKernel(s, kernel);
    // Edges clamp, so even border pixels see the uniform scene; DC gain is exactly 1.
    for (float v : p.pixels) EXPECT_NEAR(v, 38.5f, 38.5f * 1e-6f);
}

TEST(OpticsKernel, BandMtfLiesBetweenItsEdgeWavelengthsAndCutsOffAtTheShortest) {
    // The monochromatic MTF falls with λ at fixed ν, so any positive spectral weighting over
    // 8–12 µm lies between the 12 µm and 8 µm curves, and vanishes from 1/(8 µm·F#) on.
    const radiometry::Band lwir = radiometry::Band::Lwir();
    const double F = 1.3;
    for (double nu : {5e3, 2e4, 4e4, 6e4, 9e4}) {
        const double m = BandDiffractionMtf(lwir, 300.0, nu, F);
        EXPECT_LE(m, ReferenceDiffraction(nu, 8e-6, F) + 1e-12) << nu;
        EXPECT_GE(m, ReferenceDiffraction(nu, 12e-6, F) - 1e-12) << nu;
    }
    EXPECT_EQ(BandDiffractionMtf(lwir, 300.0, 1.0 / (8e-6 * F) * 1.0001, F), 0.0);
    EXPECT_GT(BandDiffractionMtf(lwir, 300.0, 1.0 / (8e-6 * F) * 0.99, F), 0.0);
    // Small-x slope of Goodman's formula: 1 − (4/π)x + O(x³).
    const double x = 1e-4;
    EXPECT_NEAR(DiffractionMtf(x), 1.0 - 4.0 / kPi * x, 1e-10);
}

TEST(OpticsKernel, BandMtfIsTheContrastWeightedMeanOfMonochromaticMtfs) {
    // Independent reference: 4000-point midpoint rule over 8–12 µm of Goodman's MTF weighted
    // by ∂L_λ/∂T (Planck's law differentiated by hand, CODATA c1, c2).
    const double c1 = 1.191042972e-16, c2 = 1.438776877e-2, T = 300.0, F = 1.0;
    for (double nu : {1e4, 3e4, 6e4, 1e5}) {
        double num = 0.0, den = 0.0;
        const int steps = 4000;
        for (int i = 0; i < steps; ++i) {
            const double l = 8e-6 + (i + 0.5) * 4e-6 / steps;
            const double e = std::exp(c2 / (l * T));
            const double dLdT = c1 / std::pow(l, 5) * e * c2 / (l * T * T) / ((e - 1) * (e - 1));
            num += dLdT * ReferenceDiffraction(nu, l, F);
            den += dLdT;
        }
        EXPECT_NEAR(BandDiffractionMtf(radiometry::Band::Lwir(), T, nu, F), num / den, 1e-5) << nu;
    }
}

TEST(OpticsKernel, FootprintIsZeroAtTheInverseWidthAndTwoOverPiAtNyquist) {
    const double p = 17e-6;
    EXPECT_NEAR(FootprintOtf(1.0 / p, p), 0.0, 1e-12);
    EXPECT_NEAR(FootprintOtf(0.5 / p, p), 2.0 / kPi, 1e-12);  // 0.637 (physics.md)
    EXPECT_NEAR(GaussianBlurMtf(1.0 / (2.0 * kPi * 1e-6), 1e-6), std::exp(-0.5), 1e-12);
}

TEST(OpticsKernel, RejectsBadGeometry) {
    OpticsGeometry g;
    g.fillFactor = 1.5;
    EXPECT_THROW(BuildSamplingKernel(radiometry::Band::Lwir(), g, 2, 4), InputError);
    g = OpticsGeometry{};
    EXPECT_THROW(BuildSamplingKernel(radiometry::Band::Lwir(), g, 0, 4), InputError);
    EXPECT_THROW(BuildSamplingKernel(radiometry::Band::Lwir(), g, 40, 4), InputError);
}

}  // namespace
}  // namespace seasense::sensors
