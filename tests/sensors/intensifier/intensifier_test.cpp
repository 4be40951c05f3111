// Image intensifier: photoelectrons from étendue, scintillation SNR √(N/F), ABC hold and lag,
// field stop, halo size, settings and thread-count independence.
#include "sensors/intensifier/intensifier.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "scene/core/rng.h"

namespace seasense::sensors {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

IntensifierSettings Small(int w = 64, int h = 48) {
    IntensifierSettings s;
    s.width_px = w;
    s.height_px = h;
    s.hfov_rad = 51.78 * kDegToRad;
    s.seed = 1234;
    return s;
}

// A uniform scene: every sample (N×N per pixel, 3 sub-bands) at radiance / 3 per sub-band.
Image Uniform(const IntensifierSettings& s, int n, double radiance) {
    Image img(s.width_px * n, s.height_px * n, 3);
    for (float& v : img.pixels) v = float(radiance / 3.0);
    return img;
}

// Mean over the field stop of an image.
double FieldMean(const Intensifier& t, const Image& img) {
    double sum = 0.0;
    int count = 0;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x)
            if (t.InField(x, y)) {
                sum += *img.At(x, y);
                ++count;
            }
    return sum / count;
}

TEST(Intensifier, PhotoelectronsOfUniformLambertianSceneMatchEtendue) {
    IntensifierSettings s = Small(320, 240);
    s.fNumber = 1.4;
    s.opticsTransmission = 0.75;
    s.qePeak = 0.25;
    s.frameTime_s = 1.0 / 60.0;
    const int n = 2;
    Intensifier t(s, n);
    const double L = 3e14;  // photons s⁻¹ m⁻² sr⁻¹
    t.Process(Uniform(s, n, L), 0.0, 0);
    // Entrance pupil area π(f/2F)² times the pixel's solid angle (pitch/f)²: the photon rate
    // through the aperture into one pixel; × QE × τ × t.
    const double f = s.FocalLength_m();
    const double pitch = f * 2.0 * std::tan(0.5 * s.hfov_rad) / s.width_px;
    const double D = f / s.fNumber;
    const double expected = L * std::numbers::pi * D * D / 4.0 * (pitch / f) * (pitch / f) *
                            s.qePeak * s.opticsTransmission * s.frameTime_s;
    EXPECT_NEAR(t.PhotoelectronsPerRadiance() * L / expected, 1.0, 1e-9);
    // The noisy count's field mean (≈ 6e4 pixels) within 1 %.
    EXPECT_NEAR(FieldMean(t, t.Photoelectrons()) / expected, 1.0, 0.01);
    // The focal length puts the 18 mm photocathode behind the 40° field stop.
    EXPECT_NEAR(2.0 * std::atan(9e-3 / f), 40.0 * kDegToRad, 1e-12);
}

// Temporal SNR of each pixel over 64 frames, averaged over the field: √(N/F) within 10 %.
void CheckSnr(double meanPe, double F) {
    IntensifierSettings s = Small(32, 32);
    s.noiseFactor = F;
    Intensifier t(s, 1);
    const double L = meanPe / t.PhotoelectronsPerRadiance();
    const Image scene = Uniform(s, 1, L);
    const size_t px = size_t(s.width_px) * size_t(s.height_px);
    std::vector<double> sum(px, 0.0), sum2(px, 0.0);
    const int frames = 64;
    for (int k = 0; k < frames; ++k) {
        t.Process(scene, k / 30.0, k);
        for (size_t i = 0; i < px; ++i) {
            const double v = t.Photoelectrons().pixels[i];
            sum[i] += v;
            sum2[i] += v * v;
        }
    }
    // Over the pixels inside the field stop (outside it no light reaches the photocathode).
    double var = 0.0, mean = 0.0;
    int count = 0;
    for (size_t i = 0; i < px; ++i) {
        if (!t.InField(int(i % size_t(s.width_px)), int(i / size_t(s.width_px)))) continue;
        const double m = sum[i] / frames;
        mean += m;
        var += (sum2[i] - frames * m * m) / (frames - 1);
        ++count;
    }
    mean /= double(count);
    var /= double(count);
    EXPECT_NEAR(mean / std::sqrt(var) / std::sqrt(meanPe / F), 1.0, 0.10)
        << "N " << meanPe << " F " << F;
}

