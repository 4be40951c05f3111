// Analytic clear daylight sky (Preetham, Shirley & Smits 1999) in scene-linear Rec.709
// luminance units (cd/m²), with the sun disc and a direction table for per-sample lookups.
#pragma once

#include <cstddef>
#include <glm/glm.hpp>
#include <vector>

namespace seasense::radiometry {

// Angular radius of the sun seen from Earth, mean (IAU nominal solar radius 695 700 km at
// 1 au = 149 597 870.7 km → 0.2666°).
inline constexpr double kSunAngularRadius_rad = 4.6526e-3;

// Illuminance (lx, Rec.709 RGB; D65 white, so equal components) of the sun on a plane normal
// to it: sunIlluminance_lux while the top of the disc is above the horizon, else 0.
glm::dvec3 SunIlluminanceRgb(const glm::dvec3& sunDirection, double sunIlluminance_lux);
// Solid angle of the sun's disc, sr: 2π(1 − cos r).
double SunDiscSolidAngle_sr();

// sunDirection (unit ENU) with its elevation and azimuth rounded to multiples of step_rad: a
// pure function of the direction, so that a sky table built for the result can be reused
// while the sun moves less than a step. The result is at most step_rad / √2 from the input.
glm::dvec3 QuantizeSunDirection(const glm::dvec3& sunDirection, double step_rad);

class AnalyticSky {
  public:
    // sunDirection: unit ENU vector toward the sun. sunIlluminance_lux: illuminance on a
    // plane normal to the sun. turbidity: Preetham's T (clear 2, hazy 6+). The sky's own
    // luminance comes from Preetham's zenith-luminance fit; it is valid for sun elevations
    // ≥ 0 (the sun is held at the horizon below that: twilight belongs to the sky model of
    // the ephemeris issue).
    AnalyticSky(const glm::dvec3& sunDirection, double sunIlluminance_lux, double turbidity);

    // Sky radiance (cd/m², linear Rec.709) toward unit ENU direction d, without the sun disc.
    // Directions below the horizon see the horizon's radiance.
    glm::dvec3 Radiance(const glm::dvec3& d) const;
    // As Radiance, bilinear from a precomputed table over the upper hemisphere in the
    // hemi-octahedral parameterisation (no trigonometry per lookup); within 1 % of Radiance
    // more than 10° from the sun.
    glm::vec3 LookUp(const glm::vec3& d) const;

    // Radiance at the horizon (elevation 0) in the azimuth of the horizontal part of d, from
    // a 1-D table: the airlight colour of distant fog.
    glm::vec3 HorizonLookUp(const glm::vec3& d) const;

    // Batched LookUp / HorizonLookUp over n directions in structure-of-arrays form (x[i],
    // y[i], z[i]), writing rgb to r[i], g[i], b[i]. Four lanes at a time with SSE2; every
    // lane does exactly the scalar arithmetic, so results equal the one-at-a-time calls bit
    // for bit whatever the batch size or a sample's position in it.
    void LookUp(size_t n, const float* x, const float* y, const float* z, float* r, float* g,
                float* b) const;
    void HorizonLookUp(size_t n, const float* x, const float* y, float* r, float* g,
                       float* b) const;

    // Sun disc luminance (cd/m², Rec.709 RGB): illuminance / solid angle of the disc.
    glm::dvec3 SunRadiance() const { return sunRadiance_; }
    glm::dvec3 SunIlluminance() const { return sunIlluminanceRgb_; }
    const glm::dvec3& SunDirection() const { return sunDir_; }

    // Illuminance (lx, RGB) from the sky dome alone on an upward horizontal surface, by
    // numerical integration of L·cosθ over the hemisphere.
    glm::dvec3 HorizontalSkyIlluminance() const { return skyHorizontal_; }

  private:
    double Perez(const double coeffs[5], double cosTheta, double gamma) const;

    glm::dvec3 sunDir_;
    glm::dvec3 sunRadiance_;
    glm::dvec3 sunIlluminanceRgb_;
    double thetaSun_;
    double zenithY_, zenithX_, zenithYchroma_;
    double coefY_[5], coefX_[5], coefYc_[5];
    double normY_, normX_, normYc_;
    glm::dvec3 skyHorizontal_{0.0};
    // kTableSize², hemi-octahedral map of the upper hemisphere; rgb padded to 16 bytes so a
    // batched lookup loads one texel per instruction and transposes four of them.
    std::vector<glm::vec4> table_;
    std::vector<glm::vec4> horizon_;  // kHorizonSize + 1 entries around the horizon
};

}  // namespace seasense::radiometry
