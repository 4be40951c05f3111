// environment.ocean.surf in a scenario: keys read into SurfSettings (degrees to radians, files
// relative to the scenario), absent section leaves the ocean alone, errors name file:line:column
// and the key path.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>

#include "scene/config/config_error.h"
#include "scene/scenario/scenario_loader.h"
#include "scene/surf/bathymetry.h"

namespace seasense::scene {
namespace {

namespace fs = std::filesystem;
const fs::path kFixtures = fs::path(SEASENSE_SOURCE_DIR) / "tests/data/configs";
const std::string kOceanDepth = "    depth_m: 50\n";

class SurfConfigTest : public ::testing::Test {
  protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        folder_ = fs::path(::testing::TempDir()) / (std::string("seasense_surf_") + info->name());
        fs::remove_all(folder_);
        fs::create_directories(folder_);
        for (const char* name : {"materials.yaml", "triangle.obj"})
            fs::copy_file(kFixtures / name, folder_ / name);
        std::ifstream in(kFixtures / "valid.yaml");
        std::ostringstream text;
        text << in.rdbuf();
        valid_ = text.str();
        EXPECT_NE(valid_.find(kOceanDepth), std::string::npos);
    }
    void TearDown() override { fs::remove_all(folder_); }

    // The fixture with `surf` (lines indented under environment.ocean.surf) added.
    std::string WithSurf(const std::string& surf) const {
        std::string text = valid_;
        text.insert(text.find(kOceanDepth) + kOceanDepth.size(), "    surf:\n" + surf);
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

TEST_F(SurfConfigTest, NoSurfSectionNoSurf) {
    EXPECT_FALSE(LoadScenario(Write(valid_)).environment.ocean.surf.has_value());
}

TEST_F(SurfConfigTest, EveryKeyIsRead) {
    const Scenario s = LoadScenario(Write(WithSurf(
        "      shoreline: {origin_m: [10, -20], azimuth_deg: -35.5}\n"
        "      tide_m: 0.4\n"
        "      supralittoral: {slope: 0.1, width_m: 30}\n"
        "      intertidal: {slope: 0.04, low_water_m: -0.8, high_water_m: 1.2}\n"
        "      sublittoral: {slope: 0.015, width_m: 250}\n"
        "      offshore_slope: 0.03\n"
        "      regions:\n"
        "        - width_m: 500\n"
        "          sandbar: {width_m: 25, length_m: 300, crest_depth_m: 1.5, distance_m: 90,\n"
        "                    side_slope_m: 30}\n"
        "        - {width_m: 250}\n")));
    ASSERT_TRUE(s.environment.ocean.surf.has_value());
    const SurfSettings& f = *s.environment.ocean.surf;
    EXPECT_DOUBLE_EQ(f.shoreline.origin_m.x, 10.0);
    EXPECT_DOUBLE_EQ(f.shoreline.origin_m.y, -20.0);
    EXPECT_DOUBLE_EQ(f.shoreline.azimuth_rad, -35.5 * std::numbers::pi / 180.0);
    EXPECT_DOUBLE_EQ(f.tide_m, 0.4);
    EXPECT_DOUBLE_EQ(f.supralittoral.slope, 0.1);
    EXPECT_DOUBLE_EQ(f.supralittoral.width_m, 30.0);
    EXPECT_DOUBLE_EQ(f.intertidal.slope, 0.04);
    EXPECT_DOUBLE_EQ(f.lowTide_m, -0.8);
    EXPECT_DOUBLE_EQ(f.highTide_m, 1.2);
    EXPECT_DOUBLE_EQ(f.sublittoral.slope, 0.015);
    EXPECT_DOUBLE_EQ(f.sublittoral.width_m, 250.0);
    EXPECT_DOUBLE_EQ(f.offshoreSlope, 0.03);
    ASSERT_EQ(f.regions.size(), 2u);
    ASSERT_TRUE(f.regions[0].sandbar.has_value());
    EXPECT_FALSE(f.regions[1].sandbar.has_value());
    const SandbarSettings& bar = *f.regions[0].sandbar;
    EXPECT_DOUBLE_EQ(bar.width_m, 25.0);
    EXPECT_DOUBLE_EQ(bar.length_m, 300.0);
    EXPECT_DOUBLE_EQ(bar.crestDepth_m, 1.5);
    EXPECT_DOUBLE_EQ(bar.distance_m, 90.0);
    EXPECT_DOUBLE_EQ(bar.sideSlope_m, 30.0);
    // The bar's crest, 90 m seaward of the origin in the middle of region 0, is 1.5 m deep.
    const Bathymetry b(f, s.environment.ocean.depth_m);
    const glm::dvec2 crest = b.Frame().WorldFromShore(90.0, 250.0);
    EXPECT_NEAR(b.Depth_m(crest.x, crest.y), 1.5, 1e-9);
}

TEST_F(SurfConfigTest, DepthGridIsReadRelativeToTheScenario) {
    {
        auto out = OIIO::ImageOutput::create((folder_ / "bathy.tif").string());
        ASSERT_TRUE(out);
        ASSERT_TRUE(out->open((folder_ / "bathy.tif").string(),
                              OIIO::ImageSpec(2, 2, 1, OIIO::TypeDesc::FLOAT)));
        const float v[4] = {1.0f, 2.0f, 3.0f, 4.0f};
        ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, v));
        out->close();
    }
    const Scenario s = LoadScenario(
        Write(WithSurf("      shoreline: {origin_m: [0, 0], azimuth_deg: 0}\n"
                       "      depth_grid: {file: bathy.tif, origin_m: [0, 10], cell_m: 10, "
                       "values: elevation}\n")));
    const SurfSettings& f = *s.environment.ocean.surf;
    ASSERT_TRUE(f.depthGrid.has_value());
    EXPECT_EQ(f.depthGrid->values, DepthGridValues::Elevation);
    const Bathymetry b(f, 50.0);
    EXPECT_NEAR(b.SeabedZ_m(10.0, 0.0), 4.0, 1e-6);
    EXPECT_NEAR(b.SeabedZ_m(5.0, 5.0), 2.5, 1e-6);
}

TEST_F(SurfConfigTest, ErrorsNameTheKey) {
    std::string text = WithSurf(
        "      shoreline: {origin_m: [0, 0], azimuth_deg: 0}\n"
        "      regions:\n"
        "        - width_m: 200\n"
        "          sandbar: {width_m: 25, length_m: 300, crest_depth_m: 1.5}\n");
    EXPECT_EQ(ErrorFor(text),
              At(text, "sandbar:", "300") +
                  "environment.ocean.surf.regions[0].sandbar.length_m: expected length_m + 2 "
                  "side_slope_m <= the region's width_m = 200 (a bar stays inside its region), "
                  "found 300 + 2 × 20");

    text = WithSurf(
        "      shoreline: {origin_m: [0, 0], azimuth_deg: 0}\n"
        "      sublittoral: {slope: 0.02, widht_m: 100}\n");
    const std::string unknown = ErrorFor(text);
    EXPECT_EQ(unknown.rfind(At(text, "sublittoral:", "widht_m") +
                                "environment.ocean.surf.sublittoral.widht_m: expected one of the "
                                "keys",
                            0),
              0u)
        << unknown;
    EXPECT_NE(unknown.find("did you mean 'width_m'?"), std::string::npos) << unknown;

    text = WithSurf(
        "      shoreline: {origin_m: [0, 0], azimuth_deg: 0}\n"
        "      intertidal: {slope: 0}\n");
    EXPECT_EQ(ErrorFor(text), At(text, "intertidal:", "0}") +
                                  "environment.ocean.surf.intertidal.slope: expected a number in "
                                  "(0, 1], found 0");

    text = WithSurf("      tide_m: 0.5\n");
    EXPECT_NE(ErrorFor(text).find("environment.ocean.surf.shoreline: expected a mapping"),
              std::string::npos);

    text = WithSurf(
        "      shoreline: {origin_m: [0, 0], azimuth_deg: 0}\n"
        "      depth_grid: {file: nothing.tif, origin_m: [0, 0], cell_m: 1, values: depth}\n");
    const std::string missing = ErrorFor(text);
    EXPECT_EQ(missing.rfind(At(text, "depth_grid:", "nothing.tif") +
                                "environment.ocean.surf.depth_grid.file: expected a "
                                "single-channel float image",
                            0),
              0u)
        << missing;
}

TEST_F(SurfConfigTest, SprayAndSwashKeysAreRead) {
    const Scenario s = LoadScenario(Write(
        WithSurf("      shoreline: {origin_m: [0, 0], azimuth_deg: 0}\n"
                 "      spray: {enabled: false, radius_m: 90, cell_m: 2.5, interval_s: 0.3,\n"
                 "              probability: 0.4, droplets_per_burst: 7, lifetime_s: 2.2,\n"
                 "              launch_speed_mps: 4.5, drag_time_s: 0.3, clump_radius_m: 0.2,\n"
                 "              opacity: 0.9, max_particles: 5000, seed: 9}\n"
                 "      swash: {enabled: false, cusp_spacing_m: 35, cusp_amplitude: 0.25}\n")));
    const SpraySettings& p = s.environment.ocean.surf->spray;
    EXPECT_FALSE(p.enabled);
    EXPECT_DOUBLE_EQ(p.radius_m, 90.0);
    EXPECT_DOUBLE_EQ(p.cell_m, 2.5);
    EXPECT_DOUBLE_EQ(p.interval_s, 0.3);
    EXPECT_DOUBLE_EQ(p.probability, 0.4);
    EXPECT_EQ(p.dropletsPerBurst, 7);
    EXPECT_DOUBLE_EQ(p.lifetime_s, 2.2);
    EXPECT_DOUBLE_EQ(p.launchSpeed_mps, 4.5);
    EXPECT_DOUBLE_EQ(p.dragTime_s, 0.3);
    EXPECT_DOUBLE_EQ(p.clumpRadius_m, 0.2);
    EXPECT_DOUBLE_EQ(p.opacity, 0.9);
    EXPECT_EQ(p.maxParticles, 5000);
    EXPECT_EQ(p.seed, 9u);
    const SwashSettings& w = s.environment.ocean.surf->swash;
    EXPECT_FALSE(w.enabled);
    EXPECT_DOUBLE_EQ(w.cuspSpacing_m, 35.0);
    EXPECT_DOUBLE_EQ(w.cuspAmplitude, 0.25);

    std::string text = WithSurf(
        "      shoreline: {origin_m: [0, 0], azimuth_deg: 0}\n"
        "      spray: {radius_m: 90, lifetme_s: 2}\n");
    const std::string unknown = ErrorFor(text);
    EXPECT_EQ(unknown.rfind(At(text, "spray:", "lifetme_s") +
                                "environment.ocean.surf.spray.lifetme_s: expected one of the keys",
                            0),
              0u)
        << unknown;
    EXPECT_NE(unknown.find("did you mean 'lifetime_s'?"), std::string::npos) << unknown;
    text = WithSurf(
        "      shoreline: {origin_m: [0, 0], azimuth_deg: 0}\n"
        "      swash: {cusp_amplitude: 1.5}\n");
    EXPECT_EQ(ErrorFor(text), At(text, "swash:", "1.5") +
                                  "environment.ocean.surf.swash.cusp_amplitude: expected a number "
                                  "in [0, 1], found 1.5");
}

TEST_F(SurfConfigTest, DepthGridExcludesTheSlopeKeys) {
    {
        auto out = OIIO::ImageOutput::create((folder_ / "bathy.tif").string());
        ASSERT_TRUE(out);
        ASSERT_TRUE(out->open((folder_ / "bathy.tif").string(),
                              OIIO::ImageSpec(2, 2, 1, OIIO::TypeDesc::FLOAT)));
        const float v[4] = {1.0f, 2.0f, 3.0f, 4.0f};
        ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, v));
        out->close();
    }
    const std::string text = WithSurf(
        "      shoreline: {origin_m: [0, 0], azimuth_deg: 0}\n"
        "      depth_grid: {file: bathy.tif, origin_m: [0, 0], cell_m: 1, values: depth}\n"
        "      offshore_slope: 0.1\n");
    EXPECT_EQ(ErrorFor(text), At(text, "offshore_slope:", "0.1") +
                                  "environment.ocean.surf.offshore_slope: expected no "
                                  "offshore_slope with depth_grid (the grid replaces the slopes "
                                  "and sandbars), found 0.1");
}

}  // namespace
}  // namespace seasense::scene
