// Thermal AGC (plateau equalization, linear clip, manual), smoothing, polarity and palettes.
#include "sensors/thermal/thermal_display.h"

#include <immintrin.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "scene/core/check.h"
#include "scene/core/error.h"

namespace seasense::sensors {

namespace {

[[noreturn]] void BadSetting(const char* what, double value, const char* expected) {
    std::ostringstream msg;
    msg << "thermal imager AGC: " << what << " = " << value << "; expected " << expected;
    throw InputError(msg.str());
}

uint8_t ToByte(double v) { return uint8_t(std::lround(255.0 * std::clamp(v, 0.0, 1.0))); }

// The count v[rank] of the sorted pixel counts: the first level whose cumulative count
// exceeds rank.
int CountAtRank(std::span<const uint32_t> histogram, uint64_t rank) {
    uint64_t cumulative = 0;
    for (size_t c = 0; c < histogram.size(); ++c) {
        cumulative += histogram[c];
        if (cumulative > rank) return int(c);
    }
    return int(histogram.size()) - 1;
}

}  // namespace

std::vector<uint32_t> CountHistogram(std::span<const uint16_t> counts) {
    // Blocks of the frame are counted in parallel and their histograms summed level by level:
    // integer sums, so the result does not depend on the threading.
    constexpr size_t kBlock = size_t(1) << 16;
    const size_t blocks = std::max<size_t>(1, (counts.size() + kBlock - 1) / kBlock);
    std::vector<uint32_t> partial(blocks * kAdcLevels, 0);
    tbb::parallel_for(size_t(0), blocks, [&](size_t b) {
        uint32_t* h = partial.data() + b * kAdcLevels;
        const size_t end = std::min(counts.size(), (b + 1) * kBlock);
        for (size_t i = b * kBlock; i < end; ++i) {
            const uint16_t c = counts[i];
            ++h[c < kAdcLevels ? c : kAdcMaxCount];
        }
    });
    if (blocks == 1) return partial;
    std::vector<uint32_t> h(kAdcLevels, 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, kAdcLevels, 2048),
                      [&](const tbb::blocked_range<size_t>& levels) {
                          for (size_t b = 0; b < blocks; ++b) {
                              const uint32_t* p = partial.data() + b * kAdcLevels;
                              for (size_t c = levels.begin(); c < levels.end(); ++c) h[c] += p[c];
                          }
                      });
    return h;
}

std::vector<float> PlateauEqualizationMap(std::span<const uint32_t> histogram, double plateau) {
    if (!(std::isfinite(plateau) && plateau >= 1.0))
        BadSetting("plateau (pixels per bin)", plateau, "a finite value >= 1");
    std::vector<float> map(histogram.size(), 0.0f);
    // Cumulative clipped histogram in double: exact for any realistic frame (integers
    // < 2^53), so the map does not depend on summation order.
    std::vector<double> cumulative(histogram.size());
    double sum = 0.0;
    size_t first = histogram.size();
    for (size_t c = 0; c < histogram.size(); ++c) {
        if (histogram[c] > 0 && first == histogram.size()) first = c;
        sum += std::min(double(histogram[c]), plateau);
        cumulative[c] = sum;
    }
    if (first == histogram.size()) return std::vector<float>(histogram.size(), 0.5f);
    const double base = cumulative[first];
    const double span = sum - base;
    if (span <= 0.0) return std::vector<float>(histogram.size(), 0.5f);
    for (size_t c = 0; c < histogram.size(); ++c)
        map[c] = float(std::max(0.0, cumulative[c] - base) / span);
    return map;
}

std::pair<double, double> ClipPercentileCounts(std::span<const uint32_t> histogram, double clipLow,
                                               double clipHigh) {
    uint64_t n = 0;
    for (uint32_t h : histogram) n += h;
    if (n == 0) return {0.0, double(kAdcMaxCount)};
    const double last = double(n - 1);
    const auto lowRank = uint64_t(std::floor(clipLow * last));
    const auto highRank = uint64_t(std::min(last, std::ceil((1.0 - clipHigh) * last)));
    return {double(CountAtRank(histogram, lowRank)), double(CountAtRank(histogram, highRank))};
}

