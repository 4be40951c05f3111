// Sea state presets against the WMO tables and the Pierson–Moskowitz relations; reading the
// spectral ocean settings, good and bad.
#include "scene/ocean/sea_state.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <sstream>

#include "scene/config/config_error.h"
#include "scene/ocean/fft_ocean.h"
#include "scene/ocean/gerstner.h"

namespace seasense::scene {
namespace {

constexpr double g = kGravity_mps2;
const std::string kFile = "sea.yaml";

TEST(SeaState, TablesTileTheirScales) {
    // WMO publishes Beaufort limits to 0.1 m/s: each band starts 0.1 m/s above the last.
    const auto beaufort = BeaufortScale();
    ASSERT_EQ(beaufort.size(), 13u);
    for (size_t i = 0; i < beaufort.size(); ++i) {
        EXPECT_EQ(beaufort[i].force, int(i));
        if (i > 0) {
            EXPECT_NEAR(beaufort[i].windMin_mps, beaufort[i - 1].windMax_mps + 0.1, 1e-9);
            EXPECT_GE(beaufort[i].probableHeight_m, beaufort[i - 1].probableHeight_m);
        }
        const double u = BeaufortWindSpeed_mps(int(i));
        EXPECT_GE(u, beaufort[i].windMin_mps);
        EXPECT_LE(u, beaufort[i].windMax_mps);
    }
    EXPECT_EQ(beaufort[12].windMin_mps, 32.7);  // hurricane force (WMO)
    const auto states = WmoSeaStates();
    ASSERT_EQ(states.size(), 10u);
    for (size_t i = 1; i < states.size(); ++i) {
        EXPECT_EQ(states[i].heightMin_m, states[i - 1].heightMax_m);
        const double hs = SeaStateSignificantHeight_m(int(i));
        EXPECT_GT(hs, states[i].heightMin_m);
        EXPECT_LE(hs, states[i].heightMax_m);
    }
    // physics.md: sea state 4 is 1.25–2.5 m, 9 is over 14 m.
    EXPECT_EQ(states[4].heightMin_m, 1.25);
    EXPECT_EQ(states[4].heightMax_m, 2.5);
    EXPECT_EQ(states[9].heightMin_m, 14.0);
}

TEST(SeaState, SeaStateCodeGivesItsHeightAndAFullyDevelopedWind) {
    for (int code = 1; code <= 9; ++code) {
        SeaStateSettings s;
        s.seaState = code;
        s.spectrum.model = SpectrumModel::PiersonMoskowitz;
        const SpectrumSettings resolved = ResolveSeaState(s);
        const WaveSpectrum sea(resolved);
        EXPECT_NEAR(sea.SignificantHeight_m(), SeaStateSignificantHeight_m(code), 1e-9);
        // The wind is the fully developed one: Hs ≈ 0.21 U19.5² / g (physics.md), so the PM sea of
        // that wind has the height without rescaling.
        const double u = WindSpeed19_5(resolved.windSpeed_mps);
        EXPECT_NEAR(sea.SignificantHeight_m(), 0.21 * u * u / g, 0.01 * sea.SignificantHeight_m());
        SpectrumSettings unscaled = resolved;
        unscaled.significantHeight_m.reset();
        EXPECT_NEAR(WaveSpectrum(unscaled).SignificantHeight_m(), sea.SignificantHeight_m(),
                    1e-6 * sea.SignificantHeight_m());
    }
    SeaStateSettings calm;
    calm.seaState = 0;
    EXPECT_EQ(WaveSpectrum(ResolveSeaState(calm)).Variance_m2(), 0.0);
}

TEST(SeaState, BeaufortForceSetsTheWind) {
    SeaStateSettings s;
    s.beaufort = 6;
    const SpectrumSettings r = ResolveSeaState(s);
    EXPECT_NEAR(r.windSpeed_mps, 0.5 * (10.8 + 13.8), 1e-12);
    EXPECT_FALSE(r.significantHeight_m.has_value());
    // A fully developed PM sea at force 6 lies near WMO's probable height of 3 m.
    s.spectrum.model = SpectrumModel::PiersonMoskowitz;
    EXPECT_NEAR(WaveSpectrum(ResolveSeaState(s)).SignificantHeight_m(), 3.0, 0.5);
}

TEST(SeaState, MarkdownTablesListEveryPreset) {
    const std::string md = SeaStatePresetsMarkdown();
    // Data rows start "| <digit>"; both tables have header and separator rows besides.
    size_t rows = 0;
    std::istringstream lines(md);
    for (std::string line; std::getline(lines, line);)
        rows +=
            line.size() > 2 && line[0] == '|' && std::isdigit(static_cast<unsigned char>(line[2]));
    EXPECT_EQ(rows, 13u + 10u);
    EXPECT_NE(md.find("| 12 | Hurricane | ≥ 32.7 |"), std::string::npos);
    EXPECT_NE(md.find("| 9 | Phenomenal | ≥ 14.00 |"), std::string::npos);
    EXPECT_NE(md.find("| 4 | Moderate | 1.25–2.50 | 1.875 |"), std::string::npos) << md;
}

SpectralOceanSettings Read(const std::string& text) {
    ConfigDocument doc = ParseConfigText(text, kFile);
    ConfigMap root(doc.root);
    SpectralOceanSettings s = ReadSpectralOceanSettings(root.Require("ocean", "a mapping"));
    root.Finish();
    return s;
}

std::string ErrorOf(const std::string& text) {
    try {
        Read(text);
    } catch (const ConfigError& e) {
        return e.what();
    }
    ADD_FAILURE() << "no ConfigError for:\n" << text;
    return "";
}

TEST(SeaState, ReadsSettings) {
    const SpectralOceanSettings s = Read(
        "ocean:\n"
        "  beaufort: 5\n"
        "  wind_direction_deg: 90\n"
        "  fetch_m: 50000\n"
        "  depth_m: 12\n"
        "  spectrum: tma\n"
        "  spreading: hasselmann\n"
        "  gamma: 2.5\n"
        "  phillips: {exponent: 4.5, against_wind_factor: 0.2}\n"
        "  swell: {significant_height_m: 0.7, peak_period_s: 12, direction_deg: 180}\n"
        "  fft: {grid_size: 128, patch_sizes_m: [300, 44.4], choppiness: 0.8, seed: 99}\n");
    EXPECT_EQ(s.sea.beaufort, 5);
    EXPECT_NEAR(s.sea.spectrum.windDirection_rad, std::numbers::pi / 2, 1e-15);
    EXPECT_EQ(s.sea.spectrum.fetch_m, 50000.0);
    EXPECT_EQ(s.sea.spectrum.depth_m, 12.0);
    EXPECT_EQ(s.sea.spectrum.model, SpectrumModel::Tma);
    EXPECT_EQ(s.sea.spectrum.spreading, SpreadingModel::Hasselmann);
    EXPECT_EQ(s.sea.spectrum.gamma, 2.5);
    EXPECT_EQ(s.sea.spectrum.phillips.exponent, 4.5);
    EXPECT_EQ(s.sea.spectrum.phillips.againstWindFactor, 0.2);
    ASSERT_TRUE(s.sea.spectrum.swell.has_value());
    EXPECT_EQ(s.sea.spectrum.swell->peakPeriod_s, 12.0);
    EXPECT_NEAR(s.sea.spectrum.swell->direction_rad, std::numbers::pi, 1e-15);
    EXPECT_EQ(s.fft.gridSize, 128);
    EXPECT_EQ(s.fft.patchSizes_m, (std::vector<double>{300.0, 44.4}));
    EXPECT_EQ(s.fft.choppiness, 0.8);
    EXPECT_EQ(s.fft.seed, 99u);
    // The settings build an ocean.
    const FftOcean ocean(WaveSpectrum(ResolveSeaState(s.sea)), s.fft);
    EXPECT_EQ(ocean.Cascades().size(), 2u);
    // Defaults: empty mapping is a deep fully developed JONSWAP sea.
    const SpectralOceanSettings d = Read("ocean: {}\n");
    EXPECT_EQ(d.sea.spectrum.model, SpectrumModel::Jonswap);
    EXPECT_TRUE(std::isinf(d.sea.spectrum.fetch_m));
    EXPECT_EQ(d.fft.gridSize, 256);
}

TEST(SeaState, BadSettingsNameTheirKey) {
    EXPECT_NE(ErrorOf("ocean:\n  beaufort: 13\n").find("sea.yaml:2:13: ocean.beaufort: expected"),
              std::string::npos);
    EXPECT_NE(ErrorOf("ocean:\n  beaufort: 3\n  wind_speed_mps: 4\n")
                  .find("ocean.wind_speed_mps: expected no wind_speed_mps next to beaufort"),
              std::string::npos);
    EXPECT_NE(ErrorOf("ocean:\n  sea_state: 3\n  significant_height_m: 1\n")
                  .find("ocean.significant_height_m"),
              std::string::npos);
    EXPECT_NE(ErrorOf("ocean:\n  spectrum: bretschneider\n").find("ocean.spectrum"),
              std::string::npos);
    EXPECT_NE(
        ErrorOf("ocean:\n  spectrum: phillips\n  peak_period_s: 8\n").find("ocean.peak_period_s"),
        std::string::npos);
    EXPECT_NE(ErrorOf("ocean:\n  sea_state: 5\n  wind_speed_mps: 0\n").find("ocean.wind_speed_mps"),
              std::string::npos);
    EXPECT_NE(ErrorOf("ocean:\n  swell: {significant_height_m: 1}\n")
                  .find("ocean.swell.peak_period_s: expected"),
              std::string::npos);
    EXPECT_NE(ErrorOf("ocean:\n  fft: {grid_size: 200}\n").find("ocean.fft.grid_size"),
              std::string::npos);
    EXPECT_NE(
        ErrorOf("ocean:\n  fft: {patch_sizes_m: [100, 150]}\n").find("ocean.fft.patch_sizes_m[1]"),
        std::string::npos);
    EXPECT_NE(ErrorOf("ocean:\n  fft: {chopiness: 1}\n").find("ocean.fft.chopiness"),
              std::string::npos);
    EXPECT_NE(ErrorOf("ocean:\n  depth_m: -3\n").find("ocean.depth_m"), std::string::npos);
    EXPECT_NE(ErrorOf("ocean:\n  windspeed_mps: 3\n").find("ocean.windspeed_mps"),
              std::string::npos);
}

}  // namespace
}  // namespace seasense::scene
