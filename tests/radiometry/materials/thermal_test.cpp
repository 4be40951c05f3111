// Tests of the lumped surface heat balance: the analytic exponential relaxation, relaxation to
// the air temperature in an isothermal environment, the discrete energy balance of each
// implicit step, and the diurnal behaviour of sunlit and shaded plates.
#include "radiometry/materials/thermal.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "scene/core/error.h"

namespace seasense::radiometry {
namespace {

double Sigma() { return kStefanBoltzmann_W_m2_K4; }

TEST(HeatBalance, McAdamsCoefficientAndViewFactors) {
    EXPECT_DOUBLE_EQ(ConvectionCoefficient_W_m2K(0.0), 5.7);
    EXPECT_DOUBLE_EQ(ConvectionCoefficient_W_m2K(5.0), 5.7 + 19.0);
    const double sky = 300.0, Tg = 290.0, ground = Sigma() * std::pow(Tg, 4);
    EXPECT_NEAR(TiltedLongwaveIrradiance_W_m2(sky, 0.0, Tg), sky, 1e-12);
    EXPECT_NEAR(TiltedLongwaveIrradiance_W_m2(sky, std::numbers::pi, Tg), ground, 1e-9);
    EXPECT_NEAR(TiltedLongwaveIrradiance_W_m2(sky, 0.5 * std::numbers::pi, Tg),
                0.5 * (sky + ground), 1e-9);
}

TEST(HeatBalance, ConvectionOnlyRelaxesExponentially) {
    // C dT/dt = h (T_a − T): T = T_a + (T0 − T_a) exp(−h t / C).
    HeatBalanceParameters p;
    p.solarAbsorptance = 0.0;
    p.emissivity = 0.0;
    p.arealHeatCapacity_J_m2K = 4.0e4;
    std::vector<ThermalDrivers> d;
    for (int i = 0; i <= 10; ++i) d.push_back({i * 1800.0, 0.0, 0.0, 280.0, 0.0});
    const std::vector<double> T = IntegrateSurfaceTemperature(p, d, 300.0, 10.0);
    ASSERT_EQ(T.size(), d.size());
    for (size_t i = 0; i < T.size(); ++i) {
        const double exact =
            280.0 + 20.0 * std::exp(-5.7 * d[i].time_s / p.arealHeatCapacity_J_m2K);
        EXPECT_NEAR(T[i], exact, 0.03) << d[i].time_s;
    }
}

TEST(HeatBalance, NoSunNoWindRelaxesToTheAirTemperature) {
    // Isothermal surroundings (sky longwave σT_a⁴): the only fixed point is T = T_a.
    HeatBalanceParameters p;
    p.arealHeatCapacity_J_m2K = 2.0e4;
    const double Ta = 285.0;
    std::vector<ThermalDrivers> d{{0.0, 0.0, Sigma() * std::pow(Ta, 4), Ta, 0.0},
                                  {86400.0, 0.0, Sigma() * std::pow(Ta, 4), Ta, 0.0}};
    for (double T0 : {250.0, 330.0}) {
        const std::vector<double> T = IntegrateSurfaceTemperature(p, d, T0);
        EXPECT_NEAR(T.back(), Ta, 0.01) << T0;
    }
    EXPECT_NEAR(EquilibriumTemperature_K(p, d[0]), Ta, 1e-9);
}

TEST(HeatBalance, EachImplicitStepConservesEnergy) {
    // Backward Euler: C (T1 − T0) = Δt · NetHeatFlux(T1), the energy absorbed in the step.
    HeatBalanceParameters p;
    p.backingConductance_W_m2K = 2.0;
    const ThermalDrivers a{0.0, 600.0, 320.0, 290.0, 3.0};
    ThermalDrivers b = a;
    b.time_s = 45.0;
    const std::vector<double> T = IntegrateSurfaceTemperature(p, {a, b}, 280.0, 60.0);
    EXPECT_NEAR(p.arealHeatCapacity_J_m2K * (T[1] - T[0]), 45.0 * NetHeatFlux_W_m2(p, b, T[1]),
                1e-9 * p.arealHeatCapacity_J_m2K * (T[1] - T[0]));
}

TEST(HeatBalance, ConstantDriversReachTheEquilibrium) {
    HeatBalanceParameters p;
    const ThermalDrivers d0{0.0, 700.0, 330.0, 295.0, 2.0};
    ThermalDrivers d1 = d0;
    d1.time_s = 3 * 86400.0;
    const double Teq = EquilibriumTemperature_K(p, d0);
    EXPECT_NEAR(NetHeatFlux_W_m2(p, d0, Teq), 0.0, 1e-8);
    EXPECT_GT(Teq, 295.0);  // absorbed sun heats the plate above the air
    EXPECT_NEAR(IntegrateSurfaceTemperature(p, {d0, d1}, 260.0).back(), Teq, 1e-6);
}

TEST(HeatBalance, SunlitSideIsWarmerInTheAfternoonAndAllCoolAfterSunset) {
    // Two days of clear weather, every 10 minutes: sun 06–18 h, air 285 ± 4 K peaking at 15 h,
    // wind 3 m/s, sky longwave 0.8 σT_a⁴, vertical plates (half sky, half sea at 288 K).
    HeatBalanceParameters paint;
    paint.solarAbsorptance = 0.7;
    paint.emissivity = 0.9;
    paint.arealHeatCapacity_J_m2K = 4.0e4;  // ~10 mm of steel
    std::vector<ThermalDrivers> sunlit, shaded;
    for (int i = 0; i <= 2 * 144; ++i) {
        const double t = i * 600.0, hour = std::fmod(t / 3600.0, 24.0);
        const double sun =
            (hour > 6.0 && hour < 18.0) ? std::sin(std::numbers::pi * (hour - 6.0) / 12.0) : 0.0;
        const double Ta = 285.0 + 4.0 * std::cos(2.0 * std::numbers::pi * (hour - 15.0) / 24.0);
        const double lw = TiltedLongwaveIrradiance_W_m2(0.8 * Sigma() * std::pow(Ta, 4),
                                                        0.5 * std::numbers::pi, 288.0);
        sunlit.push_back({t, 700.0 * sun + 80.0 * sun, lw, Ta, 3.0});
        shaded.push_back({t, 80.0 * sun, lw, Ta, 3.0});
    }
    const auto Tsun =
        IntegrateSurfaceTemperature(paint, sunlit, EquilibriumTemperature_K(paint, sunlit[0]));
    const auto Tshade =
        IntegrateSurfaceTemperature(paint, shaded, EquilibriumTemperature_K(paint, shaded[0]));
    const size_t at15h = 144 + 15 * 6, at18h = 144 + 18 * 6, at23h = 144 + 23 * 6;
    EXPECT_GT(Tsun[at15h], Tshade[at15h] + 5.0);
    for (size_t i = at18h + 1; i <= at23h; ++i) {
        EXPECT_LT(Tsun[i], Tsun[i - 1]) << i;
        EXPECT_LT(Tshade[i], Tshade[i - 1]) << i;
    }
}

TEST(HeatBalance, RejectsBadInput) {
    HeatBalanceParameters p;
    const ThermalDrivers d{0.0, 0.0, 300.0, 290.0, 1.0};
    EXPECT_THROW(IntegrateSurfaceTemperature(p, {}, 290.0), InputError);
    EXPECT_THROW(IntegrateSurfaceTemperature(p, {d, d}, 290.0), InputError);  // time not increasing
    ThermalDrivers bad = d;
    bad.solarIrradiance_W_m2 = -1.0;
    EXPECT_THROW(IntegrateSurfaceTemperature(p, {bad}, 290.0), InputError);
    p.arealHeatCapacity_J_m2K = 0.0;
    EXPECT_THROW(IntegrateSurfaceTemperature(p, {d}, 290.0), InputError);
}

}  // namespace
}  // namespace seasense::radiometry
