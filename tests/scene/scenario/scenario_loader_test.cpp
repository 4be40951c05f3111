// Tests of the scenario schema: a complete file converts to SI units, each class of bad input
// gives one "file:line:column: key.path: expected ..., found ..." error at the right place.
#include "scene/scenario/scenario_loader.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>

#include "scene/config/config_error.h"
#include "scene/config/digest.h"

namespace seasense::scene {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = std::numbers::pi;

const fs::path kFixtures = fs::path(SEASENSE_SOURCE_DIR) / "tests/data/configs";

std::string ReadText(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    std::ostringstream out;
    out << in.rdbuf();
    return out.str();
}

void WriteText(const fs::path& file, const std::string& text) {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out << text;
}

// Text with the single occurrence of `from` replaced by `to`.
std::string Replace(std::string text, const std::string& from, const std::string& to) {
    const size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << "fixture lacks: " << from;
    EXPECT_EQ(text.find(from, at + 1), std::string::npos) << "fixture has twice: " << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
    return text;
}

// "line:column" (1-based) of `part` after the first occurrence of `context` in text.
std::string Where(const std::string& text, const std::string& context, const std::string& part) {
    const size_t contextAt = text.find(context);
    EXPECT_NE(contextAt, std::string::npos) << "text lacks: " << context;
    const size_t at = text.find(part, contextAt);
    EXPECT_NE(at, std::string::npos) << "text lacks: " << part;
    int line = 1;
    size_t lineStart = 0;
    for (size_t i = 0; i < at && i < text.size(); ++i) {
        if (text[i] == '\n') {
            ++line;
            lineStart = i + 1;
        }
    }
    return std::to_string(line) + ":" + std::to_string(at - lineStart + 1);
}

// Each test gets a folder holding copies of the valid fixture, its material table and model.
class ScenarioLoaderTest : public ::testing::Test {
  protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        folder_ =
            fs::path(::testing::TempDir()) / (std::string("seasense_scenario_") + info->name());
        fs::remove_all(folder_);
        fs::create_directories(folder_);
        for (const char* name : {"materials.yaml", "triangle.obj"})
            fs::copy_file(kFixtures / name, folder_ / name);
        valid_ = ReadText(kFixtures / "valid.yaml");
    }
    void TearDown() override { fs::remove_all(folder_); }

    fs::path Write(const std::string& text, const std::string& name = "scenario.yaml") {
        const fs::path file = folder_ / name;
        WriteText(file, text);
        return file;
    }

    // The ConfigError message for loading text ("" and a test failure when it loads).
    std::string ErrorFor(const std::string& text) {
        const fs::path file = Write(text);
        try {
            LoadScenario(file);
        } catch (const ConfigError& e) {
            return e.what();
        }
        ADD_FAILURE() << "scenario loaded without error";
        return "";
    }

    // Expected start of a message about `part` (found after `context`) in text.
    std::string At(const std::string& text, const std::string& context, const std::string& part,
                   const std::string& keyPath) {
        return (folder_ / "scenario.yaml").string() + ":" + Where(text, context, part) + ": " +
               keyPath + ": expected ";
    }

    fs::path folder_;
    std::string valid_;
};

