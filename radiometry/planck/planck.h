// Planck blackbody radiometry: spectral, band and photon radiance, dL/dT, the inverse
// (band radiance → temperature) and a fast per-pixel lookup table.
#pragma once

#include <cstddef>
#include <vector>

#include "radiometry/bands/band.h"

namespace seasense::radiometry {

// Exact SI defining constants (CODATA 2018; BIPM SI Brochure, 9th ed., 2019).
inline constexpr double kPlanck_J_s = 6.62607015e-34;
inline constexpr double kSpeedOfLight_m_s = 299792458.0;
inline constexpr double kBoltzmann_J_K = 1.380649e-23;
// First radiation constant for spectral radiance, c1L = 2hc² = 1.191042972e-16 W·m²·sr⁻¹,
// and second radiation constant c2 = hc/k = 1.438776877e-2 m·K (CODATA 2018).
inline constexpr double kPlanckC1_W_m2_sr =
    2.0 * kPlanck_J_s * kSpeedOfLight_m_s * kSpeedOfLight_m_s;
inline constexpr double kPlanckC2_m_K = kPlanck_J_s * kSpeedOfLight_m_s / kBoltzmann_J_K;

// Blackbody spectral radiance L_λ = c1 / (λ⁵ (exp(c2/(λT)) − 1)) (Planck 1901) at
// wavelength lambda_m (m, in vacuum) and temperature T_K (K), in W·m⁻²·sr⁻¹·m⁻¹.
// Throws InputError unless both arguments are finite and > 0.
double PlanckRadiance(double lambda_m, double T_K);
// ∂L_λ/∂T at (lambda_m, T_K), in W·m⁻²·sr⁻¹·m⁻¹·K⁻¹.
double PlanckRadianceDerivative(double lambda_m, double T_K);
// Blackbody spectral photon radiance L_p = L_λ·λ/(hc), in photons·s⁻¹·m⁻²·sr⁻¹·m⁻¹.
double PlanckPhotonRadiance(double lambda_m, double T_K);
// ∂L_p/∂T, in photons·s⁻¹·m⁻²·sr⁻¹·m⁻¹·K⁻¹.
double PlanckPhotonRadianceDerivative(double lambda_m, double T_K);

// Band radiance L_B(T) = ∫ R(λ) L_λ(λ, T) dλ in W·m⁻²·sr⁻¹ (R relative, see Band).
// Exact to rounding for the piecewise-linear response: each segment is a combination of
// closed-form moments ∫₀^λ λ'^j L_λ dλ' (Widger & Woodall 1976 series), no quadrature.
// Throws InputError unless T_K is finite and > 0.
double BandRadiance(const Band& band, double T_K);
// dL_B/dT in W·m⁻²·sr⁻¹·K⁻¹.
double BandRadianceDerivative(const Band& band, double T_K);
// Band photon radiance ∫ R(λ) L_p(λ, T) dλ in photons·s⁻¹·m⁻²·sr⁻¹.
double BandPhotonRadiance(const Band& band, double T_K);
// Its temperature derivative in photons·s⁻¹·m⁻²·sr⁻¹·K⁻¹.
double BandPhotonRadianceDerivative(const Band& band, double T_K);
// Inverse of BandRadiance: the blackbody temperature (K) whose band radiance is
// radiance_W_m2_sr, by Newton's method on ln L_B with a bisection bracket; relative accuracy
// ~1e-13. Throws InputError unless the radiance is finite and > 0 and the temperature lies in
// (0, 1e9] K.
double BandTemperature(const Band& band, double radiance_W_m2_sr);

// Band radiance tabulated over [minT_K, maxT_K] for per-pixel use: ln L_B and d(ln L_B)/dT
// at nodes every ~step_K, cubic Hermite interpolation of ln L_B in T (smooth in T even
// where L_B varies over many decades). With the default 2 K step (1176 nodes, 28 KB) the
// relative error is < 1e-7 for the MWIR and LWIR bands over 150–2500 K (error ∝ step⁴). Outside the
// table range every call falls back to the exact direct evaluation (BandRadiance, BandTemperature):
// results stay correct, only slower. The table keeps its own copy of the band.
class BandRadianceTable {
  public:
    // Throws InputError unless 0 < minT_K < maxT_K, 0 < step_K ≤ maxT_K − minT_K (all finite)
    // and the band's radiance at minT_K is a positive normal double.
    explicit BandRadianceTable(Band band, double minT_K = 150.0, double maxT_K = 2500.0,
                               double step_K = 2.0);

    const Band& GetBand() const { return band_; }
    double MinTemperature_K() const { return minT_K_; }
    double MaxTemperature_K() const { return maxT_K_; }

    // L_B(T_K) in W·m⁻²·sr⁻¹. Throws InputError unless T_K is finite and > 0.
    double Radiance(double T_K) const;
    // Radiance(T_K[k]) into out[k] for k < n, each the bits of its own call: the polynomials of
    // the values in the table's range first, then their exponentials (one library call each,
    // none between the polynomials), the others Radiance's direct evaluation. For callers with
    // many temperatures at once (a plume cell's pixels), saving a call per value.
    void Radiances(size_t n, const double* T_K, double* out) const;
    // dL_B/dT in W·m⁻²·sr⁻¹·K⁻¹. Throws InputError unless T_K is finite and > 0.
    double RadianceDerivative(double T_K) const;
    // Temperature (K) of the blackbody with band radiance radiance_W_m2_sr, inverting the
    // same interpolant. Throws InputError unless the radiance is finite and > 0.
    double Temperature(double radiance_W_m2_sr) const;

  private:
    // The cubic Hermite polynomial of ln L_B over one cell in its local coordinate t ∈ [0, 1],
    // p(t) = lnL + t(m0 + t(c2 + t c3)), its coefficients formed once from the nodes.
    struct Cell {
        double lnL;     // ln(L_B / (W·m⁻²·sr⁻¹)) at the cell's first node
        double m0;      // d(ln L_B)/dT there, times the cell width
        double c2, c3;  // 3Δ − 2m0 − m1 and m0 + m1 − 2Δ (Δ the rise of ln L_B over the cell)
    };
    // Cubic Hermite ln L_B at cell i, local coordinate t ∈ [0, 1]; slope in t if wanted.
    double Interpolate(size_t i, double t, double* dlnLdt) const;

    Band band_;
    double minT_K_, maxT_K_, step_K_;
    std::vector<Cell> cells_;
    std::vector<double> lnL_;  // ln L_B at the nodes (cells_[i].lnL and the last node's)
};

}  // namespace seasense::radiometry