std::array<std::array<uint8_t, 3>, 256> PaletteTable(Palette palette) {
    std::array<std::array<uint8_t, 3>, 256> table{};
    constexpr double kTwoPi = 2.0 * std::numbers::pi;
    for (int i = 0; i < 256; ++i) {
        const double t = i / 255.0;
        double r = t, g = t, b = t;
        if (palette == Palette::Ironbow) {
            // gnuplot's traditional pm3d colour formulae 7, 5, 15 (√t, t³, sin 2πt; Williams &
            // Kelley, gnuplot manual, "set palette rgbformulae"): black → blue → red →
            // yellow. Blue rises again linearly over the top quarter so the hottest level is
            // white, as in ironbow thermography displays.
            r = std::sqrt(t);
            g = t * t * t;
            b = std::max({std::sin(kTwoPi * t), 4.0 * (t - 0.75), 0.0});
        } else if (palette == Palette::Rainbow) {
            // Hue from 240° (blue, cold) to 0° (red, hot) at full saturation and value;
            // HSV → RGB after Smith, "Color gamut transform pairs", SIGGRAPH 1978.
            const double h6 = 4.0 * (1.0 - t);  // hue in sixths of a turn, 4 = 240°
            const int sector = std::min(int(h6), 5);
            const double f = h6 - sector;
            switch (sector) {
                case 0:
                    r = 1, g = f, b = 0;
                    break;
                case 1:
                    r = 1 - f, g = 1, b = 0;
                    break;
                case 2:
                    r = 0, g = 1, b = f;
                    break;
                case 3:
                    r = 0, g = 1 - f, b = 1;
                    break;
                default:
                    r = f, g = 0, b = 1;
                    break;  // only h6 = 4 exactly (t = 0)
            }
        }
        table[size_t(i)] = {ToByte(r), ToByte(g), ToByte(b)};
    }
    return table;
}

ThermalDisplay::ThermalDisplay(const AgcSettings& settings)
    : settings_(settings),
      palette_(PaletteTable(settings.palette)),
      lut_(kAdcLevels, 0.5f),
      index_(kAdcLevels + 3, 0),
      target_(kAdcLevels, 0.0f) {
    if (!(std::isfinite(settings.plateau) && settings.plateau >= 1.0))
        BadSetting("plateau (pixels per bin)", settings.plateau, "a finite value >= 1");
    if (!(settings.clipLow >= 0.0 && settings.clipLow < 0.5))
        BadSetting("low clip fraction", settings.clipLow, "a value in [0, 0.5)");
    if (!(settings.clipHigh >= 0.0 && settings.clipHigh < 0.5))
        BadSetting("high clip fraction", settings.clipHigh, "a value in [0, 0.5)");
    if (!(std::isfinite(settings.timeConstant_s) && settings.timeConstant_s >= 0.0))
        BadSetting("time constant (s)", settings.timeConstant_s, "a finite value >= 0");
    if (!(std::isfinite(settings.manualGain) && settings.manualGain > 0.0))
        BadSetting("manual gain", settings.manualGain, "a finite value > 0");
    if (!std::isfinite(settings.manualLevel_counts))
        BadSetting("manual level (counts)", settings.manualLevel_counts, "a finite value");
    RebuildIndex();
}

