// FLIR clouds: band radiance of cloud layers, grey bodies at the lapse-rate temperature of
// where the ray enters them, seen through the path, over the clear sky behind.
#pragma once

#include <functional>
#include <glm/glm.hpp>

#include "channels/cloud/cloud_sky.h"
#include "radiometry/planck/planck.h"

namespace seasense::channels {

// Water-vapour scale height for the path below a cloud: 2 km, the H_w of the clear-sky model
// (radiometry/atmosphere; e.g. Wallace & Hobbs, "Atmospheric Science", 2nd ed. 2006, §3.2:
// 2–3 km), whose continuum dominates the window bands' absorption.
inline constexpr double kWaterVapourScaleHeight_m = 2000.0;

struct FlirCloudOptics {
    const radiometry::BandRadianceTable* table = nullptr;  // the channel's band
    double surfaceAir_K = 288.15;                          // air temperature at sea level (z = 0)
    double airRadiance = 0.0;                              // band B(T_air), W·m⁻²·sr⁻¹
    // Horizontal transmittance of the surface air over a range (m) in the channel's band.
    std::function<double(double range_m)> transmittance;
};

// The cover of a ray in unit direction d that met cloud (hit): emissivity
// ε = CloudInfraredEmissivity(τ) of the ray's visible optical depth, and the cloud's band
// radiance at the aperture τ_p B(T_c) + (1 − τ_p) B(T_air), T_c the standard-atmosphere
// temperature (AirTemperature_K) at the altitude where the ray enters the cloud (an optically
// thick cloud emits from its first infrared optical depths, within a few tens of metres of the
// entry), τ_p the band transmittance of the path to it (the surface air's over the
// water-vapour-equivalent horizontal path, EquivalentHorizontalPath_m), B(T_air) its emission.
// So the pixel reads (1 − ε) L_sky + ε [τ_p B(T_c) + (1 − τ_p) B(T_air)]: the clear sky's
// radiance (which holds the path to space) where the cloud is transparent.
CloudCover FlirCloudCover(const FlirCloudOptics& optics, const glm::dvec3& eye, const glm::dvec3& d,
                          const scene::CloudHit& hit);

}  // namespace seasense::channels