TEST_F(ScenarioLoaderTest, ValidScenarioConvertsToSiUnitsAndRadians) {
    const fs::path file = Write(valid_);
    const Scenario s = LoadScenario(file);
    EXPECT_EQ(s.file, file);
    EXPECT_EQ(s.hash, Fnv1a64Hex(valid_));

    EXPECT_DOUBLE_EQ(s.world.latitude_deg, 33.2);
    EXPECT_DOUBLE_EQ(s.world.longitude_deg, -117.4);
    // date -u -d 2026-06-21T18:30:00Z +%s = 1782066600.
    EXPECT_EQ(s.world.start.unixNs, int64_t(1782066600) * 1000000000);
    EXPECT_DOUBLE_EQ(s.world.timeScale, 2.0);
    EXPECT_DOUBLE_EQ(s.world.frameRate_hz, 30.0);
    EXPECT_EQ(s.world.seed, 42u);

    const EnvironmentSettings& env = s.environment;
    EXPECT_DOUBLE_EQ(env.sun.azimuth_rad, 4.0 * kPi / 3.0);     // 240°
    EXPECT_DOUBLE_EQ(env.sun.elevation_rad, 5.0 * kPi / 36.0);  // 25°
    EXPECT_DOUBLE_EQ(env.sun.illuminance_lux, 90000.0);
    EXPECT_DOUBLE_EQ(env.sky.turbidity, 3.0);
    EXPECT_DOUBLE_EQ(env.visibility_m, 20000.0);
    EXPECT_DOUBLE_EQ(env.windSpeed_mps, 6.0);
    EXPECT_DOUBLE_EQ(env.windDirection_rad, kPi / 4.0);
    EXPECT_DOUBLE_EQ(env.ocean.depth_m, 50.0);
    ASSERT_EQ(env.ocean.waves.size(), 2u);
    EXPECT_DOUBLE_EQ(env.ocean.waves[0].direction_rad, kPi / 4.0);
    EXPECT_DOUBLE_EQ(env.ocean.waves[0].wavelength_m, 60.0);
    EXPECT_DOUBLE_EQ(env.ocean.waves[0].amplitude_m, 0.6);
    EXPECT_DOUBLE_EQ(env.ocean.waves[0].steepness, 0.6);
    EXPECT_DOUBLE_EQ(env.ocean.waves[0].phase_rad, 0.0);
    EXPECT_DOUBLE_EQ(env.ocean.waves[1].direction_rad, kPi / 2.0);
    EXPECT_DOUBLE_EQ(env.ocean.waves[1].phase_rad, kPi / 6.0);

    ASSERT_EQ(s.entities.size(), 1u);
    const EntitySettings& barge = s.entities[0];
    EXPECT_EQ(barge.name, "target-barge");
    EXPECT_EQ(barge.model, (folder_ / "triangle.obj").lexically_normal());
    EXPECT_EQ(barge.position_m, glm::dvec3(120.0, 300.0, 0.0));
    EXPECT_DOUBLE_EQ(barge.attitude.heading_rad, kPi / 6.0);
    EXPECT_DOUBLE_EQ(barge.scale, 1.5);
    EXPECT_EQ(barge.material, "hull_gray");

    EXPECT_EQ(s.eyepoint.position_m, glm::dvec3(0.0, 0.0, 2.0));
    EXPECT_EQ(s.eyepoint.attitude.heading_rad, 0.0);

    ASSERT_EQ(s.channels.size(), 2u);
    const ChannelSettings& otw = s.channels[0];
    EXPECT_EQ(otw.name, "otw-center");
    EXPECT_EQ(otw.kind, ChannelKind::Otw);
    EXPECT_EQ(otw.width, 640);
    EXPECT_EQ(otw.height, 480);
    EXPECT_DOUBLE_EQ(otw.hfov_rad, kPi / 3.0);  // 60°
    EXPECT_EQ(otw.supersampling, 2);
    EXPECT_DOUBLE_EQ(otw.near_m, 0.25);
    EXPECT_TRUE(otw.shadows);
    EXPECT_EQ(otw.formats, (std::vector<std::string>{"exr", "png"}));
    EXPECT_EQ(otw.exposure.mode, ExposureMode::Auto);
    EXPECT_DOUBLE_EQ(otw.exposure.keyValue, 0.18);
    EXPECT_EQ(otw.ocioView, "ACES 1.0 - SDR Video");

    const ChannelSettings& flir = s.channels[1];
    EXPECT_EQ(flir.kind, ChannelKind::Flir);
    EXPECT_DOUBLE_EQ(flir.hfov_rad, kPi / 9.0);  // 20°
    EXPECT_EQ(flir.offset_m, glm::dvec3(0.5, 0.0, -0.2));
    EXPECT_DOUBLE_EQ(flir.attitude.heading_rad, -kPi / 2.0);
    EXPECT_DOUBLE_EQ(flir.attitude.pitch_rad, -kPi / 36.0);  // -5°
    EXPECT_EQ(flir.exposure.mode, ExposureMode::Manual);
    EXPECT_DOUBLE_EQ(flir.exposure.ev, -1.5);
    EXPECT_EQ(flir.formats, (std::vector<std::string>{"tiff"}));

    ASSERT_EQ(s.materials.size(), 2u);
    EXPECT_EQ(s.materials[0].name, "hull_gray");
    EXPECT_EQ(s.materials[0].reflectanceRgb, glm::dvec3(0.24, 0.25, 0.27));

    ASSERT_NE(s.FindChannel("flir-1"), nullptr);
    EXPECT_EQ(s.FindChannel("flir-1")->width, 320);
    EXPECT_EQ(s.FindChannel("nvg"), nullptr);
    ASSERT_NE(s.FindMaterial("sea_water"), nullptr);
    EXPECT_EQ(s.FindMaterial("sea_water")->reflectanceRgb.b, 0.025);
    EXPECT_EQ(s.FindMaterial("foam"), nullptr);
}

TEST_F(ScenarioLoaderTest, EphemerisSunAndMotionAreRead) {
    const std::string text = Replace(
        Replace(
            Replace(valid_, "  sun: {azimuth_deg: 240, elevation_deg: 25, illuminance_lux: 90000}",
                    "  sun: ephemeris"),
            "    scale: 1.5\n", "    scale: 1.5\n    speed_mps: 6.5\n    ride_waves: true\n"),
        "eyepoint:\n", "eyepoint:\n  speed_mps: -2\n");
    const Scenario sc = LoadScenario(Write(text));
    EXPECT_TRUE(sc.environment.sun.fromEphemeris);
    ASSERT_FALSE(sc.entities.empty());
    EXPECT_EQ(sc.entities[0].speed_mps, 6.5);
    EXPECT_TRUE(sc.entities[0].rideWaves);
    EXPECT_EQ(sc.eyepoint.speed_mps, -2.0);
    const Scenario fixed = LoadScenario(Write(valid_));
    EXPECT_FALSE(fixed.environment.sun.fromEphemeris);
    EXPECT_EQ(fixed.entities[0].speed_mps, 0.0);
    EXPECT_FALSE(fixed.entities[0].rideWaves);
}

