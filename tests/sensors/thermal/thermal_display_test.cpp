// Thermal AGC and palettes against their definitions (equalization, percentiles, smoothing).
#include "sensors/thermal/thermal_display.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "scene/core/error.h"

namespace seasense::sensors {
namespace {

// Counts with an uneven histogram over [1000, 3000]: a dense cluster plus a sparse tail.
std::vector<uint16_t> SkewedCounts() {
    std::vector<uint16_t> c;
    for (int i = 0; i < 20000; ++i) {
        const double u = (i * 0.6180339887498949) - std::floor(i * 0.6180339887498949);
        c.push_back(uint16_t(1000 + std::lround(2000.0 * u * u * u)));
    }
    return c;
}

TEST(ThermalDisplay, HugePlateauIsPlainHistogramEqualization) {
    const std::vector<uint16_t> counts = SkewedCounts();
    AgcSettings a;
    a.plateau = 1e9;
    ThermalDisplay d(a);
    d.Update(counts, 0.0);
    // Textbook equalization (Gonzalez & Woods, "Digital Image Processing", eq. 3.3-8 with
    // the cdf_min offset): (#pixels ≤ c − #pixels at the lowest level)/(n − that number).
    std::vector<uint16_t> sorted = counts;
    std::sort(sorted.begin(), sorted.end());
    const double n = double(sorted.size());
    const double atMin = double(std::count(sorted.begin(), sorted.end(), sorted.front()));
    float previous = -1.0f;
    for (int c = 900; c <= 3100; ++c) {
        const double le =
            double(std::upper_bound(sorted.begin(), sorted.end(), uint16_t(c)) - sorted.begin());
        const double expected = std::max(0.0, (le - atMin) / (n - atMin));
        EXPECT_NEAR(d.Level(uint16_t(c)), expected, 1e-6) << c;
        EXPECT_GE(d.Level(uint16_t(c)), previous);  // monotone
        previous = d.Level(uint16_t(c));
    }
    // Full range: the darkest occupied level is black, the brightest white.
    EXPECT_EQ(d.Index(sorted.front()), 0);
    EXPECT_EQ(d.Index(sorted.back()), 255);
}

TEST(ThermalDisplay, UnitPlateauGivesEqualStepsPerOccupiedLevel) {
    // Vickers 1996: at plateau 1 every occupied level counts once, whatever its population.
    const std::vector<uint16_t> counts = {10, 10, 10, 10, 10, 20, 30, 30, 40};
    const std::vector<float> map = PlateauEqualizationMap(CountHistogram(counts), 1.0);
    EXPECT_FLOAT_EQ(map[10], 0.0f);
    EXPECT_FLOAT_EQ(map[20], 1.0f / 3.0f);
    EXPECT_FLOAT_EQ(map[25], 1.0f / 3.0f);
    EXPECT_FLOAT_EQ(map[30], 2.0f / 3.0f);
    EXPECT_FLOAT_EQ(map[40], 1.0f);
    EXPECT_THROW(PlateauEqualizationMap(CountHistogram(counts), 0.5), InputError);
}

TEST(ThermalDisplay, LinearMinMaxMapsTheClipPercentilesToBlackAndWhite) {
    std::vector<uint16_t> counts;
    for (int i = 0; i < 10000; ++i) counts.push_back(uint16_t((i * 7919) % 10000 + 3000));
    AgcSettings a;
    a.mode = AgcMode::LinearMinMax;
    a.clipLow = 0.01;
    a.clipHigh = 0.02;
    a.timeConstant_s = 0.0;
    ThermalDisplay d(a);
    d.Update(counts, 0.0);
    // Nearest-rank percentiles from a full sort.
    std::vector<uint16_t> sorted = counts;
    std::sort(sorted.begin(), sorted.end());
    const uint16_t lo = sorted[size_t(std::floor(0.01 * 9999))];
    const uint16_t hi = sorted[size_t(std::ceil(0.98 * 9999))];
    EXPECT_EQ(d.LinearLow(), lo);
    EXPECT_EQ(d.LinearHigh(), hi);
    EXPECT_EQ(d.Index(lo), 0);
    EXPECT_EQ(d.Index(uint16_t(lo - 5)), 0);
    EXPECT_EQ(d.Index(hi), 255);
    EXPECT_EQ(d.Index(uint16_t(hi + 5)), 255);
    EXPECT_NEAR(d.Level(uint16_t((lo + hi) / 2)), 0.5, 1.0 / (hi - lo));
}

TEST(ThermalDisplay, BlackHotInvertsWhiteHot) {
    const std::vector<uint16_t> counts = SkewedCounts();
    for (AgcMode mode : {AgcMode::PlateauEqualization, AgcMode::LinearMinMax, AgcMode::Manual}) {
        AgcSettings a;
        a.mode = mode;
        ThermalDisplay white(a);
        a.polarity = Polarity::BlackHot;
        ThermalDisplay black(a);
        white.Update(counts, 0.0);
        black.Update(counts, 0.0);
        for (int c = 0; c < kAdcLevels; c += 7)
            ASSERT_EQ(int(black.Index(uint16_t(c))), 255 - int(white.Index(uint16_t(c))));
    }
}

TEST(ThermalDisplay, MappingConvergesGeometricallyWithTheTimeConstant) {
    AgcSettings a;
    a.mode = AgcMode::LinearMinMax;
    a.clipLow = a.clipHigh = 0.0;
    a.timeConstant_s = 0.5;
    ThermalDisplay d(a);
    std::vector<uint16_t> cold, hot;
    for (int i = 0; i <= 1000; ++i) {
        cold.push_back(uint16_t(1000 + i));
        hot.push_back(uint16_t(5000 + 2 * i));
    }
    d.Update(cold, 0.0);
    EXPECT_EQ(d.LinearLow(), 1000.0);  // the first frame takes its own mapping
    const double dt = 0.1, ratio = std::exp(-dt / a.timeConstant_s);
    double lowGap = d.LinearLow() - 5000.0, highGap = d.LinearHigh() - 7000.0;
    for (int f = 0; f < 20; ++f) {
        d.Update(hot, dt);
        EXPECT_NEAR((d.LinearLow() - 5000.0) / lowGap, ratio, 1e-9);
        EXPECT_NEAR((d.LinearHigh() - 7000.0) / highGap, ratio, 1e-9);
        lowGap = d.LinearLow() - 5000.0;
        highGap = d.LinearHigh() - 7000.0;
    }
    // Plateau mode smooths the whole mapping the same way.
    AgcSettings p;
    p.timeConstant_s = 0.5;
    ThermalDisplay e(p);
    e.Update(cold, 0.0);
    const double start = e.Level(1500);
    e.Update(hot, dt);
    e.Update(hot, dt);
    // Target level of count 1500 in the hot frame is 0 (below every hot count).
    EXPECT_NEAR(e.Level(1500), start * ratio * ratio, 1e-6);
}

TEST(ThermalDisplay, ManualGainAndLevel) {
    AgcSettings a;
    a.mode = AgcMode::Manual;
    a.manualGain = 4.0;
    a.manualLevel_counts = 6000.0;
    ThermalDisplay d(a);
    d.Update(std::vector<uint16_t>{1, 2, 3}, 0.0);
    EXPECT_FLOAT_EQ(d.Level(6000), 0.5f);
    // ±16383/(2·gain) counts from the level reach the display ends.
    EXPECT_FLOAT_EQ(d.Level(uint16_t(6000 + 16383 / 8)), 0.5f + float(16383 / 8) * 4.0f / 16383.0f);
    EXPECT_EQ(d.Index(uint16_t(6000 - 2048)), 0);
    EXPECT_EQ(d.Index(uint16_t(6000 + 2048)), 255);
}

TEST(ThermalDisplay, PaletteEndsAndRender) {
    const auto gray = PaletteTable(Palette::Grayscale);
    for (int i = 0; i < 256; ++i) EXPECT_EQ(gray[size_t(i)][1], i);
    const auto iron = PaletteTable(Palette::Ironbow);
    EXPECT_EQ(iron[0], (std::array<uint8_t, 3>{0, 0, 0}));
    EXPECT_EQ(iron[255], (std::array<uint8_t, 3>{255, 255, 255}));
    EXPECT_EQ(iron[64][2], 255);  // sin 2πt peaks at t = ¼: the cold end is blue
    // Red √t and green t³ rise monotonically.
    for (int i = 1; i < 256; ++i) {
        EXPECT_GE(iron[size_t(i)][0], iron[size_t(i - 1)][0]);
        EXPECT_GE(iron[size_t(i)][1], iron[size_t(i - 1)][1]);
    }
    const auto rainbow = PaletteTable(Palette::Rainbow);
    EXPECT_EQ(rainbow[0], (std::array<uint8_t, 3>{0, 0, 255}));    // hue 240°
    EXPECT_EQ(rainbow[255], (std::array<uint8_t, 3>{255, 0, 0}));  // hue 0°
    // Full saturation and value: one channel at 255 and one at 0 everywhere.
    for (const auto& rgb : rainbow) {
        EXPECT_EQ(std::max({rgb[0], rgb[1], rgb[2]}), 255);
        EXPECT_EQ(std::min({rgb[0], rgb[1], rgb[2]}), 0);
    }

    AgcSettings a;
    a.mode = AgcMode::Manual;
    a.palette = Palette::Rainbow;
    ThermalDisplay d(a);
    const std::vector<uint16_t> counts = {0, 8192, 16383};
    d.Update(counts, 0.0);
    std::vector<uint8_t> out;
    d.Render(counts, out);
    ASSERT_EQ(out.size(), 9u);
    EXPECT_EQ(out[0], 0);
    EXPECT_EQ(out[2], 255);  // count 0 → level 0 → blue
    EXPECT_EQ(out[6], 255);  // count 16383 → level 1 → red
    EXPECT_EQ(out[8], 0);
}

TEST(ThermalDisplay, RejectsBadSettings) {
    AgcSettings a;
    a.clipLow = 0.6;
    EXPECT_THROW(ThermalDisplay{a}, InputError);
    a = AgcSettings{};
    a.timeConstant_s = -1.0;
    EXPECT_THROW(ThermalDisplay{a}, InputError);
    a = AgcSettings{};
    a.manualGain = 0.0;
    EXPECT_THROW(ThermalDisplay{a}, InputError);
}

}  // namespace
}  // namespace seasense::sensors
