// Lumped heat balance of a surface and its implicit time integration.
#include "radiometry/materials/thermal.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "scene/core/error.h"

namespace seasense::radiometry {
namespace {

void Fail(const std::string& what) { throw InputError("surface heat balance: " + what); }

void CheckParameters(const HeatBalanceParameters& p) {
    std::ostringstream m;
    if (!(p.solarAbsorptance >= 0.0 && p.solarAbsorptance <= 1.0))
        m << "solar absorptance " << p.solarAbsorptance << "; expected [0, 1]";
    else if (!(p.emissivity >= 0.0 && p.emissivity <= 1.0))
        m << "emissivity " << p.emissivity << "; expected [0, 1]";
    else if (!(p.arealHeatCapacity_J_m2K > 0.0 && std::isfinite(p.arealHeatCapacity_J_m2K)))
        m << "areal heat capacity " << p.arealHeatCapacity_J_m2K << " J/(m2 K); expected > 0";
    else if (!(p.backingConductance_W_m2K >= 0.0 && std::isfinite(p.backingConductance_W_m2K)))
        m << "backing conductance " << p.backingConductance_W_m2K << " W/(m2 K); expected >= 0";
    else if (!(p.backingTemperature_K > 0.0 && std::isfinite(p.backingTemperature_K)))
        m << "backing temperature " << p.backingTemperature_K << " K; expected > 0";
    else
        return;
    Fail(m.str());
}

void CheckDrivers(const ThermalDrivers& d, size_t i) {
    std::ostringstream m;
    m << "driver sample " << i << ": ";
    if (!std::isfinite(d.time_s)) Fail(m.str() + "time must be finite");
    if (!(d.solarIrradiance_W_m2 >= 0.0 && std::isfinite(d.solarIrradiance_W_m2)))
        Fail(m.str() + "solar irradiance must be finite and >= 0 W/m2");
    if (!(d.longwaveIrradiance_W_m2 >= 0.0 && std::isfinite(d.longwaveIrradiance_W_m2)))
        Fail(m.str() + "longwave irradiance must be finite and >= 0 W/m2");
    if (!(d.airTemperature_K > 0.0 && std::isfinite(d.airTemperature_K)))
        Fail(m.str() + "air temperature must be finite and > 0 K");
    if (!(d.windSpeed_mps >= 0.0 && std::isfinite(d.windSpeed_mps)))
        Fail(m.str() + "wind speed must be finite and >= 0 m/s");
}

// Root of g(T) = C (T − T_prev) / dt − NetHeatFlux(T), strictly increasing and convex in T:
// Newton from the right of the root converges monotonically; a bisection bracket guards it.
double SolveImplicit(const HeatBalanceParameters& p, const ThermalDrivers& d, double T_prev,
                     double dt) {
    const double c = dt > 0.0 ? p.arealHeatCapacity_J_m2K / dt : 0.0;
    const double h = ConvectionCoefficient_W_m2K(d.windSpeed_mps) + p.backingConductance_W_m2K;
    const auto g = [&](double T) { return c * (T - T_prev) - NetHeatFlux_W_m2(p, d, T); };
    const auto dg = [&](double T) {
        return c + h + 4.0 * p.emissivity * kStefanBoltzmann_W_m2_K4 * T * T * T;
    };
    // Bracket: g(lo) < 0 < g(hi). The linear terms alone bound the root; 1 K keeps T⁴ positive.
    double lo = 1.0, hi = std::max({T_prev, d.airTemperature_K, p.backingTemperature_K}) + 1.0;
    while (g(hi) <= 0.0) hi *= 2.0;
    double T = hi;
    for (int iter = 0; iter < 100; ++iter) {
        const double gt = g(T);
        if (gt > 0.0)
            hi = T;
        else
            lo = T;
        double next = T - gt / dg(T);
        if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
        if (std::abs(next - T) <= 1e-12 * T) return next;
        T = next;
    }
    return T;
}

ThermalDrivers Lerp(const ThermalDrivers& a, const ThermalDrivers& b, double t_s) {
    const double f = (t_s - a.time_s) / (b.time_s - a.time_s);
    const auto mix = [f](double x, double y) { return x + f * (y - x); };
    return {t_s, mix(a.solarIrradiance_W_m2, b.solarIrradiance_W_m2),
            mix(a.longwaveIrradiance_W_m2, b.longwaveIrradiance_W_m2),
            mix(a.airTemperature_K, b.airTemperature_K), mix(a.windSpeed_mps, b.windSpeed_mps)};
}

}  // namespace

double ConvectionCoefficient_W_m2K(double windSpeed_mps) {
    return 5.7 + 3.8 * std::max(windSpeed_mps, 0.0);  // McAdams (1954)
}

double TiltedLongwaveIrradiance_W_m2(double skyIrradiance_W_m2, double tiltAngle_rad,
                                     double groundTemperature_K) {
    const double c = std::cos(tiltAngle_rad);
    const double T = groundTemperature_K;
    return 0.5 * (1.0 + c) * skyIrradiance_W_m2 +
           0.5 * (1.0 - c) * kStefanBoltzmann_W_m2_K4 * T * T * T * T;
}

double NetHeatFlux_W_m2(const HeatBalanceParameters& p, const ThermalDrivers& d, double T_K) {
    const double T4 = T_K * T_K * T_K * T_K;
    return p.solarAbsorptance * d.solarIrradiance_W_m2 +
           p.emissivity * (d.longwaveIrradiance_W_m2 - kStefanBoltzmann_W_m2_K4 * T4) +
           ConvectionCoefficient_W_m2K(d.windSpeed_mps) * (d.airTemperature_K - T_K) +
           p.backingConductance_W_m2K * (p.backingTemperature_K - T_K);
}

double EquilibriumTemperature_K(const HeatBalanceParameters& p, const ThermalDrivers& d) {
    CheckParameters(p);
    CheckDrivers(d, 0);
    return SolveImplicit(p, d, 0.0, 0.0);
}

std::vector<double> IntegrateSurfaceTemperature(const HeatBalanceParameters& p,
                                                const std::vector<ThermalDrivers>& drivers,
                                                double initial_T_K, double maxStep_s) {
    CheckParameters(p);
    if (drivers.empty()) Fail("needs at least one driver sample");
    if (!(initial_T_K > 0.0 && std::isfinite(initial_T_K)))
        Fail("initial temperature must be finite and > 0 K");
    if (!(maxStep_s > 0.0 && std::isfinite(maxStep_s))) Fail("time step must be finite and > 0 s");
    for (size_t i = 0; i < drivers.size(); ++i) {
        CheckDrivers(drivers[i], i);
        if (i > 0 && !(drivers[i].time_s > drivers[i - 1].time_s)) {
            std::ostringstream m;
            m << "driver sample " << i << ": times must strictly increase";
            Fail(m.str());
        }
    }
    std::vector<double> out{initial_T_K};
    double T = initial_T_K;
    for (size_t i = 1; i < drivers.size(); ++i) {
        const double t0 = drivers[i - 1].time_s, t1 = drivers[i].time_s;
        const int steps = int(std::ceil((t1 - t0) / maxStep_s - 1e-9));
        const double dt = (t1 - t0) / std::max(steps, 1);
        for (int k = 1; k <= std::max(steps, 1); ++k) {
            const double t = k == steps ? t1 : t0 + k * dt;
            T = SolveImplicit(p, Lerp(drivers[i - 1], drivers[i], t), T, dt);
        }
        out.push_back(T);
    }
    return out;
}

}  // namespace seasense::radiometry