TEST_F(ScenarioLoaderTest, BadSunAndSpeedsAreRejected) {
    const std::string sun =
        Replace(valid_, "  sun: {azimuth_deg: 240, elevation_deg: 25, illuminance_lux: 90000}",
                "  sun: almanac");
    EXPECT_NE(ErrorFor(sun).find("environment.sun: expected 'ephemeris' or a mapping"),
              std::string::npos)
        << ErrorFor(sun);
    const std::string fast =
        Replace(valid_, "    scale: 1.5\n", "    scale: 1.5\n    speed_mps: 500\n");
    EXPECT_NE(ErrorFor(fast).find("entities[0].speed_mps: expected"), std::string::npos)
        << ErrorFor(fast);
    const std::string ride =
        Replace(valid_, "    scale: 1.5\n", "    scale: 1.5\n    ride_waves: maybe\n");
    EXPECT_NE(ErrorFor(ride).find("entities[0].ride_waves: expected"), std::string::npos)
        << ErrorFor(ride);
}

TEST_F(ScenarioLoaderTest, HashFollowsTheFileBytes) {
    const Scenario a = LoadScenario(Write(valid_));
    const Scenario b = LoadScenario(Write(valid_ + "# a comment changes the bytes\n"));
    EXPECT_EQ(a.hash.size(), 16u);
    EXPECT_NE(a.hash, b.hash);
}

TEST_F(ScenarioLoaderTest, UnknownKeySuggestsTheRightName) {
    const std::string text = Replace(valid_, "    hfov_deg: 60\n", "    hfvo_deg: 60\n");
    const std::string message = ErrorFor(text);
    EXPECT_EQ(message, At(text, "hfvo_deg", "hfvo_deg", "channels[0].hfvo_deg") +
                           "the required key 'hfov_deg', found unknown key 'hfvo_deg' (did you "
                           "mean 'hfov_deg'?)");

    const std::string extra =
        Replace(valid_, "  visibility_m: 20000\n", "  visibility_m: 20000\n  visibilty_km: 20\n");
    const std::string extraMessage = ErrorFor(extra);
    EXPECT_EQ(extraMessage.rfind(
                  At(extra, "visibilty_km", "visibilty_km", "environment.visibilty_km"), 0),
              0u)
        << extraMessage;
    EXPECT_NE(extraMessage.find("(did you mean 'visibility_m'?)"), std::string::npos)
        << extraMessage;

    const std::string top = Replace(valid_, "eyepoint:\n", "eyepiont:\n");
    EXPECT_NE(ErrorFor(top).find("(did you mean 'eyepoint'?)"), std::string::npos);
}

TEST_F(ScenarioLoaderTest, KeyOfTheOtherExposureModeIsRejected) {
    // "key" belongs to auto exposure; in manual mode it is unknown and ev is missing.
    const std::string text =
        Replace(valid_, "{mode: manual, ev: -1.5}", "{mode: manual, ev: -1.5, key: 0.2}");
    const std::string message = ErrorFor(text);
    EXPECT_EQ(message, At(text, "mode: manual", "key", "channels[1].exposure.key") +
                           "one of the keys mode, ev, found unknown key 'key'");
}

TEST_F(ScenarioLoaderTest, NanIsRejected) {
    const std::string text = Replace(valid_, "    hfov_deg: 60\n", "    hfov_deg: .nan\n");
    EXPECT_EQ(ErrorFor(text), At(text, "hfov_deg", ".nan", "channels[0].hfov_deg") +
                                  "a finite number (deg) in (0, 180), found .nan");
}

TEST_F(ScenarioLoaderTest, InfinityIsRejected) {
    const std::string text = Replace(valid_, "visibility_m: 20000", "visibility_m: .inf");
    EXPECT_EQ(ErrorFor(text), At(text, "visibility_m", ".inf", "environment.visibility_m") +
                                  "a finite number (m) > 0, found .inf");
}

TEST_F(ScenarioLoaderTest, NegativeSizesAreRejected) {
    const std::string wave = Replace(valid_, "wavelength_m: 60", "wavelength_m: -60");
    EXPECT_EQ(ErrorFor(wave),
              At(wave, "wavelength_m", "-60", "environment.ocean.waves[0].wavelength_m") +
                  "a number (m) > 0, found -60");
    const std::string scale = Replace(valid_, "scale: 1.5", "scale: -1.5");
    EXPECT_EQ(ErrorFor(scale),
              At(scale, "scale:", "-1.5", "entities[0].scale") + "a number > 0, found -1.5");
    const std::string depth = Replace(valid_, "depth_m: 50", "depth_m: 0");
    EXPECT_EQ(ErrorFor(depth),
              At(depth, "depth_m", "0", "environment.ocean.depth_m") + "a number (m) > 0, found 0");
}

TEST_F(ScenarioLoaderTest, WavesSteeperThanTheStokesLimitAreRejected) {
    // Michell (1893): H/λ ≤ 0.142, so for λ = 60 m the amplitude may not exceed 4.26 m.
    const std::string ok = Replace(valid_, "amplitude_m: 0.6", "amplitude_m: 4.2");
    EXPECT_NO_THROW(LoadScenario(Write(ok)));
    const std::string steep = Replace(valid_, "amplitude_m: 0.6", "amplitude_m: 4.4");
    EXPECT_NE(ErrorFor(steep).find("environment.ocean.waves[0].amplitude_m: expected a number (m) "
                                   "<= 0.071 × wavelength_m = 4.26"),
              std::string::npos)
        << ErrorFor(steep);
}

