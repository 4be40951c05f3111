// Analytic optics/detector MTFs and the OTF-derived sampling kernel of the thermal imager.
#include "sensors/thermal/optics_kernel.h"

#include <immintrin.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>
#include <sstream>

#include "radiometry/planck/planck.h"
#include "scene/core/error.h"
#include "scene/core/int_div.h"

namespace seasense::sensors {

namespace {

constexpr double kPi = std::numbers::pi;
// Simpson intervals per linear segment of the band response: the weight R·∂L/∂T is smooth
// within a segment and the MTF has at most one kink (its cutoff), so 32 intervals put the
// quadrature error far below 1e-4.
constexpr int kSimpsonIntervals = 32;
constexpr int kMaxKernelTaps = 255;

// Wavelength nodes and normalised quadrature weights of R(λ)·∂L_λ/∂T(T) over the band.
struct SpectralWeights {
    std::vector<double> lambda_m;
    std::vector<double> weight;
};

SpectralWeights ContrastWeights(const radiometry::Band& band, double T_K) {
    SpectralWeights sw;
    const std::vector<double>& lam = band.Wavelengths_m();
    double total = 0.0;
    for (size_t s = 0; s + 1 < lam.size(); ++s) {
        const double a = lam[s], b = lam[s + 1];
        const double h = (b - a) / kSimpsonIntervals;
        for (int i = 0; i <= kSimpsonIntervals; ++i) {
            // Composite Simpson 1, 4, 2, …, 4, 1 (h/3) per segment.
            const double simpson = (i == 0 || i == kSimpsonIntervals) ? 1.0 : (i % 2 ? 4.0 : 2.0);
            const double l = i == kSimpsonIntervals ? b : a + h * i;
            const double w =
                simpson * h / 3.0 * band.Response(l) * radiometry::PlanckRadianceDerivative(l, T_K);
            if (w <= 0.0) continue;
            sw.lambda_m.push_back(l);
            sw.weight.push_back(w);
            total += w;
        }
    }
    if (!(total > 0.0)) {
        std::ostringstream msg;
        msg << "band '" << band.Name() << "' has no thermal contrast at " << T_K
            << " K; expected a band with response where dL/dT > 0";
        throw InputError(msg.str());
    }
    for (double& w : sw.weight) w /= total;
    return sw;
}

double WeightedDiffractionMtf(const SpectralWeights& sw, double nu_per_m, double fNumber) {
    double m = 0.0;
    for (size_t i = 0; i < sw.lambda_m.size(); ++i)
        m += sw.weight[i] * DiffractionMtf(nu_per_m * sw.lambda_m[i] * fNumber);
    return m;
}

double Sinc(double x) { return std::abs(x) < 1e-8 ? 1.0 - x * x / 6.0 : std::sin(x) / x; }

double SystemOtf(const SpectralWeights& sw, const OpticsGeometry& g, double nuX, double nuY) {
    const double nu = std::hypot(nuX, nuY);
    const double a_m = g.pitch_m * std::sqrt(g.fillFactor);
    return WeightedDiffractionMtf(sw, nu, g.fNumber) * GaussianBlurMtf(nu, g.aberrationSigma_m) *
           FootprintOtf(nuX, a_m) * FootprintOtf(nuY, a_m);
}

void RequireGeometry(const OpticsGeometry& g) {
    auto bad = [](const char* what, double v, const char* expected) {
        std::ostringstream msg;
        msg << "thermal imager optics: " << what << " = " << v << "; expected " << expected;
        throw InputError(msg.str());
    };
    if (!(std::isfinite(g.fNumber) && g.fNumber > 0)) bad("F-number", g.fNumber, "> 0");
    if (!(std::isfinite(g.pitch_m) && g.pitch_m > 0)) bad("pixel pitch (m)", g.pitch_m, "> 0");
    if (!(g.fillFactor > 0 && g.fillFactor <= 1)) bad("fill factor", g.fillFactor, "in (0, 1]");
    if (!(std::isfinite(g.aberrationSigma_m) && g.aberrationSigma_m >= 0))
        bad("aberration sigma (m)", g.aberrationSigma_m, ">= 0");
    if (!(std::isfinite(g.referenceT_K) && g.referenceT_K > 0))
        bad("reference temperature (K)", g.referenceT_K, "> 0");
}

}  // namespace

double DiffractionMtf(double x) {
    x = std::abs(x);
    if (x >= 1.0) return 0.0;
    return 2.0 / kPi * (std::acos(x) - x * std::sqrt(1.0 - x * x));
}

double BandDiffractionMtf(const radiometry::Band& band, double referenceT_K, double nu_per_m,
                          double fNumber) {
    return WeightedDiffractionMtf(ContrastWeights(band, referenceT_K), nu_per_m, fNumber);
}

double GaussianBlurMtf(double nu_per_m, double sigma_m) {
    return std::exp(-2.0 * kPi * kPi * sigma_m * sigma_m * nu_per_m * nu_per_m);
}

double FootprintOtf(double nu_per_m, double width_m) { return Sinc(kPi * width_m * nu_per_m); }

double SystemOtf(const radiometry::Band& band, const OpticsGeometry& geometry, double nuX_per_m,
                 double nuY_per_m) {
    RequireGeometry(geometry);
    return SystemOtf(ContrastWeights(band, geometry.referenceT_K), geometry, nuX_per_m, nuY_per_m);
}

int SamplingKernelRadius_px(const radiometry::Band& band, const OpticsGeometry& geometry,
                            int minRadius_px) {
    RequireGeometry(geometry);
    const double lambda_m = 0.5 * (band.MinWavelength_m() + band.MaxWavelength_m());
    const double airy_px = 6.0 * lambda_m * geometry.fNumber / geometry.pitch_m;
    const double blur_px = 4.0 * geometry.aberrationSigma_m / geometry.pitch_m + 1.0;
    return std::max({minRadius_px, int(std::ceil(airy_px)), int(std::ceil(blur_px))});
}

SamplingKernel BuildSamplingKernel(const radiometry::Band& band, const OpticsGeometry& geometry,
                                   int supersamples, int radius_px) {
    RequireGeometry(geometry);
    const int n = supersamples;
    if (n < 1 || radius_px < 1 || 2 * radius_px * n + (n % 2) > kMaxKernelTaps) {
        std::ostringstream msg;
        msg << "thermal imager sampling kernel: " << n << " supersamples and a radius of "
            << radius_px
            << " px; expected N >= 1, radius >= 1 and 2·radius·N <= " << kMaxKernelTaps - 1
            << " taps";
        throw InputError(msg.str());
    }
    const SpectralWeights sw = ContrastWeights(band, geometry.referenceT_K);
    SamplingKernel kernel;
    kernel.supersamples = n;
    kernel.size = 2 * radius_px * n + (n % 2);
    const int K = kernel.size;
    kernel.padded = (K + 3) / 4 * 4;

    // Frequencies k/(K·Δ), k = −⌊K/2⌋ … ⌊K/2⌋; for even K the Nyquist pair ±K/2 shares one
    // DFT bin and gets weight ½ each, which keeps the real, even OTF symmetric.
    const double delta_m = geometry.pitch_m / n;
    const int half = K / 2;
    const int L = 2 * half + 1;
    std::vector<double> nu(static_cast<size_t>(L)), binWeight(static_cast<size_t>(L), 1.0);
    for (int k = -half; k <= half; ++k) {
        nu[size_t(k + half)] = k / (K * delta_m);
        if (K % 2 == 0 && std::abs(k) == half) binWeight[size_t(k + half)] = 0.5;
    }
    std::vector<double> otf(size_t(L) * size_t(L));
    for (int l = 0; l < L; ++l)
        for (int k = 0; k < L; ++k)
            otf[size_t(l) * L + size_t(k)] = binWeight[size_t(l)] * binWeight[size_t(k)] *
                                             SystemOtf(sw, geometry, nu[size_t(k)], nu[size_t(l)]);
    // cosTable[k][j] = cos(2π k u_j / K), u_j = j − (K − 1)/2: the OTF is even in each axis,
    // so the inverse DFT keeps only the cosine products.
    std::vector<double> cosTable(size_t(L) * size_t(K));
    for (int k = 0; k < L; ++k)
        for (int j = 0; j < K; ++j)
            cosTable[size_t(k) * K + size_t(j)] =
                std::cos(2.0 * kPi * (k - half) * (j - 0.5 * (K - 1)) / K);
    // rowSums[l][j] = Σ_k otf[l][k] cos[k][j]; taps[i][j] = Σ_l cos[l][i] rowSums[l][j] / K².
    std::vector<double> rowSums(size_t(L) * size_t(K), 0.0);
    for (int l = 0; l < L; ++l)
        for (int k = 0; k < L; ++k) {
            const double o = otf[size_t(l) * L + size_t(k)];
            for (int j = 0; j < K; ++j)
                rowSums[size_t(l) * K + size_t(j)] += o * cosTable[size_t(k) * K + size_t(j)];
        }
    std::vector<double> taps(size_t(K) * size_t(K), 0.0);
    double sum = 0.0;
    for (int i = 0; i < K; ++i)
        for (int j = 0; j < K; ++j) {
            double t = 0.0;
            for (int l = 0; l < L; ++l)
                t += cosTable[size_t(l) * K + size_t(i)] * rowSums[size_t(l) * K + size_t(j)];
            taps[size_t(i) * K + size_t(j)] = t;
            sum += t;
        }
    // Analytically the taps sum to OTF(0, 0) = 1; dividing by the computed sum removes the
    // rounding so a uniform scene keeps its radiance. Mirrored rows and columns are averaged
    // so the x and y symmetry the row and column folding rely on holds bit for bit.
    kernel.taps.assign(size_t(K) * size_t(kernel.padded), 0.0f);
    const auto tap = [&](int i, int j) { return taps[size_t(i) * K + size_t(j)]; };
    for (int i = 0; i < K; ++i)
        for (int j = 0; j < K; ++j) {
            const double mirrored = 0.25 * ((tap(i, j) + tap(K - 1 - i, j)) +
                                            (tap(i, K - 1 - j) + tap(K - 1 - i, K - 1 - j)));
            kernel.taps[size_t(i) * kernel.padded + size_t(j)] = float(mirrored / sum);
        }
    return kernel;
}

namespace {

// Vectors per step of the tap loop (KernelSteps): ten accumulators (twelve of the sixteen vector
// registers with the tap and the pair sum), so that a tap pair's column offsets and loop overhead
// serve 80 pixels (eight lanes), a 640-pixel row in eight whole steps; and the pixels of the widest
// step, which the phase arrays are padded to.
constexpr int kGroups = 10;
constexpr int kPixelsPerStep = 8 * kGroups;
// Floats per tap in the broadcast tap table: one vector of the widest path, so that a pair's tap
// is one load rather than a load and a broadcast.
constexpr int kTapLanes = 8;

// Offsets (floats) of a tap pair's two columns within folded row 0 (the centre column twice).
struct TapColumns {
    ptrdiff_t first, second;
};

// The folded rows and tap pairs of one row, as SampleKernelRow lays them out.
struct FoldedRow {
    const float* phases;  // folded row 0; row i at phases + i · rowStride
    size_t rowStride;
    const float* taps;  // per folded row, perRow taps, each broadcast to kTapLanes floats
    int folded, pairs, perRow;
    bool centre;                // odd K: a centre column after the pairs
    const TapColumns* columns;  // perRow entries
};

// GCC vector types of four and eight floats: + and * are the lanes' single-precision adds and
// multiplies, so one body serves both widths with the same operations per pixel.
typedef float Lanes4 __attribute__((vector_size(16)));
typedef float Lanes8 __attribute__((vector_size(32)));

// The tap loop for all pixels of the row, kGroups vectors of V (independent chains of additions
// that hide the adder's latency) per step. Fixed summation order per pixel (folded rows, then
// pairs, then the centre column): the result of a pixel does not depend on its lane, on the
// width of V or on the threading. Always inlined, so that it is compiled for the caller's
// instruction set (KernelSteps8: AVX).
template <class V>
__attribute__((always_inline)) inline void KernelSteps(const FoldedRow& r, int w, float* out) {
    constexpr int kLanes = int(sizeof(V) / sizeof(float));
    for (int x = 0; x < w; x += kLanes * kGroups) {
        // Zeroed per vector: the whole-array initialiser zeroes a stack copy (rep stos) first.
        V acc[kGroups];
        for (int g = 0; g < kGroups; ++g) acc[g] = V{};
        for (int i = 0; i < r.folded; ++i) {
            const float* row = r.phases + size_t(i) * r.rowStride + size_t(x);
            const float* tap = r.taps + size_t(i) * size_t(r.perRow) * kTapLanes;
            const TapColumns* c = r.columns;
            for (const TapColumns* end = c + r.pairs; c != end; ++c, tap += kTapLanes) {
                const float* u = row + c->first;
                const float* v = row + c->second;
                V t;  // the tap in every lane
                __builtin_memcpy(&t, tap, sizeof(V));
                for (int g = 0; g < kGroups; ++g) {
                    V a, b;  // unaligned loads
                    __builtin_memcpy(&a, u + kLanes * g, sizeof(V));
                    __builtin_memcpy(&b, v + kLanes * g, sizeof(V));
                    acc[g] = acc[g] + t * (a + b);
                }
            }
            if (r.centre) {
                const float* u = row + c->first;
                V t;
                __builtin_memcpy(&t, tap, sizeof(V));
                for (int g = 0; g < kGroups; ++g) {
                    V a;
                    __builtin_memcpy(&a, u + kLanes * g, sizeof(V));
                    acc[g] = acc[g] + t * a;
                }
            }
        }
        // A whole step straight to the row, the last partial one through a buffer.
        const int count = std::min(kLanes * kGroups, w - x);
        alignas(32) float lanes[kLanes * kGroups];
        float* dst = count == kLanes * kGroups ? out + x : lanes;
        for (int g = 0; g < kGroups; ++g) __builtin_memcpy(dst + kLanes * g, &acc[g], sizeof(V));
        if (dst == lanes) std::copy(lanes, lanes + count, out + x);
    }
}

void KernelSteps4(const FoldedRow& r, int w, float* out) { KernelSteps<Lanes4>(r, w, out); }

// Eight lanes (twice the pixels per load and per add): target("avx") enables the 256-bit
// registers without FMA, so nothing is fused. Chosen at run time (SamplingKernelWidePath), as
// the plume bins' AVX2 path.
__attribute__((target("avx"))) void KernelSteps8(const FoldedRow& r, int w, float* out) {
    KernelSteps<Lanes8>(r, w, out);
}

}  // namespace

bool SamplingKernelWidePath() {
    static const bool avx = __builtin_cpu_supports("avx");
    return avx;
}

void SampleKernelRow(const Image& samples, const SamplingKernel& kernel, int y, float* out,
                     std::vector<float>& scratch, bool wide) {
    const int n = kernel.supersamples, K = kernel.size, Kp = kernel.padded;
    CHECK(samples.channels == 1 && samples.width % n == 0 && samples.height % n == 0);
    const int W = samples.width, H = samples.height, w = W / n;
    const int o = (n - K) / 2;  // first tap relative to the pixel's first sample (≤ 0)
    // Tap (i, j) of pixel x reads sample column n·x + o + j. With d = o + j that is
    // n·(x + ⌊d/n⌋) + (d mod n): entry x + ⌊d/n⌋ of phase d mod n, where phase r of a row
    // holds its samples r, n + r, 2n + r, … So the taps of four neighbouring pixels are four
    // consecutive floats of one phase array, and the loop runs four pixels to a lane group.
    const int mMin = FloorDiv(o, n);
    const int steps = (w + kPixelsPerStep - 1) / kPixelsPerStep;
    const int len = steps * kPixelsPerStep + FloorDiv(o + K - 1, n) - mMin + 1;
    // Folded rows: row i holds S[y₀ + i] + S[y₀ + K − 1 − i] (the centre row of an odd K
    // alone), split into its n phases; entry m − mMin of phase r is column n·m + r, clamped to
    // the image (the border samples repeat outward).
    const int folded = (K + 1) / 2;
    const int pairs = K / 2;  // columns j and K − 1 − j share a tap (even OTF)
    const size_t phaseStride = size_t(len), rowStride = size_t(n) * phaseStride;
    const size_t tapFloats = size_t(folded) * size_t(pairs + 1) * kTapLanes;
    scratch.resize(size_t(folded) * rowStride + tapFloats + kTapLanes);
    float* phases = scratch.data();
    for (int i = 0; i < folded; ++i) {
        const float* a = samples.At(0, std::clamp(y * n + o + i, 0, H - 1));
        const float* b = samples.At(0, std::clamp(y * n + o + K - 1 - i, 0, H - 1));
        const bool centre = 2 * i + 1 == K;
        float* row = phases + size_t(i) * rowStride;
        // Columns n·m + r inside the image for m in [mLo, mHi).
        const int mLo = std::max(0, mMin), mHi = std::min(W / n, mMin + len);
        // Outside the image the column n·m + r clamps to the first column (m < 0 ≤ mLo) or
        // the last (m ≥ mHi = W/n), whatever the phase r.
        auto at = [&](int c) { return centre ? a[c] : a[c] + b[c]; };
        const float left = at(0), right = at(W - 1);
        for (int r = 0; r < n; ++r) {
            float* dst = row + size_t(r) * phaseStride - mMin;
            std::fill(dst + mMin, dst + mLo, left);
            std::fill(dst + std::max(mHi, mLo), dst + mMin + len, right);
        }
        int m = mLo;
        if (n == 2 && !centre) {
            // Even and odd samples of eight columns at a time.
            float* even = row - mMin;
            float* odd = row + phaseStride - mMin;
#if defined(__AVX2__)
            for (; m + 8 <= mHi; m += 8) {
                // (s0 s2 s8 s10 | s4 s6 s12 s14) and the odd ones, put in order by vpermpd.
                const __m256 s0 =
                    _mm256_add_ps(_mm256_loadu_ps(a + 2 * m), _mm256_loadu_ps(b + 2 * m));
                const __m256 s1 =
                    _mm256_add_ps(_mm256_loadu_ps(a + 2 * m + 8), _mm256_loadu_ps(b + 2 * m + 8));
                const auto Ordered = [](__m256 v) {
                    return _mm256_castpd_ps(
                        _mm256_permute4x64_pd(_mm256_castps_pd(v), _MM_SHUFFLE(3, 1, 2, 0)));
                };
                _mm256_storeu_ps(even + m,
                                 Ordered(_mm256_shuffle_ps(s0, s1, _MM_SHUFFLE(2, 0, 2, 0))));
                _mm256_storeu_ps(odd + m,
                                 Ordered(_mm256_shuffle_ps(s0, s1, _MM_SHUFFLE(3, 1, 3, 1))));
            }
#endif
            for (; m + 4 <= mHi; m += 4) {
                const __m128 s0 = _mm_add_ps(_mm_loadu_ps(a + 2 * m), _mm_loadu_ps(b + 2 * m));
                const __m128 s1 =
                    _mm_add_ps(_mm_loadu_ps(a + 2 * m + 4), _mm_loadu_ps(b + 2 * m + 4));
                _mm_storeu_ps(even + m, _mm_shuffle_ps(s0, s1, _MM_SHUFFLE(2, 0, 2, 0)));
                _mm_storeu_ps(odd + m, _mm_shuffle_ps(s0, s1, _MM_SHUFFLE(3, 1, 3, 1)));
            }
        }
        for (; m < mHi; ++m)
            for (int r = 0; r < n; ++r)
                row[size_t(r) * phaseStride + size_t(m - mMin)] =
                    centre ? a[n * m + r] : a[n * m + r] + b[n * m + r];
    }
    // Taps broadcast to kTapLanes floats: pairs (and the centre column of an odd K) per folded
    // row. Each holds 0 + tap, as V{} + tap would broadcast it (the tap, +0 for a −0 tap).
    float* taps = phases + size_t(folded) * rowStride;
    taps += (32 - reinterpret_cast<uintptr_t>(taps) % 32) % 32 / sizeof(float);
    const int perRow = pairs + K % 2;
    for (int i = 0; i < folded; ++i)
        for (int p = 0; p < perRow; ++p)
            std::fill_n(taps + (size_t(i) * size_t(perRow) + size_t(p)) * kTapLanes, kTapLanes,
                        0.0f + kernel.taps[size_t(i) * size_t(Kp) + size_t(p)]);
    // Offsets of the two columns of each pair (the centre column twice) within folded row 0.
    std::array<TapColumns, (kMaxKernelTaps + 1) / 2> columns;
    for (int p = 0; p < perRow; ++p) {
        const int d1 = o + p, d2 = o + K - 1 - p;
        columns[size_t(p)].first =
            ptrdiff_t(d1 - FloorDiv(d1, n) * n) * ptrdiff_t(phaseStride) + FloorDiv(d1, n) - mMin;
        columns[size_t(p)].second =
            ptrdiff_t(d2 - FloorDiv(d2, n) * n) * ptrdiff_t(phaseStride) + FloorDiv(d2, n) - mMin;
    }
    const FoldedRow folding{phases, rowStride, taps,       folded,
                            pairs,  perRow,    K % 2 == 1, columns.data()};
    if (wide && SamplingKernelWidePath())
        KernelSteps8(folding, w, out);
    else
        KernelSteps4(folding, w, out);
}

Image ApplySamplingKernel(const Image& samples, const SamplingKernel& kernel, bool wide) {
    const int n = kernel.supersamples;
    CHECK(samples.channels == 1 && samples.width % n == 0 && samples.height % n == 0);
    Image out(samples.width / n, samples.height / n, 1);
    tbb::parallel_for(tbb::blocked_range<int>(0, out.height),
                      [&](const tbb::blocked_range<int>& r) {
                          std::vector<float> scratch;
                          for (int y = r.begin(); y < r.end(); ++y)
                              SampleKernelRow(samples, kernel, y, out.At(0, y), scratch, wide);
                      });
    return out;
}

}  // namespace seasense::sensors
