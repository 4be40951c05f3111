// Image intensifier: photon radiance → photoelectrons → MCP noise → halo → tube MTF → ABC → P43.
#include "sensors/intensifier/intensifier.h"

#include <immintrin.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>

#include "radiometry/color/rec709.h"
#include "scene/core/check.h"
#include "scene/core/rng.h"
#include "scene/core/simd_lanes.h"
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

using simd::kLanes, simd::Load, simd::Select, simd::Splat, simd::Store, simd::VF, simd::VI;

// Four doubles (two SSE2 pairs where the build has no AVX): IEEE operations per lane.
using VD = double __attribute__((vector_size(4 * sizeof(double))));
inline VD LoadVD(const double* p) {
    VD v;
    std::memcpy(&v, p, sizeof v);
    return v;
}
using VU = uint64_t __attribute__((vector_size(4 * sizeof(uint64_t))));
using VL = int64_t __attribute__((vector_size(4 * sizeof(int64_t))));
inline bool AllLanes(VL mask) {
#if defined(__AVX__)
    return _mm256_movemask_pd(__m256d(mask)) == 0xF;
#else
    return (mask[0] & mask[1] & mask[2] & mask[3]) != 0;
#endif
}
inline VD SqrtVD(VD v) {
#if defined(__AVX__)
    return _mm256_sqrt_pd(v);
#else
    return VD{std::sqrt(v[0]), std::sqrt(v[1]), std::sqrt(v[2]), std::sqrt(v[3])};
#endif
}
// Σ term(L[x]) over the span in the order of x: the terms (a function of four doubles, lane for
// lane) four at a time.
template <class Term>
double SumInOrder(const float* L, PixelSpan span, const Term& term) {
    double sum = 0.0;
    int x = span.begin;
    for (; x + 4 <= span.end; x += 4) {
        const VD t = term(VD{L[x], L[x + 1], L[x + 2], L[x + 3]});
        for (int l = 0; l < 4; ++l) sum += t[l];
    }
    for (; x < span.end; ++x) sum += term(VD{L[x], 0.0, 0.0, 0.0})[0];
    return sum;
}

// Pixels of a halo block: its disc sums stay in registers while the disc's rows are added
// (eight AVX or SSE2 registers).
constexpr int kHaloBlock = int(simd::kLanes) * 4;

// sRGB encoding of linear v in [0, 1] (IEC 61966-2-1:1999).
double SrgbEncode(double v) {
    return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}

}  // namespace

