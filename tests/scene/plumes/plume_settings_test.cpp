// Tests of the plumes configuration reader: good input with units converted, per-kind keys,
// and errors that name the offending key path.
#include "scene/plumes/plume_settings.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

namespace seasense::scene {
namespace {

PlumesSettings Parse(const std::string& text) {
    ConfigDocument doc = ParseConfigText(text, "plumes.yaml");
    ConfigMap map(doc.root);
    return ParsePlumesSettings(map);
}

// The ConfigError message of parsing text ("" when it parses).
std::string ErrorOf(const std::string& text) {
    try {
        Parse(text);
    } catch (const ConfigError& e) {
        return e.what();
    }
    return "";
}

TEST(PlumeSettings, ReadsAllKinds) {
    const PlumesSettings s = Parse(
        "stability: E\n"
        "inversion_height_m: 300\n"
        "air_temperature_K: 280\n"
        "sources:\n"
        "  - kind: smoke\n"
        "    position_m: [100, 200, 0]\n"
        "    heat_release_W: 5.0e7\n"
        "    duration_s: 600\n"
        "    seed: 9\n"
        "  - kind: flame\n"
        "    position_m: [100, 200, 0]\n"
        "    flame_temperature_K: 1300\n"
        "  - kind: dust\n"
        "    position_m: [0, 0, 2]\n"
        "    speed_mps: 12\n"
        "    heading_deg: 90\n"
        "    soil: dry_clay\n"
        "    road: clay\n"
        "  - kind: exhaust\n"
        "    position_m: [0, 0, 35]\n"
        "    exit_velocity_mps: 20\n"
        "    exit_temperature_K: 650\n"
        "  - kind: steam\n"
        "    position_m: [0, 0, 20]\n"
        "    albedo: 0.95\n"
        "    decay_rate_hz: 0.1\n");
    ASSERT_TRUE(s.stability.has_value());
    EXPECT_EQ(*s.stability, StabilityClass::E);
    EXPECT_EQ(s.inversionHeight_m, 300.0);
    EXPECT_EQ(s.airTemperature_K, 280.0);
    ASSERT_EQ(s.sources.size(), 5u);
    EXPECT_EQ(s.sources[0].kind, PlumeKind::Smoke);
    EXPECT_EQ(s.sources[0].heatRelease_W, 5.0e7);
    EXPECT_EQ(s.sources[0].duration_s, 600.0);
    EXPECT_EQ(s.sources[0].seed, 9u);
    EXPECT_EQ(s.sources[1].flameTemperature_K, 1300.0);
    EXPECT_EQ(s.sources[2].kind, PlumeKind::Dust);
    EXPECT_NEAR(s.sources[2].heading_rad, std::numbers::pi / 2, 1e-15);
    EXPECT_EQ(s.sources[2].soil, SoilType::DryClay);
    EXPECT_EQ(SeedIndex(s.sources[2].soil), 0.5);
    EXPECT_EQ(SeedIndex(s.sources[2].road), 0.5);
    EXPECT_EQ(s.sources[3].exitVelocity_mps, 20.0);
    EXPECT_EQ(s.sources[4].albedo, 0.95);
    EXPECT_EQ(s.sources[4].longTermFraction, 0.0);  // the steam default: evaporates entirely
}

TEST(PlumeSettings, DefaultsAreAutoStabilityAndNoLid) {
    const PlumesSettings s = Parse("sources: []\n");
    EXPECT_FALSE(s.stability.has_value());
    EXPECT_TRUE(std::isinf(s.inversionHeight_m));
    EXPECT_TRUE(s.sources.empty());
}

TEST(PlumeSettings, ErrorsNameTheKey) {
    EXPECT_NE(ErrorOf("stability: G\nsources: []\n").find("stability"), std::string::npos);
    const std::string badRate = ErrorOf(
        "sources:\n"
        "  - kind: smoke\n"
        "    position_m: [0, 0, 0]\n"
        "    rate_hz: -2\n");
    EXPECT_NE(badRate.find("sources[0].rate_hz"), std::string::npos) << badRate;
    const std::string badKind = ErrorOf(
        "sources:\n"
        "  - kind: smog\n"
        "    position_m: [0, 0, 0]\n");
    EXPECT_NE(badKind.find("sources[0].kind"), std::string::npos) << badKind;
    // A key of another kind is unknown here.
    const std::string wrongKind = ErrorOf(
        "sources:\n"
        "  - kind: smoke\n"
        "    position_m: [0, 0, 0]\n"
        "    speed_mps: 10\n");
    EXPECT_NE(wrongKind.find("sources[0].speed_mps"), std::string::npos) << wrongKind;
    const std::string missing = ErrorOf("sources:\n  - kind: steam\n");
    EXPECT_NE(missing.find("sources[0].position_m"), std::string::npos) << missing;
    const std::string badSoil = ErrorOf(
        "sources:\n"
        "  - kind: dust\n"
        "    position_m: [0, 0, 0]\n"
        "    soil: gravel\n");
    EXPECT_NE(badSoil.find("sources[0].soil"), std::string::npos) << badSoil;
    EXPECT_NE(ErrorOf("inversion_height_m: 0\nsources: []\n").find("inversion_height_m"),
              std::string::npos);
    EXPECT_NE(ErrorOf("sources: []\nwind: 3\n").find("wind"), std::string::npos);
}

}  // namespace
}  // namespace seasense::scene
