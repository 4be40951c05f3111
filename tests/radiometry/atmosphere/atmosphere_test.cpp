// Tests of the clear-sky and path model: Kirchhoff's isothermal limit, τ limits, Koschmieder's
// definition of visibility, Beer–Lambert, the LOWTRAN form of the water continuum, monotone sky.
#include "radiometry/atmosphere/atmosphere.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "radiometry/planck/planck.h"
#include "scene/config/config.h"
#include "scene/core/error.h"

namespace seasense::radiometry {
namespace {

TEST(ApertureRadiance, IsothermalSceneGivesTheAirBlackbodyForAnyTauAndEmissivity) {
    // Kirchhoff: in an isothermal enclosure every path and surface radiates B(T).
    const double b = BandRadiance(Band::Lwir(), 290.0);
    for (double tau : {0.0, 0.1, 0.5, 0.93, 1.0})
        for (double eps : {0.0, 0.3, 0.98, 1.0})
            EXPECT_NEAR(ApertureRadiance(tau, eps, b, b, b), b, 1e-12 * b);
}

TEST(ApertureRadiance, TransmittanceLimits) {
    const double bT = 40.0, sky = 5.0, air = 30.0, eps = 0.9;
    EXPECT_DOUBLE_EQ(ApertureRadiance(1.0, eps, bT, sky, air), eps * bT + (1 - eps) * sky);
    EXPECT_DOUBLE_EQ(ApertureRadiance(0.0, eps, bT, sky, air), air);
}

TEST(Atmosphere, BoltonAndBrutsaertPublishedValues) {
    // Saturation vapour pressure 6.112 hPa at 0 °C and 23.4 hPa at 20 °C (Bolton 1980; WMO).
    EXPECT_NEAR(SaturationVapourPressure_Pa(273.15), 611.2, 1e-9);
    EXPECT_NEAR(SaturationVapourPressure_Pa(293.15), 2339.0, 5.0);
    // Brutsaert (1975): clear-sky emissivities of mid-latitude air lie near 0.7–0.85.
    EXPECT_NEAR(BrutsaertEmissivity(1000.0, 283.15), 1.24 * std::pow(10.0 / 283.15, 1.0 / 7.0),
                1e-12);
    EXPECT_GT(BrutsaertEmissivity(1000.0, 283.15), 0.7);
    EXPECT_LT(BrutsaertEmissivity(1000.0, 283.15), 0.85);
}

TEST(Atmosphere, KruseKimExponent) {
    EXPECT_EQ(KruseKimExponent(60e3), 1.6);
    EXPECT_EQ(KruseKimExponent(20e3), 1.3);
    EXPECT_NEAR(KruseKimExponent(3e3), 0.16 * 3 + 0.34, 1e-12);
    EXPECT_NEAR(KruseKimExponent(0.7e3), 0.2, 1e-12);
    EXPECT_EQ(KruseKimExponent(0.3e3), 0.0);
}

TEST(Atmosphere, WaterContinuumMatchesTheLowtranMassForm) {
    // LOWTRAN's form of the same fit: C_s = 4.18 + 5578 exp(−7.87e-3 ν) cm² g⁻¹ atm⁻¹ at 296 K
    // (Kneizys et al. 1980, AFGL-TR-80-0067), times the water mass density and broadening
    // pressure. Avogadro 6.02214076e23 and M_w = 18.015 g/mol convert molecules to grams.
    const double T = 296.0, e = 2000.0, P = 101325.0, lambda = 10.0e-6, nu = 1000.0;
    const double cs = 4.18 + 5578.0 * std::exp(-7.87e-3 * nu);
    const double rho_g_cm3 = e * 18.015e-3 / (8.314462618 * T) * 1e-3;
    const double expected_per_m = cs * rho_g_cm3 * (e + 0.002 * (P - e)) / P * 100.0;
    EXPECT_NEAR(WaterContinuumAbsorption_per_m(lambda, T, e, P), expected_per_m,
                2e-3 * expected_per_m);
    EXPECT_EQ(WaterContinuumAbsorption_per_m(4e-6, T, e, P), 0.0);
}

TEST(Atmosphere, VisibleTransmittanceAtTheVisibilityIsTwoPercent) {
    // Koschmieder: the meteorological range is where contrast falls to 2 % (physics.md).
    const Band green = Band::Flat("green", 0.549e-6, 0.551e-6);
    for (double v : {500.0, 5000.0, 30000.0}) {
        const Atmosphere atm(green, AtmosphereSettings{}, v);
        EXPECT_NEAR(atm.Transmittance(v), 0.02, 0.0005) << v;
    }
}

TEST(Atmosphere, NarrowBandObeysBeerLambert) {
    const Band line = Band::Flat("10um", 10.0e-6, 10.001e-6);
    const Atmosphere atm(line, AtmosphereSettings{}, 10000.0);
    EXPECT_NEAR(atm.Transmittance(0.0), 1.0, 1e-12);
    for (double r : {100.0, 2000.0, 15000.0})
        EXPECT_NEAR(atm.Transmittance(2 * r), atm.Transmittance(r) * atm.Transmittance(r), 1e-6);
}

TEST(Atmosphere, SkyIsColdAtZenithWarmAtHorizonAndMonotone) {
    for (const Band& band : {Band::Lwir(), Band::Mwir()}) {
        const Atmosphere atm(band, AtmosphereSettings{}, 20000.0);
        double previous = atm.SkyRadiance(1.0);
        EXPECT_LT(previous, 0.8 * atm.AirRadiance()) << band.Name();
        for (double c = 0.98; c > 0.0; c -= 0.02) {
            const double l = atm.SkyRadiance(c);
            EXPECT_GT(l, previous) << band.Name() << " cos " << c;
            EXPECT_LE(l, atm.AirRadiance());
            previous = l;
        }
        EXPECT_NEAR(atm.SkyRadiance(1e-4), atm.AirRadiance(), 1e-6 * atm.AirRadiance());
        EXPECT_EQ(atm.SkyRadiance(-0.3), atm.AirRadiance());
    }
}

TEST(Atmosphere, HumidityWarmsTheSkyAndDimsThePath) {
    AtmosphereSettings dry, humid;
    dry.relativeHumidity = 0.2;
    humid.relativeHumidity = 0.95;
    const Atmosphere a(Band::Lwir(), dry, 20000.0), b(Band::Lwir(), humid, 20000.0);
    EXPECT_LT(a.SkyRadiance(1.0), b.SkyRadiance(1.0));
    EXPECT_GT(a.Transmittance(5000.0), b.Transmittance(5000.0));
    EXPECT_LT(a.SkyLongwaveIrradiance_W_m2(), b.SkyLongwaveIrradiance_W_m2());
}

TEST(Atmosphere, PathRadianceAndFogLimit) {
    const Atmosphere fog(Band::Lwir(), AtmosphereSettings{}, 100.0);
    EXPECT_NEAR(fog.Transmittance(2000.0), 0.0, 1e-9);
    EXPECT_NEAR(fog.PathRadiance(2000.0), fog.AirRadiance(), 1e-9 * fog.AirRadiance());
    EXPECT_NEAR(fog.SkyRadiance(1.0), fog.AirRadiance(), 1e-6 * fog.AirRadiance());
    EXPECT_NEAR(fog.PathRadiance(0.0), 0.0, 1e-12 * fog.AirRadiance());
}

TEST(Atmosphere, LookUpTablesMatchTheExactSums) {
    const Atmosphere atm(Band::Lwir(), AtmosphereSettings{}, 8000.0);
    for (float c = 0.0f; c <= 1.0f; c += 0.0173f)
        EXPECT_NEAR(atm.SkyLookUp(c), atm.SkyRadiance(c), 1e-3 * atm.SkyRadiance(c)) << c;
    for (float r : {0.0f, 3.0f, 57.0f, 880.0f, 4321.0f, 25000.0f, 150000.0f})
        EXPECT_NEAR(atm.TransmittanceLookUp(r), atm.Transmittance(r),
                    1e-3 * atm.Transmittance(r) + 1e-7)
            << r;
    float cs[2] = {0.3f, 0.9f}, rs[2] = {10.0f, 1e4f}, out[2];
    atm.SkyLookUp(2, cs, out);
    EXPECT_EQ(out[1], atm.SkyLookUp(0.9f));
    atm.TransmittanceLookUp(2, rs, out);
    EXPECT_EQ(out[0], atm.TransmittanceLookUp(10.0f));
}

TEST(Atmosphere, RejectsBadInput) {
    AtmosphereSettings s;
    EXPECT_THROW(Atmosphere(Band::Lwir(), s, 0.0), InputError);
    s.relativeHumidity = 1.5;
    EXPECT_THROW(Atmosphere(Band::Lwir(), s, 1e4), InputError);
    EXPECT_THROW(Atmosphere(Band::Flat("far", 50e-6, 200e-6), AtmosphereSettings{}, 1e4),
                 InputError);
}

TEST(AtmosphereSettings, ParsesGoodAndNamesTheKeyOfBadInput) {
    const auto parse = [](const std::string& text) {
        const scene::ConfigDocument doc = scene::ParseConfigText(text, "air.yaml");
        return scene::ReadMap(doc.root, [](scene::ConfigMap& root) {
            return ParseAtmosphereSettings(root.Require("atmosphere", "a mapping"));
        });
    };
    const AtmosphereSettings s = parse(
        "atmosphere: {air_temperature_K: 300, relative_humidity: 0.5, pressure_Pa: 100000}\n");
    EXPECT_EQ(s.airTemperature_K, 300.0);
    EXPECT_EQ(s.relativeHumidity, 0.5);
    EXPECT_EQ(s.pressure_Pa, 100000.0);
    for (const char* bad :
         {"atmosphere: {relative_humidity: 75}\n", "atmosphere: {air_temperature_K: -3}\n",
          "atmosphere: {humidity: 0.5}\n"}) {
        try {
            parse(bad);
            ADD_FAILURE() << "no ConfigError for " << bad;
        } catch (const scene::ConfigError& e) {
            EXPECT_NE(std::string(e.what()).find("atmosphere."), std::string::npos) << e.what();
        }
    }
}

}  // namespace
}  // namespace seasense::radiometry
