// Ocean wave variance spectra (Phillips, Pierson–Moskowitz, JONSWAP, TMA), directional spreading
// (cos^2s after Mitsuyasu and Hasselmann, Donelan–Banner sech²) and an optional swell system.
#pragma once

#include <limits>
#include <numbers>
#include <optional>

namespace seasense::scene {

// ---- frequency spectra S(ω): variance density in m²·s/rad, ω in rad/s -------------------------

// Pierson & Moskowitz (1964): S(ω) = α g² ω⁻⁵ exp(−β (ω₀/ω)⁴), α = 8.1e-3, β = 0.74,
// ω₀ = g / U19.5, wind speed U19.5 at 19.5 m above the sea (m/s).
double PiersonMoskowitzSpectrum(double omega_radps, double windSpeed19_5_mps);

// Wind speed at 19.5 m from the wind at 10 m: U19.5 ≈ 1.026 U10 (Stewart, "Introduction to
// Physical Oceanography", 2008, §16.3, for a neutral log profile with C_D = 1.3e-3).
double WindSpeed19_5(double windSpeed10_mps);

// Peak angular frequency of the Pierson–Moskowitz spectrum, ω_p = (4β/5)^¼ g/U19.5
// ≈ 0.877 g/U19.5 (rad/s), for the wind at 10 m (m/s).
double PiersonMoskowitzPeakOmega(double windSpeed10_mps);

// Hasselmann et al. (1973) JONSWAP: α g² ω⁻⁵ exp(−5/4 (ω_p/ω)⁴) γ^r,
// r = exp(−(ω − ω_p)² / (2 σ² ω_p²)), σ = σ_a for ω ≤ ω_p and σ_b above.
double JonswapSpectrum(double omega_radps, double alpha, double omegaPeak_radps, double gamma,
                       double sigmaA = 0.07, double sigmaB = 0.09);

// Fetch-limited JONSWAP parameters (Hasselmann et al. 1973): with ξ = g F / U10²,
// α = 0.076 ξ^−0.22 and ω_p = 22 (g/U10) ξ^(−1/3). Growth stops at full development: ξ is
// capped where ω_p reaches the Pierson–Moskowitz peak. fetch_m = +∞ means fully developed.
struct JonswapParameters {
    double alpha = 0.0;
    double omegaPeak_radps = 0.0;
};
JonswapParameters JonswapFromFetch(double windSpeed10_mps, double fetch_m);

// Wavenumber k (rad/m) of a linear wave of angular frequency ω (rad/s) in depth h (m): the root
// of ω² = g k tanh(k h), solved by Newton iteration from Fenton & McKee's (1990) explicit
// approximation. Exact to ~1e-14 relative.
double WavenumberForOmega(double omega_radps, double depth_m);

// Kitaigorodskii, Krasitskii & Zaslavskii (1975) depth factor of the TMA spectrum (Bouws et al.
// 1985): Φ(ω, h) = [k⁻³ ∂k/∂ω]_h / [k⁻³ ∂k/∂ω]_∞, evaluated exactly from the dispersion
// relation (→ 1 in deep water, → ½ ω² h / g in shallow water). Dimensionless.
double KitaigorodskiiFactor(double omega_radps, double depth_m);

// ---- directional spreading D(θ), 1/rad, ∫_{−π}^{π} D dθ = 1
// --------------------------------------

// theta is the direction of travel relative to the mean direction, radians.
enum class SpreadingModel {
    Mitsuyasu,      // cos^2s, s(ω) after Mitsuyasu et al. (1975)
    Hasselmann,     // cos^2s, s(ω) after Hasselmann, Dunckel & Ewing (1980)
    DonelanBanner,  // sech², Donelan, Hamilton & Hui (1985) with Banner's (1990) tail
};

// Longuet-Higgins, Cartwright & Smith (1963) normalised cos^2s(θ/2):
// D = Γ(s+1) / (2√π Γ(s+½)) · cos^2s(θ/2).
double Cos2sSpreading(double theta_rad, double s);

// Mitsuyasu et al. (1975) spreading exponent: s_p = 11.5 (ω_p U10/g)^−2.5 times (ω/ω_p)^5 below
// the peak and (ω/ω_p)^−2.5 above it.
double MitsuyasuExponent(double omega_radps, double omegaPeak_radps, double windSpeed10_mps);

// Hasselmann et al. (1980): s = 6.97 (ω/ω_p)^4.06 below the peak, 9.77 (ω/ω_p)^μ above with
// μ = −2.33 − 1.45 (U10/c_p − 1.17), c_p = g/ω_p.
double HasselmannExponent(double omega_radps, double omegaPeak_radps, double windSpeed10_mps);

// Donelan, Hamilton & Hui (1985): D = β / (2 tanh βπ) sech²(βθ), β = 2.61 (ω/ω_p)^1.3 below
// 0.95 ω_p, 2.28 (ω/ω_p)^−0.65 up to 1.6 ω_p and 10^(−0.4 + 0.8393 exp(−0.567 ln((ω/ω_p)²)))
// beyond (Banner 1990), as collected by Horvath (2015).
double DonelanBannerSpreading(double theta_rad, double omega_radps, double omegaPeak_radps);

double DirectionalSpreading(SpreadingModel model, double theta_rad, double omega_radps,
                            double omegaPeak_radps, double windSpeed10_mps);

// ---- a complete directional sea --------------------------------------------------------------

enum class SpectrumModel { Phillips, PiersonMoskowitz, Jonswap, Tma };

// Tessendorf's (2001, eq. 40) Phillips spectrum with the extensions of seed 003 (Lachman):
// P(k) = α k⁻⁴ (k L)^(4−p) exp(−1/(k L)²) |k̂·ŵ|^n · (f if k̂·ŵ < 0) · exp(−k² ℓ²), L = U10²/g.
// p = 4, n = 2, f = 1, ℓ = 0 is Tessendorf's form. The default α = 8.1e-3/π makes the p = 4,
// n = 2, f = 0 spectrum match the Phillips saturation range of Pierson–Moskowitz, whose tail in
// wavenumber space is (α_PM/2) k⁻⁴ D(θ) with D = (2/π) cos²θ.
struct PhillipsSettings {
    double alpha = 8.1e-3 / std::numbers::pi;  // dimensionless
    double exponent = 4.0;                     // p: power law of the wavenumber spectrum, > 1
    double alignmentExponent = 2.0;            // n: ≥ 0, larger aligns waves closer to the wind
    double againstWindFactor = 0.0;  // f in [0, 1]: 0 removes waves travelling against the wind
    double smallWaveCutoff_m = 0.0;  // ℓ: suppresses wavelengths ≲ 2π ℓ
};

// A swell system: a narrow JONSWAP-shaped spectrum with its own height, period and direction,
// added to the wind sea.
struct SwellSettings {
    double significantHeight_m = 1.0;  // Hs = 4√m0 of the swell alone
    double peakPeriod_s = 12.0;        // T_p = 2π/ω_p
    double direction_rad = 0.0;        // direction of travel, azimuth from north clockwise
    double gamma = 3.3;                // JONSWAP peak enhancement (Hasselmann et al. 1973 mean)
    // Peak cos^2s exponent with Mitsuyasu's frequency dependence; Goda ("Random Seas and Design
    // of Maritime Structures", 2000, §2.3) recommends 25 for swell of short and 75 for swell
    // of long decay distance.
    double spreadingPeak = 75.0;
};

// Fully resolved parameters of a directional sea (see scene/ocean/sea_state.h for presets).
struct SpectrumSettings {
    SpectrumModel model = SpectrumModel::Jonswap;
    SpreadingModel spreading = SpreadingModel::DonelanBanner;
    double windSpeed_mps = 10.0;     // U10, at 10 m
    double windDirection_rad = 0.0;  // direction the wind blows toward, azimuth from north cw
    double fetch_m = std::numeric_limits<double>::infinity();  // JONSWAP/TMA; ∞: fully developed
    double depth_m = 1.0e4;  // water depth, TMA factor and dispersion
    double gamma = 3.3;      // JONSWAP peak enhancement (Hasselmann et al. 1973 mean)
    double sigmaA = 0.07;    // JONSWAP peak width below ω_p
    double sigmaB = 0.09;    // JONSWAP peak width above ω_p
    // When set, the wind sea is rescaled to this Hs = 4√m0 (its shape unchanged).
    std::optional<double> significantHeight_m;
    // When set, replaces the peak period from wind and fetch (not for Phillips).
    std::optional<double> peakPeriod_s;
    PhillipsSettings phillips;
    std::optional<SwellSettings> swell;
};

// A directional variance spectrum of wind sea plus optional swell.
class WaveSpectrum {
  public:
    // Throws InputError for parameters outside their physical range.
    explicit WaveSpectrum(const SpectrumSettings& settings);