TEST_F(ScenarioLoaderTest, ResolutionAbove16384IsRejected) {
    const std::string text = Replace(valid_, "[640, 480]", "[16385, 480]");
    EXPECT_EQ(ErrorFor(text), At(text, "resolution", "16385", "channels[0].resolution[0]") +
                                  "an integer in [1, 16384], found 16385");
    const std::string zero = Replace(valid_, "[640, 480]", "[640, 0]");
    EXPECT_EQ(ErrorFor(zero), At(zero, "[640, 0]", "0]", "channels[0].resolution[1]") +
                                  "an integer in [1, 16384], found 0");
    const std::string three = Replace(valid_, "[640, 480]", "[640, 480, 3]");
    EXPECT_EQ(ErrorFor(three), At(three, "[640, 480, 3]", "[", "channels[0].resolution") +
                                   "a sequence of 2 integers, found a sequence of 3 items");
}

TEST_F(ScenarioLoaderTest, SupersampledResolutionMustStayWithin16384) {
    // 4096 x 4 = 16384 is allowed; 4096 x 8 is not, and the message names the largest factor.
    const std::string fits = Replace(Replace(valid_, "[640, 480]", "[4096, 480]"),
                                     "supersampling: 2", "supersampling: 4");
    EXPECT_NO_THROW(LoadScenario(Write(fits)));
    const std::string text = Replace(Replace(valid_, "[640, 480]", "[4096, 480]"),
                                     "supersampling: 2", "supersampling: 8");
    EXPECT_EQ(ErrorFor(text),
              At(text, "supersampling", "8", "channels[0].supersampling") +
                  "an integer in [1, 4] for resolution 4096x480 (resolution x supersampling <= "
                  "16384 per axis), found 8");
    // The second channel has no supersampling key: the default 2 applies.
    const std::string byDefault = Replace(valid_, "[320, 256]", "[320, 16384]");
    EXPECT_EQ(ErrorFor(byDefault),
              At(byDefault, "[320, 16384]", "[", "channels[1].resolution") +
                  "at most 8192 pixels per axis with the default supersampling 2 (resolution x "
                  "supersampling <= 16384 per axis), found [320, 16384]");
}

TEST_F(ScenarioLoaderTest, FieldOfViewMustLieInsideTheOpenInterval) {
    for (const char* bad : {"0", "180", "-10", "200"}) {
        const std::string text =
            Replace(valid_, "    hfov_deg: 60\n", std::string("    hfov_deg: ") + bad + "\n");
        EXPECT_EQ(ErrorFor(text), At(text, "hfov_deg", bad, "channels[0].hfov_deg") +
                                      "a number (deg) in (0, 180), found " + bad);
    }
    const Scenario wide =
        LoadScenario(Write(Replace(valid_, "    hfov_deg: 60\n", "    hfov_deg: 179.9\n")));
    EXPECT_DOUBLE_EQ(wide.channels[0].hfov_rad, 179.9 * kPi / 180.0);
}

TEST_F(ScenarioLoaderTest, FlirChannelTakesAnImagerRawFormatsAndMayLeaveOutTheFov) {
    // With an `imager:` the hfov may come from the imager's focal length (checked where the
    // channel is built); raw formats are for flir channels only.
    const std::string flir = Replace(valid_, "    hfov_deg: 20\n    pose: {offset_m: [0.5",
                                     "    imager: {optics: {focal_length_mm: 25}}\n"
                                     "    pose: {offset_m: [0.5");
    const Scenario sc =
        LoadScenario(Write(Replace(flir, "formats: [tiff]", "formats: [raw_png, exr]")));
    const ChannelSettings& ch = sc.channels[1];
    ASSERT_TRUE(ch.imager.has_value());
    EXPECT_FALSE(ch.hfovGiven);
    EXPECT_EQ(ch.formats, (std::vector<std::string>{"raw_png", "exr"}));
    EXPECT_TRUE(sc.channels[0].hfovGiven);
    // Without an imager the flir channel needs its hfov.
    const std::string noFov = Replace(valid_, "    hfov_deg: 20\n", "");
    EXPECT_NE(ErrorFor(noFov).find("channels[1]"), std::string::npos);
    // An otw channel has no raw output.
    const std::string otwRaw = Replace(valid_, "formats: [exr, png]", "formats: [exr, raw_png]");
    const std::string error = ErrorFor(otwRaw);
    EXPECT_EQ(
        error.rfind(At(otwRaw, "formats: [exr, ", "raw_png", "channels[0].output.formats[1]"), 0),
        0u)
        << error;
}

TEST_F(ScenarioLoaderTest, OtwDisplayImagesAreExactUnlessTheLutIsAskedFor) {
    using Display = ChannelSettings::Display;
    EXPECT_EQ(LoadScenario(Write(valid_)).channels[0].display, Display::Exact);
    const std::string lut =
        Replace(valid_, "formats: [exr, png]", "formats: [exr, png], display: lut");
    EXPECT_EQ(LoadScenario(Write(lut)).channels[0].display, Display::Lut);
    const std::string exact = Replace(lut, "display: lut", "display: exact");
    EXPECT_EQ(LoadScenario(Write(exact)).channels[0].display, Display::Exact);
    const std::string fast = Replace(lut, "display: lut", "display: fast");
    EXPECT_EQ(ErrorFor(fast), At(fast, "display: fast", "fast", "channels[0].output.display") +
                                  "one of exact, lut, found 'fast'");
    // The flir channel's display is its imager's (palette or polarity), not OCIO.
    const std::string flir = Replace(valid_, "formats: [tiff]", "formats: [tiff], display: lut");
    EXPECT_EQ(ErrorFor(flir), At(flir, "display: lut", "lut", "channels[1].output.display") +
                                  "no display key: only otw channels display through OpenColorIO "
                                  "(flir and nvg have their own display chains), found display "
                                  "on a flir channel");
}

