// Analytic sky against published daylight magnitudes and its own lookup table.
#include "radiometry/sky/analytic_sky.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "radiometry/color/rec709.h"
#include "radiometry/surface/fresnel.h"

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
