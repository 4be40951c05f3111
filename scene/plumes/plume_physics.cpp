// Closed-form plume physics: stability class, dispersion, rise, decay, flames and road dust.
#include "scene/plumes/plume_physics.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "scene/core/error.h"

namespace seasense::scene {
namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

// Seed 004 Table 1: rural dispersion constants for its Eq 6, σ = exp(I + J ln x + K ln² x),
// x in km and σ in m (McMullen 1975, as tabulated by Beychok 1979). The OCR of the seed
// dropped the minus signs of the small K values; they are restored from Beychok's table.
struct SigmaCoefficients {
    double I, J, K;
};
constexpr SigmaCoefficients kSigmaZ[kStabilityClasses] = {
    {6.035, 2.1097, 0.2770},  {4.694, 1.0629, 0.0136},  {4.110, 0.9201, -0.0020},
    {3.414, 0.7371, -0.0316}, {3.057, 0.6794, -0.0450}, {2.621, 0.6564, -0.0540}};
constexpr SigmaCoefficients kSigmaY[kStabilityClasses] = {
    {5.357, 0.8828, -0.0076}, {5.058, 0.9024, -0.0096}, {4.651, 0.9181, -0.0076},
    {4.230, 0.9222, -0.0087}, {3.922, 0.9222, -0.0064}, {3.533, 0.9181, -0.0070}};

// Beychok gives the fits from 100 m downwind; closer in, the quadratic in ln x turns upward
// for class A, so σ continues as the power law tangent (in log–log) to the fit at 100 m.
constexpr double kSigmaFitStart_km = 0.1;

double Sigma(const SigmaCoefficients& k, double x_m) {
    if (!(x_m >= 0.0) || !std::isfinite(x_m)) {
        std::ostringstream msg;
        msg << "plume dispersion: downwind distance must be finite and >= 0 m, got " << x_m;
        throw InputError(msg.str());
    }
    if (x_m == 0.0) return 0.0;
    const double x_km = x_m * 1e-3;
    if (x_km >= kSigmaFitStart_km) {
        const double l = std::log(x_km);
        return std::exp(k.I + k.J * l + k.K * l * l);
    }
    const double l0 = std::log(kSigmaFitStart_km);
    const double sigma0 = std::exp(k.I + k.J * l0 + k.K * l0 * l0);
    const double slope = k.J + 2.0 * k.K * l0;
    return sigma0 * std::pow(x_km / kSigmaFitStart_km, slope);
}

void RequireFinite(double x, const char* what) {
    if (!std::isfinite(x)) {
        std::ostringstream msg;
        msg << "plume physics: " << what << " must be finite, got " << x;
        throw InputError(msg.str());
    }
}

// Vertical potential-temperature gradients for the stable classes (EPA ISC3 vol. II
// sec. 1.1.4.3): E 0.020 K/m, F 0.035 K/m.
double StableStability_1ps2(StabilityClass c, double air_K) {
    const double dThetaDz = c == StabilityClass::E ? 0.020 : 0.035;
    return kPlumeGravity_mps2 / air_K * dThetaDz;
}

bool IsStable(StabilityClass c) { return c == StabilityClass::E || c == StabilityClass::F; }

}  // namespace

std::string_view ToString(StabilityClass c) {
    static constexpr std::string_view kNames[] = {"A", "B", "C", "D", "E", "F"};
    return kNames[int(c)];
}

std::string_view ToString(PlumeBehaviour b) {
    static constexpr std::string_view kNames[] = {"looping", "coning",     "fanning",
                                                  "lofting", "fumigation", "trapping"};
    return kNames[int(b)];
}

