// Krisciunas & Schaefer (1991) night-sky and moonlit-sky luminance.
#include "radiometry/sky/night_sky.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace seasense::radiometry {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
// Mean lunar semidiameter 15.54' (Meeus, "Astronomical Algorithms" ch. 55, at 384 400 km).
constexpr double kMoonSemidiameter_rad = 15.54 / 60.0 * kDeg;
constexpr double kMeanMoonDistance_m = 3.844e8;

// 10^x by e^(x ln 10): cheaper than std::pow.
double Pow10(double x) { return std::exp(x * std::numbers::ln10); }

}  // namespace

double ScatteringAirMass(double zenith_rad) {
    return ScatteringAirMassFromCos(std::cos(std::clamp(zenith_rad, 0.0, 0.5 * std::numbers::pi)));
}

double ScatteringAirMassFromCos(double cosZenith) {
    const double c = std::clamp(cosZenith, 0.0, 1.0);
    // 1 − 0.96 sin²z = 0.04 + 0.96 cos²z.
    return 1.0 / std::sqrt(0.04 + 0.96 * c * c);
}

double DarkSkyLuminance_cdm2(double zenith_rad, double k, double zenithLuminance_cdm2) {
    return DarkSkyLuminanceFromCos_cdm2(
        std::cos(std::clamp(zenith_rad, 0.0, 0.5 * std::numbers::pi)), k, zenithLuminance_cdm2);
}

double DarkSkyLuminanceFromCos_cdm2(double cosZenith, double k, double zenithLuminance_cdm2) {
    const double X = ScatteringAirMassFromCos(cosZenith);
    return zenithLuminance_cdm2 * Pow10(-0.4 * k * (X - 1.0)) * X;
}

MoonlitSky::MoonlitSky(double moonZenith_rad, double phaseAngle_rad, double moonDistance_m,
                       double k)
    : k_(k) {
    const double moonAltitude_rad = 0.5 * std::numbers::pi - moonZenith_rad;
    if (moonAltitude_rad <= -kMoonSemidiameter_rad) return;
    const double visible = std::min(1.0, 0.5 * (1.0 + moonAltitude_rad / kMoonSemidiameter_rad));
    const double a_deg = std::abs(phaseAngle_rad) / kDeg;
    const double iStar =
        Pow10(-0.4 * (3.84 + 0.026 * a_deg + 4e-9 * a_deg * a_deg * a_deg * a_deg));
    const double r = kMeanMoonDistance_m / moonDistance_m;
    const double Xm = ScatteringAirMass(moonZenith_rad);
    scale_cdm2_ = visible * iStar * r * r * Pow10(-0.4 * k * Xm) * kNanoLambert_cdm2;
}

double MoonlitSky::Luminance_cdm2(double cosZenith, double separation_rad,
                                  double cosSeparation) const {
    if (!(scale_cdm2_ > 0.0)) return 0.0;
    const double rho_deg = std::max(separation_rad / kDeg, 0.25);  // inside the disc: its edge
    const double c = cosSeparation;
    // 10^5.36 = 229 086.77.
    const double fRayleigh = 229086.76527677748 * (1.06 + c * c);
    // K&S switch from the exponential to the ρ⁻² form at 10°, leaving a 28 % step (7.9e5 vs
    // 6.2e5); switching where the two forms meet, 8.45°, keeps the sky continuous.
    constexpr double kMieSwitch_deg = 8.45;
    const double fMie =
        rho_deg >= kMieSwitch_deg ? Pow10(6.15 - rho_deg / 40.0) : 6.2e7 / (rho_deg * rho_deg);
    const double X = ScatteringAirMassFromCos(cosZenith);
    return scale_cdm2_ * (fRayleigh + fMie) * (1.0 - Pow10(-0.4 * k_ * X));
}

double MoonlitSkyLuminance_cdm2(double skyZenith_rad, double moonZenith_rad, double separation_rad,
                                double phaseAngle_rad, double moonDistance_m, double k) {
    const MoonlitSky moonlit(moonZenith_rad, phaseAngle_rad, moonDistance_m, k);
    const double z = std::clamp(skyZenith_rad, 0.0, 0.5 * std::numbers::pi);
    return moonlit.Luminance_cdm2(std::cos(z), separation_rad, std::cos(separation_rad));
}

double SurfaceBrightnessV_magPerArcsec2(double luminance_cdm2) {
    const double B_nL = luminance_cdm2 / kNanoLambert_cdm2;
    return (20.7233 - std::log(B_nL / 34.08)) / 0.92104;
}

}  // namespace seasense::radiometry
