// Infrared emissivity and reflectivity of the sea surface: Fresnel with water's complex index
// (Hale & Querry 1973), band-averaged with a Planck weight, and averaged over Cox–Munk wave
// slopes after Masuda, Takashima & Takayama (1988), tabulated over view angle and wind.
#pragma once

#include <algorithm>
#include <complex>
#include <cstddef>
#include <vector>

#include "radiometry/bands/band.h"
#include "scene/config/config.h"

namespace seasense::radiometry {

// Isotropic (upwind and crosswind equal) mean-square wave slope for wind speed U at 12.5 m,
// σ² = 0.003 + 5.12e-3 U (Cox & Munk 1954, J. Opt. Soc. Am. 44, 838, clean surface, as used by
// Masuda et al. 1988, Remote Sens. Environ. 24, 313, Eq. 6). Throws InputError unless
// windSpeed_mps is finite and ≥ 0.
double CoxMunkSlopeVariance(double windSpeed_mps);

// Thermal state of the sea: the user-facing settings of this module.
struct SeaSettings {
    double temperature_K = 288.15;  // sea-surface (skin) temperature; 15 °C
};
// Reads a mapping with the optional key temperature_K (K, in [250, 320]). Unknown keys and bad
// values throw ConfigError naming the key path.
SeaSettings ParseSeaSettings(const scene::ConfigValue& value);

// Sea-surface emissivity of one band. The spectral Fresnel reflectance ρ(λ, θ) is averaged over
// the band with the weight R(λ)·B(λ, T_w) (B: Planck, T_w the weight temperature), which is the
// emissivity that turns B_band(T) into emitted band radiance for T near T_w.
class SeaSurfaceEmissivity {
  public:
    // Throws InputError unless the band lies within 2.6–14 µm (the tabulated water index) and
    // weightTemperature_K is finite and > 0.
    explicit SeaSurfaceEmissivity(const Band& band, double weightTemperature_K = 290.0);

    const Band& GetBand() const { return band_; }

    // Band-averaged Fresnel reflectance of a flat sea at view-zenith cosine cosTheta, by the
    // exact spectral sum (slow; for tests and tables).
    double FlatReflectanceExact(double cosTheta) const;
    // The same, interpolated from a 4097-node table over cos θ ∈ [0, 1].
    double FlatReflectance(double cosTheta) const;
    double FlatEmissivity(double cosTheta) const { return 1.0 - FlatReflectance(cosTheta); }

    // Emissivity of a rough sea seen at view-zenith cosine cosTheta: 1 − the reflectance of
    // the facets seen from that direction, each facet weighted by its slope probability
    // (isotropic Gaussian of variance slopeVariance) and its area projected on the view
    // direction (Masuda et al. 1988, Eq. 4). Facets facing away from the viewer are excluded
    // and the weights renormalised over the visible ones, which equals Masuda's normalisation
    // by cos θ wherever no facet is hidden; shadowing and reflected sea emission are ignored
    // as in Masuda. slopeVariance = 0 is the flat sea.
    double Emissivity(double cosTheta, double slopeVariance) const;
    double EmissivityForWind(double cosTheta, double windSpeed_mps) const {
        return Emissivity(cosTheta, CoxMunkSlopeVariance(windSpeed_mps));
    }

  private:
    Band band_;
    std::vector<std::complex<double>> index_;  // water index at each spectral sample
    std::vector<double> weight_;               // normalised weight of each sample
    std::vector<double> flatR_;                // FlatReflectanceExact at cos θ = i / (size − 1)
};

// Emissivity against view-zenith cosine for one wind speed: a float table (129 nodes, linear
// in cos θ) for per-pixel lookups. Reflectivity of the sea toward the sky is 1 − emissivity
// (Kirchhoff's law for an opaque surface).
class SeaEmissivityCurve {
  public:
    explicit SeaEmissivityCurve(std::vector<float> nodes);
    // cosTheta is clamped to [0, 1].
    float Emissivity(float cosTheta) const {
        const float u = std::clamp(cosTheta, 0.0f, 1.0f) * last_;
        const size_t i = std::min(size_t(u), nodes_.size() - 2);
        return nodes_[i] + (nodes_[i + 1] - nodes_[i]) * (u - float(i));
    }
    // eps[k] = Emissivity(cosTheta[k]) for k < n.
    void Emissivity(size_t n, const float* cosTheta, float* eps) const {
        for (size_t k = 0; k < n; ++k) eps[k] = Emissivity(cosTheta[k]);
    }
    const std::vector<float>& Nodes() const { return nodes_; }

  private:
    std::vector<float> nodes_;
    float last_;  // nodes_.size() − 1
};

// SeaSurfaceEmissivity::EmissivityForWind tabulated over (cos θ, wind): 129 nodes in cos θ on
// [0, 1] × wind 0, 1, …, maxWind_mps m/s, bilinear. Absolute error against the direct
// quadrature < 2e-3 (checked in tests).
class SeaEmissivityTable {
  public:
    static constexpr int kCosNodes = 129;
    // Throws InputError unless maxWind_mps is finite and in [1, 60].
    explicit SeaEmissivityTable(const SeaSurfaceEmissivity& model, double maxWind_mps = 30.0);

    double MaxWind_mps() const { return double(windNodes_ - 1); }
    // Wind is clamped to [0, MaxWind_mps()], cosTheta to [0, 1].
    double Emissivity(double cosTheta, double windSpeed_mps) const;
    // The curve for one wind speed (per frame), interpolated between wind nodes.
    SeaEmissivityCurve Curve(double windSpeed_mps) const;
    // SeaEmissivityTable(model, maxWind_mps).Curve(windSpeed_mps), bit for bit, from only the
    // one or two wind nodes it interpolates (a channel of one wind needs no more: the whole table
    // is 31 nodes of 129 × 64 × 24 facets each). Throws as the constructor.
    static SeaEmissivityCurve CurveForWind(const SeaSurfaceEmissivity& model, double windSpeed_mps,
                                           double maxWind_mps = 30.0);

  private:
    int windNodes_;
    std::vector<float> table_;  // [wind][cos]
};

}  // namespace seasense::radiometry
