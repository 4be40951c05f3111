// Tests of the closed-form plume physics against hand values from the published formulas and
// tables, numerical integration of the equations of motion, and their limiting behaviour.
#include "scene/plumes/plume_physics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>

#include "scene/core/error.h"

namespace seasense::scene {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
using enum StabilityClass;
constexpr StabilityClass kClasses[] = {A, B, C, D, E, F};

// Seed 004 Table 1 typed in again (with Beychok's signs): I, J, K for σz then σy.
struct Row {
    double Iz, Jz, Kz, Iy, Jy, Ky;
};
constexpr Row kTable1[] = {{6.035, 2.1097, 0.2770, 5.357, 0.8828, -0.0076},
                           {4.694, 1.0629, 0.0136, 5.058, 0.9024, -0.0096},
                           {4.110, 0.9201, -0.0020, 4.651, 0.9181, -0.0076},
                           {3.414, 0.7371, -0.0316, 4.230, 0.9222, -0.0087},
                           {3.057, 0.6794, -0.0450, 3.922, 0.9222, -0.0064},
                           {2.621, 0.6564, -0.0540, 3.533, 0.9181, -0.0070}};

TEST(PlumeDispersion, SigmaAtOneKilometreIsExpI) {
    // ln(1 km) = 0, so Eq 6 gives σ = e^I at 1 km.
    for (int c = 0; c < kStabilityClasses; ++c) {
        EXPECT_NEAR(SigmaY_m(kClasses[c], 1000.0), std::exp(kTable1[c].Iy), 1e-9) << c;
        EXPECT_NEAR(SigmaZ_m(kClasses[c], 1000.0), std::exp(kTable1[c].Iz), 1e-9) << c;
    }
    // Hand values: class D σy = e^4.230 = 68.72 m, σz = e^3.414 = 30.39 m (the familiar
    // Pasquill–Gifford chart values at 1 km).
    EXPECT_NEAR(SigmaY_m(D, 1000.0), 68.72, 0.01);
    EXPECT_NEAR(SigmaZ_m(D, 1000.0), 30.39, 0.01);
}

TEST(PlumeDispersion, SigmaFollowsEquation6AwayFromOneKilometre) {
    for (double x_km : {0.1, 0.35, 2.0, 7.5, 20.0}) {
        const double l = std::log(x_km);
        for (int c = 0; c < kStabilityClasses; ++c) {
            const Row& r = kTable1[c];
            const double sy = std::exp(r.Iy + r.Jy * l + r.Ky * l * l);
            const double sz = std::exp(r.Iz + r.Jz * l + r.Kz * l * l);
            EXPECT_NEAR(SigmaY_m(kClasses[c], x_km * 1000.0) / sy, 1.0, 1e-12);
            EXPECT_NEAR(SigmaZ_m(kClasses[c], x_km * 1000.0) / sz, 1.0, 1e-12);
        }
    }
    // Class D at 2 km by hand: σy = exp(4.230 + 0.63922 − 0.00418) = e^4.86504 = 129.68 m.
    EXPECT_NEAR(SigmaY_m(D, 2000.0), 129.68, 0.01);
}

TEST(PlumeDispersion, MoreStableSpreadsLess) {
    for (double x_m : {50.0, 300.0, 1000.0, 5000.0}) {
        for (int c = 0; c + 1 < kStabilityClasses; ++c) {
            EXPECT_GT(SigmaY_m(kClasses[c], x_m), SigmaY_m(kClasses[c + 1], x_m)) << x_m;
            EXPECT_GT(SigmaZ_m(kClasses[c], x_m), SigmaZ_m(kClasses[c + 1], x_m)) << x_m;
        }
    }
}

TEST(PlumeDispersion, NearFieldIsContinuousAndGrowsFromZero) {
    for (StabilityClass c : kClasses) {
        EXPECT_EQ(SigmaZ_m(c, 0.0), 0.0);
        EXPECT_NEAR(SigmaZ_m(c, 99.999) / SigmaZ_m(c, 100.001), 1.0, 1e-4);
        EXPECT_NEAR(SigmaY_m(c, 99.999) / SigmaY_m(c, 100.001), 1.0, 1e-4);
        double previous = 0.0;
        for (double x = 1.0; x <= 200.0; x += 1.0) {
            EXPECT_GT(SigmaZ_m(c, x), previous);
            previous = SigmaZ_m(c, x);
        }
    }
    EXPECT_THROW(SigmaY_m(D, -1.0), InputError);
    EXPECT_THROW(SigmaY_m(D, NAN), InputError);
}

TEST(PlumeRise, BriggsTwoThirdsLawByHand) {
    // 1.6 · 100^(1/3) · 1000^(2/3) / 5 = 1.6 · 4.641589 · 100 / 5 = 148.53 m.
    EXPECT_NEAR(BriggsTransitionalRise_m(100.0, 1000.0, 5.0), 148.5309, 1e-3);
    // Δh ∝ x^(2/3) and ∝ 1/u.
    EXPECT_NEAR(
        BriggsTransitionalRise_m(100.0, 8000.0, 5.0) / BriggsTransitionalRise_m(100.0, 1000.0, 5.0),
        4.0, 1e-12);
    EXPECT_NEAR(BriggsTransitionalRise_m(100.0, 1000.0, 10.0) /
                    BriggsTransitionalRise_m(100.0, 1000.0, 5.0),
                0.5, 1e-12);
    EXPECT_THROW(BriggsTransitionalRise_m(100.0, 1000.0, 0.0), InputError);
}

TEST(PlumeRise, FinalRiseMatchesBriggsClosedForms) {
    // Neutral/unstable: Δh_f = 21.425 F^(3/4) / u for F < 55, 38.71 F^(3/5) / u otherwise
    // (Briggs 1975 as printed in EPA ISC3 vol. II eqs. 1-30, 1-31).
    EXPECT_NEAR(BriggsFinalRise_m(D, 20.0, 4.0, 288.15), 21.425 * std::pow(20.0, 0.75) / 4.0, 0.01);
    EXPECT_NEAR(BriggsFinalRise_m(C, 100.0, 4.0, 288.15), 38.71 * std::pow(100.0, 0.6) / 4.0, 0.01);
    EXPECT_NEAR(BriggsFinalRiseDistance_m(D, 100.0, 4.0, 288.15), 119.0 * std::pow(100.0, 0.4),
                1e-9);
    // Stable F: s = g/T dθ/dz = 9.80665 / 288.15 · 0.035; Δh = 2.6 (F / (u s))^(1/3).
    const double s = 9.80665 / 288.15 * 0.035;
    EXPECT_NEAR(BriggsFinalRise_m(F, 100.0, 4.0, 288.15), 2.6 * std::cbrt(100.0 / (4.0 * s)), 1e-9);
    EXPECT_NEAR(BriggsFinalRiseDistance_m(F, 100.0, 4.0, 288.15), 2.0715 * 4.0 / std::sqrt(s),
                1e-9);
    // A stable atmosphere stops the plume lower than a neutral one.
    EXPECT_LT(BriggsFinalRise_m(F, 100.0, 4.0, 288.15), BriggsFinalRise_m(D, 100.0, 4.0, 288.15));
}

TEST(PlumeRise, BuoyancyFluxes) {
    // g w r² ΔT / T_s = 9.80665 · 15 · 1 · 200 / 500.
    EXPECT_NEAR(StackBuoyancyFlux_m4ps3(15.0, 1.0, 500.0, 300.0), 58.8399, 1e-4);
    EXPECT_EQ(StackBuoyancyFlux_m4ps3(15.0, 1.0, 280.0, 300.0), 0.0);
    // w² r² T_a / T_s = 225 · 0.25 · 300 / 500.
    EXPECT_NEAR(StackMomentumFlux_m4ps2(15.0, 0.5, 500.0, 300.0), 33.75, 1e-12);
    // Briggs (1969): F = 8.8e-6 m⁴ s⁻³ per watt of heat release.
    EXPECT_NEAR(HeatBuoyancyFlux_m4ps3(1.0e7, 288.15) / 1.0e7, 8.8e-6, 0.05e-6);
}

TEST(PlumeRise, WindProfile) {
    EXPECT_NEAR(WindAtHeight_mps(D, 5.0, 100.0), 5.0 * std::pow(10.0, 0.15), 1e-12);
    EXPECT_NEAR(WindAtHeight_mps(F, 5.0, 40.0), 5.0 * std::pow(4.0, 0.55), 1e-12);
    EXPECT_EQ(WindAtHeight_mps(D, 5.0, 2.0), 5.0);   // not extrapolated below 10 m
    EXPECT_EQ(WindAtHeight_mps(D, 0.2, 10.0), 1.0);  // ISC3 floor
}

TEST(PlumeMass, DecayLaw) {
    const double fd = 0.3, delta = 0.05;
    EXPECT_DOUBLE_EQ(MassDecayFactor(0.0, fd, delta), 1.0);
    EXPECT_NEAR(MassDecayFactor(20.0, fd, delta), fd + (1 - fd) / std::numbers::e, 1e-15);
    EXPECT_NEAR(MassDecayFactor(1e4, fd, delta), fd, 1e-15);
    // dM/dt = −δ (M − f_d M0): the decaying part is first order.
    const double h = 1e-4;
    for (double t : {0.0, 3.0, 40.0}) {
        const double m = MassDecayFactor(t + h, fd, delta);
        const double dm =
            (MassDecayFactor(t + 2 * h, fd, delta) - MassDecayFactor(t, fd, delta)) / (2 * h);
        EXPECT_NEAR(dm, -delta * (m - fd), 1e-9);
    }
    EXPECT_THROW(MassDecayFactor(1.0, 1.5, 0.1), InputError);
    EXPECT_THROW(MassDecayFactor(-1.0, 0.5, 0.1), InputError);
}

TEST(PlumeStability, PasquillTurnerTable) {
    // Day, strong sun (70°): < 2 m/s A, 3–5 B, > 6 C.
    EXPECT_EQ(PasquillTurnerClass(1.0, 70 * kDeg, 0.0), A);
    EXPECT_EQ(PasquillTurnerClass(4.0, 70 * kDeg, 0.0), B);
    EXPECT_EQ(PasquillTurnerClass(8.0, 70 * kDeg, 0.0), C);
    // Moderate (45°): 2–3 B, > 6 D. Slight (20°): < 2 B, 3–5 C, 5–6 D.
    EXPECT_EQ(PasquillTurnerClass(2.5, 45 * kDeg, 0.0), B);
    EXPECT_EQ(PasquillTurnerClass(7.0, 45 * kDeg, 0.0), D);
    EXPECT_EQ(PasquillTurnerClass(1.0, 20 * kDeg, 0.0), B);
    EXPECT_EQ(PasquillTurnerClass(4.0, 20 * kDeg, 0.0), C);
    EXPECT_EQ(PasquillTurnerClass(5.5, 20 * kDeg, 0.0), D);
    // Night: <= 3/8 cloud 2–3 F, 3–5 E; >= 4/8 cloud 2–3 E, 3–5 D; windy nights D.
    EXPECT_EQ(PasquillTurnerClass(2.5, -10 * kDeg, 0.1), F);
    EXPECT_EQ(PasquillTurnerClass(4.0, -10 * kDeg, 0.1), E);
    EXPECT_EQ(PasquillTurnerClass(2.5, -10 * kDeg, 0.6), E);
    EXPECT_EQ(PasquillTurnerClass(4.0, -10 * kDeg, 0.6), D);
    EXPECT_EQ(PasquillTurnerClass(7.0, -10 * kDeg, 0.0), D);
    // Overcast is neutral, day or night.
    EXPECT_EQ(PasquillTurnerClass(1.0, 70 * kDeg, 1.0), D);
    EXPECT_EQ(PasquillTurnerClass(1.0, -30 * kDeg, 1.0), D);
    EXPECT_THROW(PasquillTurnerClass(-1.0, 0.0, 0.0), InputError);
    EXPECT_THROW(PasquillTurnerClass(1.0, 0.0, 1.5), InputError);
}

TEST(PlumeStability, Behaviour) {
    const double inf = std::numeric_limits<double>::infinity();
    EXPECT_EQ(ClassifyBehaviour(B, 20, 200, inf), PlumeBehaviour::Looping);
    EXPECT_EQ(ClassifyBehaviour(D, 20, 200, inf), PlumeBehaviour::Coning);
    EXPECT_EQ(ClassifyBehaviour(F, 20, 200, inf), PlumeBehaviour::Fanning);
    EXPECT_EQ(ClassifyBehaviour(F, 20, 200, 100), PlumeBehaviour::Lofting);
    EXPECT_EQ(ClassifyBehaviour(E, 20, 80, 100), PlumeBehaviour::Fanning);
    EXPECT_EQ(ClassifyBehaviour(B, 20, 200, 500), PlumeBehaviour::Fumigation);
    EXPECT_EQ(ClassifyBehaviour(D, 20, 200, 500), PlumeBehaviour::Trapping);
    EXPECT_EQ(ClassifyBehaviour(D, 600, 700, 500), PlumeBehaviour::Lofting);
}

TEST(PlumeFlame, HeskestadHeightByHand) {
    // 0.235 · 1000^0.4 − 1.02 · 1 = 0.235 · 15.8489 − 1.02 = 2.7045 m for 1 MW on a 1 m fire.
    EXPECT_NEAR(HeskestadFlameHeight_m(1.0e6, 1.0), 0.235 * std::pow(1000.0, 0.4) - 1.02, 1e-12);
    EXPECT_NEAR(HeskestadFlameHeight_m(1.0e6, 1.0), 2.7045, 1e-4);
    EXPECT_EQ(HeskestadFlameHeight_m(1.0e3, 5.0), 0.0);
}

// Classical RK4 for a scalar ODE y' = f(y), y(0) = 0, integrated to t.
double Rk4(const std::function<double(double)>& f, double t, int steps, double* integral) {
    double y = 0.0, x = 0.0;
    const double h = t / steps;
    for (int i = 0; i < steps; ++i) {
        const double k1 = f(y), k2 = f(y + 0.5 * h * k1), k3 = f(y + 0.5 * h * k2),
                     k4 = f(y + h * k3);
        // Position by Simpson on the same stage values (velocity at 0, h/2, h).
        x += h / 6.0 * (y + 2.0 * (y + 0.5 * h * k1) + 2.0 * (y + 0.5 * h * k2) + (y + h * k3));
        y += h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4);
    }
    *integral = x;
    return y;
}

