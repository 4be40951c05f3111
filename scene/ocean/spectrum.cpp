// Wave spectra and directional spreading from the published formulas (Horvath 2015 collects
// them), with exact finite-depth wavenumbers and quadrature for the variance.
#include "scene/ocean/spectrum.h"

#include <cmath>
#include <numbers>
#include <sstream>
#include <string>

#include "scene/core/check.h"
#include "scene/core/error.h"
#include "scene/ocean/gerstner.h"

namespace seasense::scene {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double g = kGravity_mps2;

// Pierson & Moskowitz (1964) constants.
constexpr double kPmAlpha = 8.1e-3;
constexpr double kPmBeta = 0.74;

// Wraps an angle to (−π, π].
double WrapAngle(double a) {
    a = std::remainder(a, 2.0 * kPi);
    return a <= -kPi ? a + 2.0 * kPi : a;
}

// ∫ f(x) dx over [lo, hi] (lo > 0) by composite Simpson in u = ln x: smooth for spectra that
// span decades and have narrow peaks. n must be even.
template <class F>
double IntegrateLog(F&& f, double lo, double hi, int n) {
    const double a = std::log(lo), h = (std::log(hi) - a) / n;
    double sum = 0.0;
    for (int i = 0; i <= n; ++i) {
        const double x = std::exp(a + h * i);
        const double w = (i == 0 || i == n) ? 1.0 : (i % 2 ? 4.0 : 2.0);
        sum += w * f(x) * x;
    }
    return sum * h / 3.0;
}

void Require(bool ok, const std::string& what, double value, const std::string& expected) {
    if (ok) return;
    std::ostringstream out;
    out << "wave spectrum: " << what << " = " << value << " is invalid; expected " << expected;
    throw InputError(out.str());
}

}  // namespace

double WindSpeed19_5(double windSpeed10_mps) { return 1.026 * windSpeed10_mps; }

double PiersonMoskowitzSpectrum(double omega, double u19_5) {
    if (omega <= 0.0 || u19_5 <= 0.0) return 0.0;
    const double omega0 = g / u19_5;
    const double r = omega0 / omega;
    return kPmAlpha * g * g * std::pow(omega, -5.0) * std::exp(-kPmBeta * r * r * r * r);
}

double PiersonMoskowitzPeakOmega(double windSpeed10_mps) {
    // dS/dω = 0 ⇔ ω_p⁴ = (4β/5) ω₀⁴.
    return std::pow(4.0 * kPmBeta / 5.0, 0.25) * g / WindSpeed19_5(windSpeed10_mps);
}

double JonswapSpectrum(double omega, double alpha, double omegaPeak, double gamma, double sigmaA,
                       double sigmaB) {
    if (omega <= 0.0 || omegaPeak <= 0.0) return 0.0;
    const double rp = omegaPeak / omega;
    const double sigma = omega <= omegaPeak ? sigmaA : sigmaB;
    const double d = (omega - omegaPeak) / (sigma * omegaPeak);
    const double r = std::exp(-0.5 * d * d);
    return alpha * g * g * std::pow(omega, -5.0) * std::exp(-1.25 * rp * rp * rp * rp) *
           std::pow(gamma, r);
}

JonswapParameters JonswapFromFetch(double u10, double fetch_m) {
    CHECK(u10 > 0.0 && fetch_m > 0.0);
    // ξ at which 22 (g/U10) ξ^(−1/3) equals the Pierson–Moskowitz peak: full development.
    const double fullyDevelopedXi = std::pow(22.0 * g / u10 / PiersonMoskowitzPeakOmega(u10), 3.0);
    const double xi = std::min(g * fetch_m / (u10 * u10), fullyDevelopedXi);
    JonswapParameters p;
    p.alpha = 0.076 * std::pow(xi, -0.22);
    p.omegaPeak_radps = 22.0 * (g / u10) * std::pow(xi, -1.0 / 3.0);
    return p;
}

double WavenumberForOmega(double omega, double depth_m) {
    CHECK(omega >= 0.0 && depth_m > 0.0);
    const double k0 = omega * omega / g;
    if (k0 == 0.0) return 0.0;
    const double k0h = k0 * depth_m;
    // tanh(k h) = 1 to double precision: the deep-water root.
    if (k0h > 20.0) return k0;
    // Fenton & McKee (1990): k h ≈ k0 h coth((k0 h)^¾)^⅔, within 1.5 % everywhere.
    double k = k0 / std::pow(std::tanh(std::pow(k0h, 0.75)), 2.0 / 3.0);
    for (int i = 0; i < 8; ++i) {
        const double t = std::tanh(k * depth_m);
        const double f = g * k * t - omega * omega;
        const double df = g * t + g * k * depth_m * (1.0 - t * t);
        const double step = f / df;
        k -= step;
        if (std::abs(step) <= 1e-15 * k) break;
    }
    return k;
}