TEST(Intensifier, ScintillationSnrIsRootNOverF) {
    CheckSnr(20.0, 2.0);   // few photoelectrons (exact Poisson branch)
    CheckSnr(400.0, 1.6);  // many (normal branch)
}

TEST(Intensifier, AbcHoldsOutputOverADecadeAboveThreshold) {
    IntensifierSettings s = Small();
    s.haloFraction = 0.0;
    for (double k : {2.0, 5.0, 20.0}) {
        Intensifier t(s, 1);
        const double pe = k * s.PixelFramePe(s.abcThreshold_pe_s_mm2);
        t.Process(Uniform(s, 1, pe / t.PhotoelectronsPerRadiance()), 0.0, 0);
        EXPECT_NEAR(FieldMean(t, t.Brightness()) / s.abcLevel, 1.0, 0.02) << k;
    }
    // Below the threshold the gain is at its maximum: output proportional to the input.
    Intensifier t(s, 1);
    const double pe = 0.2 * s.PixelFramePe(s.abcThreshold_pe_s_mm2);
    t.Process(Uniform(s, 1, pe / t.PhotoelectronsPerRadiance()), 0.0, 0);
    EXPECT_NEAR(FieldMean(t, t.Brightness()) / (0.2 * s.abcLevel), 1.0, 0.05);
}

// A step of 25 % (the screen stays below saturation): the gain follows the first-order lag.
TEST(Intensifier, AbcStepResponseHasTheConfiguredTimeConstant) {
    IntensifierSettings s = Small();
    s.abcTimeConstant_s = 0.2;
    s.haloFraction = 0.0;
    Intensifier t(s, 1);
    const double perPe = 1.0 / t.PhotoelectronsPerRadiance();
    const double pe0 = 4.0 * s.PixelFramePe(s.abcThreshold_pe_s_mm2);
    const double dt = 1.0 / 30.0;
    t.Process(Uniform(s, 1, pe0 * perPe), 0.0, 0);
    const double g0 = t.Gain();
    const Image brighter = Uniform(s, 1, 1.25 * pe0 * perPe);
    const double gInf = s.abcLevel / (1.25 * pe0);
    for (int k = 1; k <= 30; ++k) {
        t.Process(brighter, k * dt, k);
        // (g − g∞) = (g0 − g∞)·exp(−t/τ).
        const double expected = gInf + (g0 - gInf) * std::exp(-k * dt / s.abcTimeConstant_s);
        EXPECT_NEAR(t.Gain() / expected, 1.0, 1e-6) << k;
    }
}

// After Restart the next frame starts settled, as a new intensifier's first frame does: its gain
// is the fixed point level / mean photoelectrons at once, not the lagged step from the frames
// before, and the whole frame equals a new intensifier's bit for bit.
TEST(Intensifier, RestartForgetsTheAbcHistory) {
    IntensifierSettings s = Small();
    s.abcTimeConstant_s = 0.2;
    s.haloFraction = 0.0;
    Intensifier used(s, 1), fresh(s, 1);
    const double perPe = 1.0 / used.PhotoelectronsPerRadiance();
    const double pe0 = 4.0 * s.PixelFramePe(s.abcThreshold_pe_s_mm2);
    const double dt = 1.0 / 30.0;
    used.Process(Uniform(s, 1, pe0 * perPe), 0.0, 0);
    used.Process(Uniform(s, 1, pe0 * perPe), dt, 1);
    used.Restart();
    const Image brighter = Uniform(s, 1, 1.25 * pe0 * perPe);
    used.Process(brighter, 2 * dt, 2);
    fresh.Process(brighter, 2 * dt, 2);
    EXPECT_NEAR(used.Gain() / (s.abcLevel / (1.25 * pe0)), 1.0, 1e-6);
    EXPECT_EQ(used.Gain(), fresh.Gain());
    EXPECT_TRUE(used.Brightness().pixels == fresh.Brightness().pixels);
    EXPECT_TRUE(std::equal(used.Display().begin(), used.Display().end(), fresh.Display().begin(),
                           fresh.Display().end()));
}

