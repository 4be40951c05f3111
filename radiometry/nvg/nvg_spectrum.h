// Image-intensifier spectral basis: three photocathode sub-bands, the photon response of a
// photocathode, and per-source conversions from photometric to sub-band photon quantities.
#pragma once

#include <array>
#include <functional>
#include <glm/glm.hpp>

#include "radiometry/bands/band.h"

namespace seasense::radiometry {

// Edges (m) of the three NVG sub-bands: 350–600, 600–750, 750–950 nm. Together they cover the
// Gen II (S-25, ≈ 380–920 nm) and Gen III (GaAs, ≈ 450–930 nm) photocathodes (physics.md,
// radiometry/bands/builtin_bands). Component k of an NVG band-basis radiance is
// ∫_{sub-band k} P(λ) L_p(λ) dλ, P the photon response below and L_p the spectral photon
// radiance (photons s⁻¹ m⁻² sr⁻¹ m⁻¹), so the sum of the components is the photocathode-
// weighted photon radiance.
inline constexpr std::array<double, 4> kNvgSubBandEdges_m{350e-9, 600e-9, 750e-9, 950e-9};

// Relative spectral density of a source (any scale): power per unit wavelength at lambda_m.
using Spectrum = std::function<double(double lambda_m)>;

// The photon (quantum-efficiency) response of a photocathode, peak 1, from its band's relative
// radiant sensitivity S(λ) (per watt): QE ∝ S(λ)/λ, since a watt at λ carries λ/(hc) photons.
class PhotonResponse {
  public:
    explicit PhotonResponse(const Band& radiantSensitivity);
    // Relative quantum efficiency at lambda_m (peak 1; 0 outside the band).
    double operator()(double lambda_m) const;
    const Band& GetBand() const { return band_; }

  private:
    Band band_;
    double scale_ = 1.0;  // 1 / max over λ of S(λ)/λ
};

// The three sub-band integrals ∫_{k} P(λ) · spectrum(λ) · λ/(hc) dλ of a spectral power density
// (W·m⁻²·sr⁻¹·m⁻¹ → photons s⁻¹ m⁻² sr⁻¹), trapezoid rule on a 1 nm grid.
glm::dvec3 SubBandPhotons(const PhotonResponse& response, const Spectrum& spectrum);

// Sub-band photon radiance of a blackbody at T_K (photons s⁻¹ m⁻² sr⁻¹ per component).
glm::dvec3 BlackbodySubBandPhotons(const PhotonResponse& response, double T_K);

// Photometric quantity of a spectral power density: 683 lm/W · ∫ ȳ(λ) spectrum(λ) dλ (CIE 1931
// ȳ of radiometry/bands CieY), lx for an irradiance, cd/m² for a radiance.
double Photometric(const Spectrum& spectrum);

// Source spectra (relative; every use divides by Photometric of the same spectrum):
// Sunlight: a 5778 K blackbody (the sun's effective temperature, IAU 2015 Resolution B3
// nominal 5772 K; the extra-atmospheric spectrum in the 400–950 nm range follows it within
// ~10 %, Gueymard 2004, Solar Energy 76).
Spectrum SunSpectrum();
// Moonlight: sunlight × the lunar disc reflectance, which rises from ≈ 0.07 at 400 nm to
// ≈ 0.15 at 950 nm, roughly linearly (ROLO lunar model: Kieffer & Stone 2005, Astron. J. 129,
// 2887, Fig. 16): the moon is redder than the sun (B−V 0.92 vs 0.65, Allen's Astrophysical
// Quantities, 4th ed., §12.5).
Spectrum MoonSpectrum();
// Sky light scattered by air: source × λ⁻⁴ (Rayleigh scattering).
Spectrum RayleighScattered(const Spectrum& source);
// Moonless clear night sky (airglow, zodiacal light, starlight): spectral radiance through the
// dark-sky surface brightness at La Palma, B 22.7, V 21.9, R 21.0, I 20.0 mag arcsec⁻² (Benn &
// Ellison 1998, New Astron. Rev. 42, 503, Table 2), converted with the Johnson–Cousins zero
// points f_λ(0) = 6.32e-9, 3.631e-9, 2.177e-9, 1.126e-9 erg s⁻¹ cm⁻² Å⁻¹ at 438, 545, 641,
// 798 nm (Bessell, Castelli & Plez 1998, A&A 333, 231, Table A2); linear between the bands,
// held constant outside them (beyond 800 nm the OH airglow keeps rising, so the NIR is a lower
// bound).
Spectrum NightSkySpectrum();
// Lightning: the return-stroke channel as a blackbody at 28 000 K (peak channel temperatures
// 28 000–31 000 K from N II line ratios, Orville 1968, J. Atmos. Sci. 25, 827). The real
// spectrum adds strong N I/O I lines at 747, 777 and 868 nm (Orville & Henderson 1984, J.
// Atmos. Sci. 41, 3180), so its NIR share is a lower bound.
Spectrum LightningSpectrum();
// A blackbody at T_K (stars at their colour temperature, flames).
Spectrum BlackbodySpectrum(double T_K);

// Photon radiance per unit photometric quantity: SubBandPhotons / Photometric of the spectrum
// (photons s⁻¹ m⁻² sr⁻¹ per cd/m², equally photons s⁻¹ m⁻² per lx).
glm::dvec3 PhotonsPerPhotometric(const PhotonResponse& response, const Spectrum& spectrum);

// Per-component diffuse reflectance of a surface from its visible Rec.709 reflectance (R, G, B
// at ≈ 610, 550, 465 nm) and its 0.6–0.9 µm reflectance (material table reflectance_nir):
// 350–600 nm the mean of green and blue, 600–750 nm the mean of red and NIR, 750–950 nm NIR.
glm::dvec3 SubBandReflectance(const glm::dvec3& reflectanceRgb, double reflectanceNir);

}  // namespace seasense::radiometry