double KitaigorodskiiFactor(double omega, double depth_m) {
    if (omega <= 0.0) return 0.0;
    if (omega * omega / g * depth_m > 20.0) return 1.0;
    const double k = WavenumberForOmega(omega, depth_m);
    // Deep water: k⁻³ dk/dω = 2 g² / ω⁵; at depth h: k⁻³ / c_g.
    return std::pow(omega, 5.0) / (2.0 * g * g * k * k * k * GroupSpeed(k, depth_m));
}

double Cos2sSpreading(double theta, double s) {
    const double c = std::abs(std::cos(0.5 * WrapAngle(theta)));
    const double norm =
        std::exp(std::lgamma(s + 1.0) - std::lgamma(s + 0.5)) / (2.0 * std::sqrt(kPi));
    return norm * std::pow(c, 2.0 * s);
}

double MitsuyasuExponent(double omega, double omegaPeak, double u10) {
    const double sp = 11.5 * std::pow(omegaPeak * u10 / g, -2.5);
    const double r = omega / omegaPeak;
    return r <= 1.0 ? sp * std::pow(r, 5.0) : sp * std::pow(r, -2.5);
}

double HasselmannExponent(double omega, double omegaPeak, double u10) {
    const double r = omega / omegaPeak;
    if (r < 1.0) return 6.97 * std::pow(r, 4.06);
    const double cp = g / omegaPeak;
    const double mu = -2.33 - 1.45 * (u10 / cp - 1.17);
    return 9.77 * std::pow(r, mu);
}

double DonelanBannerSpreading(double theta, double omega, double omegaPeak) {
    const double r = omega / omegaPeak;
    double beta;
    if (r < 0.95)
        beta = 2.61 * std::pow(r, 1.3);
    else if (r < 1.6)
        beta = 2.28 * std::pow(r, -0.65);
    else
        beta = std::pow(10.0, -0.4 + 0.8393 * std::exp(-0.567 * std::log(r * r)));
    const double sech = 1.0 / std::cosh(beta * WrapAngle(theta));
    return beta / (2.0 * std::tanh(beta * kPi)) * sech * sech;
}

double DirectionalSpreading(SpreadingModel model, double theta, double omega, double omegaPeak,
                            double u10) {
    switch (model) {
        case SpreadingModel::Mitsuyasu:
            return Cos2sSpreading(theta, MitsuyasuExponent(omega, omegaPeak, u10));
        case SpreadingModel::Hasselmann:
            return Cos2sSpreading(theta, HasselmannExponent(omega, omegaPeak, u10));
        case SpreadingModel::DonelanBanner:
            return DonelanBannerSpreading(theta, omega, omegaPeak);
    }
    CHECK_MSG(false, "unknown spreading model");
}