// A tenfold flash: the gain set for the dim scene saturates the screen (washout); the ABC,
// sensing the saturated screen current, brings the image back to its level.
TEST(Intensifier, AbcLagWashesOutAFlashThenRecovers) {
    IntensifierSettings s = Small();
    s.abcTimeConstant_s = 0.2;
    s.haloFraction = 0.0;
    Intensifier t(s, 1);
    const double perPe = 1.0 / t.PhotoelectronsPerRadiance();
    const double pe0 = 2.0 * s.PixelFramePe(s.abcThreshold_pe_s_mm2);
    const double dt = 1.0 / 30.0;
    t.Process(Uniform(s, 1, pe0 * perPe), 0.0, 0);
    const Image bright = Uniform(s, 1, 10.0 * pe0 * perPe);
    t.Process(bright, dt, 1);
    EXPECT_GT(FieldMean(t, t.Brightness()), 0.95);
    double previous = t.Gain();
    for (int k = 2; k <= 120; ++k) {
        t.Process(bright, k * dt, k);
        EXPECT_LE(t.Gain(), previous);  // monotonic recovery, no overshoot
        previous = t.Gain();
    }
    EXPECT_NEAR(FieldMean(t, t.Brightness()) / s.abcLevel, 1.0, 0.03);
}

TEST(Intensifier, FieldStopIsA40DegreeCircle) {
    IntensifierSettings s = Small(160, 120);
    Intensifier t(s, 1);
    t.Process(Uniform(s, 1, 1000.0 / t.PhotoelectronsPerRadiance()), 0.0, 0);
    const double tanH = std::tan(0.5 * s.hfov_rad), tanV = tanH * 120.0 / 160.0;
    int inside = 0, outside = 0;
    for (int y = 0; y < 120; ++y)
        for (int x = 0; x < 160; ++x) {
            const double u = ((x + 0.5) / 160 * 2 - 1) * tanH, v = ((y + 0.5) / 120 * 2 - 1) * tanV;
            const double off_deg = std::atan(std::hypot(u, v)) / kDegToRad;
            const float b = *t.Brightness().At(x, y);
            if (off_deg > 20.0) {
                EXPECT_EQ(b, 0.0f);
                const uint8_t* rgb = &t.Display()[3 * (size_t(y) * 160 + size_t(x))];
                EXPECT_EQ(rgb[0] + rgb[1] + rgb[2], 0);
                ++outside;
            } else if (off_deg < 19.0) {
                EXPECT_GT(b, 0.0f);
                ++inside;
            }
        }
    EXPECT_GT(inside, 0);
    EXPECT_GT(outside, 0);
}

// The field stop lies in front of the photocathode: light outside it makes no photoelectrons,
// so a scene bright everywhere outside the stop and black inside leaves the whole screen dark
// — no halo or tube blur carries it in across the edge.
TEST(Intensifier, LightOutsideTheFieldStopNeverReachesTheScreen) {
    IntensifierSettings s = Small(160, 120);
    s.halo_rad = 3.0 * kDegToRad;
    s.haloFraction = 0.2;
    Intensifier t(s, 2);
    Image img(160 * 2, 120 * 2, 3);
    for (int y = 0; y < 120 * 2; ++y)
        for (int x = 0; x < 160 * 2; ++x)
            if (!t.InField(x / 2, y / 2))
                for (int c = 0; c < 3; ++c)
                    img.At(x, y)[c] = float(1e4 / t.PhotoelectronsPerRadiance());
    t.Process(img, 0.0, 0);
    for (float v : t.PhotonRadiance().pixels) ASSERT_EQ(v, 0.0f);
    for (float v : t.Photoelectrons().pixels) ASSERT_EQ(v, 0.0f);
    for (float v : t.Brightness().pixels) ASSERT_EQ(v, 0.0f);
    // The same light inside the stop does reach it.
    Intensifier u(s, 2);
    u.Process(Uniform(s, 2, 1e4 / u.PhotoelectronsPerRadiance()), 0.0, 0);
    EXPECT_GT(*u.Brightness().At(80, 60), 0.0f);
}

