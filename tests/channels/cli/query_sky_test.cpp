// `seasense query sky` end to end: JSON keys, published solstice and full-moon facts, errors.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "tests/support/shell.h"

namespace {

using Result = seasense::testing::ShellResult;

// Runs the seasense binary under test with args.
Result Seasense(const std::string& args, bool mergeStderr = true) {
    return seasense::testing::Shell(std::string(SEASENSE_BINARY) + " " + args, mergeStderr);
}

TEST(QuerySky, SolsticeNoonSunStandsOverTheTropicOfCancer) {
    // At the June solstice the sun's declination equals the obliquity (23.44°), so at apparent
    // noon on the Tropic of Cancer it stands in the zenith. 2026-06-21, longitude 0: apparent
    // noon ≈ 12:02 UTC (equation of time ≈ −1.6 min).
    const Result r =
        Seasense("query sky --lat 23.4367 --lon 0 --time 2026-06-21T12:02:00Z --json", false);
    ASSERT_EQ(r.status, 0) << r.output;
    const auto j = nlohmann::json::parse(r.output);
    EXPECT_GT(j["sun"]["altitude_deg"].get<double>(), 89.5);
    EXPECT_EQ(j["twilight"], "day");
    // A high sun: 1.2–1.3e5 lx (physics.md, USNO Circular 171).
    EXPECT_GT(j["illuminance_lux"]["sun"].get<double>(), 1.2e5);
    EXPECT_LT(j["illuminance_lux"]["sun"].get<double>(), 1.3e5);
    for (const char* key : {"sun", "moon", "sky", "total"})
        EXPECT_TRUE(j["illuminance_lux"].contains(key)) << key;
    for (const char* key :
         {"altitude_deg", "azimuth_deg", "illuminated_fraction", "phase_angle_deg"})
        EXPECT_TRUE(j["moon"].contains(key)) << key;
    EXPECT_TRUE(j["events"]["sun"]["next_rise"].is_string());
    EXPECT_TRUE(j["events"]["sun"]["next_set"].is_string());
}

TEST(QuerySky, FullMoonIsFullyIlluminated) {
    // USNO lists the full moon of 2024-01-25 at 17:54 UTC.
    const Result r =
        Seasense("query sky --lat 38.89 --lon -77.03 --time 2024-01-25T17:54:00Z --json", false);
    ASSERT_EQ(r.status, 0) << r.output;
    const auto j = nlohmann::json::parse(r.output);
    EXPECT_GT(j["moon"]["illuminated_fraction"].get<double>(), 0.99);
    EXPECT_LT(j["moon"]["phase_angle_deg"].get<double>(), 12.0);
}

TEST(QuerySky, TextOutputAndBadInput) {
    Result r = Seasense("query sky --lat 10 --lon 20 --time 2026-03-20T00:00:00Z");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("twilight"), std::string::npos);
    EXPECT_EQ(Seasense("query sky --lat 91 --lon 0 --time 2026-03-20T00:00:00Z").status, 2);
    EXPECT_EQ(Seasense("query sky --lat 0 --lon 200 --time 2026-03-20T00:00:00Z").status, 2);
    r = Seasense("query sky --lat 0 --lon 0 --time yesterday");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find("ISO-8601"), std::string::npos) << r.output;
    EXPECT_EQ(
        Seasense("query sky --lat 0 --lon 0 --time 2026-03-20T00:00:00Z --sky-divisor 20").status,
        2);
    EXPECT_EQ(Seasense("query sky --lon 0 --time 2026-03-20T00:00:00Z").status, 2);
}

}  // namespace
