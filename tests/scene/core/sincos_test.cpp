// SinCos against libm's sin and cos: a few ulp over the range the wave phases use, exact
// quadrant symmetry, and the identity sin² + cos² = 1.
#include "scene/core/sincos.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "scene/core/rng.h"

namespace seasense::scene {
namespace {

TEST(SinCos, MatchesLibmWithinAFewUlpOverThePhaseRange) {
    double worst = 0.0;
    for (int i = 0; i < 2000000; ++i) {
        // Log-uniform magnitudes from 1e-6 to 1e6 rad (< 2²⁰), both signs.
        const double m = std::pow(10.0, -6.0 + 12.0 * Uniform01(7, 1, uint64_t(i)));
        const double x = (i & 1) ? m : -m;
        double s, c;
        SinCos(x, s, c);
        // The argument itself is only known to half an ulp: allow that times the derivative.
        const double tol = 4e-16 + 1.2e-16 * std::abs(x);
        EXPECT_NEAR(s, std::sin(x), tol) << x;
        EXPECT_NEAR(c, std::cos(x), tol) << x;
        worst = std::max(worst, std::abs(s * s + c * c - 1.0));
    }
    EXPECT_LT(worst, 1e-15);
}

TEST(SinCos, QuadrantsAndSpecialAngles) {
    constexpr double kPi = std::numbers::pi;
    double s, c;
    SinCos(0.0, s, c);
    EXPECT_EQ(s, 0.0);
    EXPECT_EQ(c, 1.0);
    for (int k = -8; k <= 8; ++k) {
        SinCos(k * kPi / 2.0, s, c);
        EXPECT_NEAR(s, std::sin(k * kPi / 2.0), 1e-15) << k;
        EXPECT_NEAR(c, std::cos(k * kPi / 2.0), 1e-15) << k;
        SinCos(k * kPi / 2.0 + kPi / 6.0, s, c);
        EXPECT_NEAR(s, std::sin(k * kPi / 2.0 + kPi / 6.0), 1e-15) << k;
        EXPECT_NEAR(c, std::cos(k * kPi / 2.0 + kPi / 6.0), 1e-15) << k;
    }
    // sin 30° = cos 60° = 1/2 to within two ulp (the arguments are rounded to doubles).
    SinCos(kPi / 6.0, s, c);
    EXPECT_NEAR(s, 0.5, 2.5e-16);
    SinCos(kPi / 3.0, s, c);
    EXPECT_NEAR(c, 0.5, 2.5e-16);
}

}  // namespace
}  // namespace seasense::scene