// FieldStopSpans: each row's run holds exactly the pixels whose centre ray is within half the
// field stop of the axis (the angle from the pixel's tangent-plane coordinates).
TEST(Intensifier, FieldStopSpansHoldThePixelsWithinHalfTheStop) {
    IntensifierSettings s = Small(200, 150);
    s.fieldStop_rad = 36.0 * kDegToRad;
    const std::vector<PixelSpan> spans = FieldStopSpans(s);
    ASSERT_EQ(spans.size(), 150u);
    const double tanH = std::tan(0.5 * s.hfov_rad), tanV = tanH * 150.0 / 200.0;
    for (int y = 0; y < 150; ++y)
        for (int x = 0; x < 200; ++x) {
            const double u = ((x + 0.5) / 200 * 2 - 1) * tanH, v = ((y + 0.5) / 150 * 2 - 1) * tanV;
            const double off_deg = std::atan(std::hypot(u, v)) / kDegToRad;
            const bool in = x >= spans[size_t(y)].begin && x < spans[size_t(y)].end;
            if (std::abs(off_deg - 18.0) > 1e-9) {
                EXPECT_EQ(in, off_deg < 18.0) << x << ", " << y;
            }
        }
}

TEST(Intensifier, HaloHasTheConfiguredAngularDiameterAndGrowsWithTheSource) {
    IntensifierSettings s = Small(640, 480);
    s.halo_rad = 1.8 * kDegToRad;
    s.haloFraction = 0.05;
    const auto haloRow = [&](double sourcePe, std::vector<float>& row) {
        Intensifier t(s, 1);
        Image img(640, 480, 3);
        img.At(320, 240)[1] = float(sourcePe / t.PhotoelectronsPerRadiance());
        t.Process(img, 0.0, 0);
        row.assign(t.Brightness().At(0, 240), t.Brightness().At(0, 240) + 640);
    };
    std::vector<float> a, b;
    haloRow(2e5, a);
    haloRow(4e5, b);
    int first = -1, last = -1;
    for (int x = 0; x < 640; ++x)
        if (a[size_t(x)] > 0.0f) {
            if (first < 0) first = x;
            last = x;
        }
    const double degPerPx = std::atan(std::tan(0.5 * s.hfov_rad) / 320.0) / kDegToRad;
    // Lit extent: the halo disc plus the tube blur (≈ 1 px each side).
    EXPECT_NEAR((last - first - 1) * degPerPx, 1.8, 0.15);
    // A pixel well inside the halo, away from the core: twice the source, twice the halo
    // (both below saturation; the gain is the same, both fields are below the ABC threshold).
    const size_t probe = 320 + 8;
    EXPECT_GT(a[probe], 0.0f);
    EXPECT_LT(b[probe], 1.0f);
    EXPECT_NEAR(b[probe] / a[probe], 2.0, 0.1);
}

// The halo against the disc summed pixel by pixel: every pixel within R (the halo radius, whole
// pixels) of the pixel, over the disc's full pixel count, in the field stop. The tube blur is made
// negligible (limiting resolution 10⁴ lp/mm: the MTF kernel's side taps are e^(−1/(2σ²)) ≈ 0), so
// the screen below saturation is the gain times the halo.
TEST(Intensifier, HaloIsTheDiscMeanOfThePhotoelectrons) {
    IntensifierSettings s = Small(96, 72);
    s.halo_rad = 8.0 * kDegToRad;
    s.haloFraction = 0.4;
    s.resolution_lp_mm = 1e4;
    Intensifier t(s, 1);
    Image scene(96, 72, 3);
    for (int y = 0; y < 72; ++y)
        for (int x = 0; x < 96; ++x)
            scene.At(x, y)[1] = float((50.0 + 40.0 * std::sin(0.3 * x) * std::cos(0.2 * y) +
                                       (x == 40 && y == 30 ? 5e3 : 0.0)) /
                                      t.PhotoelectronsPerRadiance());
    t.Process(scene, 0.0, 0);
    const int R = int(std::floor(t.HaloRadius_px()));
    ASSERT_GE(R, 6);
    int discCount = 0;
    for (int dy = -R; dy <= R; ++dy)
        for (int dx = -R; dx <= R; ++dx) discCount += dx * dx + dy * dy <= R * R;
    const Image& e = t.Photoelectrons();
    int compared = 0;
    for (int y = 0; y < 72; ++y)
        for (int x = 0; x < 96; ++x) {
            const double b = *t.Brightness().At(x, y);
            if (!t.InField(x, y) || b >= 1.0) continue;
            double disc = 0.0;
            for (int dy = -R; dy <= R; ++dy)
                for (int dx = -R; dx <= R; ++dx)
                    if (dx * dx + dy * dy <= R * R && x + dx >= 0 && x + dx < 96 && y + dy >= 0 &&
                        y + dy < 72)
                        disc += *e.At(x + dx, y + dy);
            const double halo =
                (1.0 - s.haloFraction) * *e.At(x, y) + s.haloFraction * disc / discCount;
            EXPECT_NEAR(b / (t.Gain() * halo), 1.0, 1e-5) << x << " " << y;
            ++compared;
        }
    EXPECT_GT(compared, 96 * 72 / 3);
}

