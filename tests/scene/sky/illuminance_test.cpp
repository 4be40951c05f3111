// Natural illuminance against published typical values (physics.md, USNO/IES) and physical laws.
#include "scene/sky/illuminance.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "scene/core/error.h"

namespace seasense::scene {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kMeanMoonDistance_m = 384400e3;  // IAU mean Earth-moon distance

UtcTime At(const std::string& iso) {
    const auto t = ParseIso8601(iso);
    EXPECT_TRUE(t.has_value()) << iso;
    return t.value_or(UtcTime{});
}

TEST(Illuminance, SunAtZenithIsAboutOneHundredTwentyFiveKilolux) {
    // Published clear-sky value for the sun at the zenith: 1.2-1.3e5 lx (physics.md).
    const double e = SunIlluminance_lux(90.0 * kDeg);
    EXPECT_GE(e, 1.2e5);
    EXPECT_LE(e, 1.3e5);
}

TEST(Illuminance, SunOnHorizonAndAtCivilTwilightEnd) {
    // USNO/IES: about 700 lx with the sun on the horizon (700-1000 lx); about 3 lx when the
    // sun is 6 deg down, the end of civil twilight (1-6 lx).
    const double horizon = SunIlluminance_lux(0.0);
    EXPECT_GE(horizon, 700.0);
    EXPECT_LE(horizon, 1000.0);
    const double civilEnd = SunIlluminance_lux(-6.0 * kDeg);
    EXPECT_GE(civilEnd, 1.0);
    EXPECT_LE(civilEnd, 6.0);
    // Below -18 deg the sun contributes nothing (astronomical night).
    EXPECT_EQ(SunIlluminance_lux(-18.5 * kDeg), 0.0);
    EXPECT_EQ(SunIlluminance_lux(-90.0 * kDeg), 0.0);
}

TEST(Illuminance, SunFollowsInverseSquareOfDistance) {
    // Perihelion 0.98329 au, aphelion 1.01671 au: 6.9 % more light in January than in July.
    constexpr double au = 1.495978707e11;
    const double ratio = SunIlluminance_lux(40.0 * kDeg, 0.98329 * au) /
                         SunIlluminance_lux(40.0 * kDeg, 1.01671 * au);
    EXPECT_NEAR(ratio, std::pow(1.01671 / 0.98329, 2.0), 1e-12);
}

// Sweep an illuminance function of altitude: it must never fall as the body rises, except
// for the published fit's own steps where its pieces join (each under 2 %).
template <typename F>
void ExpectRisesWithAltitude(F illuminance, double from_deg, double to_deg) {
    double previous = illuminance(from_deg * kDeg);
    int steps = 0;
    for (double h = from_deg + 0.01; h <= to_deg; h += 0.01) {
        const double e = illuminance(h * kDeg);
        EXPECT_GE(e, 0.98 * previous) << "altitude " << h << " deg";
        if (e < previous) ++steps;
        previous = e;
    }
    // Only the joins (at most one downward step per join) may go down.
    EXPECT_LE(steps, 3);
}

TEST(Illuminance, SunRisesMonotonicallyWithAltitude) {
    ExpectRisesWithAltitude([](double h) { return SunIlluminance_lux(h); }, -18.0, 90.0);
    // Over the whole range the increase spans about 8 decades (6e-4 lx to 1.3e5 lx).
    EXPECT_GT(SunIlluminance_lux(90.0 * kDeg) / SunIlluminance_lux(-17.99 * kDeg), 1e7);
}

TEST(Illuminance, MoonRisesMonotonicallyWithAltitude) {
    ExpectRisesWithAltitude(
        [](double h) { return MoonIlluminance_lux(h, 0.0, kMeanMoonDistance_m); }, -0.8, 90.0);
    EXPECT_EQ(MoonIlluminance_lux(-1.0 * kDeg, 0.0, kMeanMoonDistance_m), 0.0);
}

TEST(Illuminance, FullMoonHighIsAFewTenthsOfALux) {
    // Full moon high in a clear sky: 0.1-0.3 lx (physics.md).
    for (double h : {50.0, 60.0, 75.0, 90.0}) {
        const double e = MoonIlluminance_lux(h * kDeg, 0.0, kMeanMoonDistance_m);
        EXPECT_GE(e, 0.1) << h;
        EXPECT_LE(e, 0.3) << h;
    }
}

TEST(Illuminance, QuarterMoonIsAboutOneHundredthOfALux) {
    // Quarter moon (phase angle 90 deg): about 0.01 lx (order of magnitude: 0.005-0.03 lx).
    for (double h : {30.0, 45.0, 60.0}) {
        const double e = MoonIlluminance_lux(h * kDeg, 90.0 * kDeg, kMeanMoonDistance_m);
        EXPECT_GE(e, 0.005) << h;
        EXPECT_LE(e, 0.03) << h;
    }
    // A quarter moon gives roughly a tenth of full moon's light (not half: opposition surge
    // and shadowing make the full moon disproportionately bright; Allen's phase law).
    const double ratio = MoonIlluminance_lux(45.0 * kDeg, 90.0 * kDeg, kMeanMoonDistance_m) /
                         MoonIlluminance_lux(45.0 * kDeg, 0.0, kMeanMoonDistance_m);
    EXPECT_GT(ratio, 0.07);
    EXPECT_LT(ratio, 0.15);
    // New moon is darker still.
    EXPECT_LT(MoonIlluminance_lux(45.0 * kDeg, 170.0 * kDeg, kMeanMoonDistance_m),
              MoonIlluminance_lux(45.0 * kDeg, 150.0 * kDeg, kMeanMoonDistance_m));
}

TEST(Illuminance, MoonFollowsInverseSquareOfDistance) {
    // A perigee moon (356 500 km) against an apogee moon (406 700 km): (406.7/356.5)^2 = 1.30.
    const double perigee = MoonIlluminance_lux(50.0 * kDeg, 0.0, 356500e3);
    const double apogee = MoonIlluminance_lux(50.0 * kDeg, 0.0, 406700e3);
    const double expected = std::pow(406700.0 / 356500.0, 2.0);
    EXPECT_NEAR(perigee / apogee, expected, 1e-3 * expected);
    EXPECT_GT(perigee / apogee, 1.28);
    EXPECT_LT(perigee / apogee, 1.32);
}

TEST(Illuminance, NightSkyFloorClearAndOvercast) {
    // Clear starlight with airglow 1-2e-3 lx; overcast starlight about 1e-4 lx (physics.md).
    EXPECT_GE(NightSkyIlluminance_lux(), 1e-3);
    EXPECT_LE(NightSkyIlluminance_lux(), 2e-3);

    // New moon 2024-02-09 22:59 UTC (USNO phases): local midnight near 15 deg E has the sun
    // far below -18 deg and the moon, beside the sun, below the horizon.
    const Observer observer{.latitude_deg = 0.0, .longitude_deg = 15.0};
    const UtcTime t = At("2024-02-09T23:00:00Z");
    const Illuminance clear = NaturalIlluminance(t, observer);
    EXPECT_EQ(clear.sun_lux, 0.0);
    EXPECT_EQ(clear.moon_lux, 0.0);
    EXPECT_EQ(clear.twilight, TwilightState::Night);
    EXPECT_GE(clear.total_lux, 1e-3);
    EXPECT_LE(clear.total_lux, 2e-3);

    const Illuminance overcast = NaturalIlluminance(t, observer, kDarkStratusDivisor);
    EXPECT_GE(overcast.total_lux, 0.5e-4);
    EXPECT_LE(overcast.total_lux, 2e-4);
    EXPECT_NEAR(overcast.total_lux * 10.0, clear.total_lux, 1e-15);
}

TEST(Illuminance, FullMoonNightFromTheEphemeris) {
    // Full moon 2024-01-25 17:54 UTC (USNO phases), declination about +20 deg: at 90 deg E the
    // local time is near midnight and at 25 deg N the moon stands near the zenith.
    const Observer observer{.latitude_deg = 25.0, .longitude_deg = 90.0};
    const Illuminance e = NaturalIlluminance(At("2024-01-25T18:00:00Z"), observer);
    EXPECT_EQ(e.sun_lux, 0.0);
    EXPECT_EQ(e.twilight, TwilightState::Night);
    EXPECT_GE(e.moon_lux, 0.1);
    EXPECT_LE(e.moon_lux, 0.3);
    EXPECT_DOUBLE_EQ(e.total_lux, e.sun_lux + e.moon_lux + e.sky_lux);
}

TEST(Illuminance, SolsticeNoonOnTheTropicFromTheEphemeris) {
    // June solstice 2024-06-20 20:51 UTC: at 12:00 UTC on the Tropic of Cancer at 0 deg E the
    // sun is within a degree of the zenith (equation of time is -1.7 min).
    const Observer observer{.latitude_deg = 23.44, .longitude_deg = 0.0};
    const Illuminance e = NaturalIlluminance(At("2024-06-20T12:00:00Z"), observer);
    EXPECT_EQ(e.twilight, TwilightState::Day);
    EXPECT_GE(e.sun_lux, 1.2e5);
    EXPECT_LE(e.sun_lux, 1.3e5);
    // The sky-condition divisor divides every term (Circular 171).
    const Illuminance stratus = NaturalIlluminance(At("2024-06-20T12:00:00Z"), observer, 10.0);
    EXPECT_NEAR(stratus.sun_lux * 10.0, e.sun_lux, 1e-9 * e.sun_lux);
}

TEST(Illuminance, TwilightStatesFollowTheSixDegreeBands) {
    // Civil 0-6 deg, nautical 6-12 deg, astronomical 12-18 deg below the horizon.
    EXPECT_EQ(TwilightFromSunAltitude(10.0 * kDeg), TwilightState::Day);
    EXPECT_EQ(TwilightFromSunAltitude(-3.0 * kDeg), TwilightState::Civil);
    EXPECT_EQ(TwilightFromSunAltitude(-9.0 * kDeg), TwilightState::Nautical);
    EXPECT_EQ(TwilightFromSunAltitude(-15.0 * kDeg), TwilightState::Astronomical);
    EXPECT_EQ(TwilightFromSunAltitude(-20.0 * kDeg), TwilightState::Night);
    EXPECT_EQ(ToString(TwilightState::Day), "day");
    EXPECT_EQ(ToString(TwilightState::Civil), "civil");
    EXPECT_EQ(ToString(TwilightState::Nautical), "nautical");
    EXPECT_EQ(ToString(TwilightState::Astronomical), "astronomical");
    EXPECT_EQ(ToString(TwilightState::Night), "night");
}

TEST(Illuminance, RejectsBadInput) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW(SunIlluminance_lux(nan), InputError);
    EXPECT_THROW(SunIlluminance_lux(2.0), InputError);
    EXPECT_THROW(SunIlluminance_lux(0.5, 0.0), InputError);
    EXPECT_THROW(MoonIlluminance_lux(0.5, -0.1, kMeanMoonDistance_m), InputError);
    EXPECT_THROW(MoonIlluminance_lux(0.5, 4.0, kMeanMoonDistance_m), InputError);
    EXPECT_THROW(MoonIlluminance_lux(0.5, 0.0, 1000.0), InputError);
    EXPECT_THROW(TwilightFromSunAltitude(nan), InputError);
    const Observer observer{};
    const UtcTime t = At("2024-01-01T00:00:00Z");
    EXPECT_THROW(NaturalIlluminance(t, observer, 0.5), InputError);
    EXPECT_THROW(NaturalIlluminance(t, observer, 11.0), InputError);
    EXPECT_THROW(NaturalIlluminance(t, observer, nan), InputError);
}

