// Sun and moon ephemeris against Meeus's worked examples, USNO almanac times and geometry.
#include "scene/sky/ephemeris.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "scene/core/error.h"

namespace seasense::scene {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

UtcTime At(const std::string& iso) {
    const auto t = ParseIso8601(iso);
    EXPECT_TRUE(t.has_value()) << iso;
    return t.value_or(UtcTime{});
}

double Deg(double rad) { return rad / kDeg; }

// Minutes between two instants.
double Minutes(UtcTime a, UtcTime b) { return (a.UnixSeconds() - b.UnixSeconds()) / 60.0; }

TEST(Ephemeris, TtMinusUtcFollowsLeapSecondTable) {
    // IERS Bulletin C: TAI-UTC = 10 s from 1972-01-01, 27 s from 1992-07-01, 37 s from
    // 2017-01-01; TT - TAI = 32.184 s.
    EXPECT_DOUBLE_EQ(TtMinusUtc_s(At("1972-01-01T00:00:00Z")), 42.184);
    EXPECT_DOUBLE_EQ(TtMinusUtc_s(At("1992-06-30T23:59:59Z")), 58.184);
    EXPECT_DOUBLE_EQ(TtMinusUtc_s(At("1992-10-13T00:00:00Z")), 59.184);
    EXPECT_DOUBLE_EQ(TtMinusUtc_s(At("2026-06-21T00:00:00Z")), 69.184);
}

TEST(Ephemeris, SunMatchesMeeusExample25a) {
    // Meeus Example 25.a, 1992 Oct 13.0 TD (JDE 2448908.5): apparent RA 198.38083 deg,
    // Dec -7.78507 deg, R = 0.99766 AU (that example's low-accuracy method is good to 0.01 deg;
    // the VSOP87 result of Example 25.b, 198.378121 / -7.783817, lies within 0.003 deg).
    const EquatorialPosition s = SunApparentGeocentric(2448908.5);
    EXPECT_NEAR(Deg(s.rightAscension_rad), 198.38083, 0.005);
    EXPECT_NEAR(Deg(s.declination_rad), -7.78507, 0.005);
    EXPECT_NEAR(s.distance_m / 149597870700.0, 0.99766, 1e-4);
    // Example 25.b (VSOP87 series, as libnova uses): tighter, R = 0.99760775 AU.
    EXPECT_NEAR(s.distance_m / 149597870700.0, 0.99760775, 2e-6);
    EXPECT_NEAR(Deg(s.rightAscension_rad), 198.378121, 0.0005);
    EXPECT_NEAR(Deg(s.declination_rad), -7.783817, 0.0005);
}

TEST(Ephemeris, MoonMatchesMeeusExample47a) {
    // Meeus Example 47.a, 1992 April 12 0h TD (JDE 2448724.5): geometric lambda 133.162655,
    // Delta-psi +0.004610 so apparent lambda 133.167265; beta -3.229126; distance 368409.7 km;
    // apparent RA 134.688470, Dec 13.768368 (Meeus's abridged series is good to ~10").
    const EquatorialPosition m = MoonApparentGeocentric(2448724.5);
    EXPECT_NEAR(Deg(m.eclipticLongitude_rad), 133.162655 + 0.004610, 0.003);
    EXPECT_NEAR(Deg(m.eclipticLatitude_rad), -3.229126, 0.003);
    EXPECT_NEAR(m.distance_m / 1000.0, 368409.7, 10.0);
    EXPECT_NEAR(Deg(m.rightAscension_rad), 134.688470, 0.003);
    EXPECT_NEAR(Deg(m.declination_rad), 13.768368, 0.003);
}

TEST(Ephemeris, MoonPhaseMatchesMeeusExample48a) {
    // Meeus Example 48.a, 1992 April 12 0h TD = 1992-04-11 23:59:01.816 UTC (TT-UTC 58.184 s):
    // phase angle i = 69.0756 deg, k = 0.6786, bright-limb position angle chi = 285.0 deg.
    const UtcTime t = At("1992-04-11T23:59:01.816Z");
    EXPECT_NEAR(JulianEphemerisDay(t), 2448724.5, 1e-7);
    const LunarPhase p = MoonPhase(t, Observer{});
    EXPECT_NEAR(Deg(p.phaseAngle_rad), 69.0756, 0.01);
    EXPECT_NEAR(p.illuminatedFraction, 0.6786, 0.0005);
    EXPECT_NEAR(Deg(p.brightLimbPositionAngle_rad), 285.0, 0.1);
}

TEST(Ephemeris, HorizontalMatchesMeeusExample13b) {
    // Meeus Example 13.b: Venus at USNO Washington (38 deg 55' 17" N, 77 deg 03' 56" W) on
    // 1987 April 10 19:21:00 UT, apparent RA 23h09m16.641s, Dec -6 deg 43' 11.61": azimuth
    // 68.0337 deg west of south (248.0337 from north), altitude 15.1249 deg (no parallax,
    // no refraction; the body is placed far away and the air removed).
    EquatorialPosition venus;
    venus.rightAscension_rad = (23.0 + 9.0 / 60.0 + 16.641 / 3600.0) * 15.0 * kDeg;
    venus.declination_rad = -(6.0 + 43.0 / 60.0 + 11.61 / 3600.0) * kDeg;
    venus.distance_m = 1e20;
    Observer usno{38.0 + 55.0 / 60.0 + 17.0 / 3600.0, -(77.0 + 3.0 / 60.0 + 56.0 / 3600.0), 0.0};
    usno.pressure_hPa = 0.0;
    const CelestialPosition p = HorizontalPosition(venus, At("1987-04-10T19:21:00Z"), usno);
    EXPECT_NEAR(Deg(p.azimuth_rad), 248.0337, 0.002);
    EXPECT_NEAR(Deg(p.altitudeGeometric_rad), 15.1249, 0.002);
    EXPECT_DOUBLE_EQ(p.altitude_rad, p.altitudeGeometric_rad);
    EXPECT_NEAR(glm::length(p.direction), 1.0, 1e-12);
    // ENU direction agrees with azimuth (from north through east) and altitude.
    EXPECT_NEAR(p.direction.x, std::cos(p.altitude_rad) * std::sin(p.azimuth_rad), 1e-12);
    EXPECT_NEAR(p.direction.z, std::sin(p.altitude_rad), 1e-12);
}

TEST(Ephemeris, MoonParallaxLowersAltitudeByHorizontalParallax) {
    // Diurnal parallax: topocentric altitude = geocentric altitude - pi cos h to first order
    // (Meeus ch. 40), pi = asin(a / distance) ~ 0.95 deg; it must be applied for 0.05 deg.
    const Observer obs{0.0, 0.0, 0.0, 0.0, 10.0};
    const UtcTime t = At("2026-03-10T06:00:00Z");
    const EquatorialPosition g = MoonApparentGeocentric(JulianEphemerisDay(t));
    EquatorialPosition far = g;
    far.distance_m = 1e20;
    const CelestialPosition topo = HorizontalPosition(g, t, obs);
    const CelestialPosition geo = HorizontalPosition(far, t, obs);
    const double pi = std::asin(6378137.0 / g.distance_m);
    EXPECT_GT(pi, 0.88 * kDeg);  // the moon's horizontal parallax is 0.90-1.01 deg
    EXPECT_NEAR(geo.altitudeGeometric_rad - topo.altitudeGeometric_rad,
                pi * std::cos(geo.altitudeGeometric_rad), 0.01 * kDeg);
    EXPECT_NEAR(topo.distance_m, g.distance_m - 6378137.0 * std::sin(geo.altitudeGeometric_rad),
                30e3);
}

TEST(Ephemeris, RefractionAgreesWithBennettAndIsContinuous) {
    // Bennett (J. Navigation 35, 255, 1982; Meeus eq. 16.3) gives refraction from the apparent
    // altitude h0: R = 1' / tan(h0 + 7.31/(h0 + 4.4)). Saemundsson's inverse agrees to ~0.1'.
    for (double h = 0.0; h < 89.0; h += 2.5) {
        const double app_deg = Deg(ApparentAltitude_rad(h * kDeg, 1010.0, 10.0));
        const double bennett_arcmin = 1.0 / std::tan((app_deg + 7.31 / (app_deg + 4.4)) * kDeg);
        EXPECT_NEAR((app_deg - h) * 60.0, bennett_arcmin, 0.1) << "h = " << h;
    }
    // Standard horizontal refraction is about 34' (Meeus ch. 16): apparent 0 for h ~ -0.57.
    EXPECT_NEAR(Deg(ApparentAltitude_rad(-34.5 / 60.0 * kDeg, 1010.0, 10.0)), 0.0, 0.05);
    // Continuous and monotonic across the -1 deg and -2 deg joins, zero well below.
    for (double edge : {-1.0, -2.0}) {
        const double lo = ApparentAltitude_rad((edge - 1e-9) * kDeg, 1010.0, 10.0);
        const double hi = ApparentAltitude_rad((edge + 1e-9) * kDeg, 1010.0, 10.0);
        EXPECT_NEAR(lo, hi, 1e-8);
    }
    double previous = -1e9;
    for (double h = -5.0; h <= 90.0; h += 0.01) {
        const double a = ApparentAltitude_rad(h * kDeg, 1010.0, 10.0);
        EXPECT_GT(a, previous);
        previous = a;
    }
    EXPECT_DOUBLE_EQ(ApparentAltitude_rad(-3.0 * kDeg, 1010.0, 10.0), -3.0 * kDeg);
    EXPECT_NEAR(ApparentAltitude_rad(90.0 * kDeg, 1010.0, 10.0), 90.0 * kDeg, 1e-6);
}

struct UsnoDay {
    const char* place;
    double lat_deg, lon_deg;
    // USNO Astronomical Applications "Sun and Moon Data for One Day", 2002 March 20, EST
    // (UTC-5), as quoted at http://stevekluge.com/astronomy/equinoxsunrise.html; minutes
    // after local midnight, rounded by USNO to the minute.
    double civilDawn, rise, transit, set, civilDusk;
};

TEST(Ephemeris, SunEventsMatchUsnoAlmanac) {
    const UsnoDay days[] = {
        {"Washington DC", 38.9, -77.0, 5 * 60 + 45, 6 * 60 + 12, 12 * 60 + 16, 18 * 60 + 21,
         18 * 60 + 47},
        {"Cape May NJ", 38.9, -74.9, 5 * 60 + 37, 6 * 60 + 4, 12 * 60 + 7, 18 * 60 + 12,
         18 * 60 + 39},
    };
    const UtcTime localMidnight = At("2002-03-20T05:00:00Z");
    for (const UsnoDay& d : days) {
        const SunEvents e = SunEventsInDay(localMidnight, Observer{d.lat_deg, d.lon_deg, 0.0});
        ASSERT_TRUE(e.civilDawn && e.rise && e.transit && e.set && e.civilDusk) << d.place;
        // Target <= 1 min plus up to 0.5 min from USNO's rounding to the minute.
        EXPECT_NEAR(Minutes(*e.civilDawn, localMidnight), d.civilDawn, 1.5) << d.place;
        EXPECT_NEAR(Minutes(*e.rise, localMidnight), d.rise, 1.5) << d.place;
        EXPECT_NEAR(Minutes(*e.transit, localMidnight), d.transit, 1.5) << d.place;
        EXPECT_NEAR(Minutes(*e.set, localMidnight), d.set, 1.5) << d.place;
        EXPECT_NEAR(Minutes(*e.civilDusk, localMidnight), d.civilDusk, 1.5) << d.place;
    }
}

TEST(Ephemeris, SunEventsAreConsistentAndOrdered) {
    // Washington DC at the June solstice 2026, local (EDT, UTC-4) day.
    const Observer dc{38.8895, -77.0353, 0.0};
    const UtcTime start = At("2026-06-21T04:00:00Z");
    const SunEvents e = SunEventsInDay(start, dc);
    ASSERT_TRUE(e.astronomicalDawn && e.nauticalDawn && e.civilDawn && e.rise && e.transit &&
                e.set && e.civilDusk && e.nauticalDusk && e.astronomicalDusk);
    EXPECT_FALSE(e.upAllDay);
    EXPECT_FALSE(e.downAllDay);
    const UtcTime order[] = {*e.astronomicalDawn, *e.nauticalDawn, *e.civilDawn, *e.rise,
                             *e.transit,          *e.set,          *e.civilDusk, *e.nauticalDusk,
                             *e.astronomicalDusk};
    for (size_t i = 0; i + 1 < std::size(order); ++i) EXPECT_LT(order[i], order[i + 1]) << i;
    // The events sit at their defining geometric altitudes (Meeus ch. 15).
    auto geometric = [&](UtcTime t) { return Deg(SunPosition(t, dc).altitudeGeometric_rad); };
    EXPECT_NEAR(geometric(*e.rise), -0.8333, 0.01);
    EXPECT_NEAR(geometric(*e.set), -0.8333, 0.01);
    EXPECT_NEAR(geometric(*e.civilDawn), -6.0, 0.01);
    EXPECT_NEAR(geometric(*e.nauticalDusk), -12.0, 0.01);
    EXPECT_NEAR(geometric(*e.astronomicalDawn), -18.0, 0.01);
    // At sunrise the refracted centre is about 16' (one semidiameter) below the horizon.
    EXPECT_NEAR(Deg(SunPosition(*e.rise, dc).altitude_rad), -16.0 / 60.0, 0.1);
    // Transit: the sun is due south and at its highest, 90 - lat + dec ~ 74.5 deg.
    const CelestialPosition noon = SunPosition(*e.transit, dc);
    EXPECT_NEAR(Deg(noon.azimuth_rad), 180.0, 0.01);
    EXPECT_NEAR(Deg(noon.altitudeGeometric_rad), 90.0 - 38.8895 + 23.44, 0.05);
    // Solstice day length at 38.9 N is about 14 h 54 min (almanac tables; cos H0 relation).
    EXPECT_NEAR(Minutes(*e.set, *e.rise), 14 * 60 + 54, 3.0);
}

TEST(Ephemeris, PolarDayAndNightHaveNoSunriseOrSunset) {
    const Observer tromso{69.65, 18.96, 0.0};
    const SunEvents summer = SunEventsInDay(At("2026-06-21T00:00:00Z"), tromso);
    EXPECT_FALSE(summer.rise);
    EXPECT_FALSE(summer.set);
    EXPECT_FALSE(summer.civilDusk);
    EXPECT_TRUE(summer.upAllDay);
    EXPECT_FALSE(summer.downAllDay);
    EXPECT_TRUE(summer.transit);
    const SunEvents winter = SunEventsInDay(At("2026-12-21T00:00:00Z"), tromso);
    EXPECT_FALSE(winter.rise);
    EXPECT_FALSE(winter.set);
    EXPECT_TRUE(winter.downAllDay);
    // The sun reaches about -3 deg at noon: civil twilight still begins and ends.
    EXPECT_TRUE(winter.civilDawn);
    EXPECT_TRUE(winter.civilDusk);
}

TEST(Ephemeris, MoonRisesOncePerLunarDay) {
    // The moon rises on average every 24 h 50 min, so in 30 consecutive days it rises 28 or
    // 29 times and one or two days have no moonrise (nullopt).
    const Observer dc{38.8895, -77.0353, 0.0};
    const UtcTime start = At("2026-01-01T05:00:00Z");
    int rises = 0;
    for (int day = 0; day < 30; ++day) {
        const MoonEvents e = MoonEventsInDay(start.PlusSeconds(day * 86400.0), dc);
        if (!e.rise) continue;
        ++rises;
        // At moonrise the geocentric altitude is Meeus's h0 = 0.7275 pi - 34' (ch. 15).
        const EquatorialPosition g = MoonApparentGeocentric(JulianEphemerisDay(*e.rise));
        EquatorialPosition far = g;
        far.distance_m = 1e20;
        const double pi_deg = Deg(std::asin(6378137.0 / g.distance_m));
        EXPECT_NEAR(Deg(HorizontalPosition(far, *e.rise, dc).altitudeGeometric_rad),
                    0.7275 * pi_deg - 34.0 / 60.0, 0.02);
        // Rising: the moon is in the eastern half of the sky.
        EXPECT_LT(Deg(MoonPosition(*e.rise, dc).azimuth_rad), 180.0);
    }
    EXPECT_GE(rises, 28);
    EXPECT_LE(rises, 29);
}

TEST(Ephemeris, RejectsBadObserver) {
    const UtcTime t = At("2026-06-21T00:00:00Z");
    EXPECT_THROW(SunPosition(t, Observer{91.0, 0.0, 0.0}), InputError);
    EXPECT_THROW(MoonPosition(t, Observer{0.0, std::nan(""), 0.0}), InputError);
    Observer cold{0.0, 0.0, 0.0};
    cold.temperature_C = -300.0;
    EXPECT_THROW(SunEventsInDay(t, cold), InputError);
}

}  // namespace
}  // namespace seasense::scene