TEST_F(ScenarioLoaderTest, WrongNodeTypeIsNamed) {
    const std::string sun = Replace(
        valid_, "sun: {azimuth_deg: 240, elevation_deg: 25, illuminance_lux: 90000}", "sun: 25");
    EXPECT_EQ(ErrorFor(sun), At(sun, "sun:", "25", "environment.sun") +
                                 "'ephemeris' or a mapping {azimuth_deg, elevation_deg}, found 25");
    const std::string fov = Replace(valid_, "    hfov_deg: 60\n", "    hfov_deg: [60]\n");
    EXPECT_EQ(ErrorFor(fov), At(fov, "hfov_deg", "[", "channels[0].hfov_deg") +
                                 "a number (deg) in (0, 180), found a sequence of 1 item");
    const std::string channels = Replace(valid_, "channels:\n  - name: otw-center",
                                         "channels: {}\nx:\n  - name: otw-center");
    EXPECT_NE(ErrorFor(channels).find("channels: expected a sequence of 1 to 64 channels, found a "
                                      "mapping"),
              std::string::npos);
}

TEST_F(ScenarioLoaderTest, MissingRequiredKeyPointsAtTheMapping) {
    const std::string text = Replace(valid_, "  start_utc: \"2026-06-21T18:30:00Z\"\n", "");
    EXPECT_EQ(ErrorFor(text), At(text, "world:", "origin", "world.start_utc") +
                                  "an ISO-8601 UTC time (e.g. 2026-06-21T18:30:00Z), found "
                                  "nothing (the key is required)");
    const std::string noChannels = valid_.substr(0, valid_.find("channels:"));
    EXPECT_EQ(ErrorFor(noChannels), At(noChannels, "world:", "world", "channels") +
                                        "a sequence of channels, found nothing (the key is "
                                        "required)");
}

TEST_F(ScenarioLoaderTest, UnreadableFilesAreReported) {
    const fs::path missing = folder_ / "missing.yaml";
    try {
        LoadScenario(missing);
        ADD_FAILURE() << "missing file loaded";
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()),
                  missing.string() + ": cannot read file: " + std::strerror(ENOENT));
    }
    try {
        LoadScenario(folder_);
        ADD_FAILURE() << "directory loaded";
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()),
                  folder_.string() + ": cannot read file: " + std::strerror(EISDIR));
    }
}

TEST_F(ScenarioLoaderTest, YamlSyntaxErrorGivesLineAndColumn) {
    const std::string text = Replace(valid_, "[640, 480]", "[640, 480]]");
    EXPECT_EQ(ErrorFor(text), (folder_ / "scenario.yaml").string() + ":" +
                                  Where(text, "[640, 480]]", "]\n") +
                                  ": YAML syntax error: illegal flow end");
}

TEST_F(ScenarioLoaderTest, DuplicateChannelNamesAreRejected) {
    const std::string text = Replace(valid_, "name: flir-1", "name: otw-center");
    EXPECT_EQ(ErrorFor(text),
              At(text, "  - name: otw-center\n    kind: flir", "otw-center", "channels[1].name") +
                  "a channel name not used before (channels[0] has it), found 'otw-center'");
}

TEST_F(ScenarioLoaderTest, DuplicateEntityNamesAreRejected) {
    const size_t begin = valid_.find("  - name: target-barge");
    const size_t end = valid_.find("eyepoint:");
    const std::string entity = valid_.substr(begin, end - begin);
    const std::string text = Replace(valid_, entity, entity + entity);
    const std::string message = ErrorFor(text);
    EXPECT_EQ(message, At(text, "material: hull_gray", "target-barge", "entities[1].name") +
                           "an entity name not used before (entities[0] has it), found "
                           "'target-barge'");
}

TEST_F(ScenarioLoaderTest, ChannelNamesAreRestricted) {
    const std::string text = Replace(valid_, "name: flir-1", "name: \"flir 1\"");
    EXPECT_EQ(ErrorFor(text), At(text, "name: \"flir 1\"", "\"", "channels[1].name") +
                                  "a name of letters, digits, '_' and '-', found \"flir 1\"");
}

TEST_F(ScenarioLoaderTest, BadEnumSuggests) {
    const std::string text = Replace(valid_, "kind: flir", "kind: flr");
    EXPECT_EQ(ErrorFor(text), At(text, "kind: flr", "flr", "channels[1].kind") +
                                  "one of otw, flir, nvg, found 'flr' (did you mean 'flir'?)");
    const std::string format = Replace(valid_, "[exr, png]", "[exr, jpeg]");
    EXPECT_EQ(ErrorFor(format), At(format, "[exr, jpeg]", "jpeg", "channels[0].output.formats[1]") +
                                    "one of exr, png, tiff, found 'jpeg'");
    const std::string twice = Replace(valid_, "[exr, png]", "[png, png]");
    EXPECT_EQ(ErrorFor(twice), At(twice, "png, png]", "png]", "channels[0].output.formats[1]") +
                                   "each format at most once, found 'png' again");
}

