// environment.ocean selecting the spectral sea: defaults from the scenario (seed, wind, depth),
// Gerstner waves added, and bad input reported at file:line:column with the key path.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>

#include "scene/config/config_error.h"
#include "scene/ocean/ocean_surface.h"
#include "scene/scenario/scenario_loader.h"

namespace seasense::scene {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = std::numbers::pi;
const fs::path kFixtures = fs::path(SEASENSE_SOURCE_DIR) / "tests/data/configs";

// The Gerstner wave list of the valid fixture, replaced by each test's ocean keys.
const std::string kFixtureWaves =
    "    waves:\n"
    "      - {direction_deg: 45, wavelength_m: 60, amplitude_m: 0.6, steepness: 0.6, "
    "phase_deg: 0}\n"
    "      - {direction_deg: 90, wavelength_m: 12, amplitude_m: 0.1, steepness: 0.3, "
    "phase_deg: 30}\n";

class SpectralOceanConfigTest : public ::testing::Test {
  protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        folder_ =
            fs::path(::testing::TempDir()) / (std::string("seasense_spectral_") + info->name());
        fs::remove_all(folder_);
        fs::create_directories(folder_);
        for (const char* name : {"materials.yaml", "triangle.obj"})
            fs::copy_file(kFixtures / name, folder_ / name);
        std::ifstream in(kFixtures / "valid.yaml");
        std::ostringstream text;
        text << in.rdbuf();
        valid_ = text.str();
        EXPECT_NE(valid_.find(kFixtureWaves), std::string::npos);
    }
    void TearDown() override { fs::remove_all(folder_); }

    // The fixture with its ocean's wave list replaced by `ocean` (keys under environment.ocean).
    std::string WithOcean(const std::string& ocean) const {
        std::string text = valid_;
        text.replace(text.find(kFixtureWaves), kFixtureWaves.size(), ocean);
        return text;
    }
    fs::path Write(const std::string& text) const {
        const fs::path file = folder_ / "scenario.yaml";
        std::ofstream(file) << text;
        return file;
    }
    std::string ErrorFor(const std::string& text) const {
        try {
            LoadScenario(Write(text));
        } catch (const ConfigError& e) {
            return e.what();
        }
        ADD_FAILURE() << "scenario loaded without error";
        return "";
    }
    // "file:line:column: " of the first `part` after `context`.
    std::string At(const std::string& text, const std::string& context,
                   const std::string& part) const {
        const size_t at = text.find(part, text.find(context));
        int line = 1;
        size_t lineStart = 0;
        for (size_t i = 0; i < at; ++i)
            if (text[i] == '\n') ++line, lineStart = i + 1;
        return (folder_ / "scenario.yaml").string() + ":" + std::to_string(line) + ":" +
               std::to_string(at - lineStart + 1) + ": ";
    }

    fs::path folder_;
    std::string valid_;
};

TEST_F(SpectralOceanConfigTest, SpectralSeaTakesSeedWindAndDepthFromTheScenario) {
    const Scenario s = LoadScenario(Write(WithOcean("    spectral: {beaufort: 5}\n")));
    const OceanSettings& o = s.environment.ocean;
    ASSERT_TRUE(o.spectral.has_value());
    EXPECT_TRUE(o.waves.empty());
    EXPECT_EQ(o.spectral->sea.beaufort, 5);
    EXPECT_EQ(o.spectral->fft.seed, 42u);                                     // world.seed
    EXPECT_DOUBLE_EQ(o.spectral->sea.spectrum.windDirection_rad, kPi / 4.0);  // wind 45°
    EXPECT_DOUBLE_EQ(o.spectral->sea.spectrum.depth_m, 50.0);
    EXPECT_DOUBLE_EQ(o.foamThreshold, 0.3);
    // The Beaufort preset sets the wind (9.35 m/s), not environment.wind's 6 m/s.
    const OceanSurface sea(o);
    EXPECT_NEAR(sea.Summary().windSpeed_mps, 9.35, 1e-12);
    EXPECT_DOUBLE_EQ(sea.Summary().depth_m, 50.0);
}

TEST_F(SpectralOceanConfigTest, WithoutASeaStateTheScenarioWindMakesTheSea) {
    const Scenario s = LoadScenario(Write(WithOcean("    spectral: {fetch_m: 20000}\n")));
    const OceanSurface sea(s.environment.ocean);
    EXPECT_NEAR(sea.Summary().windSpeed_mps, 6.0, 1e-12);
    EXPECT_NEAR(sea.Summary().windDirection_rad, kPi / 4.0, 1e-12);
}