WaveSpectrum::WaveSpectrum(const SpectrumSettings& s) : settings_(s) {
    Require(std::isfinite(s.windSpeed_mps) && s.windSpeed_mps >= 0.0, "wind speed (m/s)",
            s.windSpeed_mps, "a finite number >= 0");
    Require(std::isfinite(s.windDirection_rad), "wind direction (rad)", s.windDirection_rad,
            "a finite number");
    Require(s.fetch_m > 0.0, "fetch (m)", s.fetch_m, "> 0 (infinity: fully developed)");
    Require(std::isfinite(s.depth_m) && s.depth_m > 0.0, "depth (m)", s.depth_m,
            "a finite number > 0");
    Require(s.gamma >= 1.0 && s.gamma <= 20.0, "JONSWAP gamma", s.gamma, "a number in [1, 20]");
    Require(s.sigmaA > 0.0 && s.sigmaA < 1.0, "JONSWAP sigma_a", s.sigmaA, "a number in (0, 1)");
    Require(s.sigmaB > 0.0 && s.sigmaB < 1.0, "JONSWAP sigma_b", s.sigmaB, "a number in (0, 1)");
    if (s.significantHeight_m)
        Require(std::isfinite(*s.significantHeight_m) && *s.significantHeight_m >= 0.0,
                "significant wave height (m)", *s.significantHeight_m, "a finite number >= 0");
    if (s.peakPeriod_s)
        Require(std::isfinite(*s.peakPeriod_s) && *s.peakPeriod_s > 0.0, "peak period (s)",
                *s.peakPeriod_s, "a finite number > 0");
    const PhillipsSettings& ph = s.phillips;
    Require(ph.alpha > 0.0 && std::isfinite(ph.alpha), "Phillips alpha", ph.alpha, "> 0");
    Require(ph.exponent > 2.0 && ph.exponent <= 10.0, "Phillips exponent", ph.exponent,
            "a number in (2, 10] (finite variance)");
    Require(ph.alignmentExponent >= 0.0 && ph.alignmentExponent <= 64.0,
            "Phillips alignment exponent", ph.alignmentExponent, "a number in [0, 64]");
    Require(ph.againstWindFactor >= 0.0 && ph.againstWindFactor <= 1.0,
            "Phillips against-wind factor", ph.againstWindFactor, "a number in [0, 1]");
    Require(ph.smallWaveCutoff_m >= 0.0 && std::isfinite(ph.smallWaveCutoff_m),
            "Phillips small-wave cutoff (m)", ph.smallWaveCutoff_m, "a finite number >= 0");

    const double u = s.windSpeed_mps;
    double windVariance = 0.0;
    if (u > 0.0) {
        if (s.model == SpectrumModel::Phillips) {
            Require(!s.peakPeriod_s, "peak period (s)", s.peakPeriod_s.value_or(0.0),
                    "no peak period with the Phillips spectrum (its peak follows the wind)");
            phillipsLength_m_ = u * u / g;
            const double n = ph.alignmentExponent;
            phillipsDirectional_ =
                (1.0 + ph.againstWindFactor) * std::sqrt(kPi) *
                std::exp(std::lgamma(0.5 * (n + 1.0)) - std::lgamma(0.5 * n + 1.0));
            // Peak of k·P_r(k) ∝ k^(1−p) exp(−1/(kL)²): k_p² = 2 / ((p − 1) L²).
            const double kp = std::sqrt(2.0 / (ph.exponent - 1.0)) / phillipsLength_m_;
            omegaPeak_ = DispersionOmega(kp, s.depth_m);
            windVariance =
                phillipsDirectional_ * IntegrateLog([&](double k) { return k * PhillipsK(k, 1.0); },
                                                    kp / 30.0, kp * 1e5, 8192);
        } else {
            if (s.model == SpectrumModel::PiersonMoskowitz) {
                alpha_ = kPmAlpha;
                omegaPeak_ = PiersonMoskowitzPeakOmega(u);
            } else {
                const JonswapParameters jp = JonswapFromFetch(u, s.fetch_m);
                alpha_ = jp.alpha;
                omegaPeak_ = jp.omegaPeak_radps;
            }
            if (s.peakPeriod_s) omegaPeak_ = 2.0 * kPi / *s.peakPeriod_s;
            windVariance = IntegrateLog([&](double w) { return WindSeaOmega(w); },
                                        omegaPeak_ / 30.0, omegaPeak_ * 1e3, 8192);
        }
        longestPeakWavelength_m_ = 2.0 * kPi / WavenumberForOmega(omegaPeak_, s.depth_m);
    }
    if (s.significantHeight_m) {
        const double target = 0.0625 * *s.significantHeight_m * *s.significantHeight_m;
        if (target > 0.0) {
            Require(windVariance > 0.0, "wind speed (m/s)", u,
                    "> 0 when a significant wave height is requested");
            windSeaScale_ = target / windVariance;
        } else {
            windSeaScale_ = 0.0;
        }
    }
    variance_m2_ = windSeaScale_ * windVariance;

    if (s.swell) {
        const SwellSettings& sw = *s.swell;
        Require(std::isfinite(sw.significantHeight_m) && sw.significantHeight_m >= 0.0,
                "swell significant height (m)", sw.significantHeight_m, "a finite number >= 0");
        Require(std::isfinite(sw.peakPeriod_s) && sw.peakPeriod_s > 0.0, "swell peak period (s)",
                sw.peakPeriod_s, "a finite number > 0");
        Require(std::isfinite(sw.direction_rad), "swell direction (rad)", sw.direction_rad,
                "a finite number");
        Require(sw.gamma >= 1.0 && sw.gamma <= 20.0, "swell gamma", sw.gamma,
                "a number in [1, 20]");
        Require(sw.spreadingPeak >= 0.0 && sw.spreadingPeak <= 1000.0, "swell spreading exponent",
                sw.spreadingPeak, "a number in [0, 1000]");
        swellOmegaPeak_ = 2.0 * kPi / sw.peakPeriod_s;
        swellScale_ = 1.0;
        const double shape = IntegrateLog([&](double w) { return SwellOmega(w); },
                                          swellOmegaPeak_ / 30.0, swellOmegaPeak_ * 1e3, 8192);
        swellScale_ = 0.0625 * sw.significantHeight_m * sw.significantHeight_m / shape;
        variance_m2_ += swellScale_ * shape;
        if (sw.significantHeight_m > 0.0)
            longestPeakWavelength_m_ =
                std::max(longestPeakWavelength_m_,
                         2.0 * kPi / WavenumberForOmega(swellOmegaPeak_, s.depth_m));
    }
}

