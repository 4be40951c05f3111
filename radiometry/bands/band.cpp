// Spectral band construction, validation and response lookup.
#include "radiometry/bands/band.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "scene/core/error.h"

namespace seasense::radiometry {

Band::Band(std::string name, std::vector<double> wavelengths_m, std::vector<double> weights)
    : name_(std::move(name)),
      wavelengths_m_(std::move(wavelengths_m)),
      weights_(std::move(weights)) {
    const auto fail = [&](const std::string& what) {
        throw InputError("spectral band '" + name_ + "': " + what);
    };
    if (name_.empty()) fail("the band name must not be empty");
    if (wavelengths_m_.size() != weights_.size()) {
        std::ostringstream msg;
        msg << wavelengths_m_.size() << " wavelengths but " << weights_.size()
            << " weights; expected one weight per wavelength";
        fail(msg.str());
    }
    if (wavelengths_m_.size() < 2) fail("needs at least two (wavelength, weight) samples");
    bool anyPositive = false;
    for (size_t i = 0; i < wavelengths_m_.size(); ++i) {
        const double lambda = wavelengths_m_[i], w = weights_[i];
        std::ostringstream msg;
        msg << "sample " << i << " (wavelength " << lambda << " m, weight " << w << "): ";
        if (!std::isfinite(lambda) || lambda <= 0.0)
            fail(msg.str() + "wavelength must be finite and > 0 (metres)");
        if (i > 0 && !(lambda > wavelengths_m_[i - 1]))
            fail(msg.str() + "wavelengths must be strictly increasing");
        if (!std::isfinite(w) || w < 0.0) fail(msg.str() + "weight must be finite and >= 0");
        anyPositive = anyPositive || w > 0.0;
    }
    if (!anyPositive) fail("all weights are zero; expected at least one weight > 0");
}

namespace {
std::vector<double> Firsts(const std::vector<std::pair<double, double>>& curve) {
    std::vector<double> out;
    out.reserve(curve.size());
    for (const auto& p : curve) out.push_back(p.first);
    return out;
}
std::vector<double> Seconds(const std::vector<std::pair<double, double>>& curve) {
    std::vector<double> out;
    out.reserve(curve.size());
    for (const auto& p : curve) out.push_back(p.second);
    return out;
}
}  // namespace

Band::Band(std::string name, const std::vector<std::pair<double, double>>& curve)
    : Band(std::move(name), Firsts(curve), Seconds(curve)) {}

Band Band::Flat(std::string name, double lambdaMin_m, double lambdaMax_m) {
    return Band(std::move(name), {lambdaMin_m, lambdaMax_m}, {1.0, 1.0});
}

Band Band::Mwir() { return Flat("MWIR", 3.0e-6, 5.0e-6); }

Band Band::Lwir() { return Flat("LWIR", 8.0e-6, 12.0e-6); }

double Band::Response(double lambda_m) const {
    if (!(lambda_m >= wavelengths_m_.front() && lambda_m <= wavelengths_m_.back())) return 0.0;
    const auto it = std::upper_bound(wavelengths_m_.begin(), wavelengths_m_.end(), lambda_m);
    if (it == wavelengths_m_.end()) return weights_.back();
    const size_t i = size_t(it - wavelengths_m_.begin()) - 1;
    const double t = (lambda_m - wavelengths_m_[i]) / (wavelengths_m_[i + 1] - wavelengths_m_[i]);
    return weights_[i] + t * (weights_[i + 1] - weights_[i]);
}

}  // namespace seasense::radiometry
