// Clear-sky infrared radiance by direction, and transmission and path radiance over a range,
// per band, from air temperature, humidity and visibility; the at-aperture radiance equation.
#pragma once

#include <cstddef>
#include <vector>

#include "radiometry/bands/band.h"
#include "scene/config/config.h"

namespace seasense::radiometry {

// Near-surface air: the user-facing settings of this module.
struct AtmosphereSettings {
    double airTemperature_K = 288.15;  // 15 °C
    double relativeHumidity = 0.75;    // fraction in [0, 1]
    double pressure_Pa = 101325.0;     // standard sea-level pressure
};
// Reads a mapping with the optional keys air_temperature_K (K, [200, 330]), relative_humidity
// (fraction, [0, 1]) and pressure_Pa (Pa, [5e4, 1.1e5]). Unknown keys and bad values throw
// ConfigError naming the key path.
AtmosphereSettings ParseAtmosphereSettings(const scene::ConfigValue& value);

// Saturation vapour pressure over water (Pa) at T_K: Bolton (1980), Mon. Wea. Rev. 108, 1046,
// Eq. 10, e_s = 611.2 exp(17.67 t / (t + 243.5)), t in °C.
double SaturationVapourPressure_Pa(double T_K);

// Clear-sky broadband hemispherical emissivity of Brutsaert (1975), Water Resour. Res. 11, 742:
// ε = 1.24 (e / T)^(1/7), e the screen-level vapour pressure in hPa, T in K.
double BrutsaertEmissivity(double vapourPressure_Pa, double T_K);

// Wavelength exponent q of aerosol extinction β ∝ λ^−q for visibility V: Kruse, McGlauchlin &
// McQuistan, "Elements of Infrared Technology" (Wiley 1962): q = 1.6 (V > 50 km), 1.3
// (6–50 km); below 6 km Kim, McArthur & Korevaar, Proc. SPIE 4214, 26 (2001): 0.16 V + 0.34
// (1–6 km), V − 0.5 (0.5–1 km), 0 (< 0.5 km), V in km.
double KruseKimExponent(double visibility_m);
// Aerosol extinction coefficient (m⁻¹) at lambda_m: the Koschmieder value 3.912 / V at 0.55 µm
// (2 % contrast threshold; physics.md) scaled by (λ / 0.55 µm)^−q.
double AerosolExtinction_per_m(double lambda_m, double visibility_m);

// Water-vapour continuum absorption coefficient (m⁻¹) in the 8–12 µm window (Roberts, Selby &
// Biberman 1976, Appl. Opt. 15, 2085): k(ν, T) = [1.25e-22 + 1.67e-19 exp(−7.87e-3 ν)]
// exp[1800 (1/T − 1/296)] cm² molecule⁻¹ atm⁻¹, ν in cm⁻¹, times the water number density
// and the broadening pressure e + 0.002 (P − e) in atm. Applied at all wavelengths ≥ 7 µm;
// 0 below (the continuum of the 3–5 µm window is an order of magnitude weaker and ignored).
double WaterContinuumAbsorption_per_m(double lambda_m, double T_K, double vapourPressure_Pa,
                                      double pressure_Pa);

// The clear atmosphere seen in one band. Spectral model (our composition of the cited parts):
//   - zenith optical depth τ_z(λ) of an isothermal slab at the air temperature, the sum of
//     the water continuum (self part over a water-vapour scale height H_w/2, foreign part over
//     H_w, H_w = 2 km), aerosol (Kruse/Kim extinction over the 1 km maritime aerosol scale
//     height of OPAC, Hess, Koepke & Schult 1998, Bull. Am. Meteorol. Soc. 79, 831), saturated
//     absorption bands (H2O 2.55–2.85 µm and 5.5–7.6 µm, CO2 4.17–4.47 µm and 13.5–17 µm, H2O
//     rotation beyond 17 µm; positions after Wolfe & Zissis, "The Infrared Handbook", 1978,
//     ch. 5) with τ_z = 30, and one grey "line background" depth τ_b chosen so that the
//     broadband hemispherical emissivity of the slab equals Brutsaert's (0 if the other parts
//     already exceed it), applied at wavelengths ≥ 2.5 µm only;
//   - sky radiance toward zenith angle θ: Σ_λ R B(λ, T_air) (1 − exp(−τ_z / cos θ)), so cold at
//     the zenith, monotone in θ and equal to B_band(T_air) at the horizon;
//   - horizontal transmission over range r: Σ_λ w_λ exp(−α(λ) r), α the surface absorption
//     coefficients of the same parts (τ_z over their scale heights; CO2 over 8 km), weights
//     w_λ ∝ R B(λ, T_air); path radiance (1 − τ) B_band(T_air).
class Atmosphere {
  public:
    // Throws InputError for settings out of the ranges of ParseAtmosphereSettings, a visibility
    // that is not finite and > 0, or a band outside 0.2–100 µm.
    Atmosphere(const Band& band, const AtmosphereSettings& settings, double visibility_m);