StabilityClass PasquillTurnerClass(double windSpeed_mps, double sunElevation_rad,
                                   double cloudCover) {
    if (!std::isfinite(windSpeed_mps) || windSpeed_mps < 0.0)
        throw InputError("stability class: wind speed must be finite and >= 0 m/s");
    if (!std::isfinite(sunElevation_rad) || std::abs(sunElevation_rad) > std::numbers::pi / 2)
        throw InputError("stability class: sun elevation must be within [-90, 90] deg");
    if (!(cloudCover >= 0.0 && cloudCover <= 1.0))
        throw InputError("stability class: cloud cover must be a fraction in [0, 1]");
    using enum StabilityClass;
    // Pasquill (1961) as tabulated in Turner, "Workbook of Atmospheric Dispersion Estimates"
    // (1970), Table 1: "the neutral class D should be assumed for overcast conditions during
    // day or night". Overcast is 8 oktas; the nearest okta rounds the fraction.
    if (std::round(cloudCover * 8.0) >= 8.0) return D;
    // Wind rows of the table: < 2, 2–3, 3–5, 5–6, > 6 m/s at 10 m.
    const double u = windSpeed_mps;
    const int row = u < 2.0 ? 0 : u < 3.0 ? 1 : u < 5.0 ? 2 : u <= 6.0 ? 3 : 4;
    const double elevation_deg = sunElevation_rad * kDegPerRad;
    if (elevation_deg > 0.0) {
        // Incoming solar radiation from the sun's altitude as in Turner (1964): strong above
        // 60°, moderate 35–60°, slight 15–35°, weak below; more than half the sky clouded lowers
        // it one step (Turner 1964's cloud correction). Weak insolation is neutral (D), as for
        // the hour after sunrise and before sunset that Pasquill counts with the night.
        int insolation = elevation_deg > 60.0   ? 3
                         : elevation_deg > 35.0 ? 2
                         : elevation_deg > 15.0 ? 1
                                                : 0;
        if (cloudCover > 0.5) insolation = std::max(0, insolation - 1);
        if (insolation == 0) return D;
        // Columns strong, moderate, slight; the table's intermediate entries (A–B, B–C, C–D)
        // take the more unstable class.
        static constexpr StabilityClass kDay[5][3] = {
            {A, A, B}, {A, B, C}, {B, B, C}, {C, C, D}, {C, D, D}};
        return kDay[row][3 - insolation];
    }
    // Night: thinly overcast or >= 4/8 low cloud, or <= 3/8 cloud. The table leaves calm
    // nights (< 2 m/s) blank; they are the most stable class available here, F.
    static constexpr StabilityClass kNight[5][2] = {{F, F}, {E, F}, {D, E}, {D, D}, {D, D}};
    const int column = cloudCover >= 0.5 ? 0 : 1;
    return kNight[row][column];
}

double SigmaY_m(StabilityClass c, double x_m) { return Sigma(kSigmaY[int(c)], x_m); }
double SigmaZ_m(StabilityClass c, double x_m) { return Sigma(kSigmaZ[int(c)], x_m); }

double MassDecayFactor(double age_s, double longTermFraction, double decayRate_hz) {
    if (!(age_s >= 0.0) || !(longTermFraction >= 0.0 && longTermFraction <= 1.0) ||
        !(decayRate_hz >= 0.0) || !std::isfinite(age_s) || !std::isfinite(decayRate_hz))
        throw InputError(
            "mass decay: need a finite age >= 0 s, a long-term fraction in [0, 1] and a "
            "finite decay rate >= 0 1/s");
    return longTermFraction + (1.0 - longTermFraction) * std::exp(-decayRate_hz * age_s);
}

double StackBuoyancyFlux_m4ps3(double exitVelocity_mps, double radius_m, double exit_K,
                               double air_K) {
    RequireFinite(exitVelocity_mps, "stack exit velocity");
    RequireFinite(radius_m, "stack radius");
    if (!(exit_K > 0.0) || !(air_K > 0.0) || !std::isfinite(exit_K) || !std::isfinite(air_K))
        throw InputError("stack buoyancy flux: temperatures must be finite and > 0 K");
    if (exit_K <= air_K) return 0.0;
    return kPlumeGravity_mps2 * exitVelocity_mps * radius_m * radius_m * (exit_K - air_K) / exit_K;
}

