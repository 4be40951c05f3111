// NVG sub-band photon integrals and the spectra of the night scene's light sources.
#include "radiometry/nvg/nvg_spectrum.h"

#include <algorithm>
#include <cmath>

#include "radiometry/bands/builtin_bands.h"
#include "radiometry/planck/planck.h"
#include "scene/core/check.h"

namespace seasense::radiometry {

namespace {

constexpr double kNm = 1e-9;
// Luminous efficacy of radiation at 555 nm (SI definition of the candela), lm/W.
constexpr double kMaxLuminousEfficacy_lm_W = 683.0;

// Trapezoid rule of f over [a, b] on 1 nm steps (the bands are piecewise linear on ≥ 5 nm).
double Integrate(const std::function<double(double)>& f, double a, double b) {
    const int steps = std::max(1, int(std::lround((b - a) / kNm)));
    const double h = (b - a) / steps;
    double sum = 0.5 * (f(a) + f(b));
    for (int i = 1; i < steps; ++i) sum += f(a + i * h);
    return sum * h;
}

// Linear interpolation through (x_i, y_i), constant outside.
double PiecewiseLinear(const std::vector<std::pair<double, double>>& xy, double x) {
    if (x <= xy.front().first) return xy.front().second;
    if (x >= xy.back().first) return xy.back().second;
    for (size_t i = 1; i < xy.size(); ++i) {
        if (x <= xy[i].first) {
            const double t = (x - xy[i - 1].first) / (xy[i].first - xy[i - 1].first);
            return xy[i - 1].second + t * (xy[i].second - xy[i - 1].second);
        }
    }
    return xy.back().second;
}

}  // namespace

PhotonResponse::PhotonResponse(const Band& radiantSensitivity) : band_(radiantSensitivity) {
    double peak = 0.0;
    for (double l = band_.MinWavelength_m(); l <= band_.MaxWavelength_m(); l += 0.25 * kNm)
        peak = std::max(peak, band_.Response(l) / l);
    CHECK_MSG(peak > 0.0, "photocathode band without response");
    scale_ = 1.0 / peak;
}

double PhotonResponse::operator()(double lambda_m) const {
    return band_.Response(lambda_m) / lambda_m * scale_;
}

glm::dvec3 SubBandPhotons(const PhotonResponse& response, const Spectrum& spectrum) {
    const double hc = kPlanck_J_s * kSpeedOfLight_m_s;
    glm::dvec3 out(0.0);
    for (int k = 0; k < 3; ++k)
        out[k] = Integrate([&](double l) { return response(l) * spectrum(l) * l / hc; },
                           kNvgSubBandEdges_m[size_t(k)], kNvgSubBandEdges_m[size_t(k) + 1]);
    return out;
}

glm::dvec3 BlackbodySubBandPhotons(const PhotonResponse& response, double T_K) {
    return SubBandPhotons(response, BlackbodySpectrum(T_K));
}

double Photometric(const Spectrum& spectrum) {
    static const Band y = CieY();
    return kMaxLuminousEfficacy_lm_W *
           Integrate([&](double l) { return y.Response(l) * spectrum(l); }, y.MinWavelength_m(),
                     y.MaxWavelength_m());
}

Spectrum BlackbodySpectrum(double T_K) {
    return [T_K](double l) { return PlanckRadiance(l, T_K); };
}

Spectrum SunSpectrum() { return BlackbodySpectrum(5778.0); }

Spectrum MoonSpectrum() {
    const Spectrum sun = SunSpectrum();
    return [sun](double l) {
        // Kieffer & Stone (2005): ≈ 0.07 at 400 nm to ≈ 0.15 at 950 nm, linear between.
        const double albedo = 0.07 + (0.15 - 0.07) * (l - 400e-9) / (550e-9);
        return sun(l) * std::max(albedo, 0.0);
    };
}

Spectrum RayleighScattered(const Spectrum& source) {
    return [source](double l) {
        const double x = l / 550e-9;
        return source(l) / (x * x * x * x);
    };
}

Spectrum NightSkySpectrum() {
    // f_λ ∝ zero point × 10^(−0.4 m) per band (Benn & Ellison 1998; Bessell et al. 1998).
    const auto band = [](double zeroPoint, double mag) {
        return zeroPoint * std::pow(10.0, -0.4 * mag);
    };
    const std::vector<std::pair<double, double>> table{{438e-9, band(6.32e-9, 22.7)},
                                                       {545e-9, band(3.631e-9, 21.9)},
                                                       {641e-9, band(2.177e-9, 21.0)},
                                                       {798e-9, band(1.126e-9, 20.0)}};
    return [table](double l) { return PiecewiseLinear(table, l); };
}

Spectrum LightningSpectrum() { return BlackbodySpectrum(28000.0); }

glm::dvec3 PhotonsPerPhotometric(const PhotonResponse& response, const Spectrum& spectrum) {
    const double v = Photometric(spectrum);
    CHECK(v > 0.0);
    return SubBandPhotons(response, spectrum) / v;
}

glm::dvec3 SubBandReflectance(const glm::dvec3& reflectanceRgb, double reflectanceNir) {
    return {0.5 * (reflectanceRgb.g + reflectanceRgb.b), 0.5 * (reflectanceRgb.r + reflectanceNir),
            reflectanceNir};
}

}  // namespace seasense::radiometry
