// Tests of sea-surface emissivity: Fresnel energy conservation with a complex index, limits,
// and the published behaviour of Masuda et al. (1988) and physics.md.
#include "radiometry/sea/sea_emissivity.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <complex>
#include <cstdint>
#include <numbers>
#include <string>
#include <vector>

#include "radiometry/sea/water_index.h"
#include "radiometry/surface/fresnel.h"
#include "scene/config/config.h"
#include "scene/core/error.h"

namespace seasense::radiometry {
namespace {

double CosDeg(double deg) { return std::cos(deg * std::numbers::pi / 180.0); }

// Fraction of the incident power carried into the absorbing half-space by the transmitted wave:
// normal component of the time-averaged Poynting vector (Born & Wolf §1.5.3 and §14.2),
// T_s = Re(m cos θt) |t_s|² / cos θi, T_p = Re(m̄ cos θt) |t_p|² / cos θi.
double TransmittedFraction(double cosI, std::complex<double> m) {
    const double sinI2 = 1.0 - cosI * cosI;
    const std::complex<double> cosT = std::sqrt(1.0 - sinI2 / (m * m));
    const std::complex<double> ts = 2.0 * cosI / (cosI + m * cosT);
    const std::complex<double> tp = 2.0 * cosI / (m * cosI + cosT);
    const double Ts = (m * cosT).real() * std::norm(ts) / cosI;
    const double Tp = (std::conj(m) * cosT).real() * std::norm(tp) / cosI;
    return 0.5 * (Ts + Tp);
}

TEST(WaterIndex, ComplexFresnelConservesEnergy) {
    // R + T = 1 at a flat interface: the emissivity 1 − R is the absorbed (transmitted) fraction.
    for (const WaterIndexSample& s : HaleQuerryWaterIndex())
        for (double deg : {0.0, 20.0, 45.0, 70.0, 85.0, 89.0}) {
            const std::complex<double> m(s.n, s.k);
            EXPECT_NEAR(
                FresnelReflectanceComplex(CosDeg(deg), m) + TransmittedFraction(CosDeg(deg), m),
                1.0, 1e-12)
                << s.lambda_m << " m, " << deg << " deg";
        }
}

TEST(WaterIndex, ComplexFresnelLimits) {
    // Real index: the dielectric formula; normal incidence: ((n−1)² + k²) / ((n+1)² + k²).
    for (double c : {0.05, 0.3, 0.7, 1.0})
        EXPECT_NEAR(FresnelReflectanceComplex(c, {1.33, 0.0}), FresnelDielectric(c, 1.33), 1e-14);
    const double n = 1.218, k = 0.0508;  // Hale & Querry, 10 µm
    EXPECT_NEAR(FresnelReflectanceComplex(1.0, {n, k}),
                ((n - 1) * (n - 1) + k * k) / ((n + 1) * (n + 1) + k * k), 1e-14);
    EXPECT_NEAR(FresnelReflectanceComplex(0.0, {n, k}), 1.0, 1e-12);  // grazing: total reflection
}

TEST(WaterIndex, InterpolatesTheTableAndRejectsOtherWavelengths) {
    const std::complex<double> m = WaterRefractiveIndex(10.0e-6);
    EXPECT_NEAR(m.real(), 1.218, 1e-12);
    EXPECT_NEAR(m.imag(), 0.0508, 1e-12);
    const std::complex<double> mid = WaterRefractiveIndex(10.25e-6);
    EXPECT_NEAR(mid.real(), 0.5 * (1.218 + 1.185), 1e-12);
    EXPECT_THROW(WaterRefractiveIndex(1.0e-6), InputError);
    EXPECT_THROW(WaterRefractiveIndex(20.0e-6), InputError);
}

TEST(SeaEmissivity, CoxMunkSlopeVariance) {
    EXPECT_DOUBLE_EQ(CoxMunkSlopeVariance(0.0), 0.003);
    EXPECT_NEAR(CoxMunkSlopeVariance(10.0), 0.0542, 1e-15);
    EXPECT_THROW(CoxMunkSlopeVariance(-1.0), InputError);
}

TEST(SeaEmissivity, LwirFlatSeaMatchesPublishedValues) {
    const SeaSurfaceEmissivity sea(Band::Lwir());
    // physics.md and Masuda et al. (1988) Table 1: ≈ 0.99 at nadir in the 8–12 µm window.
    EXPECT_NEAR(sea.FlatEmissivity(1.0), 0.99, 0.003);
    // Falling steeply past 60°, ≈ 0.7 at 80° for the flat sea (physics.md).
    EXPECT_GT(sea.FlatEmissivity(CosDeg(60)), sea.FlatEmissivity(CosDeg(70)) + 0.03);
    EXPECT_GT(sea.FlatEmissivity(CosDeg(70)), sea.FlatEmissivity(CosDeg(80)) + 0.1);
    EXPECT_NEAR(sea.FlatEmissivity(CosDeg(80)), 0.7, 0.05);
    // Tabulated and exact flat reflectance agree.
    for (double c = 0.0; c <= 1.0; c += 0.0137)
        EXPECT_NEAR(sea.FlatReflectance(c), sea.FlatReflectanceExact(c), 1e-5) << c;
}

TEST(SeaEmissivity, MwirNadirIsLowerThanLwir) {
    // Water's MWIR index (n ≈ 1.35) is higher than its LWIR index (≈ 1.2): larger nadir
    // reflectance, ((1.35 − 1) / 2.35)² ≈ 0.022.
    const SeaSurfaceEmissivity mwir(Band::Mwir());
    EXPECT_NEAR(mwir.FlatEmissivity(1.0), 1.0 - 0.022, 0.004);
    EXPECT_LT(mwir.FlatEmissivity(1.0), SeaSurfaceEmissivity(Band::Lwir()).FlatEmissivity(1.0));
}

TEST(SeaEmissivity, VanishingSlopesGiveTheFresnelValue) {
    const SeaSurfaceEmissivity sea(Band::Lwir());
    for (double deg : {0.0, 30.0, 60.0, 75.0, 85.0})
        EXPECT_NEAR(sea.Emissivity(CosDeg(deg), 1e-9), sea.FlatEmissivity(CosDeg(deg)), 2e-4)
            << deg;
    EXPECT_EQ(sea.Emissivity(0.5, 0.0), sea.FlatEmissivity(0.5));
}

TEST(SeaEmissivity, WindBehavesAsInMasuda1988) {
    const SeaSurfaceEmissivity sea(Band::Lwir());
    // Near nadir roughness hardly matters (Masuda et al. 1988, Fig. 3: < 0.001 change).
    EXPECT_NEAR(sea.EmissivityForWind(1.0, 15.0), sea.FlatEmissivity(1.0), 1e-3);
    // Toward grazing, wind raises the emissivity: tilted facets face the viewer.
    for (double deg : {80.0, 85.0}) {
        const double c = CosDeg(deg);
        EXPECT_LT(sea.EmissivityForWind(c, 0.0), sea.EmissivityForWind(c, 5.0)) << deg;
        EXPECT_LT(sea.EmissivityForWind(c, 5.0), sea.EmissivityForWind(c, 15.0)) << deg;
    }
    for (double w : {0.0, 5.0, 15.0})
        for (double c = 0.0; c <= 1.0; c += 0.05) {
            const double e = sea.EmissivityForWind(c, w);
            EXPECT_GE(e, 0.0);
            EXPECT_LE(e, 1.0);
        }
}

TEST(SeaEmissivity, TableAndCurveMatchTheDirectQuadrature) {
    const SeaSurfaceEmissivity sea(Band::Lwir());
    const SeaEmissivityTable table(sea, 20.0);
    EXPECT_EQ(table.MaxWind_mps(), 20.0);
    for (double w : {0.0, 3.0, 7.5, 12.25, 20.0})
        for (double c = 0.02; c <= 1.0; c += 0.07)
            EXPECT_NEAR(table.Emissivity(c, w), sea.EmissivityForWind(c, w), 2e-3) << c << " " << w;
    const SeaEmissivityCurve curve = table.Curve(7.5);
    for (float c = 0.0f; c <= 1.0f; c += 0.031f)
        EXPECT_NEAR(curve.Emissivity(c), table.Emissivity(c, 7.5), 1e-6);
    float cs[3] = {-1.0f, 0.5f, 2.0f}, e[3];
    curve.Emissivity(3, cs, e);
    EXPECT_EQ(e[0], curve.Emissivity(0.0f));
    EXPECT_EQ(e[1], curve.Emissivity(0.5f));
    EXPECT_EQ(e[2], curve.Emissivity(1.0f));
    EXPECT_THROW(SeaEmissivityTable(sea, 0.5), InputError);
}

// The curve of one wind from its own wind nodes is the whole table's curve bit for bit: whole
// and fractional winds, calm, the table's end and beyond it (clamped), two table sizes, LWIR
// and MWIR.
TEST(SeaEmissivity, CurveForOneWindIsTheTablesCurveBitForBit) {
    for (const Band& band : {Band::Lwir(), Band::Mwir()}) {
        const SeaSurfaceEmissivity sea(band);
        for (const double maxWind : {30.0, 12.5}) {
            const SeaEmissivityTable table(sea, maxWind);
            for (const double w : {0.0, 0.4, 6.0, 7.25, 12.5, 13.0, 29.9, 30.0, 45.0, -2.0}) {
                const std::vector<float> fast =
                    SeaEmissivityTable::CurveForWind(sea, w, maxWind).Nodes();
                const std::vector<float> full = table.Curve(w).Nodes();
                ASSERT_EQ(fast.size(), full.size());
                for (size_t i = 0; i < full.size(); ++i)
                    EXPECT_EQ(std::bit_cast<uint32_t>(fast[i]), std::bit_cast<uint32_t>(full[i]))
                        << band.Name() << " " << maxWind << " " << w << " " << i;
            }
        }
    }
    EXPECT_THROW(SeaEmissivityTable::CurveForWind(SeaSurfaceEmissivity(Band::Lwir()), 5.0, 0.5),
                 InputError);
}

TEST(SeaEmissivity, RejectsBandsOutsideTheWaterTable) {
    EXPECT_THROW(SeaSurfaceEmissivity(Band::Flat("NIR", 0.7e-6, 0.9e-6)), InputError);
    EXPECT_THROW(SeaSurfaceEmissivity(Band::Lwir(), -5.0), InputError);
}

TEST(SeaSettings, ParsesGoodAndNamesTheKeyOfBadInput) {
    const auto parse = [](const std::string& text) {
        const scene::ConfigDocument doc = scene::ParseConfigText(text, "sea.yaml");
        return scene::ReadMap(doc.root, [](scene::ConfigMap& root) {
            return ParseSeaSettings(root.Require("sea", "a mapping"));
        });
    };
    EXPECT_DOUBLE_EQ(parse("sea: {temperature_K: 290.5}\n").temperature_K, 290.5);
    EXPECT_DOUBLE_EQ(parse("sea: {}\n").temperature_K, 288.15);
    for (const char* bad : {"sea: {temperature_K: 400}\n", "sea: {temperature_K: warm}\n"}) {
        try {
            parse(bad);
            ADD_FAILURE() << "no ConfigError for " << bad;
        } catch (const scene::ConfigError& e) {
            EXPECT_NE(std::string(e.what()).find("sea.temperature_K"), std::string::npos)
                << e.what();
        }
    }
    try {
        parse("sea: {temperature_C: 15}\n");
        ADD_FAILURE() << "no ConfigError for an unknown key";
    } catch (const scene::ConfigError& e) {
        EXPECT_NE(std::string(e.what()).find("sea.temperature_C"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace seasense::radiometry
