// Preetham, Shirley & Smits, "A Practical Analytic Model for Daylight", SIGGRAPH 1999,
// Appendix A.2: Perez distribution coefficients and zenith values for Y, x, y.
#include "radiometry/sky/analytic_sky.h"

#include <algorithm>
#include <cmath>

#include "radiometry/color/rec709.h"

namespace seasense::radiometry {

namespace {

constexpr int kTableSize = 128;
constexpr int kHorizonSize = 512;

// Position around the horizon in [0, 4) from a horizontal direction without trigonometry:
// the perimeter parameter of the octahedral diamond |u| + |v| = 1.
float HorizonParameter(float x, float y) {
    const float s = std::abs(x) + std::abs(y);
    if (s <= 0.0f) return 0.0f;
    const float u = x / s;
    return y >= 0.0f ? 1.0f + u : 3.0f - u;
}

// Hemi-octahedral map (Engelhardt & Dachsbacher, "Octahedron Environment Maps", VMV 2008):
// unit direction with z ≥ 0 ↔ square [-1, 1]²; area distortion stays within a factor ~2.
glm::vec2 HemiOctFromDirection(glm::vec3 d) {
    d.z = std::max(d.z, 0.0f);
    const float s = std::abs(d.x) + std::abs(d.y) + d.z;
    const float u = d.x / s, v = d.y / s;
    return {u + v, u - v};
}

glm::dvec3 DirectionFromHemiOct(double a, double b) {
    const double u = 0.5 * (a + b), v = 0.5 * (a - b);
    const glm::dvec3 d{u, v, 1.0 - std::abs(u) - std::abs(v)};
    return glm::normalize(d);
}

}  // namespace

AnalyticSky::AnalyticSky(const glm::dvec3& sunDirection, double sunIlluminance_lux, double T)
    : sunDir_(glm::normalize(sunDirection)) {
    glm::dvec3 sunForSky = sunDir_;
    if (sunForSky.z < 0.0) sunForSky = glm::normalize(glm::dvec3(sunForSky.x, sunForSky.y, 0.0));
    thetaSun_ = std::acos(std::clamp(sunForSky.z, -1.0, 1.0));
    const double ts = thetaSun_;

    // Perez coefficients A..E as linear functions of turbidity (Preetham et al. 1999, A.2).
    const double y[5] = {0.1787 * T - 1.4630, -0.3554 * T + 0.4275, -0.0227 * T + 5.3251,
                         0.1206 * T - 2.5771, -0.0670 * T + 0.3703};
    const double x[5] = {-0.0193 * T - 0.2592, -0.0665 * T + 0.0008, -0.0004 * T + 0.2125,
                         -0.0641 * T - 0.8989, -0.0033 * T + 0.0452};
    const double yc[5] = {-0.0167 * T - 0.2608, -0.0950 * T + 0.0092, -0.0079 * T + 0.2102,
                          -0.0441 * T - 1.6537, -0.0109 * T + 0.0529};
    std::copy(y, y + 5, coefY_);
    std::copy(x, x + 5, coefX_);
    std::copy(yc, yc + 5, coefYc_);

    // Zenith luminance in kcd/m² and zenith chromaticity (Preetham et al. 1999, A.2).
    const double chi = (4.0 / 9.0 - T / 120.0) * (M_PI - 2.0 * ts);
    zenithY_ = 1000.0 * std::max(0.0, (4.0453 * T - 4.9710) * std::tan(chi) - 0.2155 * T + 2.4192);
    const double t2 = T * T, s3 = ts * ts * ts, s2 = ts * ts;
    zenithX_ = t2 * (0.00166 * s3 - 0.00375 * s2 + 0.00209 * ts) +
               T * (-0.02903 * s3 + 0.06377 * s2 - 0.03202 * ts + 0.00394) +
               (0.11693 * s3 - 0.21196 * s2 + 0.06052 * ts + 0.25886);
    zenithYchroma_ = t2 * (0.00275 * s3 - 0.00610 * s2 + 0.00317 * ts) +
                     T * (-0.04214 * s3 + 0.08970 * s2 - 0.04153 * ts + 0.00516) +
                     (0.15346 * s3 - 0.26756 * s2 + 0.06670 * ts + 0.26688);
    normY_ = Perez(coefY_, 1.0, ts);
    normX_ = Perez(coefX_, 1.0, ts);
    normYc_ = Perez(coefYc_, 1.0, ts);

    // The sun: white (D65, equal Rec.709 RGB) at the given illuminance; disc solid angle
    // 2π(1 − cos r).
    const double sunSolidAngle = 2.0 * M_PI * (1.0 - std::cos(kSunAngularRadius_rad));
    const double sunUp = sunDir_.z > -kSunAngularRadius_rad ? 1.0 : 0.0;
    sunIlluminanceRgb_ = glm::dvec3(sunIlluminance_lux * sunUp);
    sunRadiance_ = sunIlluminanceRgb_ / sunSolidAngle;

    table_.resize(size_t(kTableSize) * size_t(kTableSize));
    for (int j = 0; j < kTableSize; ++j) {
        for (int i = 0; i < kTableSize; ++i) {
            const double a = -1.0 + 2.0 * i / (kTableSize - 1),
                         b = -1.0 + 2.0 * j / (kTableSize - 1);
            table_[size_t(j) * kTableSize + size_t(i)] =
                glm::vec3(Radiance(DirectionFromHemiOct(a, b)));
        }
    }

    horizon_.resize(kHorizonSize + 1);
    for (int i = 0; i <= kHorizonSize; ++i) {
        const double t = 4.0 * i / kHorizonSize;  // invert HorizonParameter
        const double u = t <= 2.0 ? t - 1.0 : 3.0 - t;
        const double v = t <= 2.0 ? 1.0 - std::abs(u) : -(1.0 - std::abs(u));
        horizon_[size_t(i)] = glm::vec3(Radiance(glm::normalize(glm::dvec3(u, v, 0.0))));
    }

    // E_h = ∫ L cosθ dω over the upper hemisphere, midpoint rule in (cosθ, φ): dω = dμ dφ.
    constexpr int kMu = 64, kPhi = 128;
    glm::dvec3 sum(0.0);
    for (int j = 0; j < kMu; ++j) {
        const double mu = (j + 0.5) / kMu;
        const double s = std::sqrt(1.0 - mu * mu);
        for (int i = 0; i < kPhi; ++i) {
            const double phi = 2.0 * M_PI * (i + 0.5) / kPhi;
            sum += Radiance({s * std::sin(phi), s * std::cos(phi), mu}) * mu;
        }
    }
    skyHorizontal_ = sum * (1.0 / kMu) * (2.0 * M_PI / kPhi);
}

double AnalyticSky::Perez(const double c[5], double cosTheta, double gamma) const {
    // F(θ, γ) = (1 + A e^{B / cos θ}) (1 + C e^{D γ} + E cos² γ) (Perez, Seals & Michalsky 1993).
    cosTheta = std::max(cosTheta, 0.01);
    const double cg = std::cos(gamma);
    return (1.0 + c[0] * std::exp(c[1] / cosTheta)) *
           (1.0 + c[2] * std::exp(c[3] * gamma) + c[4] * cg * cg);
}

glm::dvec3 AnalyticSky::Radiance(const glm::dvec3& dIn) const {
    glm::dvec3 d = dIn;
    if (d.z < 0.0) d = glm::dvec3(d.x, d.y, 0.0);
    const double len = glm::length(d);
    d = len > 0.0 ? d / len : glm::dvec3(0, 0, 1);
    glm::dvec3 sunForSky = sunDir_;
    if (sunForSky.z < 0.0) sunForSky = glm::normalize(glm::dvec3(sunForSky.x, sunForSky.y, 0.0));
    const double gamma = std::acos(std::clamp(glm::dot(d, sunForSky), -1.0, 1.0));
    const double Y = zenithY_ * Perez(coefY_, d.z, gamma) / normY_;
    const double x = zenithX_ * Perez(coefX_, d.z, gamma) / normX_;
    const double y = zenithYchroma_ * Perez(coefYc_, d.z, gamma) / normYc_;
    return glm::max(Rec709FromYxy(Y, x, y), glm::dvec3(0.0));
}

glm::vec3 AnalyticSky::LookUp(const glm::vec3& d) const {
    const glm::vec2 st = HemiOctFromDirection(d);
    const float scale = 0.5f * float(kTableSize - 1);
    const float u = std::clamp((st.x + 1.0f) * scale, 0.0f, float(kTableSize - 1));
    const float v = std::clamp((st.y + 1.0f) * scale, 0.0f, float(kTableSize - 1));
    const int i0 = std::min(int(u), kTableSize - 2), j0 = std::min(int(v), kTableSize - 2);
    const float fu = u - float(i0), fv = v - float(j0);
    const glm::vec3* row0 = &table_[size_t(j0) * kTableSize];
    const glm::vec3* row1 = row0 + kTableSize;
    const glm::vec3 a = row0[i0] + (row0[i0 + 1] - row0[i0]) * fu;
    const glm::vec3 b = row1[i0] + (row1[i0 + 1] - row1[i0]) * fu;
    return a + (b - a) * fv;
}

glm::vec3 AnalyticSky::HorizonLookUp(const glm::vec3& d) const {
    const float u = HorizonParameter(d.x, d.y) * (float(kHorizonSize) / 4.0f);
    const int i = std::clamp(int(u), 0, kHorizonSize - 1);
    const float f = std::clamp(u - float(i), 0.0f, 1.0f);
    return horizon_[size_t(i)] + (horizon_[size_t(i) + 1] - horizon_[size_t(i)]) * f;
}

}  // namespace seasense::radiometry
