// OTW cloud radiance (diffuse base, single-scattered sun and moon, haze in front) and the
// cloud pass of the OTW channel.
#include "channels/otw/cloud_layer.h"

#include <algorithm>
#include <cmath>

#include "channels/otw/celestial.h"
#include "scene/core/check.h"

namespace seasense::channels {

namespace {

// Cones traced sample by sample around the sun and moon: the disc's radius plus 0.05°, so
// that every sample of the disc (and of its edge) is in it.
constexpr double kExactConeMargin_rad = 0.05 * M_PI / 180.0;

// The part of one body's light (sun or moon, illuminance E normal to it, unit direction b)
// that a cloud seen along d sends to the eye: diffuse (returned in diffuse) and once scattered
// (returned).
double BodyLight(double E, const glm::dvec3& b, const glm::dvec3& d, double tauView,
                 double tauVertical, double Td, double& diffuse) {
    const double mu0 = b.z;
    if (!(E > 0.0) || !(mu0 > 0.0)) return 0.0;
    const double tauSun = tauVertical / mu0;
    const double direct = std::exp(-tauSun);
    // Transmitted flux less the direct beam and (nearly all forward, g = 0.85) the beam
    // scattered once, which is drawn with its phase function below.
    diffuse += E * mu0 * std::max(Td - direct * (1.0 + tauSun), 0.0);
    const double p = HenyeyGreenstein(glm::dot(b, d), kCloudAsymmetry);
    const double diff = tauSun - tauView;
    // τ (e^−τ − e^−τs) / (τs − τ), its limit τ e^−τ where the two paths are equal.
    const double path = std::abs(diff) < 1e-6 * std::max(1.0, tauView)
                            ? tauView * std::exp(-tauView)
                            : tauView * (std::exp(-tauView) - direct) / diff;
    return E * p / (4.0 * M_PI) * path;
}

}  // namespace

double HenyeyGreenstein(double cosTheta, double g) {
    const double denominator = 1.0 + g * g - 2.0 * g * cosTheta;
    return (1.0 - g * g) / (denominator * std::sqrt(denominator));
}

double CloudDiffuseTransmittance(double tau, double g) {
    CHECK(tau >= 0.0);
    return 1.0 / (1.0 + 0.75 * (1.0 - g) * tau);
}

CloudCover OtwCloudCover(const OtwCloudLighting& light, const glm::dvec3& d,
                         const scene::CloudHit& hit, const glm::dvec3& airlight) {
    const double tau = hit.opticalDepth;
    // A uniform slab crossed along d has τ |d_z| = its vertical optical depth; a column seen
    // from the side is capped at the sky's total.
    const double tauVertical = std::min(tau * std::abs(d.z), light.totalVerticalDepth);
    const double Td = CloudDiffuseTransmittance(tauVertical, kCloudAsymmetry);
    // Each body's light in its own components (Rec.709: 1, so the sums are those of grey
    // light).
    double sunDiffuse = 0.0, moonDiffuse = 0.0;
    const double sunSingle = BodyLight(light.sunIlluminance_lux, light.sunDirection, d, tau,
                                       tauVertical, Td, sunDiffuse);
    const double moonSingle = BodyLight(light.moonIlluminance_lux, light.moonDirection, d, tau,
                                        tauVertical, Td, moonDiffuse);
    const glm::dvec3 diffuse = sunDiffuse * light.sunPerLux + moonDiffuse * light.moonPerLux;
    const glm::dvec3 single = sunSingle * light.sunPerLux + moonSingle * light.moonPerLux;
    const glm::dvec3 base = (diffuse + light.skyIlluminance * Td) / M_PI;
    const double opacity = -std::expm1(-tau);
    const double haze = std::exp(
        -light.extinction_perM *
        EquivalentHorizontalPath_m(hit.distance_m, hit.distance_m * d.z, kAerosolScaleHeight_m));
    const glm::dvec3 L = haze * (opacity * base + single) + (1.0 - haze) * opacity * airlight;
    CloudCover c;
    c.alpha = float(opacity);
    for (int k = 0; k < 3; ++k) c.premultiplied[k] = float(L[k]);
    return c;
}

CloudSkyStats DrawOtwClouds(CloudSky& pass, const scene::World& world,
                            const scene::SceneState& state, const ChannelCamera& camera,
                            const VisibilityBuffer& vis, const radiometry::AnalyticSky& sky,
                            double extinction_perM, Image& radiance, const glm::dvec3& sunPerLux,
                            const glm::dvec3& moonPerLux) {
    const scene::CloudField* field = world.Clouds();
    CHECK(field != nullptr);
    const glm::dvec3 eye = state.eyepoint.position_m;
    OtwCloudLighting light;
    // Above the clouds: the world divided the direct light by the divisor along each body.
    light.sunDirection = state.sun.direction;
    light.sunIlluminance_lux = state.sun.illuminance_lux *
                               world.SkyConditionDivisor(eye, state.sun.direction, state.time_s);
    if (state.sun.direction.z <= 0.0) light.sunIlluminance_lux = 0.0;
    light.moonDirection = state.moon.direction;
    light.moonIlluminance_lux = state.moon.illuminance_lux *
                                world.SkyConditionDivisor(eye, state.moon.direction, state.time_s);
    light.skyIlluminance = sky.HorizontalSkyIlluminance();
    light.extinction_perM = extinction_perM;
    light.sunPerLux = sunPerLux;
    light.moonPerLux = moonPerLux;
    for (const scene::CloudLayerSettings& l : field->Layers())
        light.totalVerticalDepth += l.opticalDepth;

    std::vector<ExactCone> exact;
    exact.push_back(
        {state.sun.direction, std::cos(radiometry::kSunAngularRadius_rad + kExactConeMargin_rad)});
    const double moonRadius_rad = std::asin(std::min(1.0, kMoonRadius_m / state.moon.distance_m));
    exact.push_back({state.moon.direction, std::cos(moonRadius_rad + kExactConeMargin_rad)});
    return pass.Composite(
        *field, state.time_s, camera, vis,
        [&light, &sky](const glm::dvec3& d, const scene::CloudHit& hit) {
            return OtwCloudCover(light, d, hit, glm::dvec3(sky.LookUp(glm::vec3(d))));
        },
        exact, radiance);
}

}  // namespace seasense::channels