namespace {

// The normal approximation above kExactPoissonMean (or a NaN mean, drawn as 0) from a standard
// normal deviate z, rounded half up by truncation of a non-negative value (std::round is a
// library call).
inline double NormalPoisson(double mean, float z) {
    return double(int64_t(std::max(0.0, mean + std::sqrt(mean) * z) + 0.5));
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
    return NormalPoisson(mean, NormalFromBits(uint32_t(bits)));
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
    phosphorLut_.assign(size_t(kLutSize) * 4, 0);
    for (int i = 0; i < kLutSize; ++i)
        for (int c = 0; c < 3; ++c)
            phosphorLut_[size_t(i) * 4 + size_t(c)] =
                uint8_t(std::lround(255.0 * SrgbEncode(double(i) / (kLutSize - 1) * p43[c])));
    radiance_ = Image(w, h, 1);
    electrons_ = Image(w, h, 1);
    halo_ = Image(w, h, 1);
    brightness_ = Image(w, h, 1);
    display_.assign(size_t(w) * size_t(h) * 3, 0);
}

void Intensifier::Restart() {
    started_ = false;
    lastTime_s_ = 0.0;
    gain_ = 0.0, duty_ = 1.0, meanPe_ = 0.0;
}

void Intensifier::Process(const Image& samples, double time_s, int64_t frame) {
    const int w = s_.width_px, h = s_.height_px, n = n_;
    CHECK(samples.width == w * n && samples.height == h * n);
    const int comps = samples.channels;
    std::vector<double>& rowSum = rowSum_;
    rowSum.resize(size_t(h));
    // Footprint: the pixel's photon radiance is the mean over its samples, summed over bands,
    // inside the field stop; outside it no light reaches the photocathode (0), so neither the
    // noise nor the halo and tube blur of the electrons spread light from there into the field.
    // Each row also sums its photoelectron means for the field's mean.
    tbb::parallel_for(0, h, [&](int y) {
        const PixelSpan span = spans_[size_t(y)];
        float* row = radiance_.At(0, y);
        std::fill(row, row + span.begin, 0.0f);
        std::fill(row + span.end, row + w, 0.0f);
        int x = span.begin;
        if (n == 2 && comps == 3) {
            // The default 2×2 samples of three bands: four (AVX) or two pixels at a time, one
            // per lane, each lane adding its pixel's twelve values in the scalar loop's order
            // (the same sums bit for bit, without its serial chain of adds).
#if defined(__AVX__)
            for (; x + 3 < span.end; x += 4) {
                __m256d sum = _mm256_setzero_pd();
                for (int j = 0; j < 2; ++j) {
                    const float* a = samples.At(x * 2, y * 2 + j);  // six values per pixel
                    // Values 0–3 of the four pixels transposed to one vector per value, then
                    // values 4 and 5.
                    __m128 v0 = _mm_loadu_ps(a), v1 = _mm_loadu_ps(a + 6);
                    __m128 v2 = _mm_loadu_ps(a + 12), v3 = _mm_loadu_ps(a + 18);
                    _MM_TRANSPOSE4_PS(v0, v1, v2, v3);
                    const auto pair = [](const float* p) {
                        return _mm_castsi128_ps(
                            _mm_loadl_epi64(reinterpret_cast<const __m128i*>(p)));
                    };
                    const __m128 p01 = _mm_unpacklo_ps(pair(a + 4), pair(a + 10));
                    const __m128 p23 = _mm_unpacklo_ps(pair(a + 16), pair(a + 22));
                    const __m128 v4 = _mm_movelh_ps(p01, p23), v5 = _mm_movehl_ps(p23, p01);
                    for (__m128 v : {v0, v1, v2, v3, v4, v5})
                        sum = _mm256_add_pd(sum, _mm256_cvtps_pd(v));
                }
                _mm_storeu_ps(row + x, _mm256_cvtpd_ps(_mm256_div_pd(sum, _mm256_set1_pd(4.0))));
            }
#endif
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
                row[x] = out[0];
                row[x + 1] = out[1];
            }
        }
        for (; x < span.end; ++x) {
            double sum = 0.0;
            for (int j = 0; j < n; ++j) {
                const float* sampleRow = samples.At(x * n, y * n + j);
                for (int i = 0; i < n * comps; ++i) sum += sampleRow[i];
            }
            row[x] = float(sum / (n * n));
        }
        rowSum[size_t(y)] = SumInOrder(row, span, [&](VD L) { return L * pePerRadiance_; });
    });
    // Sums over the field stop: per row (in parallel), then the rows in order (deterministic for
    // any thread count).
    const auto sumRows = [&] {
        double total = 0.0;
        for (double r : rowSum) total += r;
        return total;
    };
    const auto fieldSum = [&](const auto& term) {
        tbb::parallel_for(0, h, [&](int y) {
            const PixelSpan span = spans_[size_t(y)];
            rowSum[size_t(y)] = SumInOrder(radiance_.At(0, y), span, term);
        });
        return sumRows();
    };
    // Mean photoelectrons over the field as the photocathode delivers them; BSP limits their
    // mean.
    const double count = double(fieldCount_);
    meanPe_ = count > 0.0 ? sumRows() / count : 0.0;
    const double bsp = s_.PixelFramePe(s_.bspThreshold_pe_s_mm2);
    duty_ = meanPe_ > bsp ? bsp / meanPe_ : 1.0;
    // The mean as the ABC senses it through the screen current at gain g: each pixel counts at
    // most the photoelectrons that saturate it (1/g).
    const double senseScale = pePerRadiance_ * duty_;
    const auto sensedTerm = [&](double cap) {
        return [&senseScale, cap](VD L) {  // std::min(L · senseScale, cap)
            const VD pe = L * senseScale;
            return cap < pe ? cap : pe;
        };
    };
    const auto sensed = [&](double g) {
        return count > 0.0 ? fieldSum(sensedTerm(1.0 / g)) / count : 0.0;
    };
    // ABC: the gain that puts the sensed mean at abcLevel (capped at its value at the
    // threshold), sensed at the previous frame's gain; the first frame starts settled, at the
    // fixed point g = level / sensed(g) (sensed(g)·g rises with g: bisection on log g).
    const double maxGain = s_.abcLevel / s_.PixelFramePe(s_.abcThreshold_pe_s_mm2);
    const auto targetFrom = [&](double sensedMean) {
        return std::min(maxGain, s_.abcLevel / std::max(sensedMean, 1e-300));
    };
    const double dt = time_s - lastTime_s_;
    // Following the lag, the ABC senses the field at the previous gain: summed per row in the
    // scintillation pass below, which reads the same radiances.
    const bool lag = started_ && dt > 0.0 && s_.abcTimeConstant_s > 0.0;
    if (!lag) {
        double lo = maxGain * 1e-12, hi = maxGain;
        if (targetFrom(sensed(hi)) >= hi) {
            gain_ = hi;
        } else {
            for (int i = 0; i < 60; ++i) {
                const double mid = std::sqrt(lo * hi);
                (targetFrom(sensed(mid)) > mid ? lo : hi) = mid;
            }
            gain_ = std::sqrt(lo * hi);
        }
    }
    const double senseCap = lag ? 1.0 / gain_ : 0.0;