    const Band& GetBand() const { return band_; }
    double VapourPressure_Pa() const { return vapourPressure_Pa_; }
    // Broadband longwave irradiance of the clear sky on a horizontal surface (W·m⁻²):
    // Brutsaert's ε σ T_air⁴, the driver of the materials' heat balance.
    double SkyLongwaveIrradiance_W_m2() const;
    // The grey background optical depth τ_b of the Brutsaert closure.
    double BackgroundOpticalDepth() const { return tauBackground_; }
    // Band radiance of a blackbody at the air temperature, W·m⁻²·sr⁻¹.
    double AirRadiance() const { return airRadiance_; }

    // Exact spectral sums (for tests and tables).
    // Sky band radiance (W·m⁻²·sr⁻¹) toward a direction with zenith cosine cosZenith; directions
    // at or below the horizon (cosZenith ≤ 0) see the horizon, B_band(T_air).
    double SkyRadiance(double cosZenith) const;
    // Band transmittance of a horizontal path of range_m ≥ 0 metres.
    double Transmittance(double range_m) const;
    // Path radiance (1 − τ) B_band(T_air) of that path, W·m⁻²·sr⁻¹.
    double PathRadiance(double range_m) const {
        return (1.0 - Transmittance(range_m)) * airRadiance_;
    }

    // Table lookups for per-pixel use: sky over cos θ ∈ [0, 1] (257 nodes, linear), and
    // transmittance over u = ln(1 + r / 10 m) for r ∈ [0, 200 km] (513 nodes, linear; longer
    // ranges use the 200 km value). Both within 1e-3 relative of the exact sums (tests).
    float SkyLookUp(float cosZenith) const;
    float TransmittanceLookUp(float range_m) const;
    void SkyLookUp(size_t n, const float* cosZenith, float* radiance) const;
    void TransmittanceLookUp(size_t n, const float* range_m, float* transmittance) const;

  private:
    Band band_;
    double airTemperature_K_;
    double vapourPressure_Pa_;
    double tauBackground_ = 0.0;
    double airRadiance_ = 0.0;
    std::vector<double> weight_;   // R B(λ, T_air) Δλ / Σ, per spectral sample
    std::vector<double> tauZ_;     // zenith optical depth per spectral sample
    std::vector<double> alpha_;    // horizontal absorption coefficient (m⁻¹) per sample
    std::vector<float> skyTable_;  // SkyRadiance at cos θ = i / (size − 1)
    std::vector<float> tauTable_;  // Transmittance at u = i / (size − 1) · uMax
};

// At-aperture band radiance of a surface point (W·m⁻²·sr⁻¹): τ·[ε·B(T) + (1 − ε)·L_sky] +
// (1 − τ)·B(T_air), with transmittance tau, emissivity emissivity, the surface's blackbody band
// radiance surfaceBlackbody, the reflected sky radiance skyReflected and the air's blackbody
// band radiance airBlackbody (physics.md, "Thermal infrared").
inline double ApertureRadiance(double tau, double emissivity, double surfaceBlackbody,
                               double skyReflected, double airBlackbody) {
    return tau * (emissivity * surfaceBlackbody + (1.0 - emissivity) * skyReflected) +
           (1.0 - tau) * airBlackbody;
}

}  // namespace seasense::radiometry