TEST_F(ScenarioLoaderTest, BadTimeIsRejected) {
    const std::string text = Replace(valid_, "2026-06-21T18:30:00Z", "2026-06-31T18:30:00Z");
    EXPECT_EQ(ErrorFor(text), At(text, "start_utc", "\"", "world.start_utc") +
                                  "an ISO-8601 UTC time (e.g. 2026-06-21T18:30:00Z), found "
                                  "\"2026-06-31T18:30:00Z\"");
}

TEST_F(ScenarioLoaderTest, MissingModelFileIsRejected) {
    const std::string text = Replace(valid_, "model: triangle.obj", "model: models/barge.obj");
    const std::string expected = At(text, "model:", "models", "entities[0].model") +
                                 "a readable model file (.obj, .gltf or .glb) relative to the "
                                 "scenario's folder, found 'models/barge.obj' (" +
                                 (folder_ / "models/barge.obj").string() + ": " +
                                 std::strerror(ENOENT) + ")";
    EXPECT_EQ(ErrorFor(text), expected);
    WriteText(folder_ / "triangle.txt", "v 0 0 0\n");
    const std::string extension = Replace(valid_, "model: triangle.obj", "model: triangle.txt");
    EXPECT_EQ(ErrorFor(extension), At(extension, "model:", "triangle", "entities[0].model") +
                                       "a readable model file (.obj, .gltf or .glb) relative to "
                                       "the scenario's folder, found 'triangle.txt'");
}

TEST_F(ScenarioLoaderTest, UnknownMaterialSuggests) {
    const std::string text = Replace(valid_, "material: hull_gray", "material: hull_grey");
    EXPECT_EQ(ErrorFor(text), At(text, "material:", "hull_grey", "entities[0].material") +
                                  "a material of materials.yaml (hull_gray, sea_water), found "
                                  "'hull_grey' (did you mean 'hull_gray'?)");
}

TEST_F(ScenarioLoaderTest, MaterialTableIsFoundOrReported) {
    const std::string named =
        Replace(valid_, "materials_file: materials.yaml", "materials_file: tables/none.yaml");
    EXPECT_EQ(ErrorFor(named), At(named, "materials_file", "tables", "materials_file") +
                                   "a readable material table file relative to the scenario's "
                                   "folder, found 'tables/none.yaml' (" +
                                   (folder_ / "tables/none.yaml").string() + ": " +
                                   std::strerror(ENOENT) + ")");
    // Without the key, materials.yaml beside the scenario is used, and nothing else is guessed.
    const std::string byDefault = Replace(valid_, "materials_file: materials.yaml\n", "");
    EXPECT_NO_THROW(LoadScenario(Write(byDefault)));
    fs::remove(folder_ / "materials.yaml");
    EXPECT_EQ(ErrorFor(byDefault),
              At(byDefault, "world:", "world", "materials_file") +
                  "a material table: the key materials_file, or a readable materials.yaml next to "
                  "the scenario, found neither (" +
                  (folder_ / "materials.yaml").string() + ": " + std::strerror(ENOENT) + ")");
}

TEST_F(ScenarioLoaderTest, ErrorsInsideTheMaterialTableNameThatFile) {
    const std::string table = "materials:\n  hull_gray:\n    reflectance_rgb: [0.24, 1.2, 0.27]\n";
    WriteText(folder_ / "materials.yaml", table);
    const std::string message = ErrorFor(valid_);
    EXPECT_EQ(message, (folder_ / "materials.yaml").string() + ":" +
                           Where(table, "reflectance_rgb", "1.2") +
                           ": materials.hull_gray.reflectance_rgb[1]: expected a number in [0, 1], "
                           "found 1.2");
}

TEST_F(ScenarioLoaderTest, AnglesOutsideTheirRangeAreRejected) {
    const std::string pitch = Replace(valid_, "pitch_deg: -5", "pitch_deg: -91");
    EXPECT_EQ(ErrorFor(pitch), At(pitch, "pitch_deg: -91", "-91", "channels[1].pose.pitch_deg") +
                                   "a number (deg) in [-90, 90], found -91");
    const std::string lat = Replace(valid_, "latitude_deg: 33.2", "latitude_deg: 95");
    EXPECT_EQ(ErrorFor(lat), At(lat, "latitude_deg", "95", "world.origin.latitude_deg") +
                                 "a number (deg) in [-90, 90], found 95");
    const std::string seed = Replace(valid_, "seed: 42", "seed: -1");
    EXPECT_EQ(ErrorFor(seed), At(seed, "seed", "-1", "world.seed") +
                                  "an integer in [0, 9223372036854775807], found -1");
}

TEST_F(ScenarioLoaderTest, WaveListMustHoldOneToSixtyFourWaves) {
    const size_t begin = valid_.find("    waves:\n");
    const size_t end = valid_.find("materials_file:");
    const std::string none = valid_.substr(0, begin) + "    waves: []\n" + valid_.substr(end);
    EXPECT_EQ(ErrorFor(none), At(none, "waves:", "[", "environment.ocean.waves") +
                                  "a sequence of 1 to 64 waves, found a sequence of 0 items");
}

