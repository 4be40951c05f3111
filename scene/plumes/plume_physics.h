// Plume physics in closed form: Pasquill–Turner stability, Pasquill–Gifford dispersion, Briggs
// plume rise, mass decay, flame height, buoyant puff rise and vehicle dust emission.
#pragma once

#include <cstdint>
#include <string_view>

namespace seasense::scene {

// Pasquill stability classes: A extremely unstable … D neutral … F moderately stable.
enum class StabilityClass : uint8_t { A, B, C, D, E, F };
inline constexpr int kStabilityClasses = 6;

// "A" … "F".
std::string_view ToString(StabilityClass c);

// Stability class from the 10 m wind speed (m/s), the sun's elevation (rad) and the total
// cloud cover (fraction 0..1), after the Pasquill (1961) / Turner (1964) table. Throws
// InputError for non-finite or out-of-range arguments.
StabilityClass PasquillTurnerClass(double windSpeed_mps, double sunElevation_rad,
                                   double cloudCover);

// Pasquill–Gifford horizontal (crosswind) and vertical dispersion σ (m) at downwind distance
// x_m (m ≥ 0) for the rural coefficients of seed 004 Table 1 with its Eq 6 (McMullen 1975 in
// Beychok 1979). Zero at x = 0.
double SigmaY_m(StabilityClass c, double x_m);
double SigmaZ_m(StabilityClass c, double x_m);

// Seed 004 Eq 4: M(t)/M0 = f_d + (1 − f_d) e^(−δ t), age_s ≥ 0, f_d in [0, 1], δ ≥ 0 (1/s).
double MassDecayFactor(double age_s, double longTermFraction, double decayRate_hz);

// Standard gravity, m/s² (CGPM 1901).
inline constexpr double kPlumeGravity_mps2 = 9.80665;

// Buoyancy flux of a stack (m⁴/s³): F = g w r² (T_s − T_a) / T_s (Briggs 1969); zero when the
// gas is not warmer than the air.
double StackBuoyancyFlux_m4ps3(double exitVelocity_mps, double radius_m, double exit_K,
                               double air_K);
// Momentum flux of a stack (m⁴/s²): F_m = w² r² T_a / T_s (Briggs 1969).
double StackMomentumFlux_m4ps2(double exitVelocity_mps, double radius_m, double exit_K,
                               double air_K);
// Buoyancy flux of a fire of convective heat release Q (W): F = g Q / (π ρ c_p T_a) (Briggs
// 1969), with air ρ c_p at temperature air_K from the ideal gas law.
double HeatBuoyancyFlux_m4ps3(double heatRelease_W, double air_K);

// Briggs' "2/3 law" for a hot bent-over plume in wind: Δh = 1.6 F^(1/3) x^(2/3) / u (m), for
// buoyancy flux F (m⁴/s³), downwind distance x (m) and wind speed u (m/s) at the source.
double BriggsTransitionalRise_m(double buoyancyFlux_m4ps3, double x_m, double u_mps);

// Final (maximum) buoyant rise (m) and the distance (m) at which it is reached, by stability:
// A–D (Briggs 1975): x_f = 49 F^(5/8) for F < 55, 119 F^(2/5) otherwise, Δh_f = Δh(x_f);
// E–F (Briggs 1975): Δh_f = 2.6 (F / (u s))^(1/3), x_f = 2.0715 u / √s, s = g/T_a dθ/dz with
// dθ/dz = 0.020 K/m (E) and 0.035 K/m (F) (EPA ISC3 User's Guide vol. II, 1995, sec. 1.1.4).
double BriggsFinalRise_m(StabilityClass c, double buoyancyFlux_m4ps3, double u_mps, double air_K);
double BriggsFinalRiseDistance_m(StabilityClass c, double buoyancyFlux_m4ps3, double u_mps,
                                 double air_K);

// Wind speed (m/s) at height_m from the 10 m speed with the rural power-law exponents of EPA
// ISC3 (vol. II sec. 1.1.3: A,B 0.07, C 0.10, D 0.15, E 0.35, F 0.55), never below the ISC3
// floor of 1 m/s (Briggs' rise diverges in calm air).
double WindAtHeight_mps(StabilityClass c, double windSpeed10_mps, double height_m);

// How a plume behaves (seed 004 Fig. 5).
enum class PlumeBehaviour : uint8_t { Looping, Coning, Fanning, Lofting, Fumigation, Trapping };
std::string_view ToString(PlumeBehaviour b);

// The behaviour of a plume released at sourceHeight_m that would reach effectiveHeight_m
// (source + final rise) for stability class c and an inversion at inversionHeight_m (+∞ for
// none). The inversion is read as the top of a surface inversion for the stable classes E–F
// and as the base of an elevated inversion (the mixing lid) for A–D:
//   no inversion: A–C looping, D coning, E–F fanning;
//   E–F: fanning inside the surface inversion, lofting once the plume rises above it;
//   A–D with the source below the lid: A–C fumigation (convection mixes the capped plume down
//   to the ground), D trapping (capped rise, reflection between ground and lid);
//   A–D with the source at or above the lid: lofting (the lid is a floor).
PlumeBehaviour ClassifyBehaviour(StabilityClass c, double sourceHeight_m, double effectiveHeight_m,
                                 double inversionHeight_m);

// Mean flame height (m) of a fire of total heat release Q (W) and diameter D (m): Heskestad,
// Fire Safety Journal 7 (1984) 25: L = 0.235 Q_kW^(2/5) − 1.02 D, never below 0.
double HeskestadFlameHeight_m(double heatRelease_W, double diameter_m);

// Height and speed of a puff pushed up by reduced gravity g' (m/s²) against seed 004 Eq 7's
// quadratic drag, dw/dt = g' − k w² (k in 1/m), from rest at t = 0:
// w = w_t tanh(√(g'k) t), z = ln cosh(√(g'k) t) / k with w_t = √(g'/k).
struct RiseState {
    double height_m = 0;
    double speed_mps = 0;
};
RiseState QuadraticDragRise(double reducedGravity_mps2, double drag_1pm, double t_s);
// Distance travelled by a puff released at rest into a wind of speed u under the same drag:
// dv/dt = k (u − v)² gives x = u t − ln(1 + k u t) / k.
double QuadraticDragDrift_m(double wind_mps, double drag_1pm, double t_s);

// Suspended dust (kg) raised per metre travelled by a vehicle at speed_mps on an unpaved road
// of silt content siltPercent (%) and surface moisture moisturePercent (%): US EPA AP-42
// sec. 13.2.2 (11/2006) Eq 1b with the PM-30 constants k = 6.0 lb/VMT, a = 1, c = 0.3, d = 0.3:
// E = k (s/12)^a (S/30)^d / (M/0.5)^c, S in mph (the exhaust, brake and tyre term C is not
// dust and is left out).
double UnpavedRoadDust_kgpm(double speed_mps, double siltPercent, double moisturePercent);

}  // namespace seasense::scene