void ThermalDisplay::Update(std::span<const uint16_t> counts, double dt_s) {
    CHECK(!initialized_ || (std::isfinite(dt_s) && dt_s >= 0.0));
    // First-order smoothing toward this frame's mapping: the remaining difference shrinks by
    // exp(−dt/τ) per frame, the same discrete lag as the detector's.
    const double step = !initialized_ || settings_.timeConstant_s == 0.0
                            ? 1.0
                            : 1.0 - std::exp(-dt_s / settings_.timeConstant_s);
    switch (settings_.mode) {
        case AgcMode::PlateauEqualization: {
            const std::vector<uint32_t> histogram = CountHistogram(counts);
            target_ = PlateauEqualizationMap(histogram, settings_.plateau);
            for (size_t c = 0; c < lut_.size(); ++c)
                lut_[c] = step == 1.0 ? target_[c]
                                      : float(lut_[c] + step * (double(target_[c]) - lut_[c]));
            break;
        }
        case AgcMode::LinearMinMax: {
            const std::vector<uint32_t> histogram = CountHistogram(counts);
            auto [lo, hi] = ClipPercentileCounts(histogram, settings_.clipLow, settings_.clipHigh);
            low_ = step == 1.0 ? lo : low_ + step * (lo - low_);
            high_ = step == 1.0 ? hi : high_ + step * (hi - high_);
            // Less than one count between the bounds (a uniform scene): centre a one-count
            // ramp on them so the scene shows mid-grey rather than an arbitrary end.
            double a = low_, b = high_;
            if (b - a < 1.0) {
                const double mid = 0.5 * (a + b);
                a = mid - 0.5;
                b = mid + 0.5;
            }
            for (size_t c = 0; c < lut_.size(); ++c)
                lut_[c] = float(std::clamp((double(c) - a) / (b - a), 0.0, 1.0));
            break;
        }
        case AgcMode::Manual:
            for (size_t c = 0; c < lut_.size(); ++c)
                lut_[c] = float(std::clamp(0.5 + settings_.manualGain *
                                                     (double(c) - settings_.manualLevel_counts) /
                                                     kAdcMaxCount,
                                           0.0, 1.0));
            break;
    }
    initialized_ = true;
    RebuildIndex();
}

void ThermalDisplay::RebuildIndex() {
    for (size_t c = 0; c < lut_.size(); ++c) {
        const uint8_t v = ToByte(lut_[c]);
        index_[c] = settings_.polarity == Polarity::WhiteHot ? v : uint8_t(255 - v);
    }
}

void ThermalDisplay::Render(std::span<const uint16_t> counts, std::vector<uint8_t>& out) const {
    const size_t channels = size_t(Channels());
    out.resize(counts.size() * channels);
    constexpr size_t kBlock = 16384;
    const size_t blocks = (counts.size() + kBlock - 1) / kBlock;
    tbb::parallel_for(size_t(0), blocks, [&](size_t blk) {
        const size_t begin = blk * kBlock, end = std::min(counts.size(), begin + kBlock);
        if (channels == 1) {
            size_t i = begin;
#if defined(__AVX2__)
            // Sixteen pixels at a time: each index a byte of a 32-bit gather at the count's
            // offset (index_ is padded by three bytes for the last level), packed back to bytes.
            const int* table = reinterpret_cast<const int*>(index_.data());
            const __m256i top = _mm256_set1_epi16(int16_t(kAdcMaxCount)),
                          byte = _mm256_set1_epi32(0xff);
            for (; i + 16 <= end; i += 16) {
                const __m256i c = _mm256_min_epu16(
                    _mm256_loadu_si256(reinterpret_cast<const __m256i*>(counts.data() + i)), top);
                const __m256i a = _mm256_and_si256(
                    _mm256_i32gather_epi32(table, _mm256_cvtepu16_epi32(_mm256_castsi256_si128(c)),
                                           1),
                    byte);
                const __m256i b = _mm256_and_si256(
                    _mm256_i32gather_epi32(
                        table, _mm256_cvtepu16_epi32(_mm256_extracti128_si256(c, 1)), 1),
                    byte);
                // (a0–3 b0–3 | a4–7 b4–7) as 16-bit, put in order by vpermq.
                const __m256i w =
                    _mm256_permute4x64_epi64(_mm256_packus_epi32(a, b), _MM_SHUFFLE(3, 1, 2, 0));
                _mm_storeu_si128(
                    reinterpret_cast<__m128i*>(out.data() + i),
                    _mm_packus_epi16(_mm256_castsi256_si128(w), _mm256_extracti128_si256(w, 1)));
            }
#endif
            for (; i < end; ++i) out[i] = Index(counts[i]);
        } else {
            for (size_t i = begin; i < end; ++i) {
                const std::array<uint8_t, 3>& rgb = palette_[Index(counts[i])];
                out[3 * i] = rgb[0];
                out[3 * i + 1] = rgb[1];
                out[3 * i + 2] = rgb[2];
            }
        }
    });
}

}  // namespace seasense::sensors
