// Thermal imager chain: sampling kernel, lag, NETD noise, fixed pattern, NUC, ADC and AGC.
#include "sensors/thermal/thermal_imager.h"

#include <immintrin.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "scene/core/error.h"
#include "scene/core/rng.h"
#include "scene/core/simd4.h"
#include "sensors/thermal/normal_deviates.h"

namespace seasense::sensors {

namespace {

using simd4::LoadLanes;
using simd4::StoreLanes;

constexpr double kPi = std::numbers::pi;

// Random streams of the counter RNG (scene/core/rng.h): one per pattern, one per frame of
// temporal noise and one per NUC calibration frame, so no two draws share a (stream, counter).
constexpr uint64_t kStreamPixelOffset = 1;
constexpr uint64_t kStreamPixelGain = 2;
constexpr uint64_t kStreamRow = 3;
constexpr uint64_t kStreamColumn = 4;
constexpr uint64_t kStreamTemporal = uint64_t(1) << 40;     // + frame index
constexpr uint64_t kStreamCalibration = uint64_t(2) << 40;  // + calibration frame index

// A pixel's gain never drops below this fraction of nominal, so a large gain spread cannot
// give a pixel zero or inverted response.
constexpr double kMinPixelGain = 0.01;

// Four pixels as floats, doubles and 32-bit integers (GCC vector types: the AVX build computes
// the four doubles in one vector, the SSE2 build in two, the same operation per lane).
typedef float Floats4 __attribute__((vector_size(16)));
typedef double D4 __attribute__((vector_size(32)));
typedef int32_t I4 __attribute__((vector_size(16)));

inline float Gaussian(uint64_t seed, uint64_t stream, uint64_t counter) {
    return NormalFromBits(uint32_t(scene::HashBits(seed, stream, counter) >> 32));
}

// Noise counter of pixel (x, y): one hash serves the pair (x, x + 1), x even.
inline uint64_t PairCounter(int x, int y) {
    return (uint64_t(uint32_t(y)) << 32) | uint32_t(x / 2);
}

// The frame's constants of the per-pixel chain (ThermalImager::Process).
struct ChainConstants {
    double tau, alpha, kE, adcGain, adcOffset;
    float sigma;
};

// The per-pixel chain of one row in double, four pixels at a time, with the same operations in
// the same order as the scalar definition:
//   L = τ·blurred, lagged = y + α(L − y) (L on a settled frame), E = kE·lagged,
//   s = gain·E + offset + float(noiseScale·σ·z)  (s = E + float(σ·z) for an ideal response),
//   counts = Quantize(adcGain·s + adcOffset).
// rad holds the previous frame's lagged radiance and gets this frame's; sig holds the blurred
// radiance and gets the signal. The response (ideal or not) and the lag (settled or not) are
// template arguments and the constants locals, so that the loop neither branches on them nor
// reloads them per pixel group.
template <bool kIdeal, bool kSettled>
void ChainRow(const ChainConstants& c, int w, const float* z, const float* gain,
              const float* offset, const float* noiseScale, float* rad, float* sig, uint16_t* cnt) {
    const double tau = c.tau, alpha = c.alpha, kE = c.kE, adcGain = c.adcGain,
                 adcOffset = c.adcOffset, top = double(kAdcMaxCount);
    const __m128 sigma4 = _mm_set1_ps(c.sigma);
    const D4 top4 = D4{} + top;
    const auto step = [&](int x, size_t lanes) __attribute__((always_inline)) {
        const __m128 blurred = LoadLanes(sig + x, lanes, 0.0f);
        // float(noiseScale·σ·z), left to right as the scalar product.
        const __m128 z4 = LoadLanes(z + x, lanes, 0.0f);
        const D4 L = tau * simd4::ToDouble4(blurred);
        D4 lagged = L;
        if constexpr (!kSettled) {
            const D4 prev = simd4::ToDouble4(LoadLanes(rad + x, lanes, 0.0f));
            lagged = prev + alpha * (L - prev);
        }
        const D4 E = kE * lagged;
        D4 signal;
        if constexpr (kIdeal) {
            signal = E + simd4::ToDouble4(_mm_mul_ps(sigma4, z4));
        } else {
            const __m128 noise =
                _mm_mul_ps(_mm_mul_ps(LoadLanes(noiseScale + x, lanes, 0.0f), sigma4), z4);
            signal = (simd4::ToDouble4(LoadLanes(gain + x, lanes, 0.0f)) * E +
                      simd4::ToDouble4(LoadLanes(offset + x, lanes, 0.0f))) +
                     simd4::ToDouble4(noise);
        }
        StoreLanes(rad + x, lanes, __m128(__builtin_convertvector(lagged, Floats4)));
        StoreLanes(sig + x, lanes, __m128(__builtin_convertvector(signal, Floats4)));
        // Quantize: NaN and v ≤ 0 → 0 (as maxpd(v, 0)), v ≥ 16383 → 16383 (minpd(v, 16383)),
        // else ⌊v + ½⌋.
        D4 v = adcGain * signal + adcOffset;
        v = v > 0.0 ? v : D4{};
        v = v < top ? v : top4;
        const I4 q = __builtin_convertvector(v + 0.5, I4);
        if (lanes == 4) {
            // The four counts (0 … 16383) packed to 16 bits.
            const __m128i q16 = _mm_packs_epi32(__m128i(q), __m128i(q));
            _mm_storel_epi64(reinterpret_cast<__m128i*>(cnt + x), q16);
        } else {
            for (size_t k = 0; k < lanes; ++k) cnt[size_t(x) + k] = uint16_t(q[k]);
        }
    };
    int x = 0;
    for (; x + 4 <= w; x += 4) step(x, 4);
    if (x < w) step(x, size_t(w - x));
}

void Validate(const ThermalImagerSettings& s, int supersamples) {
    std::ostringstream msg;
    auto fail = [&](const char* what, double v, const char* expected) {
        msg << "thermal imager: " << what << " = " << v << "; expected " << expected;
        throw InputError(msg.str());
    };
    auto positive = [&](const char* what, double v) {
        if (!(std::isfinite(v) && v > 0)) fail(what, v, "a finite value > 0");
    };
    auto nonNegative = [&](const char* what, double v) {
        if (!(std::isfinite(v) && v >= 0)) fail(what, v, "a finite value >= 0");
    };
    if (s.width_px < 1 || s.height_px < 1 || s.width_px > 32768 || s.height_px > 32768)
        fail("width × height (px)", double(s.width_px) * s.height_px, "1 … 32768 on each side");
    if (supersamples < 1 || supersamples > 16) fail("supersamples", supersamples, "1 … 16");
    positive("pixel pitch (m)", s.pitch_m);
    if (!(s.fillFactor > 0 && s.fillFactor <= 1)) fail("fill factor", s.fillFactor, "(0, 1]");
    nonNegative("time constant (s)", s.timeConstant_s);
    positive("focal length (m)", s.focalLength_m);
    positive("F-number", s.fNumber);
    if (!(s.opticsTransmission > 0 && s.opticsTransmission <= 1))
        fail("optics transmission", s.opticsTransmission, "(0, 1]");
    nonNegative("aberration sigma (m)", s.aberrationSigma_m);
    if (s.psfRadius_px < 1) fail("PSF radius (px)", s.psfRadius_px, ">= 1");
    nonNegative("NETD (K)", s.netd_K);
    positive("NETD reference temperature (K)", s.netdReference_K);
    nonNegative("offset FPN (K)", s.offsetFpn_K);
    if (!(s.gainFpn >= 0 && s.gainFpn <= 0.5)) fail("gain FPN", s.gainFpn, "[0, 0.5]");
    nonNegative("row FPN (K)", s.rowFpn_K);
    nonNegative("column FPN (K)", s.columnFpn_K);
    if (s.nuc) {
        positive("NUC low temperature (K)", s.nucLow_K);
        if (!(std::isfinite(s.nucHigh_K) && s.nucHigh_K > s.nucLow_K))
            fail("NUC high temperature (K)", s.nucHigh_K, "a value above the low temperature");
        if (s.nucFrames < 1) fail("NUC frames", s.nucFrames, ">= 1");
    }
    positive("ADC minimum temperature (K)", s.adcMin_K);
    if (!(std::isfinite(s.adcMax_K) && s.adcMax_K > s.adcMin_K))
        fail("ADC maximum temperature (K)", s.adcMax_K, "a value above the minimum");
}

SamplingKernel MakeKernel(const ThermalImagerSettings& s, const radiometry::Band& band,
                          int supersamples) {
    Validate(s, supersamples);
    OpticsGeometry g;
    g.fNumber = s.fNumber;
    g.pitch_m = s.pitch_m;
    g.fillFactor = s.fillFactor;
    g.aberrationSigma_m = s.aberrationSigma_m;
    g.referenceT_K = s.netdReference_K;
    return BuildSamplingKernel(band, g, supersamples,
                               SamplingKernelRadius_px(band, g, s.psfRadius_px));
}

}  // namespace

double FocalPlaneIrradiance(double radiance_W_m2_sr, double tau, double fNumber) {
    return tau * kPi * radiance_W_m2_sr / (4.0 * fNumber * fNumber + 1.0);
}

double ApparentTemperature(const radiometry::BandRadianceTable& table, double radiance_W_m2_sr,
                           double tauPath, double airT_K) {
    std::ostringstream msg;
    if (!(tauPath > 0.0 && tauPath <= 1.0)) {
        msg << "apparent temperature: path transmission " << tauPath << "; expected (0, 1]";
        throw InputError(msg.str());
    }
    if (!std::isfinite(radiance_W_m2_sr) || !(std::isfinite(airT_K) && airT_K > 0.0)) {
        msg << "apparent temperature: radiance " << radiance_W_m2_sr << " W/(m² sr), air " << airT_K
            << " K; expected a finite radiance and an air temperature > 0 K";
        throw InputError(msg.str());
    }
    const double path = tauPath < 1.0 ? (1.0 - tauPath) * table.Radiance(airT_K) : 0.0;
    const double target = (radiance_W_m2_sr - path) / tauPath;
    if (!(target > 0.0)) {
        msg << "apparent temperature: measured radiance " << radiance_W_m2_sr
            << " W/(m² sr) is not above the path radiance " << path
            << " W/(m² sr); expected a target brighter than absolute zero";
        throw InputError(msg.str());
    }
    return table.Temperature(target);
}

ThermalImager::ThermalImager(const ThermalImagerSettings& settings, radiometry::Band band,
                             int supersamples)
    : settings_(settings),
      table_(std::move(band)),
      kernel_(MakeKernel(settings, table_.GetBand(), supersamples)),
      display_(settings.agc),
      radiance_(settings.width_px, settings.height_px, 1),
      signal_(settings.width_px, settings.height_px, 1),
      counts_(size_t(settings.width_px) * size_t(settings.height_px), 0) {
    const ThermalImagerSettings& s = settings_;
    irradiancePerRadiance_ = FocalPlaneIrradiance(1.0, s.opticsTransmission, s.fNumber);
    // NETD: the temperature step whose signal change equals the temporal noise std, so
    // σ_E = NETD · dE/dT at the reference temperature.
    noiseSigma_ = s.netd_K * irradiancePerRadiance_ * table_.RadianceDerivative(s.netdReference_K);
    const double eMin = BlackbodyIrradiance(s.adcMin_K), eMax = BlackbodyIrradiance(s.adcMax_K);
    adcGain_ = double(kAdcMaxCount) / (eMax - eMin);
    adcOffset_ = -adcGain_ * eMin;
    BuildFixedPattern();
    if (s.nuc) CalibrateNuc();
}

double ThermalImager::BlackbodyIrradiance(double T_K) const {
    return irradiancePerRadiance_ * table_.Radiance(T_K);
}

double ThermalImager::HorizontalFov_rad() const {
    return 2.0 *
           std::atan(settings_.width_px * settings_.pitch_m / (2.0 * settings_.focalLength_m));
}

void ThermalImager::BuildFixedPattern() {
    const ThermalImagerSettings& s = settings_;
    const bool pattern = s.offsetFpn_K > 0 || s.gainFpn > 0 || s.rowFpn_K > 0 || s.columnFpn_K > 0;
    if (!pattern && !s.nuc) return;
    const int w = s.width_px, h = s.height_px;
    const size_t n = size_t(w) * size_t(h);
    rawGain_.assign(n, 1.0f);
    rawOffset_.assign(n, 0.0f);
    // Offsets are specified in kelvin at the NETD reference, like the NETD itself.
    const double perKelvin = irradiancePerRadiance_ * table_.RadianceDerivative(s.netdReference_K);
    std::vector<double> column(static_cast<size_t>(w));
    for (int x = 0; x < w; ++x)
        column[size_t(x)] = s.columnFpn_K * Gaussian(s.seed, kStreamColumn, uint64_t(x));
    tbb::parallel_for(0, h, [&](int y) {
        const double row = s.rowFpn_K * Gaussian(s.seed, kStreamRow, uint64_t(y));
        for (int x = 0; x < w; ++x) {
            const size_t i = size_t(y) * size_t(w) + size_t(x);
            const double g = 1.0 + s.gainFpn * Gaussian(s.seed, kStreamPixelGain, i);
            const double o = s.offsetFpn_K * Gaussian(s.seed, kStreamPixelOffset, i);
            rawGain_[i] = float(std::max(g, kMinPixelGain));
            rawOffset_[i] = float((o + row + column[size_t(x)]) * perKelvin);
        }
    });
    gain_ = rawGain_;
    offset_ = rawOffset_;
    noiseScale_.assign(n, 1.0f);
}

void ThermalImager::CalibrateNuc() {
    // Two-point NUC (Holst, "Electro-Optical Imaging System Performance", ch. 12; Scribner et
    // al., Proc. SPIE 1308, 1990): each pixel's mean response to uniform blackbodies at T1 and
    // T2 defines the linear correction s' = a·s + b that maps them to the ideal pixel's
    // signals E1 and E2. The means come from nucFrames noisy frames, so the correction
    // carries the calibration noise σ/√frames a real camera has.
    const ThermalImagerSettings& s = settings_;
    const int w = s.width_px, h = s.height_px, frames = s.nucFrames;
    const double e1 = BlackbodyIrradiance(s.nucLow_K), e2 = BlackbodyIrradiance(s.nucHigh_K);
    tbb::parallel_for(0, h, [&](int y) {
        std::vector<double> sum1(size_t(w), 0.0), sum2(size_t(w), 0.0);
        for (int f = 0; f < 2 * frames; ++f) {
            std::vector<double>& sum = f < frames ? sum1 : sum2;
            const double e = f < frames ? e1 : e2;
            for (int x = 0; x < w; x += 2) {
                float z[2] = {0.0f, 0.0f};
                if (noiseSigma_ > 0)
                    NormalPair(scene::HashBits(s.seed, kStreamCalibration + uint64_t(f),
                                               PairCounter(x, y)),
                               z[0], z[1]);
                for (int k = 0; k < 2 && x + k < w; ++k)
                    sum[size_t(x + k)] += RawSignal(size_t(y) * size_t(w) + size_t(x + k), e, z[k]);
            }
        }
        for (int x = 0; x < w; ++x) {
            const size_t i = size_t(y) * size_t(w) + size_t(x);
            const double s1 = sum1[size_t(x)] / frames, s2 = sum2[size_t(x)] / frames;
            // A pixel whose calibration gave no response difference keeps its raw response.
            if (!(s2 > s1)) continue;
            const double a = (e2 - e1) / (s2 - s1);
            const double b = e1 - a * s1;
            gain_[i] = float(a * rawGain_[i]);
            offset_[i] = float(a * rawOffset_[i] + b);
            noiseScale_[i] = float(a);
        }
    });
}

double ThermalImager::RawSignal(size_t i, double E, double z) const {
    return double(rawGain_[i]) * E + double(rawOffset_[i]) + noiseSigma_ * z;
}

void ThermalImager::Process(const Image& samples, double time_s, int64_t noiseFrame) {
    const int w = settings_.width_px, h = settings_.height_px, n = kernel_.supersamples;
    CHECK_MSG(samples.channels == 1 && samples.width == w * n && samples.height == h * n,
              "thermal imager input " << samples.width << "×" << samples.height << "×"
                                      << samples.channels << ", expected " << w * n << "×" << h * n
                                      << "×1");
    CHECK(std::isfinite(time_s));
    const bool first = frame_ == 0;
    CHECK_MSG(first || time_s > lastTime_s_,
              "frame time " << time_s << " s not after " << lastTime_s_ << " s");
    const double dt_s = first ? 0.0 : time_s - lastTime_s_;
    // First-order lag of the bolometer, exact for a scene held constant over the frame:
    // y_n = y_{n−1} + (1 − exp(−Δt/τ))(x_n − y_{n−1}) (issue 5). The first frame starts settled.
    const double alpha = first || settings_.timeConstant_s == 0.0
                             ? 1.0
                             : 1.0 - std::exp(-dt_s / settings_.timeConstant_s);
    const double tau = settings_.opticsTransmission;
    const double kE = irradiancePerRadiance_ / tau;  // detector radiance → irradiance
    const bool ideal = gain_.empty();
    const bool noisy = noiseSigma_ > 0.0;
    const float sigma = float(noiseSigma_);
    // scene::HashBits(seed, stream, c) = Mix64(key ^ c) with the key below, hoisted out of
    // the pixel loop.
    const uint64_t key =
        scene::Mix64(scene::Mix64(settings_.seed) ^ (kStreamTemporal + uint64_t(noiseFrame)));
    const bool settled = alpha == 1.0;
    const ChainConstants chain{tau, alpha, kE, adcGain_, adcOffset_, sigma};
    const auto chainRow = ideal ? (settled ? ChainRow<true, true> : ChainRow<true, false>)
                                : (settled ? ChainRow<false, true> : ChainRow<false, false>);
    tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& rows) {
        RowScratch& scratch = scratch_.local();
        scratch.noise.resize(size_t(w) + 4);
        float* z = scratch.noise.data();
        for (int y = rows.begin(); y < rows.end(); ++y) {
            float* rad = radiance_.At(0, y);
            float* sig = signal_.At(0, y);
            uint16_t* cnt = counts_.data() + size_t(y) * size_t(w);
            const size_t row = size_t(y) * size_t(w);
            // Blurred at-aperture radiance.
            SampleKernelRow(samples, kernel_, y, sig, scratch.kernel);
            if (noisy)
                NormalPairsRow(key, PairCounter(0, y), size_t(w), z);
            else
                std::fill_n(z, w, 0.0f);
            if (ideal)
                chainRow(chain, w, z, nullptr, nullptr, nullptr, rad, sig, cnt);
            else
                chainRow(chain, w, z, gain_.data() + row, offset_.data() + row,
                         noiseScale_.data() + row, rad, sig, cnt);
        }
    });
    display_.Update(counts_, dt_s);
    display_.Render(counts_, display8_);
    lastTime_s_ = time_s;
    lastNoiseFrame_ = noiseFrame;
    ++frame_;
}

