// Spectral bands: a named, piecewise-linear relative spectral response over wavelength.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace seasense::radiometry {

// A spectral band: relative response R(λ) given at increasing wavelength samples (m) and
// linear between them; R = 0 outside [first, last] sample, so a band with equal weights at
// its two ends has sharp edges. Weights are relative (unitless): band radiance is
// ∫ R(λ) L_λ dλ, not normalised by ∫ R dλ.
class Band {
  public:
    // Throws InputError unless: name non-empty; at least two samples; wavelengths finite,
    // > 0 and strictly increasing; weights finite and ≥ 0 with at least one > 0; and
    // wavelengths_m.size() == weights.size().
    Band(std::string name, std::vector<double> wavelengths_m, std::vector<double> weights);
    // Same from (wavelength_m, weight) pairs, e.g. a user-supplied response curve.
    Band(std::string name, const std::vector<std::pair<double, double>>& curve);

    // Ideal band: response 1 on [lambdaMin_m, lambdaMax_m], 0 outside (sharp edges).
    static Band Flat(std::string name, double lambdaMin_m, double lambdaMax_m);
    // Mid-wave infrared 3–5 µm, flat (the MWIR atmospheric window; physics.md).
    static Band Mwir();
    // Long-wave infrared 8–12 µm, flat (the LWIR atmospheric window; physics.md).
    static Band Lwir();

    const std::string& Name() const { return name_; }
    const std::vector<double>& Wavelengths_m() const { return wavelengths_m_; }
    const std::vector<double>& Weights() const { return weights_; }
    double MinWavelength_m() const { return wavelengths_m_.front(); }
    double MaxWavelength_m() const { return wavelengths_m_.back(); }

    // Relative response at lambda_m (m): linear between samples, 0 outside the band.
    double Response(double lambda_m) const;

  private:
    std::string name_;
    std::vector<double> wavelengths_m_;
    std::vector<double> weights_;
};

}  // namespace seasense::radiometry