// Poisson deviates from hashed bits: the frequencies of 2·10⁵ draws against the Poisson
// probabilities e^−m mᵏ/k! (exact branch), and mean and variance m (normal branch).
TEST(Intensifier, PoissonDeviatesHaveThePoissonDistribution) {
    constexpr int kDraws = 200000;
    for (double mean : {0.7, 6.5, 27.0}) {
        std::vector<int> histogram(200, 0);
        for (int i = 0; i < kDraws; ++i)
            ++histogram[size_t(PoissonDeviate(mean, scene::HashBits(3, 5, uint64_t(i))))];
        double pk = std::exp(-mean);
        for (int k = 0; k < 80; ++k) {
            if (k > 0) pk *= mean / k;
            const double expected = kDraws * pk;
            if (expected < 50.0) continue;
            // Five binomial standard deviations.
            EXPECT_NEAR(histogram[size_t(k)], expected, 5.0 * std::sqrt(expected))
                << "mean " << mean << " k " << k;
        }
    }
    for (double mean : {31.0, 400.0, 1e4}) {
        double sum = 0.0, sum2 = 0.0;
        for (int i = 0; i < kDraws; ++i) {
            const double v = PoissonDeviate(mean, scene::HashBits(4, 6, uint64_t(i)));
            EXPECT_EQ(v, std::floor(v));
            sum += v;
            sum2 += v * v;
        }
        const double m = sum / kDraws, var = sum2 / kDraws - m * m;
        EXPECT_NEAR(m / mean, 1.0, 5.0 * std::sqrt(1.0 / (mean * kDraws))) << mean;
        EXPECT_NEAR(var / mean, 1.0, 0.02) << mean;
    }
}