double WaveSpectrum::SignificantHeight_m() const { return 4.0 * std::sqrt(variance_m2_); }

double WaveSpectrum::PhillipsK(double k, double cosTheta) const {
    const PhillipsSettings& ph = settings_.phillips;
    const double kl = k * phillipsLength_m_;
    const double radial = ph.alpha * std::pow(k, -4.0) * std::pow(kl, 4.0 - ph.exponent) *
                          std::exp(-1.0 / (kl * kl)) *
                          std::exp(-k * k * ph.smallWaveCutoff_m * ph.smallWaveCutoff_m);
    const double align = std::pow(std::abs(cosTheta), ph.alignmentExponent);
    return radial * align * (cosTheta < 0.0 ? ph.againstWindFactor : 1.0);
}

double WaveSpectrum::WindSeaOmega(double omega) const {
    if (omega <= 0.0 || omegaPeak_ <= 0.0) return 0.0;
    const SpectrumSettings& s = settings_;
    switch (s.model) {
        case SpectrumModel::Phillips: {
            // S(ω) = S(k) dk/dω with S(k) = k ∫ P dθ.
            const double k = WavenumberForOmega(omega, s.depth_m);
            return k * PhillipsK(k, 1.0) * phillipsDirectional_ / GroupSpeed(k, s.depth_m);
        }
        case SpectrumModel::PiersonMoskowitz: {
            // ω_p = (4β/5)^¼ g / U19.5, so the U19.5 behind this peak (it differs from the
            // wind's only when the peak period is given explicitly).
            const double u19_5 = std::pow(4.0 * kPmBeta / 5.0, 0.25) * g / omegaPeak_;
            return PiersonMoskowitzSpectrum(omega, u19_5);
        }
        case SpectrumModel::Jonswap:
            return JonswapSpectrum(omega, alpha_, omegaPeak_, s.gamma, s.sigmaA, s.sigmaB);
        case SpectrumModel::Tma:
            return JonswapSpectrum(omega, alpha_, omegaPeak_, s.gamma, s.sigmaA, s.sigmaB) *
                   KitaigorodskiiFactor(omega, s.depth_m);
    }
    CHECK_MSG(false, "unknown spectrum model");
}

double WaveSpectrum::SwellOmega(double omega) const {
    const SwellSettings& sw = *settings_.swell;
    // Unit-α JONSWAP shape in the depth at hand (Bouws et al. 1985), scaled to Hs afterwards.
    return JonswapSpectrum(omega, 1.0, swellOmegaPeak_, sw.gamma) *
           KitaigorodskiiFactor(omega, settings_.depth_m);
}

double WaveSpectrum::DensityOmega(double omega) const {
    double s = windSeaScale_ * WindSeaOmega(omega);
    if (settings_.swell) s += swellScale_ * SwellOmega(omega);
    return s;
}

double WaveSpectrum::DensityK(double kx, double ky) const {
    const double k = std::hypot(kx, ky);
    if (k == 0.0) return 0.0;
    const SpectrumSettings& s = settings_;
    // Azimuth of travel, from north clockwise.
    const double azimuth = std::atan2(kx, ky);
    const double omega = DispersionOmega(k, s.depth_m);
    // F(k) k dk dθ = S(ω) D dω dθ and dω = c_g dk.
    const double jacobian = GroupSpeed(k, s.depth_m) / k;
    double f = 0.0;
    if (windSeaScale_ > 0.0 && omegaPeak_ > 0.0) {
        if (s.model == SpectrumModel::Phillips) {
            const double cosTheta =
                (kx * std::sin(s.windDirection_rad) + ky * std::cos(s.windDirection_rad)) / k;
            f += windSeaScale_ * PhillipsK(k, cosTheta);
        } else {
            f += windSeaScale_ * WindSeaOmega(omega) *
                 DirectionalSpreading(s.spreading, azimuth - s.windDirection_rad, omega, omegaPeak_,
                                      s.windSpeed_mps) *
                 jacobian;
        }
    }
    if (swellScale_ > 0.0) {
        const double r = omega / swellOmegaPeak_;
        const double sExp =
            s.swell->spreadingPeak * (r <= 1.0 ? std::pow(r, 5.0) : std::pow(r, -2.5));
        f += swellScale_ * SwellOmega(omega) *
             Cos2sSpreading(azimuth - s.swell->direction_rad, sExp) * jacobian;
    }
    return f;
}

}  // namespace seasense::scene
