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

using namespace simd4;

// 10^x by e^(x ln 10): cheaper than std::pow.
double Pow10(double x) { return std::exp(x * std::numbers::ln10); }
F4 Pow10_4(F4 x) { return Exp4(_mm_mul_ps(x, _mm_set1_ps(std::numbers::ln10_v<float>))); }

// ScatteringAirMassFromCos on four lanes.
F4 AirMass4(F4 cosZenith) {
    const F4 c = Clamp4(cosZenith, _mm_setzero_ps(), _mm_set1_ps(1.0f));
    return _mm_div_ps(_mm_set1_ps(1.0f),
                      _mm_sqrt_ps(_mm_add_ps(_mm_set1_ps(0.04f),
                                             _mm_mul_ps(_mm_set1_ps(0.96f), _mm_mul_ps(c, c)))));
}

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
    return Lane0(DarkSkyLuminanceFromCos4(_mm_set1_ps(float(cosZenith)), float(k),
                                          float(zenithLuminance_cdm2)));
}

F4 DarkSkyLuminanceFromCos4(F4 cosZenith, float k, float zenithLuminance_cdm2) {
    const F4 X = AirMass4(cosZenith);
    const F4 extinction =
        Pow10_4(_mm_mul_ps(_mm_set1_ps(-0.4f * k), _mm_sub_ps(X, _mm_set1_ps(1.0f))));
    return _mm_mul_ps(_mm_mul_ps(_mm_set1_ps(zenithLuminance_cdm2), extinction), X);
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
    return Lane0(Luminance4(_mm_set1_ps(float(cosZenith)), _mm_set1_ps(float(separation_rad)),
                            _mm_set1_ps(float(cosSeparation))));
}

F4 MoonlitSky::Luminance4(F4 cosZenith, F4 separation_rad, F4 cosSeparation) const {
    if (!(scale_cdm2_ > 0.0)) return _mm_setzero_ps();
    // Inside the disc: its edge.
    const F4 rho_deg =
        Max4(_mm_mul_ps(separation_rad, _mm_set1_ps(float(1.0 / kDeg))), _mm_set1_ps(0.25f));
    // 10^5.36 = 229 086.77.
    const F4 fRayleigh =
        _mm_mul_ps(_mm_set1_ps(229086.77f),
                   _mm_add_ps(_mm_set1_ps(1.06f), _mm_mul_ps(cosSeparation, cosSeparation)));
    // K&S switch from the exponential to the ρ⁻² form at 10°, leaving a 28 % step (7.9e5 vs
    // 6.2e5); switching where the two forms meet, 8.45°, keeps the sky continuous.
    constexpr float kMieSwitch_deg = 8.45f;
    const F4 fMie = Select4(
        _mm_cmpge_ps(rho_deg, _mm_set1_ps(kMieSwitch_deg)),
        Pow10_4(_mm_sub_ps(_mm_set1_ps(6.15f), _mm_mul_ps(rho_deg, _mm_set1_ps(1.0f / 40.0f)))),
        _mm_div_ps(_mm_set1_ps(6.2e7f), _mm_mul_ps(rho_deg, rho_deg)));
    const F4 X = AirMass4(cosZenith);
    const F4 sky =
        _mm_sub_ps(_mm_set1_ps(1.0f), Pow10_4(_mm_mul_ps(_mm_set1_ps(-0.4f * float(k_)), X)));
    return _mm_mul_ps(_mm_mul_ps(_mm_set1_ps(float(scale_cdm2_)), _mm_add_ps(fRayleigh, fMie)),
                      sky);
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
