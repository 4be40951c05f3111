// Analytic sky against published daylight magnitudes and its own lookup table.
#include "radiometry/sky/analytic_sky.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
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

// Preetham, Shirley & Smits (SIGGRAPH 1999), Appendix A.2, evaluated in double precision
// straight from the paper: the Perez coefficients as (slope in T, constant) pairs and the
// zenith chromaticities as [T², T, 1] · M · [θs³, θs², θs, 1]. The sky's four-lane float
// evaluation (exponentials and arccosines by polynomials) must follow it within 2e-5.
TEST(AnalyticSky, RadianceFollowsPreethamsFormulasInDoublePrecision) {
    const double perez[3][5][2] = {{{0.1787, -1.4630},
                                    {-0.3554, 0.4275},
                                    {-0.0227, 5.3251},
                                    {0.1206, -2.5771},
                                    {-0.0670, 0.3703}},
                                   {{-0.0193, -0.2592},
                                    {-0.0665, 0.0008},
                                    {-0.0004, 0.2125},
                                    {-0.0641, -0.8989},
                                    {-0.0033, 0.0452}},
                                   {{-0.0167, -0.2608},
                                    {-0.0950, 0.0092},
                                    {-0.0079, 0.2102},
                                    {-0.0441, -1.6537},
                                    {-0.0109, 0.0529}}};
    const double mx[3][4] = {{0.00166, -0.00375, 0.00209, 0.0},
                             {-0.02903, 0.06377, -0.03202, 0.00394},
                             {0.11693, -0.21196, 0.06052, 0.25886}};
    const double my[3][4] = {{0.00275, -0.00610, 0.00317, 0.0},
                             {-0.04214, 0.08970, -0.04153, 0.00516},
                             {0.15346, -0.26756, 0.06670, 0.26688}};
    double worst = 0.0;
    for (const double T : {2.0, 3.5, 6.0}) {
        for (const double elevation : {5.0, 30.0, 70.0}) {
            const glm::dvec3 sun =
                glm::normalize(glm::dvec3(0.3, 1.0, 0.0) * std::cos(elevation * M_PI / 180.0) +
                               glm::dvec3(0.0, 0.0, std::sin(elevation * M_PI / 180.0)));
            SkyConditions c;
            c.sunDirection = sun;
            c.sunIlluminance_lux = 1e5;
            c.turbidity = T;
            c.darkZenithLuminance_cdm2 = 0.0;  // Preetham's sky alone
            const AnalyticSky sky(c);
            const double ts = std::acos(sun.z);
            const auto F = [&](int k, double cosTheta, double gamma) {
                double a[5];
                for (int i = 0; i < 5; ++i) a[i] = perez[k][i][0] * T + perez[k][i][1];
                return (1.0 + a[0] * std::exp(a[1] / cosTheta)) *
                       (1.0 + a[2] * std::exp(a[3] * gamma) +
                        a[4] * std::cos(gamma) * std::cos(gamma));
            };
            const auto chroma = [&](const double(&m)[3][4]) {
                const double t[3] = {T * T, T, 1.0}, th[4] = {ts * ts * ts, ts * ts, ts, 1.0};
                double v = 0.0;
                for (int i = 0; i < 3; ++i)
                    for (int j = 0; j < 4; ++j) v += t[i] * m[i][j] * th[j];
                return v;
            };
            const double chi = (4.0 / 9.0 - T / 120.0) * (M_PI - 2.0 * ts);
            const double Yz =
                1000.0 * ((4.0453 * T - 4.9710) * std::tan(chi) - 0.2155 * T + 2.4192);
            const double xz = chroma(mx), yz = chroma(my);
            for (int az = 0; az < 360; az += 15) {
                for (const double el : {2.0, 10.0, 35.0, 60.0, 89.0}) {
                    const double a = az * M_PI / 180.0, e = el * M_PI / 180.0;
                    const glm::dvec3 d{std::cos(e) * std::sin(a), std::cos(e) * std::cos(a),
                                       std::sin(e)};
                    const double gamma = std::acos(std::clamp(glm::dot(d, sun), -1.0, 1.0));
                    const double Y = Yz * F(0, d.z, gamma) / F(0, 1.0, ts);
                    const double x = xz * F(1, d.z, gamma) / F(1, 1.0, ts);
                    const double y = yz * F(2, d.z, gamma) / F(2, 1.0, ts);
                    const glm::dvec3 expected = glm::max(Rec709FromYxy(Y, x, y), glm::dvec3(0.0));
                    const glm::dvec3 got = sky.Radiance(d) / sky.DaylightScale();
                    for (int k = 0; k < 3; ++k) {
                        worst = std::max(worst, std::abs(got[k] - expected[k]) / Y);
                        EXPECT_NEAR(got[k], expected[k], 2e-5 * Y)
                            << "T " << T << " sun " << elevation << " az " << az << " el " << el;
                    }
                }
            }
        }
    }
    std::printf("largest difference from Preetham's formulas: %.3g of the luminance\n", worst);
}

