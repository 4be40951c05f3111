// Analytic optics/detector MTFs and the OTF-derived sampling kernel of the thermal imager.
#include "sensors/thermal/optics_kernel.h"

#include <emmintrin.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "radiometry/planck/planck.h"
#include "scene/core/error.h"

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
    // rounding so a uniform scene keeps its radiance. Mirrored rows are averaged so the
    // y symmetry the row folding relies on holds bit for bit.
    kernel.taps.assign(size_t(K) * size_t(kernel.padded), 0.0f);
    for (int i = 0; i < K; ++i)
        for (int j = 0; j < K; ++j) {
            const double mirrored =
                0.5 * (taps[size_t(i) * K + size_t(j)] + taps[size_t(K - 1 - i) * K + size_t(j)]);
            kernel.taps[size_t(i) * kernel.padded + size_t(j)] = float(mirrored / sum);
        }
    return kernel;
}

void SampleKernelRow(const Image& samples, const SamplingKernel& kernel, int y, float* out,
                     std::vector<float>& scratch) {
    const int n = kernel.supersamples, K = kernel.size, Kp = kernel.padded;
    CHECK(samples.channels == 1 && samples.width % n == 0 && samples.height % n == 0);
    const int W = samples.width, H = samples.height, w = W / n;
    const int o = (n - K) / 2;  // first tap relative to the pixel's first sample
    // Folded rows: row i holds S[y₀ + i] + S[y₀ + K − 1 − i] (the centre row of an odd K
    // alone), extended by Kp clamped samples on each side so no pixel needs a border case.
    const int folded = (K + 1) / 2;
    const int pad = Kp;
    const size_t stride = size_t(W + 2 * pad);
    scratch.resize(size_t(folded) * stride);
    for (int i = 0; i < folded; ++i) {
        const float* a = samples.At(0, std::clamp(y * n + o + i, 0, H - 1));
        const float* b = samples.At(0, std::clamp(y * n + o + K - 1 - i, 0, H - 1));
        float* dst = scratch.data() + size_t(i) * stride + size_t(pad);
        if (2 * i + 1 == K) {
            std::copy(a, a + W, dst);
        } else {
            for (int x = 0; x < W; ++x) dst[x] = a[x] + b[x];
        }
        std::fill(dst - pad, dst, dst[0]);
        std::fill(dst + W, dst + W + pad, dst[W - 1]);
    }
    for (int x = 0; x < w; ++x) {
        __m128 acc = _mm_setzero_ps();
        const size_t x0 = size_t(x * n + o + pad);  // ≥ 0: pad ≥ K > −o
        for (int i = 0; i < folded; ++i) {
            const float* src = scratch.data() + size_t(i) * stride + x0;
            const float* tap = kernel.taps.data() + size_t(i) * size_t(Kp);
            for (int j = 0; j < Kp; j += 4)
                acc = _mm_add_ps(acc, _mm_mul_ps(_mm_loadu_ps(src + j), _mm_loadu_ps(tap + j)));
        }
        alignas(16) float lanes[4];
        _mm_store_ps(lanes, acc);
        out[x] = (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]);
    }
}

Image ApplySamplingKernel(const Image& samples, const SamplingKernel& kernel) {
    const int n = kernel.supersamples;
    CHECK(samples.channels == 1 && samples.width % n == 0 && samples.height % n == 0);
    Image out(samples.width / n, samples.height / n, 1);
    tbb::parallel_for(tbb::blocked_range<int>(0, out.height),
                      [&](const tbb::blocked_range<int>& r) {
                          std::vector<float> scratch;
                          for (int y = r.begin(); y < r.end(); ++y)
                              SampleKernelRow(samples, kernel, y, out.At(0, y), scratch);
                      });
    return out;
}

}  // namespace seasense::sensors
