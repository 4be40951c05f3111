// Natural illuminance on a horizontal surface (lux) from sun, moon and night sky, after USNO
// Circular 171 (Janiczek & DeYoung 1987), and the twilight state from the sun's altitude.
#include "scene/sky/illuminance.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <numbers>
#include <string>

#include "scene/core/error.h"
#include "scene/sky/stars.h"

namespace seasense::scene {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// One piece of a Circular 171 fit: for altitude h in [lowAltitude_deg, ...) and x = h / 90 deg,
// log10(E / lux) = a0 + a1 x + a2 x^2 + a3 x^3.
struct FitPiece {
    double lowAltitude_deg;
    double a0, a1, a2, a3;
};

// Sun, clear sky, mean distance: Janiczek & DeYoung 1987 (USNO Circular 171), illuminance
// justification appendix; the same table is reproduced as Vallado, "Fundamentals of
// Astrodynamics and Applications", Table 5-1. Ordered from the highest piece down; the fit is
// published for -18 deg <= h <= 90 deg.
constexpr FitPiece kSunFit[] = {
    {20.0, 3.74, 3.97, -4.07, 1.47},           // 20 <= h <= 90
    {5.0, 3.05, 13.28, -45.98, 64.33},         // 5 <= h < 20
    {-0.8, 2.88, 22.26, -207.64, 1034.30},     // -0.8 <= h < 5
    {-5.0, 2.88, 21.81, -258.11, -858.36},     // -5 <= h < -0.8
    {-12.0, 2.70, 12.17, -431.69, -1899.83},   // -12 <= h < -5
    {-18.0, 13.84, 262.72, 1447.42, 2797.93},  // -18 <= h < -12
};

// Full moon at mean distance, clear sky: Janiczek & DeYoung 1987 (same appendix; Vallado
// Table 5-1). Published for -0.8 deg <= h <= 90 deg.
constexpr FitPiece kMoonFit[] = {
    {20.0, -1.95, 4.06, -4.24, 1.56},        // 20 <= h <= 90
    {5.0, -2.58, 12.58, -42.58, 59.06},      // 5 <= h < 20
    {-0.8, -2.79, 24.27, -252.95, 1321.29},  // -0.8 <= h < 5
};

// Circular 171 lunar phase law, added to log10(E) with the phase angle F in degrees:
// -8.68e-3 F - 2.2e-9 F^4 (Janiczek & DeYoung 1987; it is Allen's magnitude law
// 0.026 |F| + 4e-9 F^4 refitted to the illuminance data of the circular).
constexpr double kMoonPhaseLinear_perDeg = -8.68e-3;
constexpr double kMoonPhaseQuartic_perDeg4 = -2.2e-9;

// Circular 171 distance term for the moon: + 2 log10(HP / 0.951 deg) with HP the moon's
// horizontal parallax, asin(a / d); 0.951 deg is the mean parallax the fit refers to.
constexpr double kMoonMeanParallax_deg = 0.951;
// Earth's equatorial radius, IAU 1976 system used by the almanacs of the circular's time.
constexpr double kEarthEquatorialRadius_m = 6378140.0;

// The sun fit refers to the mean distance, 1 au (IAU 2012 Resolution B2).
constexpr double kAstronomicalUnit_m = 1.495978707e11;

// Clear moonless night sky (integrated starlight, zodiacal light and airglow) on a horizontal
// surface: 1-2e-3 lx is the typical published value (project physics.md, "Celestial lighting";
// overcast starlight 1e-4 lx is this divided by the circular's dark-stratus factor 10). The
// middle of that range is taken.
constexpr double kNightSkyClear_lux = 1.5e-3;

double EvaluateFit(const FitPiece* pieces, int count, double altitude_deg) {
    for (int i = 0; i < count; ++i) {
        const FitPiece& p = pieces[i];
        if (altitude_deg >= p.lowAltitude_deg) {
            const double x = altitude_deg / 90.0;
            return p.a0 + x * (p.a1 + x * (p.a2 + x * p.a3));
        }
    }
    return -std::numeric_limits<double>::infinity();
}

void CheckAltitude(double altitude_rad, const char* what) {
    if (!std::isfinite(altitude_rad) || std::abs(altitude_rad) > 0.5 * std::numbers::pi + 1e-12) {
        throw InputError(std::string(what) + ": altitude " + std::to_string(altitude_rad) +
                         " rad is not a finite angle in [-pi/2, pi/2]");
    }
}

void CheckDistance(double distance_m, const char* what) {
    if (!std::isfinite(distance_m) || distance_m <= 0.0) {
        throw InputError(std::string(what) + ": distance " + std::to_string(distance_m) +
                         " m is not a finite positive length");
    }
}

}  // namespace

