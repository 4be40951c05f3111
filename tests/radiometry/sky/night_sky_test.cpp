// Night, moonlit and twilight sky against published illuminance and surface-brightness values.
#include "radiometry/sky/night_sky.h"

#include <gtest/gtest.h>

#include <cmath>

#include "radiometry/color/rec709.h"
#include "radiometry/sky/analytic_sky.h"
#include "scene/sky/illuminance.h"

namespace seasense::radiometry {
namespace {

constexpr double kDeg = M_PI / 180.0;

glm::dvec3 Toward(double azimuth_deg, double elevation_deg) {
    const double a = azimuth_deg * kDeg, e = elevation_deg * kDeg;
    return {std::cos(e) * std::sin(a), std::cos(e) * std::cos(a), std::sin(e)};
}

double HorizontalLuminance(const AnalyticSky& sky) {
    return LuminanceRec709(sky.HorizontalSkyIlluminance());
}

TEST(NightSky, DarkZenithIsTwentyOnePointSixMagnitudesPerSquareArcsecond) {
    // K&S 1991 quote 79.0 nL for Mauna Kea's dark V sky; Cinzano et al. 2001 take 21.6 mag/″²
    // for the natural night sky. Garstang's conversion links the two.
    EXPECT_NEAR(SurfaceBrightnessV_magPerArcsec2(DarkSkyLuminance_cdm2(0.0, 0.172)), 21.6, 0.05);
    // Toward the horizon more airglow layer is in view (van Rhijn): the sky brightens.
    EXPECT_GT(DarkSkyLuminance_cdm2(75 * kDeg, 0.172), 1.5 * DarkSkyLuminance_cdm2(0.0, 0.172));
}

TEST(NightSky, MoonlessNightIlluminanceIsTheCircular171Floor) {
    // The sun 30° down, no moon: the dome alone gives the clear starlight-and-airglow
    // illuminance of 1–2e-3 lx (physics.md; Circular 171).
    const AnalyticSky sky(Toward(0, -30), 0.0, 2.5);
    EXPECT_EQ(sky.DaylightScale(), 0.0);
    const double E = HorizontalLuminance(sky);
    EXPECT_GT(E, 0.7e-3);
    EXPECT_LT(E, 2.0e-3);
    EXPECT_NEAR(E / scene::NightSkyIlluminance_lux(), 1.0, 0.5);
}

TEST(NightSky, DaylightDomeHasTheIesClearSkyIlluminance) {
    // IES clear sky: 0.8 + 15.5 (sin h)^½ klx; the night terms add ~1e-3 lx.
    for (double h : {5.0, 20.0, 45.0, 70.0}) {
        const AnalyticSky sky(Toward(120, h), 1e5, 3.0);
        const double ies = 1e3 * (0.8 + 15.5 * std::sqrt(std::sin(h * kDeg)));
        EXPECT_NEAR(HorizontalLuminance(sky), ies, 1e-3 * ies) << h;
    }
}

TEST(NightSky, TwilightFollowsCircular171AndFallsMonotonically) {
    // Sun on the horizon: 800 lx (IES); end of civil twilight (−6°): Circular 171's 3.4 lx
    // times 800/759 (its own horizon value); by −18° the night sky dominates.
    const double e0 = HorizontalLuminance(AnalyticSky(Toward(250, 0), 0.0, 2.5));
    EXPECT_NEAR(e0, 800.0, 1.0);
    const double civil = HorizontalLuminance(AnalyticSky(Toward(250, -6), 0.0, 2.5));
    EXPECT_NEAR(civil,
                800.0 * scene::SunIlluminance_lux(-6 * kDeg) / scene::SunIlluminance_lux(0.0),
                0.01 * civil);
    EXPECT_GT(civil, 2.0);
    EXPECT_LT(civil, 6.0);
    double previous = 1e9;
    for (double h = 10.0; h >= -20.0; h -= 0.5) {
        const AnalyticSky sky(Toward(250, h), 0.0, 2.5);
        const double z = LuminanceRec709(sky.Radiance({0, 0, 1}));
        if (h < -18.0) {
            EXPECT_NEAR(z, DarkSkyLuminance_cdm2(0.0, 0.172), 1e-12);
        } else {
            EXPECT_LT(z, previous) << h;
        }
        previous = z;
    }
    // Twilight keeps its glow toward the sun's azimuth.
    const AnalyticSky dusk(Toward(250, -4), 0.0, 2.5);
    EXPECT_GT(LuminanceRec709(dusk.Radiance(Toward(250, 5))),
              1.5 * LuminanceRec709(dusk.Radiance(Toward(70, 5))));
}

TEST(NightSky, FullMoonLightIsOfThePublishedMagnitude) {
    // physics.md (Circular 171): full moon high ≈ 0.1–0.3 lx; quarter moon ≈ 0.01 lx.
    const double full =
        scene::DirectNormalMoonIlluminance_lux(60 * kDeg, 0.0, 3.844e8) * std::sin(60 * kDeg);
    EXPECT_GT(full, 0.1);
    EXPECT_LT(full, 0.3);
    const double quarter =
        scene::DirectNormalMoonIlluminance_lux(60 * kDeg, 90 * kDeg, 3.844e8) * std::sin(60 * kDeg);
    EXPECT_GT(quarter, 0.005);
    EXPECT_LT(quarter, 0.02);
    // Against Circular 171's own fit (diffuse included) within 30 %.
    EXPECT_NEAR(full / scene::MoonIlluminance_lux(60 * kDeg, 0.0, 3.844e8), 1.0, 0.3);
    EXPECT_EQ(scene::DirectNormalMoonIlluminance_lux(-1 * kDeg, 0.0, 3.844e8), 0.0);
}

TEST(NightSky, MoonlitSkyScattersLikeTheDaylightSky) {
    // The moonlit sky is sunlight's clear-sky scattering at 1/400 000 of the light: its dome
    // illuminance relative to the direct horizontal moonlight is the daylight diffuse/direct
    // ratio at the same altitude — IES diffuse 13.8 klx over ~66 klx direct at 45° ≈ 0.2 at sea
    // level, less for K&S's high-altitude extinction (k = 0.172). Accept 0.05–0.4.
    SkyConditions c;
    c.sunDirection = Toward(0, -40);
    c.darkZenithLuminance_cdm2 = 0.0;
    c.moon = true;
    c.moonDirection = Toward(180, 45);
    c.moonPhaseAngle_rad = 0.0;
    const AnalyticSky sky(c);
    const double diffuse = HorizontalLuminance(sky);
    const double direct =
        scene::DirectNormalMoonIlluminance_lux(45 * kDeg, 0.0, 3.844e8) * std::sin(45 * kDeg);
    RecordProperty("moonlit_diffuse_over_direct", std::to_string(diffuse / direct));
    EXPECT_GT(diffuse / direct, 0.05);
    EXPECT_LT(diffuse / direct, 0.4);
    // Brightest around the moon (aerosol forward scattering), darker opposite.
    EXPECT_GT(LuminanceRec709(sky.Radiance(Toward(180, 35))),
              2.0 * LuminanceRec709(sky.Radiance(Toward(0, 35))));
    // Proportional to the moon's brightness: a quarter moon scatters what its own light is
    // worth (the same Allen phase law in both).
    SkyConditions q = c;
    q.moonPhaseAngle_rad = 90 * kDeg;
    const double ratio = HorizontalLuminance(AnalyticSky(q)) / diffuse;
    EXPECT_NEAR(ratio,
                scene::DirectNormalMoonIlluminance_lux(45 * kDeg, 90 * kDeg, 3.844e8) /
                    scene::DirectNormalMoonIlluminance_lux(45 * kDeg, 0.0, 3.844e8),
                1e-3 * ratio);
    // A set moon lights nothing.
    q.moonDirection = Toward(180, -2);
    EXPECT_EQ(HorizontalLuminance(AnalyticSky(q)), 0.0);
}

}  // namespace
}  // namespace seasense::radiometry