    const SpectrumSettings& Settings() const { return settings_; }

    // Directional variance density in wavenumber space, m⁴ (m² per (rad/m)²), at the
    // wavevector (kx east, ky north) in rad/m pointing along the direction of travel:
    // F(k) = Σ S(ω) D(θ) c_g / k over wind sea and swell, so that ∫∫ F dkx dky = m0.
    double DensityK(double kx_radpm, double ky_radpm) const;

    // Omnidirectional frequency spectrum of wind sea plus swell, m²·s/rad.
    double DensityOmega(double omega_radps) const;

    // Total variance m0 = ∫ S dω (m²) and significant height 4√m0 (m), by quadrature.
    double Variance_m2() const { return variance_m2_; }
    double SignificantHeight_m() const;

    // Peak angular frequency of the wind sea (rad/s) and the longest peak wavelength of wind
    // sea and swell (m), for choosing FFT patch sizes. Zero wind and no swell: 0 and 0.
    double PeakOmega_radps() const { return omegaPeak_; }
    double LongestPeakWavelength_m() const { return longestPeakWavelength_m_; }

  private:
    double WindSeaOmega(double omega) const;  // unscaled S(ω) of the wind sea
    double SwellOmega(double omega) const;
    double PhillipsK(double k, double cosTheta) const;

    SpectrumSettings settings_;
    double windSeaScale_ = 1.0;  // multiplies the wind sea to reach a requested Hs
    double swellScale_ = 0.0;    // multiplies the swell shape to reach its Hs
    double omegaPeak_ = 0.0;
    double alpha_ = 0.0;  // JONSWAP/TMA α
    double swellOmegaPeak_ = 0.0;
    double phillipsLength_m_ = 0.0;     // L = U²/g
    double phillipsDirectional_ = 0.0;  // ∫ |cos θ|^n (1 or f) dθ
    double variance_m2_ = 0.0;
    double longestPeakWavelength_m_ = 0.0;
};

}  // namespace seasense::scene