double SunIlluminance_lux(double altitude_rad, double distance_m) {
    CheckAltitude(altitude_rad, "SunIlluminance_lux");
    CheckDistance(distance_m, "SunIlluminance_lux");
    const double altitude_deg = altitude_rad / kDeg;
    if (altitude_deg < kSunFit[std::size(kSunFit) - 1].lowAltitude_deg) return 0.0;
    const double log10E = EvaluateFit(kSunFit, int(std::size(kSunFit)), altitude_deg);
    const double distanceRatio = kAstronomicalUnit_m / distance_m;
    return std::pow(10.0, log10E) * distanceRatio * distanceRatio;
}

double RelativeAirMass(double altitude_rad) {
    CheckAltitude(altitude_rad, "RelativeAirMass");
    const double h_deg = std::max(altitude_rad / kDeg, 0.0);
    return 1.0 / (std::sin(h_deg * kDeg) + 0.50572 * std::pow(h_deg + 6.07995, -1.6364));
}

double DirectNormalSunIlluminance_lux(double altitude_rad, double distance_m,
                                      double luminousTurbidity) {
    CheckAltitude(altitude_rad, "DirectNormalSunIlluminance_lux");
    CheckDistance(distance_m, "DirectNormalSunIlluminance_lux");
    if (!std::isfinite(luminousTurbidity) || luminousTurbidity < 0.0)
        throw InputError("DirectNormalSunIlluminance_lux: turbidity " +
                         std::to_string(luminousTurbidity) + " is not a number >= 0");
    // The disc (0.2666° radius) is gone once its upper limb is below the apparent horizon.
    if (altitude_rad < -0.2666 * kDeg) return 0.0;
    constexpr double kLuminousSolarConstant_lux = 133800.0;
    const double m = RelativeAirMass(altitude_rad);
    const double av = 1.0 / (9.9 + 0.043 * m);
    const double distanceRatio = kAstronomicalUnit_m / distance_m;
    return kLuminousSolarConstant_lux * distanceRatio * distanceRatio *
           std::exp(-av * m * luminousTurbidity);
}

double MoonIlluminance_lux(double altitude_rad, double phaseAngle_rad, double distance_m) {
    CheckAltitude(altitude_rad, "MoonIlluminance_lux");
    CheckDistance(distance_m, "MoonIlluminance_lux");
    if (!std::isfinite(phaseAngle_rad) || phaseAngle_rad < -1e-12 ||
        phaseAngle_rad > std::numbers::pi + 1e-12) {
        throw InputError("MoonIlluminance_lux: phase angle " + std::to_string(phaseAngle_rad) +
                         " rad is not in [0, pi]");
    }
    if (distance_m <= kEarthEquatorialRadius_m) {
        throw InputError("MoonIlluminance_lux: distance " + std::to_string(distance_m) +
                         " m is inside the Earth");
    }
    const double altitude_deg = altitude_rad / kDeg;
    if (altitude_deg < kMoonFit[std::size(kMoonFit) - 1].lowAltitude_deg) return 0.0;
    const double phase_deg = std::clamp(phaseAngle_rad, 0.0, std::numbers::pi) / kDeg;
    const double phase2 = phase_deg * phase_deg;
    const double parallax_deg = std::asin(kEarthEquatorialRadius_m / distance_m) / kDeg;
    const double log10E = EvaluateFit(kMoonFit, int(std::size(kMoonFit)), altitude_deg) +
                          kMoonPhaseLinear_perDeg * phase_deg +
                          kMoonPhaseQuartic_perDeg4 * phase2 * phase2 +
                          2.0 * std::log10(parallax_deg / kMoonMeanParallax_deg);
    return std::pow(10.0, log10E);
}

double ClearSkyDiffuseIlluminance_lux(double sunAltitude_rad) {
    CheckAltitude(sunAltitude_rad, "ClearSkyDiffuseIlluminance_lux");
    // IES clear sky at the horizon: 0.8 klx.
    constexpr double kHorizon_lux = 800.0;
    const auto ies = [](double h) { return 800.0 + 15.5e3 * std::sqrt(std::sin(h)); };
    // The IES fit's √(sin h) rises with unbounded slope at the horizon, where it overshoots
    // Circular 171's diffuse light (its total less the direct sun) by 2× at 1°. Below 5° the
    // illuminance is interpolated exponentially from 800 lx at the horizon to the IES value at
    // 5°, which follows the circular's diffuse light within 10 % at 1° and 3°.
    constexpr double kBlend_rad = 5.0 * kDeg;
    if (sunAltitude_rad >= kBlend_rad) return ies(sunAltitude_rad);
    if (sunAltitude_rad >= 0.0)
        return kHorizon_lux *
               std::pow(ies(kBlend_rad) / kHorizon_lux, sunAltitude_rad / kBlend_rad);
    return kHorizon_lux * SunIlluminance_lux(sunAltitude_rad) / SunIlluminance_lux(0.0);
}