void ThermalImager::Restart() {
    frame_ = 0;
    lastNoiseFrame_ = 0;
    lastTime_s_ = 0.0;
    display_.Reset();
}

Image ThermalImager::MeasuredRadiance() const {
    Image L(signal_.width, signal_.height, 1);
    const double perIrradiance = 1.0 / irradiancePerRadiance_;
    tbb::parallel_for(0, L.height, [&](int y) {
        const float* sig = signal_.At(0, y);
        float* l = L.At(0, y);
        for (int x = 0; x < L.width; ++x) l[x] = float(double(sig[x]) * perIrradiance);
    });
    return L;
}

Image ThermalImager::ApparentTemperature() const {
    Image T = MeasuredRadiance();
    tbb::parallel_for(0, T.height, [&](int y) {
        float* t = T.At(0, y);
        for (int x = 0; x < T.width; ++x) {
            const double L = double(t[x]);
            t[x] = L > 0.0 ? float(table_.Temperature(L)) : 0.0f;
        }
    });
    return T;
}

ImageMetadata ThermalImager::Metadata() const {
    const ThermalImagerSettings& s = settings_;
    ImageMetadata m;
    m.Set("seasense:band", GetBand().Name());
    m.Set("seasense:band_range_m", std::vector<float>{float(GetBand().MinWavelength_m()),
                                                      float(GetBand().MaxWavelength_m())});
    m.Set("seasense:netd_K", float(s.netd_K));
    m.Set("seasense:netd_reference_K", float(s.netdReference_K));
    m.Set("seasense:f_number", float(s.fNumber));
    m.Set("seasense:focal_length_m", float(s.focalLength_m));
    m.Set("seasense:pitch_m", float(s.pitch_m));
    m.Set("seasense:fill_factor", float(s.fillFactor));
    m.Set("seasense:optics_transmission", float(s.opticsTransmission));
    m.Set("seasense:aberration_sigma_m", float(s.aberrationSigma_m));
    m.Set("seasense:time_constant_s", float(s.timeConstant_s));
    m.Set("seasense:adc_bits", kAdcBits);
    m.Set("seasense:adc_range_K", std::vector<float>{float(s.adcMin_K), float(s.adcMax_K)});
    m.Set("seasense:nuc", s.nuc ? 1 : 0);
    // counts = round(adc_gain · E + adc_offset), E = irradiance_per_radiance · L (W·m⁻²).
    m.Set("seasense:adc_gain_counts_per_W_m2", float(adcGain_));
    m.Set("seasense:adc_offset_counts", float(adcOffset_));
    m.Set("seasense:irradiance_per_radiance_sr", float(irradiancePerRadiance_));
    static const char* const kModes[] = {"plateau", "linear", "manual"};
    static const char* const kPolarities[] = {"white_hot", "black_hot"};
    static const char* const kPalettes[] = {"grayscale", "ironbow", "rainbow"};
    m.Set("seasense:agc_mode", std::string(kModes[int(s.agc.mode)]));
    m.Set("seasense:agc_time_constant_s", float(s.agc.timeConstant_s));
    m.Set("seasense:polarity", std::string(kPolarities[int(s.agc.polarity)]));
    m.Set("seasense:palette", std::string(kPalettes[int(s.agc.palette)]));
    m.Set("seasense:frame_index", int(lastNoiseFrame_));
    return m;
}

}  // namespace seasense::sensors