TEST(ScenarioFixtures, BadFixtureFilesGiveTheirErrors) {
    const fs::path syntax = kFixtures / "bad-syntax.yaml";
    const std::string syntaxText = ReadText(syntax);
    try {
        LoadScenario(syntax);
        ADD_FAILURE();
    } catch (const ConfigError& e) {
        EXPECT_EQ(std::string(e.what()), syntax.string() + ":" +
                                             Where(syntaxText, "-117.4}]", "]") +
                                             ": YAML syntax error: illegal flow end");
    }
    for (const auto& [name, fragment] :
         {std::pair<std::string, std::string>{"bad-unknown-key.yaml", "(did you mean 'hfov_deg'?)"},
          {"bad-nan.yaml", "expected a finite number (deg) in (0, 180), found .nan"}}) {
        try {
            LoadScenario(kFixtures / name);
            ADD_FAILURE() << name;
        } catch (const ConfigError& e) {
            EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
        }
    }
}

// Rec. 709 relative luminance Y = 0.2126 R + 0.7152 G + 0.0722 B (ITU-R BT.709-6, item 3.2).
double Luminance(const glm::dvec3& rgb) { return 0.2126 * rgb.r + 0.7152 * rgb.g + 0.0722 * rgb.b; }
double Mean(const glm::dvec3& rgb) { return (rgb.r + rgb.g + rgb.b) / 3.0; }

TEST(MaterialTable, RepositoryTableIsPhysicallyPlausible) {
    const std::vector<MaterialSettings> table =
        LoadMaterialTable(fs::path(SEASENSE_SOURCE_DIR) / "configs/materials.yaml");
    auto find = [&](const std::string& name) -> glm::dvec3 {
        for (const MaterialSettings& m : table)
            if (m.name == name) return m.reflectanceRgb;
        ADD_FAILURE() << "configs/materials.yaml lacks " << name;
        return glm::dvec3(-1.0);
    };
    for (const char* name : {"sea_water", "foam", "sand_dry", "sand_wet", "hull_gray", "hull_white",
                             "deck", "glass", "stack_metal", "concrete", "wood"})
        find(name);
    // Oke (1987), Table 1.1: dry sand 0.35-0.45, wet sand 0.20-0.30; wetting darkens sand.
    EXPECT_GE(Mean(find("sand_dry")), 0.35);
    EXPECT_LE(Mean(find("sand_dry")), 0.45);
    EXPECT_GE(Mean(find("sand_wet")), 0.20);
    EXPECT_LE(Mean(find("sand_wet")), 0.30);
    // Water is the darkest natural surface (Oke: 0.03-0.10 including its specular part), and
    // clear sea water is bluer than red (Morel and Maritorena 2001).
    EXPECT_LT(Mean(find("sea_water")), 0.03);
    EXPECT_GT(find("sea_water").b, find("sea_water").r);
    // Fresh whitecap foam about 0.55 in the visible (Whitlock et al. 1982).
    EXPECT_NEAR(Luminance(find("foam")), 0.55, 0.1);
    // Navy haze gray (FS 595 26270): luminous reflectance about 25 %.
    EXPECT_NEAR(Luminance(find("hull_gray")), 0.25, 0.03);
    // Two air-glass surfaces at normal incidence, n = 1.52: 2 ((n-1)/(n+1))^2 (Fresnel).
    const double fresnel = 2.0 * std::pow((1.52 - 1.0) / (1.52 + 1.0), 2.0);
    EXPECT_NEAR(Mean(find("glass")), fresnel, 0.01);
    // White paint 0.50-0.90 (Oke 1987).
    EXPECT_GE(Mean(find("hull_white")), 0.5);
    EXPECT_LE(Mean(find("hull_white")), 0.9);
}

// A source attached to a moving entity starts at the entity's planned position at start_s
// plus the body-frame offset turned by the heading, and moves with the entity.
TEST_F(ScenarioLoaderTest, PlumesAttachToEntities) {
    const std::string text =
        Replace(valid_, "    scale: 1.5\n", "    scale: 1.5\n    speed_mps: 4\n") +
        "plumes:\n"
        "  stability: D\n"
        "  sources:\n"
        "    - kind: exhaust\n"
        "      attach_to: target-barge\n"
        "      offset_m: [0, -2, 10]\n"
        "      start_s: 5\n"
        "    - kind: smoke\n"
        "      position_m: [10, 20, 0]\n";
    const Scenario s = LoadScenario(Write(text));
    ASSERT_EQ(s.plumes.sources.size(), 2u);
    EXPECT_FALSE(s.plumes.airTemperatureGiven);
    const PlumeSourceSettings& exhaust = s.plumes.sources[0];
    // Heading 30°: forward (sin 30°, cos 30°), right (cos 30°, −sin 30°).
    const double h = kPi / 6.0;
    const glm::dvec3 forward{std::sin(h), std::cos(h), 0.0};
    const glm::dvec3 expected = glm::dvec3(120.0, 300.0, 0.0) + 4.0 * 5.0 * forward -
                                2.0 * forward + glm::dvec3(0.0, 0.0, 10.0);
    EXPECT_NEAR(glm::length(exhaust.position_m - expected), 0.0, 1e-9);
    EXPECT_NEAR(glm::length(exhaust.velocity_mps - 4.0 * forward), 0.0, 1e-12);
    EXPECT_EQ(s.plumes.sources[1].position_m, glm::dvec3(10.0, 20.0, 0.0));
    EXPECT_EQ(s.plumes.sources[1].velocity_mps, glm::dvec3(0.0));
}

