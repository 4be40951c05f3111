// Night-sky luminance: the moonless sky (airglow, zodiacal light, starlight) and the sky lit by
// scattered moonlight, after Krisciunas & Schaefer, "A model of the brightness of moonlight",
// PASP 103, 1033 (1991) (K&S below).
#pragma once

#include "scene/core/simd4.h"

namespace seasense::radiometry {

// One nanolambert in cd/m²: 1 L = 1/π cd/cm² = 10⁴/π cd/m².
inline constexpr double kNanoLambert_cdm2 = 1e-9 * 1e4 / 3.14159265358979323846;

// K&S's dark zenith sky in V at Mauna Kea, 79.0 nL (≈ 21.59 V mag/arcsec²): the natural floor
// of a moonless, unpolluted sky (Cinzano et al., MNRAS 328, 689 (2001) take 21.6).
inline constexpr double kDarkZenithSky_nL = 79.0;

// K&S eq. 3: the air mass of a scattering layer at zenith distance z_rad,
// X = (1 − 0.96 sin²z)^(−1/2); 1 at the zenith, 5 at the horizon.
double ScatteringAirMass(double zenith_rad);
// The same from the cosine of the zenith distance (clamped to [0, 1]):
// X = (0.04 + 0.96 cos²z)^(−1/2), no trigonometry.
double ScatteringAirMassFromCos(double cosZenith);

// Moonless sky luminance (cd/m²) at zenith distance z_rad: K&S eq. 2,
// B = B_zen · 10^(−0.4 k (X − 1)) · X: more emitting air toward the horizon (X), dimmed by
// extinction on the way (k in magnitudes per air mass, V band).
double DarkSkyLuminance_cdm2(double zenith_rad, double k_magPerAirmass,
                             double zenithLuminance_cdm2 = kDarkZenithSky_nL * kNanoLambert_cdm2);
// The same from the cosine of the zenith distance.
double DarkSkyLuminanceFromCos_cdm2(double cosZenith, double k_magPerAirmass,
                                    double zenithLuminance_cdm2);
// Four lanes of DarkSkyLuminanceFromCos_cdm2 in float (the scalar forms are its lane 0).
simd4::F4 DarkSkyLuminanceFromCos4(simd4::F4 cosZenith, float k_magPerAirmass,
                                   float zenithLuminance_cdm2);

// Luminance (cd/m²) of the sky at zenith distance z_rad lit by moonlight: K&S eqs. 15–21,
// B = f(ρ) · I* · 10^(−0.4 k X_moon) · [1 − 10^(−0.4 k X)] nL, with the scattering function
// f(ρ) = 10^5.36 (1.06 + cos²ρ) (Rayleigh) + 10^(6.15 − ρ/40) (aerosols; 6.2·10⁷ ρ⁻² below
// ρ = 8.45°, where the two meet; K&S switch at 10°), ρ the moon–sky angle in degrees, and the
// moon's brightness I* = 10^(−0.4 (3.84 + 0.026 |α| + 4·10⁻⁹ α⁴)) at phase angle α (degrees),
// scaled by the inverse square of the moon's distance from its mean 384 400 km. Zero when the
// moon's centre is more than its mean semidiameter below the horizon; between ± the semidiameter it
// fades linearly (the fraction of the disc above the horizon, to first order).
double MoonlitSkyLuminance_cdm2(double skyZenith_rad, double moonZenith_rad, double separation_rad,
                                double phaseAngle_rad, double moonDistance_m,
                                double k_magPerAirmass);

// MoonlitSkyLuminance_cdm2 for one moon and many sky directions: the factors that depend only
// on the moon (its brightness I*, distance, extinction 10^(−0.4 k X_moon) and visible fraction)
// are computed once.
class MoonlitSky {
  public:
    MoonlitSky() = default;  // no moon: every luminance is 0
    MoonlitSky(double moonZenith_rad, double phaseAngle_rad, double moonDistance_m,
               double k_magPerAirmass);
    // Luminance (cd/m²) toward a sky direction with cos zenith cosZenith at separation_rad
    // from the moon (cosSeparation = cos separation_rad, given to save the cosine).
    double Luminance_cdm2(double cosZenith, double separation_rad, double cosSeparation) const;
    // Four lanes of it in float (Luminance_cdm2 is its lane 0).
    simd4::F4 Luminance4(simd4::F4 cosZenith, simd4::F4 separation_rad,
                         simd4::F4 cosSeparation) const;
    // Whether any of the moon's disc is up (else every luminance is 0).
    bool Up() const { return scale_cdm2_ > 0.0; }

  private:
    double scale_cdm2_ = 0.0;  // visible · I* · (r̄/r)² · 10^(−0.4 k X_moon) · 1 nL
    double k_ = 0.0;
};

// Surface brightness in V magnitudes per square arcsecond of a luminance (cd/m²), by the
// conversion K&S quote from Garstang (1989): B[nL] = 34.08 exp(20.7233 − 0.92104 V).
double SurfaceBrightnessV_magPerArcsec2(double luminance_cdm2);

}  // namespace seasense::radiometry
