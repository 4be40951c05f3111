// Sea-surface emissivity: band-averaged complex-index Fresnel reflectance, Cox–Munk facet
// average (Masuda et al. 1988) and its (view angle × wind) tables.
#include "radiometry/sea/sea_emissivity.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "radiometry/planck/planck.h"
#include "radiometry/sea/water_index.h"
#include "scene/core/error.h"

namespace seasense::radiometry {
namespace {

constexpr int kSpectralSamples = 256;
constexpr int kFlatNodes = 4097;
// Slope-magnitude quadrature: u = 1 − exp(−s²/σ²) is uniform for the isotropic Gaussian, so a
// midpoint rule in u samples the slope distribution with equal probability per node.
constexpr int kSlopeNodes = 64;
constexpr int kAzimuthNodes = 24;

// Gauss–Legendre nodes and weights on [−1, 1] (Newton iteration on P_n; Press et al.,
// "Numerical Recipes", 3rd ed., §4.6.1).
struct GaussLegendre {
    double x[kAzimuthNodes];
    double w[kAzimuthNodes];
    GaussLegendre() {
        const int n = kAzimuthNodes;
        for (int i = 0; i < n; ++i) {
            double z = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5));
            double dp = 1.0;
            for (int iter = 0; iter < 100; ++iter) {
                double p0 = 1.0, p1 = z;
                for (int k = 2; k <= n; ++k) {
                    const double p2 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
                    p0 = p1;
                    p1 = p2;
                }
                dp = n * (z * p1 - p0) / (z * z - 1.0);
                const double dz = p1 / dp;
                z -= dz;
                if (std::abs(dz) < 1e-15) break;
            }
            x[i] = z;
            w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
        }
    }
};

const GaussLegendre& Nodes() {
    static const GaussLegendre gl;
    return gl;
}

}  // namespace

double CoxMunkSlopeVariance(double windSpeed_mps) {
    if (!std::isfinite(windSpeed_mps) || windSpeed_mps < 0.0) {
        std::ostringstream msg;
        msg << "Cox-Munk slope variance: wind speed " << windSpeed_mps
            << " m/s; expected a finite number >= 0";
        throw InputError(msg.str());
    }
    // Cox & Munk (1954) clean-surface fit, isotropic form (Masuda et al. 1988, Eq. 6).
    return 0.003 + 5.12e-3 * windSpeed_mps;
}

SeaSettings ParseSeaSettings(const scene::ConfigValue& value) {
    return scene::ReadMap(value, [](scene::ConfigMap& map) {
        SeaSettings settings;
        settings.temperature_K = map.GetDouble(
            "temperature_K", scene::NumberRange::Closed(250.0, 320.0, "K"), settings.temperature_K);
        return settings;
    });
}

SeaSurfaceEmissivity::SeaSurfaceEmissivity(const Band& band, double weightTemperature_K)
    : band_(band) {
    const auto table = HaleQuerryWaterIndex();
    const double lo = band.MinWavelength_m(), hi = band.MaxWavelength_m();
    if (lo < table.front().lambda_m || hi > table.back().lambda_m) {
        std::ostringstream msg;
        msg << "sea emissivity of band '" << band.Name() << "': its wavelengths " << lo << " .. "
            << hi << " m are not within the tabulated water index, 2.6e-06 .. 1.4e-05 m";
        throw InputError(msg.str());
    }
    if (!std::isfinite(weightTemperature_K) || weightTemperature_K <= 0.0)
        throw InputError("sea emissivity: the Planck weight temperature must be finite and > 0 K");
    // Midpoint rule over the band: the water index and R(λ) are piecewise linear, the Planck
    // weight smooth, so 256 samples converge far below the table's interpolation error.
    const double dl = (hi - lo) / kSpectralSamples;
    double sum = 0.0;
    for (int i = 0; i < kSpectralSamples; ++i) {
        const double l = lo + (i + 0.5) * dl;
        const double w = band.Response(l) * PlanckRadiance(l, weightTemperature_K) * dl;
        index_.push_back(WaterRefractiveIndex(l));
        weight_.push_back(w);
        sum += w;
    }
    if (!(sum > 0.0)) throw InputError("sea emissivity of band '" + band.Name() + "': zero weight");
    for (double& w : weight_) w /= sum;
    flatR_.resize(kFlatNodes);
    for (int i = 0; i < kFlatNodes; ++i)
        flatR_[size_t(i)] = FlatReflectanceExact(double(i) / (kFlatNodes - 1));
}

double SeaSurfaceEmissivity::FlatReflectanceExact(double cosTheta) const {
    double r = 0.0;
    for (size_t i = 0; i < index_.size(); ++i)
        r += weight_[i] * FresnelReflectanceComplex(cosTheta, index_[i]);
    return r;
}

double SeaSurfaceEmissivity::FlatReflectance(double cosTheta) const {
    const double u = std::clamp(cosTheta, 0.0, 1.0) * (kFlatNodes - 1);
    const size_t i = std::min(size_t(u), size_t(kFlatNodes - 2));
    return flatR_[i] + (flatR_[i + 1] - flatR_[i]) * (u - double(i));
}