TEST_F(SpectralOceanConfigTest, GerstnerWavesAndSynthesisKeysAreReadWithTheSpectralSea) {
    const Scenario s = LoadScenario(Write(WithOcean(
        "    foam_threshold: 0.4\n"
        "    spectral:\n"
        "      sea_state: 4\n"
        "      spectrum: pierson_moskowitz\n"
        "      wind_direction_deg: 90\n"
        "      swell: {significant_height_m: 1.5, peak_period_s: 11, direction_deg: 270}\n"
        "      fft: {grid_size: 64, cascades: 3, choppiness: 0.7, seed: 9}\n"
        "    waves:\n"
        "      - {direction_deg: 300, wavelength_m: 150, amplitude_m: 0.5, steepness: 0.3}\n")));
    const OceanSettings& o = s.environment.ocean;
    ASSERT_TRUE(o.spectral.has_value());
    ASSERT_EQ(o.waves.size(), 1u);
    EXPECT_DOUBLE_EQ(o.waves[0].wavelength_m, 150.0);
    EXPECT_DOUBLE_EQ(o.foamThreshold, 0.4);
    const SpectralOceanSettings& sp = *o.spectral;
    EXPECT_EQ(sp.sea.seaState, 4);
    EXPECT_EQ(sp.sea.spectrum.model, SpectrumModel::PiersonMoskowitz);
    EXPECT_DOUBLE_EQ(sp.sea.spectrum.windDirection_rad, kPi / 2.0);
    ASSERT_TRUE(sp.sea.spectrum.swell.has_value());
    EXPECT_DOUBLE_EQ(sp.sea.spectrum.swell->peakPeriod_s, 11.0);
    EXPECT_EQ(sp.fft.gridSize, 64);
    EXPECT_EQ(sp.fft.cascadeCount, 3);
    EXPECT_DOUBLE_EQ(sp.fft.choppiness, 0.7);
    EXPECT_EQ(sp.fft.seed, 9u);
}

TEST_F(SpectralOceanConfigTest, BadSpectralInputNamesFileLineColumnAndKey) {
    std::string text = WithOcean("    spectral: {beaufort: 5, depth_m: 30}\n");
    EXPECT_EQ(ErrorFor(text), At(text, "spectral:", "30") +
                                  "environment.ocean.spectral.depth_m: expected no depth_m here "
                                  "(the water depth is environment.ocean.depth_m), found 30");

    text = WithOcean("    spectral: {beaufurt: 5}\n");
    EXPECT_NE(ErrorFor(text).find(At(text, "spectral:", "beaufurt") +
                                  "environment.ocean.spectral.beaufurt"),
              std::string::npos);
    EXPECT_NE(ErrorFor(text).find("did you mean 'beaufort'?"), std::string::npos);

    text = WithOcean("    spectral: {beaufort: 5, wind_speed_mps: 8}\n");
    EXPECT_NE(ErrorFor(text).find(At(text, "spectral:", "8}") +
                                  "environment.ocean.spectral.wind_speed_mps: expected no "
                                  "wind_speed_mps next to beaufort"),
              std::string::npos);

    text = WithOcean("    spectral: {beaufort: 13}\n");
    EXPECT_NE(ErrorFor(text).find(At(text, "spectral:", "13") +
                                  "environment.ocean.spectral.beaufort: expected an integer"),
              std::string::npos);

    text = WithOcean("    spectral:\n      fft: {grid_size: 100}\n");
    EXPECT_NE(ErrorFor(text).find(At(text, "fft:", "100") +
                                  "environment.ocean.spectral.fft.grid_size: expected a power "
                                  "of two"),
              std::string::npos);

    text = WithOcean("    foam_threshold: 1.5\n    spectral: {beaufort: 3}\n");
    EXPECT_NE(ErrorFor(text).find(At(text, "foam_threshold", "1.5") +
                                  "environment.ocean.foam_threshold: expected"),
              std::string::npos);

    text = WithOcean("    spectral: {sea_state: 4, wind_speed_mps: 0}\n");
    EXPECT_NE(ErrorFor(text).find("environment.ocean.spectral.wind_speed_mps: expected a wind "
                                  "speed above 0"),
              std::string::npos);
}

}  // namespace
}  // namespace seasense::scene
