// Gerstner (trochoidal) wave sum after Tessendorf (2001) §3 and physics.md, with linear-theory
// finite-depth orbits.
#include "scene/ocean/gerstner.h"

#include <cmath>

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

SurfaceSample GerstnerOcean::Evaluate(double x0, double y0, double t) const {
    double dx = 0.0, dy = 0.0, z = 0.0;
    // Partial derivatives of the displaced position with respect to (x0, y0).
    double dxdx = 1.0, dxdy = 0.0, dydy = 1.0, dzdx = 0.0, dzdy = 0.0;
    const size_t n = k_.size();
    for (size_t i = 0; i < n; ++i) {
        const double theta = k_[i] * (dirX_[i] * x0 + dirY_[i] * y0) - omega_[i] * t + phase_[i];
        const double s = std::sin(theta), c = std::cos(theta);
        const double h = horizontal_[i];
        dx -= dirX_[i] * h * s;
        dy -= dirY_[i] * h * s;
        z += amplitude_[i] * c;
        const double hkc = h * k_[i] * c;
        dxdx -= dirX_[i] * dirX_[i] * hkc;
        dxdy -= dirX_[i] * dirY_[i] * hkc;
        dydy -= dirY_[i] * dirY_[i] * hkc;
        const double aks = amplitude_[i] * k_[i] * s;
        dzdx -= dirX_[i] * aks;
        dzdy -= dirY_[i] * aks;
    }
    SurfaceSample out;
    out.position = {x0 + dx, y0 + dy, z};
    // Tangents ∂P/∂x0 = (dxdx, dxdy, dzdx), ∂P/∂y0 = (dxdy, dydy, dzdy); normal = their cross.
    const glm::dvec3 tx{dxdx, dxdy, dzdx}, ty{dxdy, dydy, dzdy};
    glm::dvec3 nrm = glm::cross(tx, ty);
    const double len = glm::length(nrm);
    out.normal = len > 0.0 ? nrm / len : glm::dvec3(0.0, 0.0, 1.0);
    if (out.normal.z < 0.0) out.normal = -out.normal;  // folded surface: keep the normal upward
    out.jacobian = dxdx * dydy - dxdy * dxdy;
    return out;
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

void GerstnerOcean::LocalFrame::Evaluate(float rx, float ry, glm::vec3& position, glm::vec3& normal,
                                         float& jacobian) const {
    // The same sums as GerstnerOcean::Evaluate, in float.
    float dx = 0.0f, dy = 0.0f, z = 0.0f;
    float dxdx = 1.0f, dxdy = 0.0f, dydy = 1.0f, dzdx = 0.0f, dzdy = 0.0f;
    const size_t n = k_.size();
    for (size_t i = 0; i < n; ++i) {
        const float theta = k_[i] * (dirX_[i] * rx + dirY_[i] * ry) + phase0_[i];
        const float s = std::sin(theta), c = std::cos(theta);
        const float h = horizontal_[i];
        dx -= dirX_[i] * h * s;
        dy -= dirY_[i] * h * s;
        z += amplitude_[i] * c;
        const float hkc = h * k_[i] * c;
        dxdx -= dirX_[i] * dirX_[i] * hkc;
        dxdy -= dirX_[i] * dirY_[i] * hkc;
        dydy -= dirY_[i] * dirY_[i] * hkc;
        const float aks = amplitude_[i] * k_[i] * s;
        dzdx -= dirX_[i] * aks;
        dzdy -= dirY_[i] * aks;
    }
    position = {rx + dx, ry + dy, z};
    glm::vec3 nrm = glm::cross(glm::vec3(dxdx, dxdy, dzdx), glm::vec3(dxdy, dydy, dzdy));
    const float len = glm::length(nrm);
    nrm = len > 0.0f ? nrm / len : glm::vec3(0.0f, 0.0f, 1.0f);
    normal = nrm.z < 0.0f ? -nrm : nrm;
    jacobian = dxdx * dydy - dxdy * dxdy;
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
