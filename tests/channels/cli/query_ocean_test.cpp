// `seasense query ocean` end to end: JSON keys answering what the scene API answers, the
// Gerstner model's dominant wave, time offsets, and bad input (exit status 2).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "scene/ocean/ocean_surface.h"
#include "scene/scenario/scenario_loader.h"
#include "tests/support/shell.h"

namespace {

using Result = seasense::testing::ShellResult;
namespace fs = std::filesystem;

const std::string kOceanConfig = std::string(SEASENSE_SOURCE_DIR) + "/configs/ocean.yaml";
const std::string kGerstnerConfig = std::string(SEASENSE_SOURCE_DIR) + "/configs/single-otw.yaml";

Result Seasense(const std::string& args, bool mergeStderr = true) {
    return seasense::testing::Shell(std::string(SEASENSE_BINARY) + " " + args, mergeStderr);
}

TEST(QueryOcean, JsonAnswersWhatTheSurfaceApiAnswers) {
    const Result r = Seasense("query ocean --config " + kOceanConfig +
                                  " --x 12.5 --y -40 --time 2026-06-21T23:30:45Z --json",
                              false);
    ASSERT_EQ(r.status, 0) << r.output;
    const auto j = nlohmann::json::parse(r.output);
    for (const char* key :
         {"time_utc", "time_s", "x_m", "y_m", "model", "surface", "water_depth_m", "sea"})
        EXPECT_TRUE(j.contains(key)) << key;
    for (const char* key : {"height_m", "normal", "orbital_velocity_mps", "jacobian",
                            "min_eigenvalue", "foam_coverage", "rest_position_m"})
        EXPECT_TRUE(j["surface"].contains(key)) << key;
    for (const char* key :
         {"significant_height_m", "peak_period_s", "peak_wavelength_m", "dominant_direction_deg",
          "phase_speed_mps", "group_speed_mps", "wind_speed_mps", "wind_direction_deg"})
        EXPECT_TRUE(j["sea"].contains(key)) << key;
    EXPECT_EQ(j["model"], "spectral");
    EXPECT_EQ(j["time_s"].get<double>(), 45.0);  // after world.start_utc 23:30:00
    EXPECT_EQ(j["water_depth_m"].get<double>(), 60.0);

    const seasense::scene::Scenario sc = seasense::scene::LoadScenario(kOceanConfig);
    const seasense::scene::OceanSurface sea(sc.environment.ocean);
    const seasense::scene::OceanPointQuery q = sea.Query(12.5, -40.0, 45.0);
    EXPECT_EQ(j["surface"]["height_m"].get<double>(), q.surface.position.z);
    EXPECT_EQ(j["surface"]["orbital_velocity_mps"][2].get<double>(), q.surface.velocity_mps.z);
    EXPECT_EQ(j["surface"]["foam_coverage"].get<double>(), q.foamCoverage);
    EXPECT_EQ(j["sea"]["significant_height_m"].get<double>(), sea.Summary().significantHeight_m);
    const auto& n = j["surface"]["normal"];
    EXPECT_NEAR(std::hypot(n[0].get<double>(), n[1].get<double>(), n[2].get<double>()), 1.0, 1e-12);
    // The Beaufort-5 wind of the scenario, toward 20°.
    EXPECT_NEAR(j["sea"]["wind_speed_mps"].get<double>(), 9.35, 1e-12);
    EXPECT_NEAR(j["sea"]["dominant_direction_deg"].get<double>(), 20.0, 0.3);
}

TEST(QueryOcean, GerstnerScenarioReportsItsLargestWave) {
    // configs/single-otw.yaml: the largest wave is the 160 m swell toward 270°.
    const Result r =
        Seasense("query ocean --config " + kGerstnerConfig + " --x 0 --y 0 --json", false);
    ASSERT_EQ(r.status, 0) << r.output;
    const auto j = nlohmann::json::parse(r.output);
    EXPECT_EQ(j["model"], "gerstner");
    EXPECT_NEAR(j["sea"]["peak_wavelength_m"].get<double>(), 160.0, 1e-9);
    EXPECT_NEAR(j["sea"]["dominant_direction_deg"].get<double>(), 270.0, 1e-9);
    EXPECT_TRUE(j["sea"]["wind_speed_mps"].is_null());
    EXPECT_EQ(j["time_s"].get<double>(), 0.0);
}

TEST(QueryOcean, TextOutputAndBadInput) {
    Result r = Seasense("query ocean --config " + kOceanConfig + " --x 1 --y 2");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("height"), std::string::npos);
    EXPECT_NE(r.output.find("foam coverage"), std::string::npos);

    EXPECT_EQ(Seasense("query ocean --config " + kOceanConfig + " --y 2").status, 2);
    EXPECT_EQ(Seasense("query ocean --x 1 --y 2").status, 2);
    r = Seasense("query ocean --config " + kOceanConfig + " --x 1e7 --y 2");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find("--x: expected metres"), std::string::npos) << r.output;
    r = Seasense("query ocean --config " + kOceanConfig + " --x 1 --y 2 --time noon");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find("ISO-8601"), std::string::npos) << r.output;
    r = Seasense("query ocean --config /nonexistent/ocean.yaml --x 1 --y 2");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find("cannot read file"), std::string::npos) << r.output;

    // A scenario error names file, line, column and key.
    const fs::path folder = fs::path(::testing::TempDir()) / "seasense_query_ocean";
    fs::remove_all(folder);
    fs::create_directories(folder);
    std::ifstream in(kOceanConfig);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string from = "      beaufort: 5 ";
    ASSERT_NE(text.find(from), std::string::npos);
    text.replace(text.find(from), from.size(), "      beaufort: 14");
    const fs::path bad = folder / "ocean.yaml";
    std::ofstream(bad) << text;
    fs::copy_file(fs::path(SEASENSE_SOURCE_DIR) / "configs/materials.yaml",
                  folder / "materials.yaml");
    r = Seasense("query ocean --config " + bad.string() + " --x 1 --y 2");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find(bad.string() + ":"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("environment.ocean.spectral.beaufort: expected an integer"),
              std::string::npos)
        << r.output;
    fs::remove_all(folder);
}

}  // namespace