double StackMomentumFlux_m4ps2(double exitVelocity_mps, double radius_m, double exit_K,
                               double air_K) {
    RequireFinite(exitVelocity_mps, "stack exit velocity");
    RequireFinite(radius_m, "stack radius");
    if (!(exit_K > 0.0) || !(air_K > 0.0) || !std::isfinite(exit_K) || !std::isfinite(air_K))
        throw InputError("stack momentum flux: temperatures must be finite and > 0 K");
    return exitVelocity_mps * exitVelocity_mps * radius_m * radius_m * air_K / exit_K;
}

double HeatBuoyancyFlux_m4ps3(double heatRelease_W, double air_K) {
    if (!(heatRelease_W >= 0.0) || !std::isfinite(heatRelease_W))
        throw InputError("fire buoyancy flux: heat release must be finite and >= 0 W");
    if (!(air_K > 0.0) || !std::isfinite(air_K))
        throw InputError("fire buoyancy flux: air temperature must be finite and > 0 K");
    // Ideal gas: ρ c_p T_a = p c_p / R_d, independent of T_a; with p = 101 325 Pa,
    // c_p = 1005 J/(kg K) and R_d = 287.05 J/(kg K) this reproduces Briggs' F = 8.8e-6 Q[W].
    constexpr double kPressure_Pa = 101325.0;
    constexpr double kCp_JpkgK = 1005.0;
    constexpr double kDryAirGasConstant_JpkgK = 287.05;
    const double rhoCpT = kPressure_Pa * kCp_JpkgK / kDryAirGasConstant_JpkgK;
    return kPlumeGravity_mps2 * heatRelease_W / (std::numbers::pi * rhoCpT);
}

double BriggsTransitionalRise_m(double buoyancyFlux_m4ps3, double x_m, double u_mps) {
    if (!(buoyancyFlux_m4ps3 >= 0.0) || !(x_m >= 0.0) || !(u_mps > 0.0) ||
        !std::isfinite(buoyancyFlux_m4ps3) || !std::isfinite(x_m) || !std::isfinite(u_mps))
        throw InputError("Briggs rise: need finite F >= 0, x >= 0 m and wind speed > 0 m/s");
    return 1.6 * std::cbrt(buoyancyFlux_m4ps3) * std::pow(x_m, 2.0 / 3.0) / u_mps;
}

double BriggsFinalRiseDistance_m(StabilityClass c, double buoyancyFlux_m4ps3, double u_mps,
                                 double air_K) {
    if (!(buoyancyFlux_m4ps3 >= 0.0) || !(u_mps > 0.0) || !(air_K > 0.0))
        throw InputError("Briggs final rise: need F >= 0, wind speed > 0 and air T > 0");
    const double F = buoyancyFlux_m4ps3;
    if (IsStable(c)) return 2.0715 * u_mps / std::sqrt(StableStability_1ps2(c, air_K));
    return F < 55.0 ? 49.0 * std::pow(F, 5.0 / 8.0) : 119.0 * std::pow(F, 0.4);
}

double BriggsFinalRise_m(StabilityClass c, double buoyancyFlux_m4ps3, double u_mps, double air_K) {
    const double xf = BriggsFinalRiseDistance_m(c, buoyancyFlux_m4ps3, u_mps, air_K);
    if (IsStable(c)) {
        const double s = StableStability_1ps2(c, air_K);
        const double stableRise = 2.6 * std::cbrt(buoyancyFlux_m4ps3 / (u_mps * s));
        // The 2/3 law holds until it meets the stable ceiling.
        return std::min(stableRise, BriggsTransitionalRise_m(buoyancyFlux_m4ps3, xf, u_mps));
    }
    return BriggsTransitionalRise_m(buoyancyFlux_m4ps3, xf, u_mps);
}