TEST(DirectSun, KastenYoungAirMassAtZenithAndHorizon) {
    // Kasten & Young (1989) tabulate the air mass of the ISO standard atmosphere, 1.0 at the
    // zenith and 38.0868 at the horizon; their fit is within 0.5 % of the table there. Down
    // to 60° zenith distance the air mass is sec z within 1 % (plane-parallel atmosphere).
    EXPECT_NEAR(RelativeAirMass(M_PI / 2), 1.0, 5e-4);
    EXPECT_NEAR(RelativeAirMass(0.0), 38.0868, 0.005 * 38.0868);
    for (double alt_deg : {90.0, 60.0, 45.0, 30.0})
        EXPECT_NEAR(RelativeAirMass(alt_deg * M_PI / 180) * std::sin(alt_deg * M_PI / 180), 1.0,
                    0.01)
            << alt_deg;
    EXPECT_THROW(RelativeAirMass(std::nan("")), InputError);
}

TEST(DirectSun, ExtinctionFollowsBeerLambertAndTheDiscSets) {
    const double au = 1.495978707e11;
    // No turbidity: the luminous solar constant reaches the ground (Darula et al. 2005).
    EXPECT_NEAR(DirectNormalSunIlluminance_lux(M_PI / 2, au, 0.0), 133800.0, 1e-6);
    // ln E is linear in the turbidity factor: doubling T squares the transmittance.
    const double e1 = DirectNormalSunIlluminance_lux(0.5, au, 2.0) / 133800.0;
    const double e2 = DirectNormalSunIlluminance_lux(0.5, au, 4.0) / 133800.0;
    EXPECT_NEAR(e2, e1 * e1, 1e-12);
    // Clear-sky direct-normal illuminance of a high sun is of order 1e5 lx (IES handbook
    // range 80–110 klx); at 3° it is a few klx at most.
    const double high = DirectNormalSunIlluminance_lux(60 * M_PI / 180, au, 3.0);
    EXPECT_GT(high, 80000.0);
    EXPECT_LT(high, 110000.0);
    EXPECT_LT(DirectNormalSunIlluminance_lux(3 * M_PI / 180, au, 3.0), 5000.0);
    // Below the horizon by more than the disc radius: set.
    EXPECT_EQ(DirectNormalSunIlluminance_lux(-0.3 * M_PI / 180, au, 3.0), 0.0);
    EXPECT_GT(DirectNormalSunIlluminance_lux(-0.2 * M_PI / 180, au, 3.0), 0.0);
}

}  // namespace
}  // namespace seasense::scene
