// The four-lane SinCos4 against libm's sin and cos over the reduced phase range, and the lanes
// independent of each other.
#include "scene/core/simd4.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "scene/core/rng.h"

namespace seasense::simd4 {
namespace {

TEST(Simd4, SinCos4MatchesLibmOverTheReducedRange) {
    // |x| ≤ 4 covers phases reduced to [−π, π] with room to spare; the float argument is taken
    // as exact, so the error is the reduction's and the polynomials' (plus float rounding).
    double worstSin = 0.0, worstCos = 0.0, worstNorm = 0.0;
    for (int i = 0; i < 400000; i += 4) {
        alignas(16) float x[4], s[4], c[4];
        for (int l = 0; l < 4; ++l)
            x[l] = float(-4.0 + 8.0 * scene::Uniform01(3, 1, uint64_t(i + l)));
        F4 sv, cv;
        SinCos4(_mm_load_ps(x), sv, cv);
        _mm_store_ps(s, sv);
        _mm_store_ps(c, cv);
        for (int l = 0; l < 4; ++l) {
            worstSin = std::max(worstSin, std::abs(double(s[l]) - std::sin(double(x[l]))));
            worstCos = std::max(worstCos, std::abs(double(c[l]) - std::cos(double(x[l]))));
            worstNorm =
                std::max(worstNorm, std::abs(double(s[l]) * s[l] + double(c[l]) * c[l] - 1.0));
        }
    }
    // A float's half ulp at 1 is 6e-8: a few of them.
    EXPECT_LT(worstSin, 2.5e-7);
    EXPECT_LT(worstCos, 2.5e-7);
    EXPECT_LT(worstNorm, 5e-7);
}

TEST(Simd4, SinCos4QuadrantsAndLanes) {
    constexpr float kHalfPi = float(std::numbers::pi / 2.0);
    // Exact at zero; each quadrant's signs; the same value in any lane.
    alignas(16) const float x[4] = {0.0f, kHalfPi, -kHalfPi, 2.0f * kHalfPi};
    alignas(16) float s[4], c[4];
    F4 sv, cv;
    SinCos4(_mm_load_ps(x), sv, cv);
    _mm_store_ps(s, sv);
    _mm_store_ps(c, cv);
    EXPECT_EQ(s[0], 0.0f);
    EXPECT_EQ(c[0], 1.0f);
    for (int l = 1; l < 4; ++l) {
        EXPECT_NEAR(s[l], std::sin(double(x[l])), 2e-7) << l;
        EXPECT_NEAR(c[l], std::cos(double(x[l])), 2e-7) << l;
    }
    for (int l = 0; l < 4; ++l) {
        alignas(16) float one[4] = {1.3f, 1.3f, 1.3f, 1.3f}, s1[4], c1[4];
        one[l] = x[l];
        SinCos4(_mm_load_ps(one), sv, cv);
        _mm_store_ps(s1, sv);
        _mm_store_ps(c1, cv);
        EXPECT_EQ(s1[l], s[l]) << l;
        EXPECT_EQ(c1[l], c[l]) << l;
    }
}

}  // namespace
}  // namespace seasense::simd4