    // Scintillation: S = F · Poisson(N/F), mean N, variance F·N (SNR √(N/F)); one hash of
    // (seed, frame, pixel) per pixel inside the field stop (outside, N = 0: no electrons).
    // Each row then takes its prefix sums for the halo, padded with R zeros on the left and
    // the row's total on the right so that a disc row's run [x − hw, x + hw] needs no clipping:
    // entry R + t holds the sum of the pixels left of t (0 for t ≤ 0, the total for t ≥ w).
    const double F = s_.noiseFactor;
    const double scale = pePerRadiance_ * duty_ / F;
    const int R = int(std::floor(haloRadius_px_));
    const double f = s_.haloFraction;
    const bool halo = f > 0.0 && R >= 1;
    const int blocks = (w + kHaloBlock - 1) / kHaloBlock;
    const size_t stride = size_t(blocks * kHaloBlock + 2 * R + 1);
    if (halo) prefix_.resize(size_t(h) * stride);  // every entry is written below
    const uint64_t key = scene::Mix64(scene::Mix64(s_.seed) ^ uint64_t(frame));
    struct NoiseScratch {
        std::vector<uint64_t> bits;  // the row's hash inputs, then its hashes
        std::vector<uint32_t> low;   // the hashes' low halves
        std::vector<float> z;
    };
    tbb::enumerable_thread_specific<NoiseScratch> noiseScratch;
    tbb::parallel_for(0, h, [&](int y) {
        const PixelSpan span = spans_[size_t(y)];
        const float* L = radiance_.At(0, y);
        float* row = electrons_.At(0, y);
        std::fill(row, row + span.begin, 0.0f);
        std::fill(row + span.end, row + w, 0.0f);
        const size_t i0 = size_t(y) * size_t(w);
        // The row's hashes four at a time (a 64-bit lane product is the scalar product mod
        // 2⁶⁴) and the normal deviates of their low halves for the whole row in one call;
        // then the deviates four pixels at a time where all four take the normal branch with
        // a mean below 2⁵¹ (NormalPoisson's truncation as the rounding to nearest by 2⁵², less
        // one where that rounded up: exact for 0 ≤ v < 2⁵²), else pixel by pixel.
        NoiseScratch& noise = noiseScratch.local();
        const int count = span.end - span.begin;
        noise.bits.resize(size_t(count + 4));
        noise.low.resize(size_t(count + 4));
        noise.z.resize(size_t(count + 4));
        for (int j = 0; j < count; j += 4) {
            const VU counter = VU{0, 1, 2, 3} + uint64_t(i0 + size_t(span.begin + j));
            const VU bits =
                scene::Mix64Lanes(counter ^ key);  // scene::HashBits(seed, frame, pixel)
            std::memcpy(&noise.bits[size_t(j)], &bits, sizeof bits);
            const auto low =
                __builtin_convertvector(bits, uint32_t __attribute__((vector_size(16))));
            std::memcpy(&noise.low[size_t(j)], &low, sizeof low);
        }
        NormalsFromBits(noise.low.data(), size_t(count), noise.z.data());
        const auto draw = [&](int j, double mean) {
            row[span.begin + j] =
                float(F * (mean <= kExactPoissonMean ? PoissonDeviate(mean, noise.bits[size_t(j)])
                                                     : NormalPoisson(mean, noise.z[size_t(j)])));
        };
        int j = 0;
        for (; j + 4 <= count; j += 4) {
            const float* Lj = L + span.begin + j;
            const VD mean = VD{Lj[0], Lj[1], Lj[2], Lj[3]} * scale;
            if (!AllLanes(mean > kExactPoissonMean && mean < 0x1.0p51)) {
                for (int l = 0; l < 4; ++l) draw(j + l, mean[l]);
                continue;
            }
            const float* zj = &noise.z[size_t(j)];
            VD v = mean + SqrtVD(mean) * VD{zj[0], zj[1], zj[2], zj[3]};
            v = (0.0 < v ? v : 0.0) + 0.5;
            VD whole = (v + 0x1.0p52) - 0x1.0p52;
            whole = whole > v ? whole - 1.0 : whole;
            const VD e = F * whole;
            for (int l = 0; l < 4; ++l) row[span.begin + j + l] = float(e[l]);
        }
        for (; j < count; ++j) draw(j, double(L[span.begin + j]) * scale);
        if (lag) rowSum[size_t(y)] = SumInOrder(L, span, sensedTerm(senseCap));
        if (halo) {
            double* p = &prefix_[size_t(y) * stride];
            std::fill(p, p + R + span.begin + 1, 0.0);
            double sum = 0.0;  // p[R + x] in a register
            int x = span.begin;
            for (; x + 4 <= span.end; x += 4)
                for (int l = 0; l < 4; ++l) p[R + x + l + 1] = sum += double(row[x + l]);
            for (; x < span.end; ++x) p[R + x + 1] = sum += double(row[x]);
            std::fill(p + R + span.end + 1, p + stride, p[R + span.end]);
        }
    });
    if (lag) {
        const double target = targetFrom(count > 0.0 ? sumRows() / count : 0.0);
        gain_ = target + (gain_ - target) * std::exp(-dt / s_.abcTimeConstant_s);
    }
    started_ = true;
    lastTime_s_ = time_s;