// The frame against the intensifier's stages written pixel by pixel (the form before they were
// vectorized and fused): photoelectrons F·PoissonDeviate(L·scale, HashBits(seed, frame, pixel))
// inside the field stop, the halo disc from row prefix sums clipped at the edges, the two
// Gaussian tube-blur passes with clamped edges (taps in order) and the saturated, gained
// screen. Bit for bit, over formats whose widths are no multiple of the vector widths, halos
// wider than half the frame, wider tube blurs, the exact and the normal Poisson branches, and
// the settling first frame and a lagged second.
TEST(Intensifier, FrameEqualsThePixelByPixelStages) {
    struct Case {
        int w, h, n;
        double halo_deg, haloFraction, resolution_lp_mm;
    };
    for (const Case c : {Case{37, 23, 1, 30.0, 0.2, 8.0}, Case{61, 45, 2, 6.0, 0.03, 64.0},
                         Case{96, 72, 1, 1.8, 0.0, 20.0}, Case{17, 11, 1, 60.0, 0.5, 4.0}}) {
        IntensifierSettings s = Small(c.w, c.h);
        s.halo_rad = c.halo_deg * kDegToRad;
        s.haloFraction = c.haloFraction;
        s.resolution_lp_mm = c.resolution_lp_mm;
        Intensifier t(s, c.n);
        // Photoelectron means from ≈ 0.05 to ≈ 200 per pixel: both Poisson branches.
        Image scene(c.w * c.n, c.h * c.n, 3);
        for (int y = 0; y < scene.height; ++y)
            for (int x = 0; x < scene.width; ++x)
                for (int b = 0; b < 3; ++b)
                    scene.At(x, y)[b] =
                        float(std::exp(-3.0 + 8.5 * scene::Uniform01(7, uint64_t(y), uint64_t(x))) /
                              (3.0 * t.PhotoelectronsPerRadiance()));
        for (int64_t frame = 0; frame < 2; ++frame) {
            t.Process(scene, 0.05 * double(frame), frame);
            const int w = c.w, h = c.h;
            const Image& L = t.PhotonRadiance();
            const double scale = t.PhotoelectronsPerRadiance() * t.Duty() / s.noiseFactor;
            Image e(w, h, 1), halo(w, h, 1), across(w, h, 1);
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    const size_t i = size_t(y * w + x);
                    if (t.InField(x, y))
                        e.pixels[i] =
                            float(s.noiseFactor *
                                  PoissonDeviate(double(L.pixels[i]) * scale,
                                                 scene::HashBits(s.seed, uint64_t(frame), i)));
                }
            ASSERT_EQ(t.Photoelectrons().pixels, e.pixels) << c.w << " frame " << frame;
            const int R = int(std::floor(t.HaloRadius_px()));
            halo.pixels = e.pixels;
            if (s.haloFraction > 0.0 && R >= 1) {
                std::vector<double> prefix(size_t(h * (w + 1)), 0.0);
                for (int y = 0; y < h; ++y)
                    for (int x = 0; x < w; ++x)
                        prefix[size_t(y * (w + 1) + x + 1)] =
                            prefix[size_t(y * (w + 1) + x)] + e.pixels[size_t(y * w + x)];
                double discCount = 0.0;
                for (int dy = -R; dy <= R; ++dy)
                    discCount += 2 * int(std::floor(std::sqrt(double(R * R - dy * dy)))) + 1;
                for (int y = 0; y < h; ++y)
                    for (int x = 0; x < w; ++x) {
                        double acc = 0.0;
                        for (int dy = -R; dy <= R; ++dy) {
                            if (y + dy < 0 || y + dy >= h) continue;
                            const int hw = int(std::floor(std::sqrt(double(R * R - dy * dy))));
                            const double* p = &prefix[size_t((y + dy) * (w + 1))];
                            acc += p[std::min(w, x + hw + 1)] - p[std::max(0, x - hw)];
                        }
                        halo.pixels[size_t(y * w + x)] =
                            float((1.0 - s.haloFraction) * e.pixels[size_t(y * w + x)] +
                                  s.haloFraction * acc / discCount);
                    }
            }
            // The tube MTF's normalised float taps.
            const double sigma = t.MtfSigma_px();
            const int r = std::max(1, int(std::ceil(3.0 * sigma)));
            std::vector<float> taps;
            double sum = 0.0;
            for (int k = -r; k <= r; ++k) sum += std::exp(-0.5 * k * k / (sigma * sigma));
            for (int k = -r; k <= r; ++k)
                taps.push_back(float(std::exp(-0.5 * k * k / (sigma * sigma)) / sum));
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    float v = 0.0f;
                    for (int k = -r; k <= r; ++k)
                        v += taps[size_t(k + r)] * *halo.At(std::clamp(x + k, 0, w - 1), y);
                    *across.At(x, y) = v;
                }
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    float v = 0.0f;
                    for (int k = -r; k <= r; ++k)
                        v += taps[size_t(k + r)] * *across.At(x, std::clamp(y + k, 0, h - 1));
                    const float b = t.InField(x, y) ? std::min(1.0f, float(t.Gain()) * v) : 0.0f;
                    ASSERT_EQ(*t.Brightness().At(x, y), b)
                        << c.w << " frame " << frame << " at " << x << " " << y;
                }
        }
    }
}

