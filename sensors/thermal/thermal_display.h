// Thermal display chain: AGC of 14-bit counts, temporal smoothing, polarity and palettes.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

namespace seasense::sensors {

// The imager's ADC resolution: 14 bits, counts 0 … 16383.
inline constexpr int kAdcBits = 14;
inline constexpr int kAdcLevels = 1 << kAdcBits;
inline constexpr uint16_t kAdcMaxCount = kAdcLevels - 1;

enum class AgcMode {
    PlateauEqualization,  // Vickers 1996 histogram plateau equalization
    LinearMinMax,         // linear between clip percentiles
    Manual,               // fixed gain and level
};
enum class Polarity { WhiteHot, BlackHot };
enum class Palette { Grayscale, Ironbow, Rainbow };

struct AgcSettings {
    AgcMode mode = AgcMode::PlateauEqualization;
    // Plateau: the most pixels one histogram bin (one count) may contribute to the cumulative
    // histogram (Vickers 1996). Large values tend to plain histogram equalization, 1 to a
    // linear map over the occupied levels.
    double plateau = 200.0;
    // Linear min–max: fractions of the pixels (0 … 0.5) clipped to black and to white.
    double clipLow = 0.01;
    double clipHigh = 0.01;
    // Time constant (s) of the first-order smoothing of the mapping between frames; 0 = none.
    double timeConstant_s = 0.5;
    // Manual: display = 0.5 + gain·(count − level)/16383, clipped to [0, 1]; gain 1 spreads
    // the full 14-bit range over the display.
    double manualGain = 1.0;
    double manualLevel_counts = 8192.0;
    Polarity polarity = Polarity::WhiteHot;
    Palette palette = Palette::Grayscale;
};

// Histogram of 14-bit counts: kAdcLevels bins. Values above kAdcMaxCount go to the top bin.
std::vector<uint32_t> CountHistogram(std::span<const uint16_t> counts);

// Plateau equalization (Vickers, "Plateau equalization algorithm for real-time display of
// high-quality infrared imagery", Opt. Eng. 35(7), 1996): each bin is clipped at `plateau`
// and the cumulative clipped histogram, offset so the lowest occupied level is 0 and scaled
// so the highest is 1, is the mapping (display level in [0, 1] per count). A histogram with
// one occupied level maps to 0.5. Throws InputError unless plateau ≥ 1 (finite).
std::vector<float> PlateauEqualizationMap(std::span<const uint32_t> histogram, double plateau);

// The counts at the clip percentiles: with the n pixel counts sorted v₀ ≤ … ≤ vₙ₋₁,
// low = v[⌊clipLow·(n−1)⌋] and high = v[⌈(1 − clipHigh)·(n−1)⌉] (nearest rank). An empty
// histogram gives (0, kAdcMaxCount).
std::pair<double, double> ClipPercentileCounts(std::span<const uint32_t> histogram, double clipLow,
                                               double clipHigh);

// 256 RGB entries of a palette, from closed formulas (see the .cpp): grayscale ramp; ironbow
// (black → blue → magenta → red → yellow → white); rainbow (HSV hue 240° → 0°).
std::array<std::array<uint8_t, 3>, 256> PaletteTable(Palette palette);

// Stateful AGC and display mapping. Deterministic: the histogram is an integer count.
class ThermalDisplay {
  public:
    // Throws InputError for settings out of range (plateau < 1, clip fractions outside
    // [0, 0.5), negative time constant, manual gain ≤ 0).
    explicit ThermalDisplay(const AgcSettings& settings);

    const AgcSettings& Settings() const { return settings_; }
    // 1 for the grayscale palette, 3 (RGB) otherwise.
    int Channels() const { return settings_.palette == Palette::Grayscale ? 1 : 3; }

    // Updates the mapping from this frame's counts. dt_s (s) is the time since the previous
    // frame; the first frame after construction or Reset() takes its mapping directly, later
    // ones move toward the frame's target by 1 − exp(−dt/τ).
    void Update(std::span<const uint16_t> counts, double dt_s);
    // Forgets the smoothed mapping (the next Update starts fresh).
    void Reset() { initialized_ = false; }

    // Current mapping of a count to [0, 1] before polarity.
    float Level(uint16_t count) const { return lut_[count < kAdcLevels ? count : kAdcMaxCount]; }
    // Current 8-bit display index of a count, after polarity (before the palette).
    uint8_t Index(uint16_t count) const {
        return index_[count < kAdcLevels ? count : kAdcMaxCount];
    }
    // Smoothed linear min–max bounds (counts); meaningful in LinearMinMax mode.
    double LinearLow() const { return low_; }
    double LinearHigh() const { return high_; }

    // Display pixels for `counts` (Channels() values per pixel, interleaved), parallel.
    void Render(std::span<const uint16_t> counts, std::vector<uint8_t>& out) const;

  private:
    void RebuildIndex();

    AgcSettings settings_;
    std::array<std::array<uint8_t, 3>, 256> palette_;
    bool initialized_ = false;
    double low_ = 0.0, high_ = kAdcMaxCount;
    std::vector<float> lut_;  // kAdcLevels entries in [0, 1]
    // kAdcLevels entries, after polarity, and three zero bytes (Render reads 32 bits at a
    // level's offset).
    std::vector<uint8_t> index_;
    std::vector<float> target_;  // scratch: this frame's target mapping
};

}  // namespace seasense::sensors