// The table and the dome integrals are built in parallel: the same sky for 1, 2 and 3 threads.
TEST(AnalyticSky, SameSkyForAnyThreadCount) {
    SkyConditions c;
    c.sunDirection = glm::normalize(glm::dvec3(-0.9, 0.2, 0.03));
    c.sunIlluminance_lux = 2e4;
    c.turbidity = 3.0;
    c.moon = true;
    c.moonDirection = glm::normalize(glm::dvec3(0.8, -0.3, 0.3));
    c.moonPhaseAngle_rad = 0.4;
    const auto build = [&](int threads) {
        tbb::task_arena arena(threads);
        std::unique_ptr<AnalyticSky> sky;
        arena.execute([&] { sky = std::make_unique<AnalyticSky>(c); });
        return sky;
    };
    const auto one = build(1);
    for (const int threads : {2, 3}) {
        const auto many = build(threads);
        EXPECT_EQ(one->HorizontalSkyIlluminance(), many->HorizontalSkyIlluminance());
        EXPECT_EQ(one->DaylightScale(), many->DaylightScale());
        for (int i = 0; i < 2000; ++i) {
            const double az = 0.731 * i, el = 0.5 * M_PI * ((i * 37) % 2000) / 2000.0;
            const glm::vec3 d(float(std::cos(el) * std::sin(az)),
                              float(std::cos(el) * std::cos(az)), float(std::sin(el)));
            EXPECT_EQ(one->LookUp(d), many->LookUp(d)) << i;
        }
    }
}

TEST(AnalyticSky, BatchedLookupsEqualSingleLookupsBitForBit) {
    const AnalyticSky sky(SunAt(40.0), 8e4, 4.0);
    // Edges of the table and of the horizon's diamond: the zenith, the axes and diagonals on
    // the horizon, below it, ±0 components; then a spiral over the sphere (103 + 12: not a
    // multiple of the batch width).
    const float h = float(M_SQRT1_2);
    std::vector<float> x = {0.0f, -0.0f, 1.0f, -1.0f, 0.0f, -0.0f, h, -h, h, -h, 1.0f, 0.0f};
    std::vector<float> y = {0.0f, 0.0f, 0.0f, 0.0f, 1.0f, -1.0f, h, h, -h, -h, -0.0f, 1.0f};
    std::vector<float> z = {1.0f, 1.0f, 0.0f, 0.0f, 0.0f,  -0.0f,
                            0.0f, 0.0f, 0.0f, 0.0f, -0.5f, -0.0f};
    for (size_t i = 0; i < 103; ++i) {
        const double az = 0.37 * double(i), el = -0.2 + 1.7 * double(i) / 103;
        x.push_back(float(std::cos(el) * std::sin(az)));
        y.push_back(float(std::cos(el) * std::cos(az)));
        z.push_back(float(std::sin(el)));
    }
    // And 4001 directions of low elevation (the sea's reflected rays), spread over azimuth by
    // the golden ratio, so that neighbouring lanes read texels far apart.
    for (size_t i = 0; i < 4001; ++i) {
        const double az = 2.0 * M_PI * std::fmod(double(i) * 0.6180339887498949, 1.0);
        const double el = 0.3 * double(i) / 4001;
        x.push_back(float(std::cos(el) * std::sin(az)));
        y.push_back(float(std::cos(el) * std::cos(az)));
        z.push_back(float(std::sin(el)));
    }
    const size_t n = x.size();
    std::vector<float> r(n), g(n), b(n), hr(n), hg(n), hb(n);
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

TEST(Fresnel, LanesEqualTheScalarTableBitForBit) {
    // Every cosine of [−0.1, 1.1] in steps of 1/4096 (table nodes, between them, and beyond
    // both ends, where the scalar form clamps), ±0 and the ends exactly.
    const FresnelTable table(kSeaWaterIndexVisible);
    std::vector<float> c = {0.0f, -0.0f, 1.0f, 1.0f - 1e-7f, 1e-30f, -1e30f, 1e30f};
    for (int i = -410; i <= 4506; ++i) c.push_back(float(i) / 4096.0f);
    for (size_t i = 0; i < c.size(); i += simd::kLanes) {
        simd::VF v = simd::Splat(0.5f);
        for (size_t l = 0; l < simd::kLanes && i + l < c.size(); ++l) v[l] = c[i + l];
        const simd::VF F = table(v);
        for (size_t l = 0; l < simd::kLanes && i + l < c.size(); ++l)
            EXPECT_EQ(F[l], table(c[i + l])) << c[i + l];
    }
}

}  // namespace
}  // namespace seasense::radiometry