double WindAtHeight_mps(StabilityClass c, double windSpeed10_mps, double height_m) {
    static constexpr double kExponent[kStabilityClasses] = {0.07, 0.07, 0.10, 0.15, 0.35, 0.55};
    if (!(windSpeed10_mps >= 0.0) || !std::isfinite(windSpeed10_mps) || !std::isfinite(height_m))
        throw InputError("wind profile: need a finite wind speed >= 0 m/s and a finite height");
    // The profile is referred to 10 m and not extrapolated below it.
    const double z = std::max(height_m, 10.0);
    return std::max(1.0, windSpeed10_mps * std::pow(z / 10.0, kExponent[int(c)]));
}

PlumeBehaviour ClassifyBehaviour(StabilityClass c, double sourceHeight_m, double effectiveHeight_m,
                                 double inversionHeight_m) {
    using enum PlumeBehaviour;
    const bool unstable =
        c == StabilityClass::A || c == StabilityClass::B || c == StabilityClass::C;
    if (!std::isfinite(inversionHeight_m)) {
        if (unstable) return Looping;
        return c == StabilityClass::D ? Coning : Fanning;
    }
    if (IsStable(c)) return effectiveHeight_m > inversionHeight_m ? Lofting : Fanning;
    if (sourceHeight_m >= inversionHeight_m) return Lofting;
    return unstable ? Fumigation : Trapping;
}

double HeskestadFlameHeight_m(double heatRelease_W, double diameter_m) {
    if (!(heatRelease_W >= 0.0) || !(diameter_m >= 0.0) || !std::isfinite(heatRelease_W) ||
        !std::isfinite(diameter_m))
        throw InputError("flame height: need finite heat release >= 0 W and diameter >= 0 m");
    return std::max(0.0, 0.235 * std::pow(heatRelease_W * 1e-3, 0.4) - 1.02 * diameter_m);
}

RiseState QuadraticDragRise(double reducedGravity_mps2, double drag_1pm, double t_s) {
    if (!(drag_1pm > 0.0) || !(t_s >= 0.0) || !std::isfinite(reducedGravity_mps2))
        throw InputError("buoyant rise: need finite g', drag > 0 1/m and t >= 0 s");
    if (reducedGravity_mps2 <= 0.0) return {};
    const double rate = std::sqrt(reducedGravity_mps2 * drag_1pm);
    const double terminal = std::sqrt(reducedGravity_mps2 / drag_1pm);
    const double arg = rate * t_s;
    // ln cosh(a) = a + ln((1 + e^(−2a)) / 2), stable for large a.
    const double logCosh = arg + std::log1p(std::exp(-2.0 * arg)) - std::numbers::ln2;
    return {logCosh / drag_1pm, terminal * std::tanh(arg)};
}

double QuadraticDragDrift_m(double wind_mps, double drag_1pm, double t_s) {
    if (!(drag_1pm > 0.0) || !(t_s >= 0.0) || !std::isfinite(wind_mps))
        throw InputError("puff drift: need a finite wind, drag > 0 1/m and t >= 0 s");
    const double u = std::abs(wind_mps);
    const double x = u * t_s - std::log1p(drag_1pm * u * t_s) / drag_1pm;
    return std::copysign(x, wind_mps);
}

double UnpavedRoadDust_kgpm(double speed_mps, double siltPercent, double moisturePercent) {
    if (!(speed_mps >= 0.0) || !(siltPercent >= 0.0) || !(moisturePercent > 0.0) ||
        !std::isfinite(speed_mps) || !std::isfinite(siltPercent) || !std::isfinite(moisturePercent))
        throw InputError("road dust: need finite speed >= 0 m/s, silt >= 0 % and moisture > 0 %");
    constexpr double kMphPerMps = 1.0 / 0.44704;
    constexpr double kKgPerLb = 0.45359237;
    constexpr double kMetresPerMile = 1609.344;
    const double speed_mph = speed_mps * kMphPerMps;
    const double e_lbPerVmt = 6.0 * (siltPercent / 12.0) * std::pow(speed_mph / 30.0, 0.3) /
                              std::pow(moisturePercent / 0.5, 0.3);
    return e_lbPerVmt * kKgPerLb / kMetresPerMile;
}

}  // namespace seasense::scene