TEST_F(ScenarioLoaderTest, PlumeErrorsNameTheKey) {
    const std::string base = valid_ + "plumes:\n  sources:\n    - kind: smoke\n";
    const auto expectError = [&](const std::string& text, const std::string& context,
                                 const std::string& part, const std::string& keyPath) {
        const std::string message = ErrorFor(text);
        EXPECT_TRUE(message.starts_with(At(text, context, part, keyPath))) << message;
        return message;
    };
    const std::string unknownEntity = base + "      attach_to: target-barg\n";
    const std::string message =
        expectError(unknownEntity, "attach_to", "target-barg", "plumes.sources[0].attach_to");
    EXPECT_NE(message.find("did you mean 'target-barge'"), std::string::npos) << message;
    expectError(base + "      position_m: [0, 0, 0]\n      heat_release_MW: 5\n", "heat_release_MW",
                "heat_release_MW", "plumes.sources[0].heat_release_MW");
    expectError(base + "      attach_to: target-barge\n      position_m: [0, 0, 0]\n",
                "barge\n      position_m", "[0, 0, 0]", "plumes.sources[0].position_m");
    expectError(base + "      position_m: [0, 0, 0]\n      rate_hz: -1\n", "rate_hz: -1", "-1",
                "plumes.sources[0].rate_hz");
    expectError(valid_ + "plumes:\n  stabilty: D\n  sources: []\n", "stabilty", "stabilty",
                "plumes.stabilty");
}

TEST_F(ScenarioLoaderTest, CloudLayersAreReadInSiUnits) {
    EXPECT_TRUE(LoadScenario(Write(valid_)).environment.clouds.empty());
    const std::string text = Replace(valid_, "  visibility_m: 20000\n",
                                     "  visibility_m: 20000\n"
                                     "  clouds:\n"
                                     "    - {type: stratocumulus, coverage_oktas: 6, base_m: 900,\n"
                                     "       thickness_m: 400, drift_east_mps: 4}\n"
                                     "    - {type: cirrus, coverage: 0.3, base_m: 8000, "
                                     "thickness_m: 1500, optical_depth: 0.5, cell_m: 3000}\n");
    const std::vector<CloudLayerSettings> clouds = LoadScenario(Write(text)).environment.clouds;
    ASSERT_EQ(clouds.size(), 2u);
    EXPECT_EQ(clouds[0].type, CloudType::Stratocumulus);
    EXPECT_DOUBLE_EQ(clouds[0].coverage, 0.75);  // 6 oktas of 8
    EXPECT_DOUBLE_EQ(clouds[0].base_m, 900.0);
    EXPECT_DOUBLE_EQ(clouds[0].thickness_m, 400.0);
    EXPECT_DOUBLE_EQ(clouds[0].drift_mps.x, 4.0);
    EXPECT_TRUE(std::isnan(clouds[0].opticalDepth));  // the type's default, filled by the field
    EXPECT_EQ(clouds[1].type, CloudType::Cirrus);
    EXPECT_DOUBLE_EQ(clouds[1].coverage, 0.3);
    EXPECT_DOUBLE_EQ(clouds[1].opticalDepth, 0.5);
    EXPECT_DOUBLE_EQ(clouds[1].cellSize_m, 3000.0);
}

TEST_F(ScenarioLoaderTest, CloudErrorsNameTheKey) {
    const auto withClouds = [&](const std::string& layers) {
        return Replace(valid_, "  visibility_m: 20000\n",
                       "  visibility_m: 20000\n  clouds:\n" + layers);
    };
    const auto expectError = [&](const std::string& text, const std::string& context,
                                 const std::string& part, const std::string& keyPath) {
        const std::string message = ErrorFor(text);
        EXPECT_TRUE(message.starts_with(At(text, context, part, keyPath))) << message;
        return message;
    };
    const std::string misspelt =
        withClouds("    - {type: stratus, coverage: 1, bsae_m: 300, thickness_m: 200}\n");
    const std::string message = ErrorFor(misspelt);
    EXPECT_NE(message.find("environment.clouds[0]"), std::string::npos) << message;
    EXPECT_NE(message.find("did you mean 'base_m'"), std::string::npos) << message;
    expectError(withClouds("    - {type: stratos, coverage: 1, base_m: 300, thickness_m: 200}\n"),
                "type: stratos", "stratos", "environment.clouds[0].type");
    expectError(withClouds("    - {type: stratus, coverage: 1.5, base_m: 300, thickness_m: 200}\n"),
                "coverage: 1.5", "1.5", "environment.clouds[0].coverage");
    expectError(withClouds("    - {type: stratus, coverage: 1, coverage_oktas: 8, base_m: 300, "
                           "thickness_m: 200}\n"),
                "coverage_oktas", "8", "environment.clouds[0].coverage_oktas");
    expectError(
        withClouds("    - {type: cirrus, coverage: 0.2, base_m: 19000, thickness_m: 2000}\n"),
        "thickness_m: 2000", "2000", "environment.clouds[0].thickness_m");
    expectError(withClouds("    - {type: stratus, coverage: 1, base_m: 300, thickness_m: 200}\n"
                           "    - {type: cumulus, coverage: 0.5, base_m: 900, thickness_m: 800,"
                           " drift_north_mps: 900}\n"),
                "drift_north_mps", "900", "environment.clouds[1].drift_north_mps");
    expectError(withClouds("    []\n"), "clouds:", "[]", "environment.clouds");
}

}  // namespace
}  // namespace seasense::scene