double DirectNormalMoonIlluminance_lux(double altitude_rad, double phaseAngle_rad,
                                       double distance_m, double observerHeight_m) {
    CheckAltitude(altitude_rad, "DirectNormalMoonIlluminance_lux");
    CheckDistance(distance_m, "DirectNormalMoonIlluminance_lux");
    if (!std::isfinite(phaseAngle_rad) || phaseAngle_rad < -1e-12 ||
        phaseAngle_rad > std::numbers::pi + 1e-12)
        throw InputError("DirectNormalMoonIlluminance_lux: phase angle " +
                         std::to_string(phaseAngle_rad) + " rad is not in [0, pi]");
    // Mean semidiameter 15.5' (Meeus ch. 55): the disc is gone once the upper limb has set.
    if (altitude_rad < -0.259 * kDeg) return 0.0;
    const double a_deg = phaseAngle_rad / kDeg;
    const double vmag = -12.73 + 0.026 * a_deg + 4e-9 * a_deg * a_deg * a_deg * a_deg;
    constexpr double kMeanMoonDistance_m = 3.844e8;
    const double r = kMeanMoonDistance_m / distance_m;
    const double k = ZenithExtinctionV_mag(observerHeight_m);
    return StarIlluminanceAboveAtmosphere_lux(vmag) * r * r *
           std::pow(10.0, -0.4 * k * RelativeAirMass(altitude_rad));
}

double NightSkyIlluminance_lux() { return kNightSkyClear_lux; }

TwilightState TwilightFromSunAltitude(double altitude_rad) {
    if (!std::isfinite(altitude_rad)) {
        throw InputError("TwilightFromSunAltitude: altitude is not finite");
    }
    const double altitude_deg = altitude_rad / kDeg;
    if (altitude_deg >= kSunriseAltitude_deg) return TwilightState::Day;
    if (altitude_deg >= kCivilTwilightAltitude_deg) return TwilightState::Civil;
    if (altitude_deg >= kNauticalTwilightAltitude_deg) return TwilightState::Nautical;
    if (altitude_deg >= kAstronomicalTwilightAltitude_deg) return TwilightState::Astronomical;
    return TwilightState::Night;
}

std::string_view ToString(TwilightState state) {
    switch (state) {
        case TwilightState::Day:
            return "day";
        case TwilightState::Civil:
            return "civil";
        case TwilightState::Nautical:
            return "nautical";
        case TwilightState::Astronomical:
            return "astronomical";
        case TwilightState::Night:
            return "night";
    }
    return "night";
}

Illuminance NaturalIlluminance(UtcTime t, const Observer& observer, double skyConditionDivisor) {
    if (!std::isfinite(skyConditionDivisor) || skyConditionDivisor < kClearSkyDivisor ||
        skyConditionDivisor > kDarkStratusDivisor) {
        throw InputError("NaturalIlluminance: sky-condition divisor " +
                         std::to_string(skyConditionDivisor) +
                         " is outside the published range [1 (clear), 10 (dark stratus)]");
    }
    // The circular's fits break at -0.8 deg, the geometric altitude of the centre at sunrise
    // and moonrise, so they take the unrefracted topocentric altitude.
    const CelestialPosition sun = SunPosition(t, observer);
    const CelestialPosition moon = MoonPosition(t, observer);
    const LunarPhase phase = MoonPhase(t, observer);

    Illuminance result;
    result.sun_lux =
        SunIlluminance_lux(sun.altitudeGeometric_rad, sun.distance_m) / skyConditionDivisor;
    result.moon_lux =
        MoonIlluminance_lux(moon.altitudeGeometric_rad, phase.phaseAngle_rad, moon.distance_m) /
        skyConditionDivisor;
    result.sky_lux = kNightSkyClear_lux / skyConditionDivisor;
    result.total_lux = result.sun_lux + result.moon_lux + result.sky_lux;
    result.twilight = TwilightFromSunAltitude(sun.altitudeGeometric_rad);
    return result;
}

}  // namespace seasense::scene
