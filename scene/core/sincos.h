// Sine and cosine of double arguments, branch-free, for the per-vertex wave sums.
//
// Why our own: the surf components need sin and cos of 12–80 phases at every sea-mesh vertex,
// and libm's sincos (a call with argument checks and slow paths, ~20 ns) was the largest single
// cost of the surf mesh. Here the argument is reduced to |r| ≤ π/4 by Cody & Waite's two-part
// subtraction of n·π/2 (W. J. Cody and W. Waite, Software Manual for the Elementary Functions,
// 1980) and sin r, cos r are their Taylor series to r¹⁵ and r¹⁶ (truncation < 5e-17 at π/4);
// the quadrant picks and signs the pair with arithmetic, not branches, so loops over many
// phases vectorize. Accurate to a few ulp for |x| < 2²⁰ (tests/scene/core/sincos_test.cpp).
// Deterministic: plain IEEE double arithmetic in the default rounding mode.
#pragma once

#include <bit>
#include <cstdint>

namespace seasense::scene {

// SinCos's argument reduction and its two series, for a double or a GCC vector of doubles
// (the same operations on every lane, so a lane gives SinCos's bits): shifted = x·2/π + 1.5·2⁵²,
// whose low mantissa bits hold the quadrant q, and s = sin r, c = cos r of the reduced argument.
template <class T>
[[gnu::always_inline]] inline void SinCosReduced(T x, T& shifted, T& s, T& c) {
    constexpr double kTwoOverPi = 0.6366197723675814;
    // π/2 = kHalfPiHi + kHalfPiLo to ~1e-27: kHalfPiHi holds 33 significant bits, so n·kHalfPiHi
    // is exact for |n| < 2²⁰.
    constexpr double kHalfPiHi = 1.5707963267341256;
    constexpr double kHalfPiLo = 6.077100506506192e-11;
    // Adding 1.5·2⁵² rounds to an integer in the default rounding mode and leaves n mod 4 in
    // the low mantissa bits (2⁵¹ ≡ 0 mod 4).
    constexpr double kRound = 6755399441055744.0;
    shifted = x * kTwoOverPi + kRound;
    const T n = shifted - kRound;
    const T r = (x - n * kHalfPiHi) - n * kHalfPiLo;
    const T r2 = r * r;
    // Taylor coefficients 1/k! with alternating signs, evaluated by Horner in r².
    s = r + r * r2 *
                (-1.0 / 6 +
                 r2 * (1.0 / 120 +
                       r2 * (-1.0 / 5040 +
                             r2 * (1.0 / 362880 + r2 * (-1.0 / 39916800 +
                                                        r2 * (1.0 / 6227020800 +
                                                              r2 * (-1.0 / 1307674368000.0)))))));
    c = 1.0 + r2 * (-0.5 + r2 * (1.0 / 24 +
                                 r2 * (-1.0 / 720 +
                                       r2 * (1.0 / 40320 +
                                             r2 * (-1.0 / 3628800 +
                                                   r2 * (1.0 / 479001600 +
                                                         r2 * (-1.0 / 87178291200.0 +
                                                               r2 * (1.0 / 20922789888000.0))))))));
}

// sin x and cos x for |x| < 2²⁰ (the reduction's n·π/2 stays exact), x in radians.
inline void SinCos(double x, double& sinX, double& cosX) {
    double shifted, s, c;
    SinCosReduced(x, shifted, s, c);
    const uint64_t quadrant = std::bit_cast<uint64_t>(shifted) & 3u;
    // Quadrant q: sin x = (s, c, −s, −c)[q], cos x = (c, −s, −c, s)[q].
    const double swap = double(quadrant & 1u);
    const double sinSign = 1.0 - double(quadrant & 2u);
    const double cosSign = 1.0 - double((quadrant + 1u) & 2u);
    sinX = sinSign * (s + swap * (c - s));
    cosX = cosSign * (c + swap * (s - c));
}

}  // namespace seasense::scene
