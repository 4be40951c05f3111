// Analytic sky against published daylight magnitudes and its own lookup table.
#include "radiometry/sky/analytic_sky.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "radiometry/color/rec709.h"
#include "radiometry/surface/fresnel.h"
#include "scene/sky/illuminance.h"

namespace seasense::radiometry {
namespace {

glm::dvec3 SunAt(double elevation_deg) {
    const double e = elevation_deg * M_PI / 180.0;
    return {0.0, std::cos(e), std::sin(e)};
}

TEST(AnalyticSky, ClearSkyDiffuseIlluminanceIsOfThePublishedMagnitude) {
    // Measured clear-sky diffuse horizontal illuminance at solar altitude 60° is about 15 klx
    // (IES clear-sky model, 0.8 + 15.5·sin(α)^½ klx; CIE 110-1994). Preetham's fit is known
    // to be brighter than measured skies (Zotti, Wilkie & Purgathofer, "A Critical Review of
    // the Preetham Skylight Model", WSCG 2007), so we require agreement within a factor of 2.
    const AnalyticSky sky(SunAt(60.0), 1e5, 2.5);
    const double E = LuminanceRec709(sky.HorizontalSkyIlluminance());
    const double ies = 1e3 * (0.8 + 15.5 * std::sqrt(std::sin(60.0 * M_PI / 180.0)));
    EXPECT_GT(E, 0.5 * ies);
    EXPECT_LT(E, 2.0 * ies);
    // The blue sky: zenith radiance has more blue than red.
    const glm::dvec3 zen = sky.Radiance({0, 0, 1});
    EXPECT_GT(zen.b, zen.r);
}

TEST(AnalyticSky, BrightestNearTheSunAndDimmerAwayFromIt) {
    const AnalyticSky sky(SunAt(30.0), 1e5, 3.0);
    const auto Y = [&](double az, double el) {
        const double a = az * M_PI / 180.0, e = el * M_PI / 180.0;
        return LuminanceRec709(
            sky.Radiance({std::cos(e) * std::sin(a), std::cos(e) * std::cos(a), std::sin(e)}));
    };
    EXPECT_GT(Y(0, 33), Y(0, 60));
    EXPECT_GT(Y(0, 33), Y(180, 33));
    EXPECT_GT(Y(0, 33), Y(90, 33));
}

TEST(AnalyticSky, QuantizedSunIsWithinHalfAStepAndChangesTheSkyByLessThanItsBound) {
    // The OTW channel builds its sky table for the sun rounded to 0.01° in elevation and
    // azimuth. Moving the sun by δ changes the Perez distribution through γ (circumsolar
    // slope |d ln F/dγ| ≤ |D|·C/(1 + C) ≈ 2.3 rad⁻¹ for T = 3.5) and the zenith luminance
    // through tan χ (|d ln Y_z/dθ_s| ≤ ~3.5 rad⁻¹ near sunset, Preetham et al. 1999, A.2): a
    // relative change of about 6 rad⁻¹ · δ, δ ≤ 0.0071° = 1.2e-4 rad, i.e. < 0.1 %, a tenth of
    // an 8-bit display step. Checked here over the sky for sun elevations from the horizon to
    // 85° and azimuths that are not on the grid.
    const double step = 0.01 * M_PI / 180.0;
    double worst = 0.0;
    for (int e = 0; e <= 85; e += 5) {
        const double el = (e + 0.0043) * M_PI / 180.0, az = (291.0 + 0.0047 * e) * M_PI / 180.0;
        const glm::dvec3 sun{std::cos(el) * std::sin(az), std::cos(el) * std::cos(az),
                             std::sin(el)};
        const glm::dvec3 q = QuantizeSunDirection(sun, step);
        EXPECT_NEAR(glm::length(q), 1.0, 1e-12);
        EXPECT_LE(std::acos(std::min(1.0, glm::dot(q, sun))), step / std::sqrt(2.0) + 1e-12);
        const AnalyticSky exact(sun, 1e5, 3.5), quantized(q, 1e5, 3.5);
        for (int j = 0; j <= 90; ++j) {
            for (int i = 0; i < 360; i += 2) {
                const double a = i * M_PI / 180.0, b = j * M_PI / 180.0;
                const glm::dvec3 d{std::cos(b) * std::sin(a), std::cos(b) * std::cos(a),
                                   std::sin(b)};
                const double y0 = LuminanceRec709(exact.Radiance(d)) / exact.DaylightScale();
                const double y1 =
                    LuminanceRec709(quantized.Radiance(d)) / quantized.DaylightScale();
                worst = std::max(worst, std::abs(y1 - y0) / y0);
            }
        }
        // On top of that the whole dome follows the measured clear-sky illuminance of the
        // sun's altitude (scene::ClearSkyDiffuseIlluminance_lux), which itself changes over
        // the quantization step: steepest just above sunset, ~0.4 % per 0.01°.
        const double hq = std::asin(q.z);
        const double domeChange = std::abs(std::log(scene::ClearSkyDiffuseIlluminance_lux(hq) /
                                                    scene::ClearSkyDiffuseIlluminance_lux(el)));
        EXPECT_LT(domeChange, 5e-3);
        const double E0 = LuminanceRec709(exact.HorizontalSkyIlluminance());
        const double E1 = LuminanceRec709(quantized.HorizontalSkyIlluminance());
        worst = std::max(worst, std::abs(E1 - E0) / E0 - domeChange);
    }
    std::printf("largest relative sky luminance change beyond the dome's: %.3g\n", worst);
    EXPECT_LT(worst, 1e-3);
}

TEST(AnalyticSky, TableLookupMatchesDirectEvaluationAwayFromTheSun) {
    const AnalyticSky sky(SunAt(25.0), 1e5, 3.0);
    for (int i = 0; i < 500; ++i) {
        const double az = 2.0 * M_PI * ((i * 37) % 500) / 500.0;
        const double el = 0.5 * M_PI * ((i * 91) % 500) / 500.0;
        const glm::dvec3 d{std::cos(el) * std::sin(az), std::cos(el) * std::cos(az), std::sin(el)};
        if (glm::dot(d, glm::normalize(SunAt(25.0))) > std::cos(10.0 * M_PI / 180.0)) continue;
        const glm::dvec3 a = sky.Radiance(d);
        const glm::vec3 b = sky.LookUp(glm::vec3(d));
        EXPECT_NEAR(b.g, a.g, 0.01 * a.g) << "az " << az << " el " << el;
        const glm::dvec3 h = sky.Radiance({d.x, d.y, 0.0});
        EXPECT_NEAR(sky.HorizonLookUp(glm::vec3(d)).g, h.g, 0.01 * h.g) << "az " << az;
    }
}

TEST(AnalyticSky, BatchedLookupsEqualSingleLookupsBitForBit) {
    const AnalyticSky sky(SunAt(40.0), 8e4, 4.0);
    const size_t n = 103;  // not a multiple of the batch width
    std::vector<float> x(n), y(n), z(n), r(n), g(n), b(n), hr(n), hg(n), hb(n);
    for (size_t i = 0; i < n; ++i) {
        const double az = 0.37 * double(i), el = -0.2 + 1.7 * double(i) / n;
        x[i] = float(std::cos(el) * std::sin(az));
        y[i] = float(std::cos(el) * std::cos(az));
        z[i] = float(std::sin(el));
    }
    sky.LookUp(n, x.data(), y.data(), z.data(), r.data(), g.data(), b.data());
    sky.HorizonLookUp(n, x.data(), y.data(), hr.data(), hg.data(), hb.data());
    for (size_t i = 0; i < n; ++i) {
        const glm::vec3 one = sky.LookUp(glm::vec3(x[i], y[i], z[i]));
        EXPECT_EQ(one.r, r[i]);
        EXPECT_EQ(one.g, g[i]);
        EXPECT_EQ(one.b, b[i]);
        const glm::vec3 h = sky.HorizonLookUp(glm::vec3(x[i], y[i], z[i]));
        EXPECT_EQ(h.r, hr[i]);
        EXPECT_EQ(h.g, hg[i]);
        EXPECT_EQ(h.b, hb[i]);
    }
}

TEST(Fresnel, WaterReflectanceAtNormalAndGrazingIncidence) {
    // Normal incidence: ((n − 1)/(n + 1))² = 0.0211 for n = 1.341; grazing → 1; Brewster's
    // angle atan(n) has zero p-reflectance so the mean equals |r_s|²/2.
    const double n = kSeaWaterIndexVisible;
    EXPECT_NEAR(FresnelDielectric(1.0, n), std::pow((n - 1) / (n + 1), 2), 1e-12);
    EXPECT_NEAR(FresnelDielectric(1e-6, n), 1.0, 1e-4);
    const double thetaB = std::atan(n), ci = std::cos(thetaB);
    const double ct = std::sqrt(1.0 - std::pow(std::sin(thetaB) / n, 2));
    const double rs = (ci - n * ct) / (ci + n * ct);
    EXPECT_NEAR(FresnelDielectric(ci, n), 0.5 * rs * rs, 1e-12);
}

TEST(Fresnel, TableFollowsTheExactFormula) {
    const FresnelTable table(kSeaWaterIndexVisible);
    for (int i = 0; i <= 5000; ++i) {
        const double c = i / 5000.0;
        EXPECT_NEAR(table(float(c)), FresnelDielectric(c, kSeaWaterIndexVisible), 2e-4) << c;
    }
}

}  // namespace
}  // namespace seasense::radiometry