    // Only the pixels inside the field stop reach the screen, so each stage below computes
    // just the columns the next one reads: the vertical tube blur of row y reads rows y − r …
    // y + r over y's span, the horizontal blur r more pixels each side.
    const int r = int(mtfKernel_.size() / 2);
    const auto needed = [&](int y) {
        PixelSpan need{w, 0};
        for (int yy = std::max(0, y - r); yy <= std::min(h - 1, y + r); ++yy) {
            const PixelSpan span = spans_[size_t(yy)];
            if (span.begin >= span.end) continue;
            need.begin = std::min(need.begin, span.begin);
            need.end = std::max(need.end, span.end);
        }
        return need;
    };
    // Halo: a fixed share of each pixel's electrons spread uniformly over a disc of the halo's
    // angular radius, the disc's rows from the row prefix sums; each pixel adds its disc's rows
    // in order from the top (kHaloBlock pixels at a time, in registers). Then the tube MTF's
    // horizontal pass (Gaussian, edges clamped): each pixel sums its taps k = −r … r in order.
    std::vector<int> halfWidth(size_t(2 * R + 1));
    double discCount = 0.0;
    if (halo) {
        for (int dy = -R; dy <= R; ++dy) {
            halfWidth[size_t(dy + R)] = int(std::floor(std::sqrt(double(R * R - dy * dy))));
            discCount += 2 * halfWidth[size_t(dy + R)] + 1;
        }
    }
    struct RowScratch {
        std::vector<double> disc;   // disc sums of a row (whole blocks)
        std::vector<float> padded;  // the halo row with r clamped pixels either side
        // Per disc row, the offsets in prefix_ of its run's ends for pixel 0: the prefix sum
        // after the run (hi) and before it (lo).
        std::vector<ptrdiff_t> hi, lo;
    };
    tbb::enumerable_thread_specific<RowScratch> scratch;
    tbb::parallel_for(0, h, [&](int y) {
        const PixelSpan need = needed(y);
        if (need.begin >= need.end) return;
        // Halo pixels [a, b): the blur's reach, within the row.
        const int a = std::max(0, need.begin - r), b = std::min(w, need.end + r);
        RowScratch& s = scratch.local();
        s.padded.resize(size_t(w + 2 * r));
        float* padded = s.padded.data() + r;  // padded[x] for x in [−r, w + r)
        const float* e = electrons_.At(0, y);
        if (halo) {
            s.disc.resize(size_t(blocks * kHaloBlock));
            const int dyLo = std::max(-R, -y), dyHi = std::min(R, h - 1 - y);
            const int blockA = a / kHaloBlock, blockB = (b + kHaloBlock - 1) / kHaloBlock;
            // The run ends as offsets from the block's first pixel, so that each disc row's
            // loads are two index registers and constant displacements.
            const size_t rows = size_t(dyHi - dyLo + 1);
            s.hi.resize(rows);
            s.lo.resize(rows);
            for (int dy = dyLo; dy <= dyHi; ++dy) {
                const int hw = halfWidth[size_t(dy + R)];
                const ptrdiff_t p = ptrdiff_t(size_t(y + dy) * stride) + R;
                s.hi[size_t(dy - dyLo)] = p + hw + 1;
                s.lo[size_t(dy - dyLo)] = p - hw;
            }
            const ptrdiff_t* hiEnd = s.hi.data() + rows;
            for (int block = blockA; block < blockB; ++block) {
                const int x0 = block * kHaloBlock;
                const double* p = prefix_.data() + x0;
                VD acc[kHaloBlock / 4];
                for (int j = 0; j < kHaloBlock / 4; ++j) acc[j] = VD{};
                const ptrdiff_t* lo = s.lo.data();
                for (const ptrdiff_t* hi = s.hi.data(); hi != hiEnd; ++hi, ++lo)
                    for (int j = 0; j < kHaloBlock / 4; ++j)
                        acc[j] += LoadVD(p + *hi + 4 * j) - LoadVD(p + *lo + 4 * j);
                for (int j = 0; j < kHaloBlock / 4; ++j)
                    std::memcpy(&s.disc[size_t(x0 + 4 * j)], &acc[j], sizeof(VD));
            }
            const double* disc = s.disc.data();
            for (int x = a; x < b; ++x)
                padded[x] = float((1.0 - f) * e[x] + f * disc[x] / discCount);
        } else {
            std::copy(e + a, e + b, padded + a);
        }
        for (int x = need.begin - r; x < 0; ++x) padded[x] = padded[0];
        for (int x = w; x < need.end + r; ++x) padded[x] = padded[w - 1];
        float* out = halo_.At(0, y);  // the horizontally blurred halo (only `need` is read)
        const auto across = [&](int x, size_t lanes) {
            VF sum = Splat(0.0f);
            for (int k = -r; k <= r; ++k)
                sum += Splat(mtfKernel_[size_t(k + r)]) * Load(padded + x + k, lanes);
            Store(out + x, sum, lanes);
        };
        int x = need.begin;
        for (; x + int(kLanes) <= need.end; x += int(kLanes)) across(x, kLanes);
        if (x < need.end) across(x, size_t(need.end - x));
    });
    // The tube MTF's vertical pass, then ABC gain, screen saturation (min(1, g·v) as
    // std::min) and the field stop; the P43 display through the LUT at lround(b·(kLutSize − 1))
    // (for v ≥ 0: v − trunc(v) is exact in float).
    const float gain = float(gain_);
    tbb::enumerable_thread_specific<std::vector<const float*>> tapRows;
    tbb::parallel_for(0, h, [&](int y) {
        const PixelSpan span = spans_[size_t(y)];
        float* bright = brightness_.At(0, y);
        uint8_t* rgb = &display_[size_t(y) * size_t(w) * 3];
        std::fill(bright, bright + span.begin, 0.0f);
        std::fill(bright + span.end, bright + w, 0.0f);
        // Outside the stop the colour of brightness 0; inside, each pixel's four LUT bytes
        // (the fourth is overwritten by the next pixel, written after it), the row's last
        // pixel three.
        const auto fill = [&](int begin, int end) {
            const uint8_t* c = phosphorLut_.data();
            if (c[0] == c[1] && c[1] == c[2])
                std::memset(rgb + 3 * begin, c[0], size_t(3 * (end - begin)));
            else
                for (int x = begin; x < end; ++x) std::memcpy(rgb + 3 * x, c, 3);
        };
        fill(0, span.begin);
        std::vector<const float*>& rows = tapRows.local();  // row y + k (clamped) at k + r
        rows.resize(size_t(2 * r + 1));
        for (int k = -r; k <= r; ++k)
            rows[size_t(k + r)] = halo_.At(0, std::clamp(y + k, 0, h - 1));
        const uint8_t* lut = phosphorLut_.data();
        const auto screen = [&](int x, size_t lanes) {
            VF sum = Splat(0.0f);
            for (int k = -r; k <= r; ++k)
                sum += Splat(mtfKernel_[size_t(k + r)]) * Load(rows[size_t(k + r)] + x, lanes);
            const VF v = Splat(gain) * sum;
            const VF b = Select(v < 1.0f, v, Splat(1.0f));
            Store(bright + x, b, lanes);
            const VF scaled = b * float(kLutSize - 1);
            const VI whole = __builtin_convertvector(scaled, VI);
            const VI code = whole - VI(scaled - __builtin_convertvector(whole, VF) >= 0.5f);
            int32_t codes[kLanes];
            std::memcpy(codes, &code, sizeof codes);
            uint8_t* out = rgb + 3 * x;
            if (lanes == kLanes && x + int(kLanes) < w) {
                for (size_t l = 0; l < kLanes; ++l) std::memcpy(out + 3 * l, lut + 4 * codes[l], 4);
            } else {
                for (size_t l = 0; l < lanes; ++l)
                    std::memcpy(out + 3 * l, lut + 4 * codes[l], x + int(l) + 1 < w ? 4 : 3);
            }
        };
        int x = span.begin;
        for (; x + int(kLanes) <= span.end; x += int(kLanes)) screen(x, kLanes);
        if (x < span.end) screen(x, size_t(span.end - x));
        fill(span.end, w);
    });
}

}  // namespace seasense::sensors
