// Preetham, Shirley & Smits, "A Practical Analytic Model for Daylight", SIGGRAPH 1999,
// Appendix A.2: Perez distribution coefficients and zenith values for Y, x, y.
#include "radiometry/sky/analytic_sky.h"

#include <algorithm>
#include <cmath>

#include "radiometry/color/rec709.h"

namespace seasense::radiometry {

namespace {
constexpr int kTableAz = 256;
constexpr int kTableEl = 64;
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

    table_.resize(size_t(kTableAz) * size_t(kTableEl + 1));
    for (int j = 0; j <= kTableEl; ++j) {
        const double el = 0.5 * M_PI * double(j) / kTableEl;
        for (int i = 0; i < kTableAz; ++i) {
            const double az = 2.0 * M_PI * double(i) / kTableAz;
            const glm::dvec3 d{std::cos(el) * std::sin(az), std::cos(el) * std::cos(az),
                               std::sin(el)};
            table_[size_t(j) * kTableAz + size_t(i)] = glm::vec3(Radiance(d));
        }
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
    return (1.0 + c[0] * std::exp(c[1] / cosTheta)) * (1.0 + c[2] * std::exp(c[3] * gamma) + c[4] * cg * cg);
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
    const float horiz = std::sqrt(d.x * d.x + d.y * d.y);
    float el = std::atan2(std::max(d.z, 0.0f), horiz);
    float az = std::atan2(d.x, d.y);
    if (az < 0.0f) az += float(2.0 * M_PI);
    const float u = az * float(kTableAz / (2.0 * M_PI));
    const float v = std::min(el * float(kTableEl / (0.5 * M_PI)), float(kTableEl));
    int i0 = int(u), j0 = int(v);
    const float fu = u - float(i0), fv = v - float(j0);
    i0 %= kTableAz;
    const int i1 = (i0 + 1) % kTableAz;
    const int j1 = std::min(j0 + 1, kTableEl);
    const glm::vec3* row0 = &table_[size_t(j0) * kTableAz];
    const glm::vec3* row1 = &table_[size_t(j1) * kTableAz];
    const glm::vec3 a = row0[i0] + (row0[i1] - row0[i0]) * fu;
    const glm::vec3 b = row1[i0] + (row1[i1] - row1[i0]) * fu;
    return a + (b - a) * fv;
}

}  // namespace seasense::radiometry
