// Cloud layers against their settings (covered fraction), the ICAO standard atmosphere,
// Beer-Lambert through a uniform slab, ray geometry and the USNO sky-condition classes.
#include "scene/sky/clouds.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "scene/config/config.h"
#include "scene/core/error.h"
#include "scene/core/rng.h"

namespace seasense::scene {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

CloudLayerSettings Layer(CloudType type, double coverage, double base_m, double thickness_m) {
    CloudLayerSettings l;
    l.type = type;
    l.coverage = coverage;
    l.base_m = base_m;
    l.thickness_m = thickness_m;
    return l;
}

glm::dvec3 FromZenith(double zenith_rad, double azimuth_rad) {
    // ENU: azimuth from north through east.
    return {std::sin(zenith_rad) * std::sin(azimuth_rad),
            std::sin(zenith_rad) * std::cos(azimuth_rad), std::cos(zenith_rad)};
}

TEST(Clouds, CoveredFractionOfSampledDirectionsMatchesCoverage) {
    // Observers spread over 400 km look up within 60 deg of the zenith at a thin layer: the
    // fraction of rays that meet a cloud is the layer's coverage.
    for (double coverage : {0.125, 0.3, 0.625, 0.9}) {
        for (uint64_t seed : {3u, 41u}) {
            CloudLayerSettings l = Layer(CloudType::Stratus, coverage, 2000.0, 10.0);
            l.cellSize_m = 1000.0;
            const CloudField field({l}, seed);
            const int rays = 20000;
            int hits = 0;
            for (int i = 0; i < rays; ++i) {
                const glm::dvec3 origin(400e3 * Uniform01(9, 1, uint64_t(i)) - 200e3,
                                        400e3 * Uniform01(9, 2, uint64_t(i)) - 200e3, 0.0);
                const double zenith = std::acos(1.0 - 0.5 * Uniform01(9, 3, uint64_t(i)));
                const double azimuth = 2.0 * kPi * Uniform01(9, 4, uint64_t(i));
                if (field.Trace(origin, FromZenith(zenith, azimuth), 0.0).hit) ++hits;
            }
            EXPECT_NEAR(double(hits) / rays, coverage, 0.025)
                << "coverage " << coverage << " seed " << seed;
        }
    }
}

TEST(Clouds, NoneAndFullCoverage) {
    const CloudField clear({Layer(CloudType::Cumulus, 0.0, 1000.0, 800.0)}, 1);
    const CloudField overcast({Layer(CloudType::Stratus, 1.0, 1000.0, 800.0)}, 1);
    for (int i = 0; i < 100; ++i) {
        const double x = 1e4 * Uniform01(5, 1, uint64_t(i));
        const double y = 1e4 * Uniform01(5, 2, uint64_t(i));
        EXPECT_FALSE(clear.Covered(0, x, y, 0.0));
        EXPECT_EQ(clear.ColumnDensity(0, x, y, 0.0), 0.0);
        EXPECT_TRUE(overcast.Covered(0, x, y, 0.0));
        EXPECT_EQ(overcast.ColumnDensity(0, x, y, 0.0), 1.0);
    }
    EXPECT_FALSE(clear.Trace({0, 0, 0}, {0, 0, 1}, 0.0).hit);
    EXPECT_EQ(clear.Trace({0, 0, 0}, {0, 0, 1}, 0.0).transmittance, 1.0);
}

TEST(Clouds, LapseRateReproducesTheStandardAtmosphere) {
    // ICAO standard atmosphere: 288.15 K at sea level, 281.65 K at 1 km, 249.15 K at 6 km,
    // 216.65 K at the 11 km tropopause and through the isothermal layer above it.
    EXPECT_DOUBLE_EQ(AirTemperature_K(288.15, 0.0), 288.15);
    EXPECT_NEAR(AirTemperature_K(288.15, 1000.0), 281.65, 1e-12);
    EXPECT_NEAR(AirTemperature_K(288.15, 6000.0), 249.15, 1e-12);
    EXPECT_NEAR(AirTemperature_K(288.15, 11000.0), 216.65, 1e-12);
    EXPECT_NEAR(AirTemperature_K(288.15, 15000.0), 216.65, 1e-12);
    // A warmer surface shifts the profile; a raised surface starts the lapse from there.
    EXPECT_NEAR(AirTemperature_K(300.0, 2000.0), 287.0, 1e-12);
    EXPECT_NEAR(AirTemperature_K(300.0, 2000.0, 500.0), 290.25, 1e-12);
    const CloudTemperatures t =
        LayerTemperatures(Layer(CloudType::Cumulus, 0.5, 1500.0, 2500.0), 293.15);
    EXPECT_NEAR(t.base_K, 293.15 - 9.75, 1e-12);
    EXPECT_NEAR(t.top_K, 293.15 - 26.0, 1e-12);
    EXPECT_THROW(AirTemperature_K(288.15, 25000.0), InputError);
    EXPECT_THROW(AirTemperature_K(-1.0, 0.0), InputError);
}

TEST(Clouds, InfraredEmissivityLimits) {
    EXPECT_EQ(CloudInfraredEmissivity(0.0), 0.0);
    // Thick water cloud is black in the thermal infrared; tau_vis = 2 means tau_IR = 1.
    EXPECT_NEAR(CloudInfraredEmissivity(100.0), 1.0, 1e-12);
    EXPECT_NEAR(CloudInfraredEmissivity(2.0), 1.0 - std::exp(-1.0), 1e-15);
    EXPECT_THROW(CloudInfraredEmissivity(-1.0), InputError);
}

TEST(Clouds, BeerLambertThroughAUniformSlab) {
    // Full cover: optical depth tau0 / cos(zenith) and transmittance exp(-tau).
    CloudLayerSettings l = Layer(CloudType::Altostratus, 1.0, 3000.0, 1500.0);
    l.opticalDepth = 4.0;
    const CloudField field({l}, 2);
    for (double zenithDeg : {0.0, 30.0, 60.0, 75.0}) {
        const CloudHit hit =
            field.Trace({100.0, -50.0, 10.0}, FromZenith(zenithDeg * kDeg, 1.0), 0.0);
        const double tau = 4.0 / std::cos(zenithDeg * kDeg);
        EXPECT_NEAR(hit.opticalDepth, tau, 1e-9 * tau) << zenithDeg;
        EXPECT_NEAR(hit.transmittance, std::exp(-tau), 1e-9) << zenithDeg;
        ASSERT_TRUE(hit.hit);
        EXPECT_NEAR(hit.distance_m, (3000.0 - 10.0) / std::cos(zenithDeg * kDeg), 1e-6);
        EXPECT_EQ(hit.layer, 0);
    }
    // Looking down from above the top: the first contact is the top.
    const CloudHit down = field.Trace({0.0, 0.0, 6000.0}, {0.0, 0.0, -1.0}, 0.0);
    ASSERT_TRUE(down.hit);
    EXPECT_NEAR(down.distance_m, 1500.0, 1e-6);
    // From inside the layer the contact is immediate; half the layer lies above.
    const CloudHit inside = field.Trace({0.0, 0.0, 3750.0}, {0.0, 0.0, 1.0}, 0.0);
    EXPECT_EQ(inside.distance_m, 0.0);
    EXPECT_NEAR(inside.opticalDepth, 2.0, 1e-9);
    // Looking away from the layer, or stopping short of it: nothing.
    EXPECT_FALSE(field.Trace({0.0, 0.0, 10.0}, {0.0, 0.0, -1.0}, 0.0).hit);
    EXPECT_FALSE(field.Trace({0.0, 0.0, 10.0}, {0.0, 0.0, 1.0}, 0.0, 2000.0).hit);
    // Two layers add their optical depths.
    CloudLayerSettings upper = Layer(CloudType::Cirrus, 1.0, 9000.0, 1000.0);
    upper.opticalDepth = 0.5;
    const CloudField both({l, upper}, 2);
    EXPECT_NEAR(both.Trace({0, 0, 0}, {0, 0, 1}, 0.0).opticalDepth, 4.5, 1e-9);
    EXPECT_NEAR(both.TotalCoverage(), 1.0, 0.0);
}

TEST(Clouds, CumulusColumnOpticalDepthFollowsColumnDensity) {
    // A cumulus column of density D is full from the base to D x thickness, so its vertical
    // optical depth is tau0 x D (resolved to a sixteenth of the thickness by the sampling).
    CloudLayerSettings l = Layer(CloudType::Cumulus, 0.5, 1000.0, 1600.0);
    l.opticalDepth = 16.0;
    const CloudField field({l}, 77);
    int clouds = 0;
    for (int i = 0; i < 400; ++i) {
        const double x = 2e4 * Uniform01(6, 1, uint64_t(i));
        const double y = 2e4 * Uniform01(6, 2, uint64_t(i));
        const double column = field.ColumnDensity(0, x, y, 0.0);
        const CloudHit hit = field.Trace({x, y, 0.0}, {0.0, 0.0, 1.0}, 0.0);
        EXPECT_NEAR(hit.opticalDepth, 16.0 * column, 16.0 / 16.0 + 1e-9);
        EXPECT_EQ(hit.hit, field.Covered(0, x, y, 0.0));
        if (hit.hit) {
            ++clouds;
            EXPECT_NEAR(hit.distance_m, 1000.0, 1e-6);  // flat base
        }
    }
    EXPECT_GT(clouds, 100);
}

TEST(Clouds, PatternIsDeterministicAndDriftsWithTheWind) {
    CloudLayerSettings l = Layer(CloudType::Stratocumulus, 0.5, 1200.0, 600.0);
    l.drift_mps = {12.0, -5.0};
    const CloudField a({l}, 1234);
    const CloudField b({l}, 1234);
    const CloudField other({l}, 1235);
    int differ = 0;
    for (int i = 0; i < 500; ++i) {
        const double x = 5e4 * Uniform01(8, 1, uint64_t(i));
        const double y = 5e4 * Uniform01(8, 2, uint64_t(i));
        EXPECT_EQ(a.ColumnDensity(0, x, y, 0.0), b.ColumnDensity(0, x, y, 0.0));
        // After t seconds the pattern has moved by drift x t.
        const double t = 37.5;
        EXPECT_EQ(a.Covered(0, x + 12.0 * t, y - 5.0 * t, t), a.Covered(0, x, y, 0.0));
        if (a.Covered(0, x, y, 0.0) != other.Covered(0, x, y, 0.0)) ++differ;
    }
    EXPECT_GT(differ, 50);  // another seed, another sky
    const glm::dvec3 d = glm::normalize(glm::dvec3(0.3, 0.2, 1.0));
    const CloudHit ha = a.Trace({10.0, 20.0, 0.0}, d, 3.0);
    const CloudHit hb = b.Trace({10.0, 20.0, 0.0}, d, 3.0);
    EXPECT_EQ(ha.hit, hb.hit);
    EXPECT_EQ(ha.distance_m, hb.distance_m);
    EXPECT_EQ(ha.opticalDepth, hb.opticalDepth);
}

TEST(Clouds, SkyConditionDivisorFollowsTheCircular171Classes) {
    const glm::dvec3 origin(0.0, 0.0, 2.0);
    const glm::dvec3 sun = FromZenith(40.0 * kDeg, 2.0);
    // Clear sky: 1.
    EXPECT_EQ(CloudField({}, 1).SkyConditionDivisor(origin, sun, 0.0), 1.0);
    // The body behind thin cloud (cirrus, tau 1 / cos 40 deg = 1.3): 2.
    CloudLayerSettings cirrus = Layer(CloudType::Cirrus, 1.0, 9000.0, 1000.0);
    EXPECT_EQ(CloudField({cirrus}, 1).SkyConditionDivisor(origin, sun, 0.0), 2.0);
    // Behind average cloud (altostratus, tau 9 / cos 40 deg = 11.7): 3.
    CloudLayerSettings as = Layer(CloudType::Altostratus, 1.0, 4000.0, 1000.0);
    EXPECT_EQ(CloudField({as}, 1).SkyConditionDivisor(origin, sun, 0.0), 3.0);
    // Overcast dark stratus (tau 30): 10. The divisor is accepted by the illuminance model's
    // published range [1, 10].
    CloudLayerSettings st = Layer(CloudType::Stratus, 1.0, 500.0, 600.0);
    EXPECT_EQ(CloudField({st}, 1).SkyConditionDivisor(origin, sun, 0.0), 10.0);
    // Broken cumulus: the class depends on whether the sun's line of sight meets a cloud.
    CloudLayerSettings cu = Layer(CloudType::Cumulus, 0.5, 1000.0, 1000.0);
    cu.opticalDepth = 40.0;
    const CloudField broken({cu}, 3);
    int clear = 0;
    int hidden = 0;
    for (int i = 0; i < 200; ++i) {
        const glm::dvec3 o(3e4 * Uniform01(4, 1, uint64_t(i)), 3e4 * Uniform01(4, 2, uint64_t(i)),
                           0.0);
        const double divisor = broken.SkyConditionDivisor(o, sun, 0.0);
        const CloudHit hit = broken.Trace(o, sun, 0.0);
        if (!hit.hit) {
            EXPECT_EQ(divisor, 1.0);
            ++clear;
        } else if (hit.opticalDepth >= 23.0) {
            EXPECT_EQ(divisor, 3.0);  // thick, but the sky is only half covered
            ++hidden;
        }
    }
    EXPECT_GT(clear, 20);
    EXPECT_GT(hidden, 20);
}

TEST(Clouds, RejectsBadLayers) {
    EXPECT_THROW(CloudField({Layer(CloudType::Cumulus, 1.2, 1000.0, 500.0)}, 1), InputError);
    EXPECT_THROW(CloudField({Layer(CloudType::Cumulus, 0.5, 1000.0, 0.0)}, 1), InputError);
    EXPECT_THROW(CloudField({Layer(CloudType::Cirrus, 0.5, 19000.0, 2000.0)}, 1), InputError);
    CloudLayerSettings l = Layer(CloudType::Stratus, 0.5, 1000.0, 500.0);
    l.opticalDepth = -1.0;
    EXPECT_THROW(CloudField({l}, 1), InputError);
    const CloudField ok({Layer(CloudType::Stratus, 0.5, 1000.0, 500.0)}, 1);
    EXPECT_THROW(ok.Trace({0, 0, 0}, {0, 0, 2}, 0.0), InputError);
}

// Parses `text` and reads its `clouds` list; returns the ConfigError message or "".
std::string ReadError(const std::string& text, std::vector<CloudLayerSettings>* out = nullptr) {
    try {
        ConfigDocument doc = ParseConfigText(text, "sky.yaml");
        ReadMap(doc.root, [&](ConfigMap& root) {
            std::vector<CloudLayerSettings> layers =
                ReadCloudLayers(root.Require("clouds", "a list of cloud layers"));
            if (out) *out = layers;
        });
    } catch (const ConfigError& e) {
        return e.what();
    }
    return "";
}

TEST(CloudConfig, ReadsLayers) {
    const std::string text =
        "clouds:\n"
        "  - type: cumulus\n"
        "    coverage_oktas: 3\n"
        "    base_m: 900\n"
        "    thickness_m: 1200\n"
        "    drift_east_mps: 4\n"
        "  - type: cirrus\n"
        "    coverage: 0.4\n"
        "    base_m: 9000\n"
        "    thickness_m: 800\n"
        "    optical_depth: 0.7\n"
        "    cell_m: 3000\n";
    std::vector<CloudLayerSettings> layers;
    ASSERT_EQ(ReadError(text, &layers), "");
    ASSERT_EQ(layers.size(), 2u);
    EXPECT_EQ(layers[0].type, CloudType::Cumulus);
    EXPECT_EQ(layers[0].coverage, 3.0 / 8.0);
    EXPECT_EQ(layers[0].base_m, 900.0);
    EXPECT_EQ(layers[0].thickness_m, 1200.0);
    EXPECT_EQ(layers[0].drift_mps, glm::dvec2(4.0, 0.0));
    EXPECT_TRUE(std::isnan(layers[0].opticalDepth));  // type default, filled by CloudField
    EXPECT_EQ(layers[1].type, CloudType::Cirrus);
    EXPECT_EQ(layers[1].coverage, 0.4);
    EXPECT_EQ(layers[1].opticalDepth, 0.7);
    EXPECT_EQ(layers[1].cellSize_m, 3000.0);
    const CloudField field(layers, 1);
    EXPECT_EQ(field.Layers()[0].opticalDepth, DefaultsFor(CloudType::Cumulus).opticalDepth);
    EXPECT_NEAR(field.TotalCoverage(), 1.0 - (5.0 / 8.0) * 0.6, 1e-15);
}

TEST(CloudConfig, ErrorsNameTheKeyPath) {
    const std::string base = "    base_m: 900\n    thickness_m: 500\n";
    std::string e = ReadError("clouds:\n  - type: nimbus\n    coverage: 0.5\n" + base);
    EXPECT_NE(e.find("clouds[0].type"), std::string::npos) << e;
    e = ReadError("clouds:\n  - type: stratus\n    coverage: 1.5\n" + base);
    EXPECT_NE(e.find("clouds[0].coverage"), std::string::npos) << e;
    e = ReadError("clouds:\n  - type: stratus\n    coverage_oktas: 9\n" + base);
    EXPECT_NE(e.find("clouds[0].coverage_oktas"), std::string::npos) << e;
    e = ReadError("clouds:\n  - type: stratus\n    coverage: 0.5\n    coverage_oktas: 4\n" + base);
    EXPECT_NE(e.find("clouds[0].coverage_oktas"), std::string::npos) << e;
    e = ReadError("clouds:\n  - type: stratus\n" + base);
    EXPECT_NE(e.find("clouds[0].coverage"), std::string::npos) << e;
    e = ReadError("clouds:\n  - type: stratus\n    coverage: 0.5\n    base_m: 900\n");
    EXPECT_NE(e.find("clouds[0].thickness_m"), std::string::npos) << e;
    e = ReadError(
        "clouds:\n  - type: stratus\n    coverage: 0.5\n    bass_m: 900\n"
        "    thickness_m: 500\n");
    EXPECT_NE(e.find("bass_m"), std::string::npos) << e;
    e = ReadError(
        "clouds:\n  - type: cirrus\n    coverage: 0.5\n    base_m: 19500\n"
        "    thickness_m: 1000\n");
    EXPECT_NE(e.find("clouds[0].thickness_m"), std::string::npos) << e;
}

}  // namespace
}  // namespace seasense::scene
