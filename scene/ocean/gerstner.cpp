// Gerstner (trochoidal) wave sum after Tessendorf (2001) §3 and physics.md, with linear-theory
// finite-depth orbits.
#include "scene/ocean/gerstner.h"

#include <cmath>
#include <limits>

#include "scene/core/check.h"

namespace seasense::scene {

double DispersionOmega(double k, double depth_m) {
    return std::sqrt(kGravity_mps2 * k * std::tanh(k * depth_m));
}

double PhaseSpeed(double k, double depth_m) { return DispersionOmega(k, depth_m) / k; }

double GroupSpeed(double k, double depth_m) {
    const double kh2 = 2.0 * k * depth_m;
    // For kh2 beyond ~700 sinh overflows; the correction term is 0 in deep water anyway.
    const double factor = kh2 > 50.0 ? 1.0 : 1.0 + kh2 / std::sinh(kh2);
    return 0.5 * PhaseSpeed(k, depth_m) * factor;
}

GerstnerOcean::GerstnerOcean(const OceanSettings& settings) {
    CHECK(settings.depth_m > 0.0);
    CHECK(settings.waves.size() <= kMaxWaves);
    for (const GerstnerWaveSettings& w : settings.waves) {
        CHECK(w.wavelength_m > 0.0);
        const double k = 2.0 * M_PI / w.wavelength_m;
        // Azimuth from north, clockwise: east component sin, north component cos.
        dirX_.push_back(std::sin(w.direction_rad));
        dirY_.push_back(std::cos(w.direction_rad));
        k_.push_back(k);
        omega_.push_back(DispersionOmega(k, settings.depth_m));
        amplitude_.push_back(w.amplitude_m);
        // Linear theory: surface particle orbits have vertical semi-axis A and horizontal
        // semi-axis A / tanh(kh) (Dean & Dalrymple, "Water Wave Mechanics", §4.4); Q scales
        // the horizontal part (Q = 1: the physical orbit, a trochoid in deep water).
        horizontal_.push_back(w.steepness * w.amplitude_m / std::tanh(k * settings.depth_m));
        phase_.push_back(w.phase_rad);
        maxAmplitude_m_ += w.amplitude_m;
        maxHorizontal_m_ += horizontal_.back();
        minWavelength_m_ = std::min(minWavelength_m_, w.wavelength_m);
    }
}

namespace {

// Displacement of the surface and its derivatives with respect to the rest position.
template <class Real>
struct WaveSum {
    Real dx = 0, dy = 0, z = 0;
    Real dxdx = 1, dxdy = 0, dydy = 1, dzdx = 0, dzdy = 0;
    Real vx = 0, vy = 0, vz = 0;  // ∂/∂t, filled when angular frequencies are given
};

// Σ over waves of the Gerstner displacement at rest offset (x, y), where wave i has phase
// k_i (d_i · (x, y)) + phase_i; shared by the double query path and the float mesh path. With
// a footprint s > 0 (m) each wave is weighted by FootprintWeight (band-limited sampling); with
// omega, the velocity ∂P/∂t for phases advancing as −ω t is summed too. With weights (the
// FootprintWeight of each wave, computed once for many points of one footprint) the footprint
// is not used.
template <class Real>
WaveSum<Real> SumWaves(size_t n, const Real* dirX, const Real* dirY, const Real* k,
                       const Real* amplitude, const Real* horizontal, const Real* phase, Real x,
                       Real y, Real footprint = 0, const Real* omega = nullptr,
                       const Real* weights = nullptr) {
    WaveSum<Real> w;
    for (size_t i = 0; i < n; ++i) {
        const Real weight = weights               ? weights[i]
                            : footprint > Real(0) ? GerstnerFootprintWeight(k[i], footprint)
                                                  : 1;
        if (weight <= Real(0)) continue;
        const Real theta = k[i] * (dirX[i] * x + dirY[i] * y) + phase[i];
        const Real s = std::sin(theta), c = std::cos(theta);
        const Real h = weight * horizontal[i], a = weight * amplitude[i];
        w.dx -= dirX[i] * h * s;
        w.dy -= dirY[i] * h * s;
        w.z += a * c;
        const Real hkc = h * k[i] * c;
        w.dxdx -= dirX[i] * dirX[i] * hkc;
        w.dxdy -= dirX[i] * dirY[i] * hkc;
        w.dydy -= dirY[i] * dirY[i] * hkc;
        const Real aks = a * k[i] * s;
        w.dzdx -= dirX[i] * aks;
        w.dzdy -= dirY[i] * aks;
        if (omega) {
            // θ = ... − ω t: ∂(−sin θ)/∂t = ω cos θ, ∂(cos θ)/∂t = ω sin θ.
            w.vx += dirX[i] * h * omega[i] * c;
            w.vy += dirY[i] * h * omega[i] * c;
            w.vz += a * omega[i] * s;
        }
    }
    return w;
}

// Upward unit normal from the tangents ∂P/∂x0 = (dxdx, dxdy, dzdx), ∂P/∂y0 = (dxdy, dydy, dzdy).
template <class Real>
glm::vec<3, Real> UpwardNormal(const WaveSum<Real>& w) {
    using V = glm::vec<3, Real>;
    V nrm = glm::cross(V(w.dxdx, w.dxdy, w.dzdx), V(w.dxdy, w.dydy, w.dzdy));
    const Real len = glm::length(nrm);
    nrm = len > Real(0) ? nrm / len : V(0, 0, 1);
    return nrm.z < Real(0) ? -nrm : nrm;  // folded surface: keep the normal upward
}

// Adds a float wave sum to mesh sums {η, Dx, Dy, ∂η/∂x, ∂η/∂y, ∂Dx/∂x, ∂Dy/∂y, ∂Dx/∂y}.
void AddTerms(const WaveSum<float>& w, float sums[8]) {
    const float terms[8] = {w.z, w.dx, w.dy, w.dzdx, w.dzdy, w.dxdx - 1.0f, w.dydy - 1.0f, w.dxdy};
    for (int i = 0; i < 8; ++i) sums[i] += terms[i];
}

}  // namespace

SurfaceSample GerstnerOcean::Evaluate(double x0, double y0, double t) const {
    const size_t n = k_.size();
    double phase[kMaxWaves];
    for (size_t i = 0; i < n; ++i) phase[i] = phase_[i] - omega_[i] * t;
    const WaveSum<double> w = SumWaves(n, dirX_.data(), dirY_.data(), k_.data(), amplitude_.data(),
                                       horizontal_.data(), phase, x0, y0);
    SurfaceSample out;
    out.position = {x0 + w.dx, y0 + w.dy, w.z};
    out.normal = UpwardNormal(w);
    out.jacobian = w.dxdx * w.dydy - w.dxdy * w.dxdy;
    return out;
}

SurfaceTerms GerstnerOcean::Terms(double x0, double y0, double t, double footprint_m) const {
    const size_t n = k_.size();
    double phase[kMaxWaves];
    for (size_t i = 0; i < n; ++i) phase[i] = phase_[i] - omega_[i] * t;
    const WaveSum<double> w =
        SumWaves(n, dirX_.data(), dirY_.data(), k_.data(), amplitude_.data(), horizontal_.data(),
                 phase, x0, y0, footprint_m, omega_.data());
    SurfaceTerms out;
    out.displacement = {w.dx, w.dy, w.z};
    out.dxx = w.dxdx - 1.0;
    out.dyy = w.dydy - 1.0;
    out.dxy = w.dxdy;
    out.sx = w.dzdx;
    out.sy = w.dzdy;
    out.velocity_mps = {w.vx, w.vy, w.vz};
    return out;
}

double GerstnerOcean::MaxElevationNear_m(double x, double y, double radius_m, double t) const {
    return ElevationBoundNear_m(x, y, radius_m, t, std::numeric_limits<double>::infinity());
}

double GerstnerOcean::ElevationBoundNear_m(double x, double y, double radius_m, double t,
                                           double maxFootprint_m) const {
    CHECK(radius_m >= 0.0 && maxFootprint_m >= 0.0);
    // The mesh forms its weights in float (LocalFrame::FootprintWeights): a margin far above
    // their rounding.
    constexpr double kWeightMargin = 1e-5;
    double bound = 0.0;
    for (size_t i = 0; i < k_.size(); ++i) {
        // The rest positions within the disc have phases within k r of the centre's (|d| = 1).
        const double half = k_[i] * radius_m + kPhaseMargin_rad;
        const double centre = std::remainder(
            k_[i] * (dirX_[i] * x + dirY_[i] * y) - omega_[i] * t + phase_[i], 2.0 * M_PI);
        // cos is largest at the crest (θ ≡ 0) when the interval holds it, else at the end nearer
        // to it; a wave's weighted elevation w A cos θ, w ∈ [0, 1], is then at most A times the
        // positive part.
        const double c =
            std::abs(centre) <= half ? 1.0 : std::cos(std::max(std::abs(centre) - half, 0.0));
        if (c >= 0.0) {
            bound += amplitude_[i] * c;
        } else if (std::isfinite(maxFootprint_m)) {
            // The weight falls as the footprint grows; 1 for a footprint of 0.
            const double w = maxFootprint_m > 0.0
                                 ? GerstnerFootprintWeight(k_[i], maxFootprint_m) - kWeightMargin
                                 : 1.0 - kWeightMargin;
            if (w > 0.0) bound += w * amplitude_[i] * c;
        }
    }
    return std::min(bound, maxAmplitude_m_);
}

GerstnerOcean::LocalFrame GerstnerOcean::Local(double ox, double oy, double t) const {
    LocalFrame f;
    for (size_t i = 0; i < k_.size(); ++i) {
        f.dirX_.push_back(float(dirX_[i]));
        f.dirY_.push_back(float(dirY_[i]));
        f.k_.push_back(float(k_[i]));
        f.amplitude_.push_back(float(amplitude_[i]));
        f.horizontal_.push_back(float(horizontal_[i]));
        const double phase = k_[i] * (dirX_[i] * ox + dirY_[i] * oy) - omega_[i] * t + phase_[i];
        f.phase0_.push_back(float(std::remainder(phase, 2.0 * M_PI)));
    }
    return f;
}

void GerstnerOcean::LocalFrame::Accumulate(float rx, float ry, float footprint_m,
                                           float sums[8]) const {
    AddTerms(SumWaves(k_.size(), dirX_.data(), dirY_.data(), k_.data(), amplitude_.data(),
                      horizontal_.data(), phase0_.data(), rx, ry, footprint_m),
             sums);
}

void GerstnerOcean::LocalFrame::FootprintWeights(float footprint_m, float* weights) const {
    for (size_t i = 0; i < k_.size(); ++i)
        weights[i] = footprint_m > 0.0f ? GerstnerFootprintWeight(k_[i], footprint_m) : 1.0f;
}

void GerstnerOcean::LocalFrame::Accumulate(float rx, float ry, const float* weights,
                                           float sums[8]) const {
    AddTerms(SumWaves(k_.size(), dirX_.data(), dirY_.data(), k_.data(), amplitude_.data(),
                      horizontal_.data(), phase0_.data(), rx, ry, 0.0f,
                      static_cast<const float*>(nullptr), weights),
             sums);
}

void GerstnerOcean::LocalFrame::Evaluate(float rx, float ry, glm::vec3& position, glm::vec3& normal,
                                         float& jacobian) const {
    const WaveSum<float> w =
        SumWaves(k_.size(), dirX_.data(), dirY_.data(), k_.data(), amplitude_.data(),
                 horizontal_.data(), phase0_.data(), rx, ry);
    position = {rx + w.dx, ry + w.dy, w.z};
    normal = UpwardNormal(w);
    jacobian = w.dxdx * w.dydy - w.dxdy * w.dxdy;
}

SurfaceSample GerstnerOcean::SampleAt(double x, double y, double t) const {
    // Fixed-point iteration x0 ← x0 + (x − P_h(x0)); contracts while the horizontal map is
    // not folded (|∂D/∂x0| < 1), which holds for physical steepness (k A < 1).
    double x0 = x, y0 = y;
    SurfaceSample s = Evaluate(x0, y0, t);
    for (int iter = 0; iter < 32; ++iter) {
        const double ex = x - s.position.x, ey = y - s.position.y;
        if (ex * ex + ey * ey < 1e-18) break;
        x0 += ex;
        y0 += ey;
        s = Evaluate(x0, y0, t);
    }
    return s;
}

double GerstnerOcean::HeightAt(double x, double y, double t) const {
    return SampleAt(x, y, t).position.z;
}

}  // namespace seasense::scene