TEST(PlumeFlame, QuadraticDragRiseSolvesTheEquationOfMotion) {
    const double gPrime = 31.0, k = 1.04;
    for (double t : {0.1, 0.5, 1.3, 4.0}) {
        double z = 0.0;
        const double w = Rk4([&](double v) { return gPrime - k * v * v; }, t, 20000, &z);
        const RiseState s = QuadraticDragRise(gPrime, k, t);
        EXPECT_NEAR(s.speed_mps, w, 1e-6 * std::max(1.0, w)) << t;
        EXPECT_NEAR(s.height_m, z, 1e-4 * std::max(1.0, z)) << t;
    }
    EXPECT_NEAR(QuadraticDragRise(gPrime, k, 100.0).speed_mps, std::sqrt(gPrime / k), 1e-9);
    EXPECT_EQ(QuadraticDragRise(-1.0, k, 1.0).height_m, 0.0);
}

TEST(PlumeFlame, QuadraticDragDriftSolvesTheEquationOfMotion) {
    const double u = 6.0, k = 0.8;
    for (double t : {0.2, 1.0, 5.0}) {
        double x = 0.0;
        Rk4([&](double v) { return k * (u - v) * (u - v); }, t, 20000, &x);
        EXPECT_NEAR(QuadraticDragDrift_m(u, k, t), x, 1e-4 * std::max(1.0, x)) << t;
    }
}

TEST(PlumeDust, Ap42ReferenceConditions) {
    // At the equation's reference point (s = 12 %, S = 30 mph, M = 0.5 %) E = k = 6.0 lb/VMT.
    const double kgPerMetre = 6.0 * 0.45359237 / 1609.344;
    EXPECT_NEAR(UnpavedRoadDust_kgpm(30.0 * 0.44704, 12.0, 0.5), kgPerMetre, 1e-15);
    // E ∝ s, S^0.3, M^−0.3.
    EXPECT_NEAR(UnpavedRoadDust_kgpm(30.0 * 0.44704, 6.0, 0.5) / kgPerMetre, 0.5, 1e-12);
    EXPECT_NEAR(UnpavedRoadDust_kgpm(15.0 * 0.44704, 12.0, 0.5) / kgPerMetre, std::pow(0.5, 0.3),
                1e-12);
    EXPECT_NEAR(UnpavedRoadDust_kgpm(30.0 * 0.44704, 12.0, 2.0) / kgPerMetre, std::pow(4.0, -0.3),
                1e-12);
    EXPECT_THROW(UnpavedRoadDust_kgpm(10.0, 12.0, 0.0), InputError);
}

}  // namespace
}  // namespace seasense::scene
