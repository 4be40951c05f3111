// Clear sky radiance in scene-linear Rec.709 luminance units (cd/m²): Preetham's daylight
// distribution scaled to measured clear-sky illuminance through sunset and twilight, the
// moonless night sky and the moonlit sky; the sun disc; direction tables for lookups.
#pragma once

#include <cstddef>
#include <glm/glm.hpp>
#include <optional>
#include <vector>

#include "radiometry/sky/night_sky.h"

namespace seasense::radiometry {

// Angular radius of the sun seen from Earth, mean (IAU nominal solar radius 695 700 km at
// 1 au = 149 597 870.7 km → 0.2666°).
inline constexpr double kSunAngularRadius_rad = 4.6526e-3;

// Everything that lights the sky dome, in the local ENU frame.
struct SkyConditions {
    glm::dvec3 sunDirection{0.0, 0.0, 1.0};  // unit vector toward the sun (apparent)
    double sunIlluminance_lux = 0.0;         // on a plane normal to the sun, at the ground
    double turbidity = 2.5;                  // Preetham's T (clear 2, hazy 6+)
    // Moonless sky at the zenith (K&S eq. 2); 0 leaves the night sky out.
    double darkZenithLuminance_cdm2 = kDarkZenithSky_nL * kNanoLambert_cdm2;
    // V-band extinction (mag per air mass) for the night and moonlit sky; K&S's Mauna Kea
    // value by default, ZenithExtinctionV_mag of the observer's height in a scenario.
    double extinctionV_magPerAirmass = 0.172;
    bool moon = false;                         // add the moonlit sky (K&S eqs. 15–21)
    glm::dvec3 moonDirection{0.0, 0.0, -1.0};  // unit vector toward the moon (apparent)
    double moonPhaseAngle_rad = 3.14159265358979323846;
    double moonDistance_m = 3.844e8;
    // --- Band basis (channels/nvg) ---
    // When set, the three components are not Rec.709 but the sub-bands of another band (NVG:
    // radiometry/nvg): the daylight sky is its luminance × daylight, the moonless night sky
    // × night, the moonlit sky × moonlit (each: that light's component per cd/m²).
    struct BandBasis {
        glm::dvec3 daylight{1.0}, night{1.0}, moonlit{1.0};
    };
    std::optional<BandBasis> basis{};
};

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
    // The daylight part has Preetham's distribution (shape and chromaticity) for the sun at
    // its elevation, or on the horizon in its azimuth once it has set, scaled so that the
    // dome's horizontal illuminance is scene::ClearSkyDiffuseIlluminance_lux of the sun's
    // altitude: the IES clear sky by day (Preetham's own zenith-luminance fit is 2–14 times
    // brighter than measured skies at low sun; Zotti, Wilkie & Purgathofer, WSCG 2007), Circular
    // 171's twilight fall-off after sunset, nothing below −18°. Added to it: the moonless night
    // sky and, when the moon is given, the sky lit by the moon (radiometry/sky/night_sky.h),
    // both grey (equal Rec.709 components).
    explicit AnalyticSky(const SkyConditions& conditions);
    // Daylight sky with the moonless night sky and no moon.
    AnalyticSky(const glm::dvec3& sunDirection, double sunIlluminance_lux, double turbidity);

    // Sky radiance (cd/m², linear Rec.709) toward unit ENU direction d, without the sun disc.
    // Directions below the horizon see the horizon's radiance. Evaluated in float by the same
    // four-lane code that builds the table (within ~1e-5 of the formulas in double precision).
    glm::dvec3 Radiance(const glm::dvec3& d) const;
    // As Radiance, bilinear from a precomputed table over the upper hemisphere in the
    // hemi-octahedral parameterisation (no trigonometry per lookup); within 1 % of Radiance
    // more than 10° from the sun.
    glm::vec3 LookUp(const glm::vec3& d) const;

    // Radiance at the horizon (elevation 0) in the azimuth of the horizontal part of d, from
    // a 1-D table: the airlight colour of distant fog.
    glm::vec3 HorizonLookUp(const glm::vec3& d) const;

    // Batched LookUp / HorizonLookUp over n directions in structure-of-arrays form (x[i],
    // y[i], z[i]), writing rgb to r[i], g[i], b[i]. simd::kLanes at a time (eight in the AVX2
    // build; texels by 16-byte loads, blended per lane); every lane does exactly the scalar
    // arithmetic, so results equal the one-at-a-time calls bit for bit whatever the batch size or a
    // sample's position in it.
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

    // Factor applied to Preetham's own luminance for the daylight part (see the constructor).
    double DaylightScale() const { return dayScale_; }
    const SkyConditions& Conditions() const { return conditions_; }

  private:
    // Four-lane float forms over unit directions (x, y, z) with z ≥ 0 (the scalar functions are
    // their lane 0): Perez's F(θ, γ) for Y, x and y (Preetham's three coefficient sets);
    // Preetham's radiance (no daylight scale); the grey night sky (moonless and moonlit);
    // Radiance.
    void Perez4(simd4::F4 cosTheta, simd4::F4 gamma, simd4::F4 cosGamma, simd4::F4 (&F)[3]) const;
    void Preetham4(simd4::F4 x, simd4::F4 y, simd4::F4 z, simd4::F4 (&rgb)[3]) const;
    // The night sky's luminance (cd/m²): the moonless sky plus the moonlit sky, which is also
    // returned alone through moonlit when given.
    simd4::F4 Night4(simd4::F4 x, simd4::F4 y, simd4::F4 z, simd4::F4* moonlit = nullptr) const;
    void Radiance4(simd4::F4 x, simd4::F4 y, simd4::F4 z, simd4::F4 (&rgb)[3]) const;

    SkyConditions conditions_;
    glm::dvec3 sunDir_;
    glm::dvec3 moonDir_{0.0, 0.0, -1.0};
    MoonlitSky moonlit_;    // no moon unless conditions.moon
    glm::dvec3 sunForSky_;  // the sun, or its azimuth on the horizon once it has set
    double dayScale_ = 1.0;
    glm::dvec3 sunRadiance_;
    glm::dvec3 sunIlluminanceRgb_;
    double thetaSun_;
    double zenithY_, zenithX_, zenithYchroma_;
    double coefY_[5], coefX_[5], coefYc_[5];
    double normY_, normX_, normYc_;
    glm::dvec3 skyHorizontal_{0.0};
    // kTableSize², hemi-octahedral map of the upper hemisphere; rgb padded to 16 bytes (a
    // texel's float index is 4 × its index).
    std::vector<glm::vec4> table_;
    std::vector<glm::vec4> horizon_;  // kHorizonSize + 1 entries around the horizon
};

}  // namespace seasense::radiometry