double SeaSurfaceEmissivity::Emissivity(double cosTheta, double slopeVariance) const {
    const double c = std::clamp(cosTheta, 0.0, 1.0);
    if (!(slopeVariance >= 0.0) || !std::isfinite(slopeVariance))
        throw InputError("sea emissivity: slope variance must be finite and >= 0");
    if (slopeVariance == 0.0) return FlatEmissivity(c);
    const double sinT = std::sqrt(1.0 - c * c);
    const GaussLegendre& gl = Nodes();
    double reflected = 0.0, area = 0.0;
    for (int iu = 0; iu < kSlopeNodes; ++iu) {
        const double u = (iu + 0.5) / kSlopeNodes;
        const double s = std::sqrt(-slopeVariance * std::log1p(-u));  // slope magnitude tan β
        // A facet of slope s tilted toward azimuth α (from the view azimuth) has projected area
        // per unit horizontal area cos θ − s sin θ cos α; it is visible where that is > 0.
        const double a = s * sinT;
        const double alphaLo = a <= c ? 0.0 : std::acos(c / a);
        const double half = 0.5 * (std::numbers::pi - alphaLo);
        const double invNorm = 1.0 / std::sqrt(1.0 + s * s);
        for (int k = 0; k < kAzimuthNodes; ++k) {
            const double alpha = alphaLo + half * (gl.x[k] + 1.0);
            const double projected = std::max(0.0, c - a * std::cos(alpha));
            const double w = gl.w[k] * half * projected;
            reflected += w * FlatReflectance(projected * invNorm);  // cos χ = n̂·v̂
            area += w;
        }
    }
    if (!(area > 0.0)) return FlatEmissivity(c);
    return 1.0 - reflected / area;
}

SeaEmissivityCurve::SeaEmissivityCurve(std::vector<float> nodes) : nodes_(std::move(nodes)) {
    if (nodes_.size() < 2) throw InputError("sea emissivity curve: needs at least two nodes");
    last_ = float(nodes_.size() - 1);
}

namespace {

// The number of wind nodes (0, 1, … m/s) of a table to maxWind_mps; InputError unless it is
// finite and in [1, 60].
int WindNodes(double maxWind_mps) {
    if (!std::isfinite(maxWind_mps) || maxWind_mps < 1.0 || maxWind_mps > 60.0) {
        std::ostringstream msg;
        msg << "sea emissivity table: maximum wind " << maxWind_mps
            << " m/s; expected a number in [1, 60]";
        throw InputError(msg.str());
    }
    return int(std::ceil(maxWind_mps)) + 1;
}

// Wind node w at or below windSpeed_mps (clamped to the table) and the weight tw of node w + 1.
void WindCell(double windSpeed_mps, int windNodes, size_t& w, double& tw) {
    const double wv = std::clamp(windSpeed_mps, 0.0, double(windNodes - 1));
    w = std::min(size_t(wv), size_t(windNodes - 2));
    tw = wv - double(w);
}

// The table's nodes at wind node w (cos θ = i / (kCosNodes − 1)).
void WindColumn(const SeaSurfaceEmissivity& model, size_t w, float* out) {
    constexpr int n = SeaEmissivityTable::kCosNodes;
    for (int i = 0; i < n; ++i)
        out[i] = float(model.EmissivityForWind(double(i) / (n - 1), double(w)));
}

// The curve between two wind nodes' columns, weight tw on the second.
SeaEmissivityCurve Blend(const float* e0, const float* e1, double tw) {
    std::vector<float> nodes(SeaEmissivityTable::kCosNodes);
    for (size_t i = 0; i < nodes.size(); ++i)
        nodes[i] = float(double(e0[i]) + (double(e1[i]) - double(e0[i])) * tw);
    return SeaEmissivityCurve(std::move(nodes));
}

}  // namespace

SeaEmissivityTable::SeaEmissivityTable(const SeaSurfaceEmissivity& model, double maxWind_mps) {
    windNodes_ = WindNodes(maxWind_mps);
    table_.resize(size_t(windNodes_) * kCosNodes);
    for (int w = 0; w < windNodes_; ++w)
        WindColumn(model, size_t(w), table_.data() + size_t(w) * kCosNodes);
}

SeaEmissivityCurve SeaEmissivityTable::CurveForWind(const SeaSurfaceEmissivity& model,
                                                    double windSpeed_mps, double maxWind_mps) {
    size_t w = 0;
    double tw = 0.0;
    WindCell(windSpeed_mps, WindNodes(maxWind_mps), w, tw);
    std::vector<float> columns(2 * size_t(kCosNodes));
    WindColumn(model, w, columns.data());
    // At a whole wind speed the second node's weight is 0 and e0 + (e1 − e0) · 0 is e0 for any
    // finite e1: the first column again serves.
    if (tw > 0.0)
        WindColumn(model, w + 1, columns.data() + kCosNodes);
    else
        std::copy_n(columns.data(), kCosNodes, columns.data() + kCosNodes);
    return Blend(columns.data(), columns.data() + kCosNodes, tw);
}

double SeaEmissivityTable::Emissivity(double cosTheta, double windSpeed_mps) const {
    const double wv = std::clamp(windSpeed_mps, 0.0, MaxWind_mps());
    const size_t w = std::min(size_t(wv), size_t(windNodes_ - 2));
    const double tw = wv - double(w);
    const double u = std::clamp(cosTheta, 0.0, 1.0) * (kCosNodes - 1);
    const size_t i = std::min(size_t(u), size_t(kCosNodes - 2));
    const double tc = u - double(i);
    const auto at = [&](size_t wi, size_t ci) { return double(table_[wi * kCosNodes + ci]); };
    const double e0 = at(w, i) + (at(w, i + 1) - at(w, i)) * tc;
    const double e1 = at(w + 1, i) + (at(w + 1, i + 1) - at(w + 1, i)) * tc;
    return e0 + (e1 - e0) * tw;
}

SeaEmissivityCurve SeaEmissivityTable::Curve(double windSpeed_mps) const {
    size_t w = 0;
    double tw = 0.0;
    WindCell(windSpeed_mps, windNodes_, w, tw);
    return Blend(table_.data() + w * kCosNodes, table_.data() + (w + 1) * kCosNodes, tw);
}

}  // namespace seasense::radiometry
