// Image intensifier: photon radiance → photoelectrons → MCP noise → halo → tube MTF → ABC → P43.
#include "sensors/intensifier/intensifier.h"

#include <emmintrin.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "radiometry/color/rec709.h"
#include "scene/core/check.h"
#include "scene/core/rng.h"
#include "sensors/thermal/normal_deviates.h"

namespace seasense::sensors {

namespace {

// P43 (Gd₂O₂S:Tb) phosphor chromaticity, CIE 1931 x = 0.333, y = 0.556 (EIA/JEDEC TEP116-C,
// "Optical characteristics of cathode-ray tube screens", 1993).
constexpr double kP43x = 0.333, kP43y = 0.556;
// Contrast at the limiting resolution: the resolution of a tube is read where its MTF falls to
// ≈ 3 % (the threshold contrast of visual bar-target readings, Csorba 1985 ch. 8).
constexpr double kLimitingMtf = 0.03;
constexpr int kLutSize = 4096;
// Largest mean drawn exactly (PoissonDeviate); above it the normal approximation, whose
// skewness 1/√mean is then below 0.18.
constexpr double kExactPoissonMean = 30.0;
// 1/k for the sequential search: up to 200, where the CDF of mean 30 is 1 − 1e-70.
constexpr int kReciprocals = 200;

struct ReciprocalTable {
    double value[kReciprocals];
    ReciprocalTable() {
        value[0] = 0.0;
        for (int k = 1; k < kReciprocals; ++k) value[k] = 1.0 / k;
    }
};

const ReciprocalTable& Reciprocals() {
    static const ReciprocalTable table;
    return table;
}

// sRGB encoding of linear v in [0, 1] (IEC 61966-2-1:1999).
double SrgbEncode(double v) {
    return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}

}  // namespace

double PoissonDeviate(double mean, uint64_t bits) {
    if (mean <= 0.0) return 0.0;
    if (mean <= kExactPoissonMean) {
        // Inversion by sequential search (Devroye 1986, §X.3.3): the smallest k whose CDF
        // exceeds u, the probabilities p_k = p_(k−1) · mean/k from p_0 = e^−mean.
        const ReciprocalTable& inverse = Reciprocals();
        const double u = double(bits >> 11) * 0x1.0p-53;
        double p = std::exp(-mean), cdf = p;
        int k = 0;
        while (u >= cdf && k + 1 < kReciprocals) {
            ++k;
            p *= mean * inverse.value[size_t(k)];
            const double next = cdf + p;
            if (next == cdf) break;  // the tail's probabilities no longer change the sum
            cdf = next;
        }
        return double(k);
    }
    const double z = NormalFromBits(uint32_t(bits));
    // Rounded half up by truncation of a non-negative value (std::round is a library call).
    return double(int64_t(std::max(0.0, mean + std::sqrt(mean) * z) + 0.5));
}

Intensifier::Intensifier(const IntensifierSettings& settings, int supersampling)
    : s_(settings), n_(supersampling) {
    CHECK(n_ >= 1 && s_.width_px > 0 && s_.height_px > 0);
    const double pitch_m = s_.PixelPitch_m();
    // Étendue of a pixel behind an f/F objective: A · π/(4F²) (projected solid angle of the
    // exit pupil, small-angle).
    pePerRadiance_ = s_.qePeak * s_.opticsTransmission * pitch_m * pitch_m * std::numbers::pi /
                     (4.0 * s_.fNumber * s_.fNumber) * s_.frameTime_s;
    const double tanPerPixel = 2.0 * std::tan(0.5 * s_.hfov_rad) / s_.width_px;
    haloRadius_px_ = std::tan(0.5 * s_.halo_rad) / tanPerPixel;
    // Gaussian MTF exp(−2π²σ²f²) = kLimitingMtf at the limiting resolution.
    const double sigma_m = std::sqrt(std::log(1.0 / kLimitingMtf) / 2.0) / std::numbers::pi /
                           (s_.resolution_lp_mm * 1e3);
    mtfSigma_px_ = sigma_m / pitch_m;
    const int r = std::max(1, int(std::ceil(3.0 * mtfSigma_px_)));
    mtfKernel_.assign(size_t(2 * r + 1), 0.0f);
    double sum = 0.0;
    for (int i = -r; i <= r; ++i) {
        const double w = std::exp(-0.5 * i * i / (mtfSigma_px_ * mtfSigma_px_));
        mtfKernel_[size_t(i + r)] = float(w);
        sum += w;
    }
    for (float& w : mtfKernel_) w = float(w / sum);
    // The field stop: pixels whose centre ray is within fieldStop/2 of the optical axis.
    const int w = s_.width_px, h = s_.height_px;
    spans_ = FieldStopSpans(s_);
    mask_.assign(size_t(w) * size_t(h), 0);
    for (int y = 0; y < h; ++y) {
        const PixelSpan& span = spans_[size_t(y)];
        std::fill(mask_.begin() + ptrdiff_t(size_t(y) * size_t(w) + size_t(span.begin)),
                  mask_.begin() + ptrdiff_t(size_t(y) * size_t(w) + size_t(span.end)), 1);
        fieldCount_ += size_t(span.end - span.begin);
    }
    // Phosphor: screen luminance ∝ brightness, in P43's colour, scaled so that saturation is
    // the brightest displayable P43 green.
    glm::dvec3 p43 = radiometry::Rec709FromYxy(1.0, kP43x, kP43y);
    p43 = glm::max(p43, glm::dvec3(0.0));
    p43 /= std::max({p43.r, p43.g, p43.b});
    phosphorLut_.resize(size_t(kLutSize) * 3);
    for (int i = 0; i < kLutSize; ++i)
        for (int c = 0; c < 3; ++c)
            phosphorLut_[size_t(i) * 3 + size_t(c)] =
                uint8_t(std::lround(255.0 * SrgbEncode(double(i) / (kLutSize - 1) * p43[c])));
    radiance_ = Image(w, h, 1);
    electrons_ = Image(w, h, 1);
    halo_ = Image(w, h, 1);
    brightness_ = Image(w, h, 1);
    display_.assign(size_t(w) * size_t(h) * 3, 0);
}

void Intensifier::Process(const Image& samples, double time_s, int64_t frame) {
    const int w = s_.width_px, h = s_.height_px, n = n_;
    CHECK(samples.width == w * n && samples.height == h * n);
    const int comps = samples.channels;
    // Footprint: the pixel's photon radiance is the mean over its samples, summed over bands,
    // inside the field stop; outside it no light reaches the photocathode (0), so neither the
    // noise nor the halo and tube blur of the electrons spread light from there into the field.
    tbb::parallel_for(0, h, [&](int y) {
        const PixelSpan span = spans_[size_t(y)];
        float* row = radiance_.At(0, y);
        std::fill(row, row + span.begin, 0.0f);
        std::fill(row + span.end, row + w, 0.0f);
        int x = span.begin;
        if (n == 2 && comps == 3) {
            // The default 2×2 samples of three bands: two pixels at a time, one per lane of an
            // SSE2 double pair, each lane adding its pixel's twelve values in the scalar
            // loop's order (the same sums bit for bit, without its serial chain of adds).
            for (; x + 1 < span.end; x += 2) {
                __m128d sum = _mm_setzero_pd();
                for (int j = 0; j < 2; ++j) {
                    const float* a = samples.At(x * 2, y * 2 + j);  // six values per pixel
                    const float* b = a + 6;
                    const __m128 a03 = _mm_loadu_ps(a), b03 = _mm_loadu_ps(b);
                    const __m128 a45 =
                        _mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(a + 4)));
                    const __m128 b45 =
                        _mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(b + 4)));
                    const __m128 lo = _mm_unpacklo_ps(a03, b03);   // a0 b0 a1 b1
                    const __m128 hi = _mm_unpackhi_ps(a03, b03);   // a2 b2 a3 b3
                    const __m128 top = _mm_unpacklo_ps(a45, b45);  // a4 b4 a5 b5
                    for (__m128 v : {lo, hi, top}) {
                        sum = _mm_add_pd(sum, _mm_cvtps_pd(v));
                        sum = _mm_add_pd(sum, _mm_cvtps_pd(_mm_movehl_ps(v, v)));
                    }
                }
                alignas(16) float out[4];
                _mm_store_ps(out, _mm_cvtpd_ps(_mm_div_pd(sum, _mm_set1_pd(4.0))));
                *radiance_.At(x, y) = out[0];
                *radiance_.At(x + 1, y) = out[1];
            }
        }
        for (; x < span.end; ++x) {
            double sum = 0.0;
            for (int j = 0; j < n; ++j) {
                const float* sampleRow = samples.At(x * n, y * n + j);
                for (int i = 0; i < n * comps; ++i) sum += sampleRow[i];
            }
            *radiance_.At(x, y) = float(sum / (n * n));
        }
    });
    // Sums over the field stop: per row in parallel, then the rows in order (deterministic for
    // any thread count).
    std::vector<double>& rowSum = rowSum_;
    rowSum.resize(size_t(h));
    const auto fieldSum = [&](const auto& term) {
        tbb::parallel_for(0, h, [&](int y) {
            const size_t row = size_t(y) * size_t(w);
            double sum = 0.0;
            for (size_t i = row; i < row + size_t(w); ++i)
                if (mask_[i]) sum += term(double(radiance_.pixels[i]));
            rowSum[size_t(y)] = sum;
        });
        double total = 0.0;
        for (double r : rowSum) total += r;
        return total;
    };
    // Mean photoelectrons over the field as the photocathode delivers them; BSP limits their
    // mean.
    const double count = double(fieldCount_);
    meanPe_ = count > 0.0 ? fieldSum([&](double L) { return L * pePerRadiance_; }) / count : 0.0;
    const double bsp = s_.PixelFramePe(s_.bspThreshold_pe_s_mm2);
    duty_ = meanPe_ > bsp ? bsp / meanPe_ : 1.0;
    // The mean as the ABC senses it through the screen current at gain g: each pixel counts at
    // most the photoelectrons that saturate it (1/g).
    const auto sensed = [&](double g) {
        const double cap = 1.0 / g, scale = pePerRadiance_ * duty_;
        return count > 0.0 ? fieldSum([&](double L) { return std::min(L * scale, cap); }) / count
                           : 0.0;
    };
    // ABC: the gain that puts the sensed mean at abcLevel (capped at its value at the
    // threshold), sensed at the previous frame's gain; the first frame starts settled, at the
    // fixed point g = level / sensed(g) (sensed(g)·g rises with g: bisection on log g).
    const double maxGain = s_.abcLevel / s_.PixelFramePe(s_.abcThreshold_pe_s_mm2);
    const auto targetAt = [&](double g) {
        return std::min(maxGain, s_.abcLevel / std::max(sensed(g), 1e-300));
    };
    const double dt = time_s - lastTime_s_;
    if (!started_ || !(dt > 0.0) || s_.abcTimeConstant_s <= 0.0) {
        double lo = maxGain * 1e-12, hi = maxGain;
        if (targetAt(hi) >= hi) {
            gain_ = hi;
        } else {
            for (int i = 0; i < 60; ++i) {
                const double mid = std::sqrt(lo * hi);
                (targetAt(mid) > mid ? lo : hi) = mid;
            }
            gain_ = std::sqrt(lo * hi);
        }
    } else {
        const double target = targetAt(gain_);
        gain_ = target + (gain_ - target) * std::exp(-dt / s_.abcTimeConstant_s);
    }
    started_ = true;
    lastTime_s_ = time_s;

    // Scintillation: S = F · Poisson(N/F), mean N, variance F·N (SNR √(N/F)); one hash of
    // (seed, frame, pixel) per pixel inside the field stop (outside, N = 0: no electrons).
    const double F = s_.noiseFactor;
    const double scale = pePerRadiance_ * duty_ / F;
    tbb::parallel_for(0, h, [&](int y) {
        const PixelSpan span = spans_[size_t(y)];
        float* row = electrons_.At(0, y);
        std::fill(row, row + span.begin, 0.0f);
        std::fill(row + span.end, row + w, 0.0f);
        for (int x = span.begin; x < span.end; ++x) {
            const size_t i = size_t(y) * size_t(w) + size_t(x);
            const uint64_t bits = scene::HashBits(s_.seed, uint64_t(frame), i);
            electrons_.pixels[i] =
                float(F * PoissonDeviate(double(radiance_.pixels[i]) * scale, bits));
        }
    });
    // Halo: a fixed share of each pixel's electrons spread uniformly over a disc of the halo's
    // angular radius, the disc's rows from row prefix sums. Each output row adds the disc's
    // rows one after another over the whole row (the same sums in the same order per pixel as
    // a pixel-by-pixel loop, but in runs the compiler vectorizes).
    const int R = int(std::floor(haloRadius_px_));
    const double f = s_.haloFraction;
    if (f > 0.0 && R >= 1) {
        std::vector<double>& prefix = prefix_;  // every entry is written below
        prefix.resize(size_t(h) * size_t(w + 1));
        tbb::parallel_for(0, h, [&](int y) {
            double* p = &prefix[size_t(y) * size_t(w + 1)];
            p[0] = 0.0;
            for (int x = 0; x < w; ++x) p[x + 1] = p[x] + electrons_.pixels[size_t(y) * w + x];
        });
        std::vector<int> halfWidth(size_t(2 * R + 1));
        double discCount = 0.0;
        for (int dy = -R; dy <= R; ++dy) {
            halfWidth[size_t(dy + R)] = int(std::floor(std::sqrt(double(R * R - dy * dy))));
            discCount += 2 * halfWidth[size_t(dy + R)] + 1;
        }
        tbb::enumerable_thread_specific<std::vector<double>> rowSums;
        tbb::parallel_for(0, h, [&](int y) {
            std::vector<double>& sum = rowSums.local();
            sum.assign(size_t(w), 0.0);
            double* __restrict acc = sum.data();
            for (int dy = -R; dy <= R; ++dy) {
                const int yy = y + dy;
                if (yy < 0 || yy >= h) continue;
                const int hw = halfWidth[size_t(dy + R)];
                const double* __restrict p = &prefix[size_t(yy) * size_t(w + 1)];
                // Runs [x − hw, x + hw] clipped to the row: clipped on the left for x < hw,
                // on the right for x + hw ≥ w, whole in between.
                const int left = std::min(hw, w), right = std::max(left, w - hw);
                for (int x = 0; x < left; ++x) acc[x] += p[std::min(w, x + hw + 1)] - p[0];
                for (int x = left; x < right; ++x) acc[x] += p[x + hw + 1] - p[x - hw];
                for (int x = right; x < w; ++x) acc[x] += p[w] - p[std::max(0, x - hw)];
            }
            for (int x = 0; x < w; ++x) {
                const size_t i = size_t(y) * size_t(w) + size_t(x);
                halo_.pixels[i] = float((1.0 - f) * electrons_.pixels[i] + f * acc[x] / discCount);
            }
        });
    } else {
        halo_.pixels = electrons_.pixels;
    }
    // Tube MTF (Gaussian, separable, edges clamped), then ABC gain, screen saturation and the
    // field stop.
    const int r = int(mtfKernel_.size() / 2);
    // Each pixel sums its taps k = −r … r in order; the loops run over a whole row per tap so
    // that they vectorize across pixels (the same sums as a pixel-by-pixel loop).
    tbb::enumerable_thread_specific<std::vector<float>> paddedRows;
    tbb::parallel_for(0, h, [&](int y) {
        // The row with r clamped samples either side: tap k of pixel x is padded[x + k + r].
        std::vector<float>& padded = paddedRows.local();
        padded.resize(size_t(w + 2 * r));
        const float* in = halo_.At(0, y);
        for (int x = -r; x < w + r; ++x) padded[size_t(x + r)] = in[std::clamp(x, 0, w - 1)];
        float* __restrict out = brightness_.At(0, y);  // horizontal pass
        std::fill_n(out, w, 0.0f);
        for (int k = -r; k <= r; ++k) {
            const float c = mtfKernel_[size_t(k + r)];
            const float* __restrict tap = padded.data() + (k + r);
            for (int x = 0; x < w; ++x) out[x] += c * tap[x];
        }
    });
    tbb::parallel_for(0, h, [&](int y) {
        float* __restrict out = halo_.At(0, y);  // the blurred electrons (halo_ is free again)
        std::fill_n(out, w, 0.0f);
        for (int k = -r; k <= r; ++k) {
            const float c = mtfKernel_[size_t(k + r)];
            const float* __restrict tap = brightness_.At(0, std::clamp(y + k, 0, h - 1));
            for (int x = 0; x < w; ++x) out[x] += c * tap[x];
        }
    });
    tbb::parallel_for(0, h, [&](int y) {
        for (int x = 0; x < w; ++x) {
            const size_t i = size_t(y) * size_t(w) + size_t(x);
            const float b = mask_[i] ? std::min(1.0f, float(gain_) * halo_.pixels[i]) : 0.0f;
            brightness_.pixels[i] = b;
            // lround of v ≥ 0 without the library call: v − trunc(v) is exact in float.
            const float v = b * (kLutSize - 1);
            const int whole = int(v);
            const size_t code = size_t(whole + (v - float(whole) >= 0.5f ? 1 : 0));
            for (int c = 0; c < 3; ++c) display_[3 * i + size_t(c)] = phosphorLut_[3 * code + c];
        }
    });
}

}  // namespace seasense::sensors
