// OTW clouds: radiance of cloud layers lit by the sun, moon and sky, and the pass that draws
// them over the sky samples (channels/cloud), hiding what lies behind them.
#pragma once

#include <glm/glm.hpp>

#include "channels/cloud/cloud_sky.h"
#include "radiometry/sky/analytic_sky.h"
#include "scene/world/world.h"

namespace seasense::channels {

// Asymmetry parameter of the Henyey–Greenstein phase function for water clouds in the
// visible: 0.85 (Hansen & Travis 1974, Space Sci. Rev. 16, 527, Fig. 12).
inline constexpr double kCloudAsymmetry = 0.85;

// Henyey–Greenstein (1941, Astrophys. J. 93, 70) phase function normalized to 4π over the
// sphere: p(cos Θ) = (1 − g²) / (1 + g² − 2 g cos Θ)^{3/2}; Θ the scattering angle.
double HenyeyGreenstein(double cosTheta, double g);

// Diffuse transmittance of a conservatively scattering plane-parallel layer of optical depth
// tau and asymmetry g in the Eddington two-stream approximation: 1 / (1 + ¾ (1 − g) τ)
// (Shettle & Weinman 1970, J. Atmos. Sci. 27, 1048; Bohren 1987, Am. J. Phys. 55, 524).
double CloudDiffuseTransmittance(double tau, double g);

// What lights the clouds of one frame, above them (the sky-condition divisor not applied).
struct OtwCloudLighting {
    glm::dvec3 sunDirection{0.0, 0.0, 1.0};  // unit ENU
    double sunIlluminance_lux = 0.0;         // normal to the sun; 0 below the horizon
    glm::dvec3 moonDirection{0.0, 0.0, -1.0};
    double moonIlluminance_lux = 0.0;
    glm::dvec3 skyIlluminance{0.0};   // horizontal, from the clear sky dome (Rec.709, lx)
    double extinction_perM = 0.0;     // Koschmieder β at the surface
    double totalVerticalDepth = 0.0;  // sum of the layers' vertical optical depths
    // Components per lx of the sun's and moon's light: 1 in Rec.709 (grey); a band basis's
    // vectors (channels/nvg) in which skyIlluminance and the airlight are then given too.
    glm::dvec3 sunPerLux{1.0}, moonPerLux{1.0};
};

// Aerosol scale height for the haze in front of a cloud: 1 km, the maritime aerosol profile
// of OPAC (Hess, Koepke & Schult 1998, Bull. Am. Meteorol. Soc. 79, 831).
inline constexpr double kAerosolScaleHeight_m = 1000.0;

// The cover of a ray in unit direction d that met cloud (hit). Model, for an observer below
// the clouds:
//   - what lies behind (sky, sun and moon discs, stars) is attenuated by e^(−τ), τ the ray's
//     optical depth: alpha = 1 − e^(−τ); the haze in front (Koschmieder transmittance t over
//     the aerosol-equivalent path to the first cloud, EquivalentHorizontalPath_m) blends the
//     cloud's radiance toward the airlight, the clear sky's radiance along d: premultiplied
//     = t L_cloud + (1 − t) alpha airlight;
//   - the cloud's diffuse radiance, a Lambertian base: (F_sun + F_moon + E_sky T_d) / π, with
//     T_d the diffuse transmittance of the column's vertical optical depth τ_v = min(τ |d_z|,
//     Σ τ_layer) and F_body = E μ0 max(T_d − e^(−τ_v/μ0)(1 + τ_v/μ0), 0): the body's light
//     transmitted less its direct and once-scattered beam;
//   - the once-scattered beam drawn with its phase function (silver linings, the glow of the
//     sun through thin cloud): E p(Θ)/(4π) τ (e^(−τ) − e^(−τ_s)) / (τ_s − τ), τ_s = τ_v/μ0,
//     exact single scattering in a uniform slab crossed by the sun's and the view's rays.
// Thick clouds (T_d small) have dark bases; the direct beam behind them is attenuated by
// e^(−τ) (the 1 − alpha of the composite).
CloudCover OtwCloudCover(const OtwCloudLighting& light, const glm::dvec3& d,
                         const scene::CloudHit& hit, const glm::dvec3& airlight);

// Draws the world's clouds over the sky samples of radiance (after the sun, moon and stars,
// before lightning and plumes): what lights them from state (its illuminances times the
// sky-condition divisors the world divided them by) and sky. In a band basis (channels/nvg)
// radiance and sky are in the basis and sunPerLux, moonPerLux are its sun's and moon's
// components per lx.
CloudSkyStats DrawOtwClouds(CloudSky& pass, const scene::World& world,
                            const scene::SceneState& state, const ChannelCamera& camera,
                            const VisibilityBuffer& vis, const radiometry::AnalyticSky& sky,
                            double extinction_perM, Image& radiance,
                            const glm::dvec3& sunPerLux = glm::dvec3(1.0),
                            const glm::dvec3& moonPerLux = glm::dvec3(1.0));

}  // namespace seasense::channels
