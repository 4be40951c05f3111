// Lumped surface heat balance: absorbed sun and sky, emission, wind convection, conduction to a
// backing, and thermal inertia, integrated over a time series of drivers (implicit Euler).
#pragma once

#include <vector>

namespace seasense::radiometry {

// Stefan–Boltzmann constant σ, W·m⁻²·K⁻⁴ (CODATA 2018).
inline constexpr double kStefanBoltzmann_W_m2_K4 = 5.670374419e-8;

// Properties of one surface (one material in one orientation class).
struct HeatBalanceParameters {
    double solarAbsorptance = 0.7;           // fraction of incident shortwave absorbed
    double emissivity = 0.9;                 // broadband thermal emissivity = LW absorptance
    double arealHeatCapacity_J_m2K = 4.0e4;  // C = ρ c_p d, per unit surface area
    double backingConductance_W_m2K = 0.0;   // conduction to the backing (0: insulated back)
    double backingTemperature_K = 293.15;    // e.g. a ship's interior
};

// Environment of the surface at one instant. The irradiances are those on the surface itself:
// the caller applies cos(incidence), shadowing and sky view factors.
struct ThermalDrivers {
    double time_s = 0.0;                   // any fixed origin; strictly increasing in a series
    double solarIrradiance_W_m2 = 0.0;     // direct + diffuse shortwave on the surface
    double longwaveIrradiance_W_m2 = 0.0;  // downwelling (and surroundings') longwave on it
    double airTemperature_K = 288.15;
    double windSpeed_mps = 0.0;
};

// Wind convection coefficient h = 5.7 + 3.8 v (W·m⁻²·K⁻¹, v in m/s), McAdams, "Heat
// Transmission", 3rd ed. (McGraw-Hill 1954), as quoted by Duffie & Beckman, "Solar Engineering
// of Thermal Processes", 4th ed. (2013), Eq. 3.15.2 (flat plate, v ≲ 5 m/s; used beyond).
double ConvectionCoefficient_W_m2K(double windSpeed_mps);

// Longwave irradiance on a surface tilted tiltAngle_rad from horizontal (0 facing up, π/2
// vertical): sky and ground/sea in proportion to their view factors (1 ± cos tilt)/2 (isotropic
// sky; Duffie & Beckman §2.16), the ground radiating as a blackbody at groundTemperature_K.
double TiltedLongwaveIrradiance_W_m2(double skyIrradiance_W_m2, double tiltAngle_rad,
                                     double groundTemperature_K);

// Net heat flux into the surface at temperature T_K (W·m⁻²):
// α E_sun + ε (E_LW − σ T⁴) + h_c (T_air − T) + g (T_back − T).
double NetHeatFlux_W_m2(const HeatBalanceParameters& p, const ThermalDrivers& d, double T_K);

// Steady-state temperature (K) under constant drivers: the root of NetHeatFlux (unique: the
// flux falls strictly with T).
double EquilibriumTemperature_K(const HeatBalanceParameters& p, const ThermalDrivers& d);

// Integrates C dT/dt = NetHeatFlux from drivers.front().time_s starting at initial_T_K, with
// implicit (backward) Euler steps of at most maxStep_s (unconditionally stable, so thin plates
// with short time constants need no smaller step) and the drivers linear in time between
// samples. Returns the temperature at every driver sample time (element 0 = initial_T_K).
// For a spin-up, start the series e.g. 24 h before the scenario and begin at the
// equilibrium of the first sample. Throws InputError unless there is at least one sample,
// times strictly increase, all values are finite, irradiances ≥ 0, temperatures > 0,
// wind ≥ 0, C > 0, absorptance and emissivity in [0, 1], conductance ≥ 0, maxStep_s > 0.
std::vector<double> IntegrateSurfaceTemperature(const HeatBalanceParameters& p,
                                                const std::vector<ThermalDrivers>& drivers,
                                                double initial_T_K, double maxStep_s = 60.0);

}  // namespace seasense::radiometry
