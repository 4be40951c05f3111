// UTC time parsing against known Julian dates and calendar rules; body-frame rotations.
#include "scene/core/time.h"

#include <gtest/gtest.h>

#include "scene/core/frames.h"

namespace seasense::scene {
namespace {

TEST(Time, J2000EpochIsJulianDate2451545) {
    // J2000.0 = 2000-01-01T12:00:00 TT ≈ JD 2451545.0 (IAU 1976); as UTC civil time the JD of
    // 2000-01-01T12:00:00Z is exactly 2451545.0.
    auto t = ParseIso8601("2000-01-01T12:00:00Z");
    ASSERT_TRUE(t);
    EXPECT_DOUBLE_EQ(t->JulianDate(), 2451545.0);
    EXPECT_EQ(ParseIso8601("1970-01-01T00:00:00Z")->unixNs, 0);
    // 2026-06-21T18:30:00Z: 20625 days after the epoch (Hinnant's algorithm is independent of
    // this count, which comes from 56 years × 365 + 14 leap days + 171 days into 2026).
    EXPECT_EQ(ParseIso8601("2026-06-21T18:30:00Z")->unixNs / 1000000000LL,
              (56LL * 365 + 14 + 171) * 86400 + 18 * 3600 + 30 * 60);
}

TEST(Time, ZonesFractionsAndRoundTrip) {
    EXPECT_EQ(ParseIso8601("2026-03-01T01:30:00+02:00")->unixNs,
              ParseIso8601("2026-02-28T23:30:00Z")->unixNs);
    EXPECT_EQ(ParseIso8601("2026-03-01T01:30:00.25Z")->unixNs -
                  ParseIso8601("2026-03-01T01:30:00Z")->unixNs,
              250000000LL);
    const UtcTime t = *ParseIso8601("1999-12-31T23:59:59.123Z");
    EXPECT_EQ(FormatIso8601(t), "1999-12-31T23:59:59.123Z");
    EXPECT_EQ(FormatIso8601(*ParseIso8601("1969-07-20T20:17:40Z")), "1969-07-20T20:17:40.000Z");
}

TEST(Time, RejectsImpossibleDates) {
    EXPECT_FALSE(ParseIso8601("2023-02-29T00:00:00Z"));  // 2023 is not a leap year
    EXPECT_TRUE(ParseIso8601("2024-02-29T00:00:00Z"));
    EXPECT_FALSE(ParseIso8601("1900-02-29T00:00:00Z"));  // century rule
    EXPECT_TRUE(ParseIso8601("2000-02-29T00:00:00Z"));   // 400-year rule
    EXPECT_FALSE(ParseIso8601("2026-13-01T00:00:00Z"));
    EXPECT_FALSE(ParseIso8601("2026-06-21T24:00:00Z"));
    EXPECT_FALSE(ParseIso8601("2026-06-21"));
    EXPECT_FALSE(ParseIso8601("noon"));
    EXPECT_FALSE(ParseIso8601("2026-06-21T12:00:00Zjunk"));
}

TEST(Frames, HeadingPitchRollFollowNavigationConventions) {
    const double deg = M_PI / 180.0;
    glm::dmat3 r = WorldFromBodyRotation({90 * deg, 0, 0});
    const glm::dvec3 fwd = r * glm::dvec3(0, 1, 0);
    EXPECT_NEAR(fwd.x, 1.0, 1e-12);  // heading 090 points east
    EXPECT_NEAR(fwd.y, 0.0, 1e-12);
    r = WorldFromBodyRotation({0, 10 * deg, 0});
    EXPECT_NEAR((r * glm::dvec3(0, 1, 0)).z, std::sin(10 * deg), 1e-12);  // nose up
    r = WorldFromBodyRotation({0, 0, 10 * deg});
    EXPECT_NEAR((r * glm::dvec3(1, 0, 0)).z, -std::sin(10 * deg), 1e-12);  // right side down
    r = WorldFromBodyRotation({0.3, -0.2, 0.9});
    EXPECT_NEAR(glm::determinant(r), 1.0, 1e-12);
    const glm::dmat3 i = glm::transpose(r) * r;
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) EXPECT_NEAR(i[a][b], a == b ? 1.0 : 0.0, 1e-12);
    const glm::dvec3 d = DirectionFromAzimuthElevation(180 * deg, 30 * deg);
    EXPECT_NEAR(d.y, -std::cos(30 * deg), 1e-12);
    EXPECT_NEAR(d.z, 0.5, 1e-12);
}

}  // namespace
}  // namespace seasense::scene