TEST(Intensifier, FrameIsIndependentOfThreadCount) {
    IntensifierSettings s = Small(200, 150);
    Image scene(400, 300, 3);
    for (size_t i = 0; i < scene.pixels.size(); ++i) scene.pixels[i] = float(1e13 * (1 + i % 97));
    const auto run = [&](int threads) {
        Intensifier t(s, 2);
        tbb::task_arena(threads).execute([&] {
            t.Process(scene, 0.0, 0);
            t.Process(scene, 0.1, 1);
        });
        return std::vector<uint8_t>(t.Display().begin(), t.Display().end());
    };
    EXPECT_EQ(run(1), run(2));
}

IntensifierSettings Read(const std::string& text) {
    scene::ConfigDocument doc = scene::ParseConfigText(text, "nvg.yaml");
    scene::ConfigMap root(doc.root);
    IntensifierSettings s = ReadIntensifierSettings(root.Require("intensifier", "a mapping"));
    root.Finish();
    return s;
}

TEST(IntensifierSettings, ReadsEveryKeyInSiUnits) {
    const IntensifierSettings s = Read(
        "intensifier:\n"
        "  optics: {f_number: 1.4, transmission: 0.7, field_stop_deg: 30,"
        " photocathode_diameter_mm: 16}\n"
        "  photocathode: {generation: gen2, minus_blue: b, qe_peak: 0.12}\n"
        "  tube: {resolution_lp_mm: 72, noise_factor: 1.5, halo_deg: 2, halo_fraction: 0.1}\n"
        "  abc: {level: 0.5, threshold_pe_s_mm2: 2e6, time_constant_s: 0.5}\n"
        "  bsp: {threshold_pe_s_mm2: 1e9}\n");
    EXPECT_DOUBLE_EQ(s.fNumber, 1.4);
    EXPECT_DOUBLE_EQ(s.opticsTransmission, 0.7);
    EXPECT_NEAR(s.fieldStop_rad, 30 * kDegToRad, 1e-15);
    EXPECT_NEAR(s.photocathodeDiameter_m, 16e-3, 1e-15);
    EXPECT_EQ(s.cathode, Photocathode::Gen2);
    EXPECT_EQ(s.filter, MinusBlue::ClassB);
    EXPECT_DOUBLE_EQ(s.qePeak, 0.12);
    EXPECT_DOUBLE_EQ(s.resolution_lp_mm, 72.0);
    EXPECT_DOUBLE_EQ(s.noiseFactor, 1.5);
    EXPECT_NEAR(s.halo_rad, 2 * kDegToRad, 1e-15);
    EXPECT_DOUBLE_EQ(s.haloFraction, 0.1);
    EXPECT_DOUBLE_EQ(s.abcLevel, 0.5);
    EXPECT_DOUBLE_EQ(s.abcThreshold_pe_s_mm2, 2e6);
    EXPECT_DOUBLE_EQ(s.abcTimeConstant_s, 0.5);
    EXPECT_DOUBLE_EQ(s.bspThreshold_pe_s_mm2, 1e9);
}

std::string ErrorOf(const std::string& text) {
    try {
        Read(text);
    } catch (const scene::ConfigError& e) {
        return e.what();
    }
    ADD_FAILURE() << "no ConfigError for:\n" << text;
    return "";
}

TEST(IntensifierSettings, ErrorsNameFileLineAndKey) {
    const std::string unknown = ErrorOf("intensifier:\n  tube: {noise_factr: 2}\n");
    EXPECT_NE(unknown.find("nvg.yaml:2"), std::string::npos) << unknown;
    EXPECT_NE(unknown.find("noise_factor"), std::string::npos) << unknown;  // the suggestion
    const std::string range = ErrorOf("intensifier:\n  optics:\n    transmission: 1.5\n");
    EXPECT_NE(range.find("nvg.yaml:3"), std::string::npos) << range;
    EXPECT_NE(range.find("intensifier.optics.transmission"), std::string::npos) << range;
    const std::string gen = ErrorOf("intensifier:\n  photocathode: {generation: gen4}\n");
    EXPECT_NE(gen.find("gen3"), std::string::npos) << gen;
}

}  // namespace
}  // namespace seasense::sensors
