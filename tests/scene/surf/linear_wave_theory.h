// Linear wave theory for the surf tests, independent of the library's own solver: the
// wavenumber from ω² = g k tanh(k h) by bisection and the group speed ½ (ω/k)(1 + 2kh / sinh 2kh).
#pragma once

#include <cmath>

namespace seasense::scene::linear_waves {

inline constexpr double kG = 9.80665;  // standard gravity, m/s²

// Wavenumber (rad/m) of angular frequency omega (rad/s) at depth h (m).
inline double K(double omega, double h) {
    double lo = 1e-8, hi = 1e3;
    for (int i = 0; i < 200; ++i) {
        const double mid = 0.5 * (lo + hi);
        (kG * mid * std::tanh(mid * h) < omega * omega ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

// Group speed (m/s) of angular frequency omega (rad/s) at depth h (m).
inline double Cg(double omega, double h) {
    const double k = K(omega, h);
    return 0.5 * omega / k * (1.0 + 2.0 * k * h / std::sinh(2.0 * k * h));
}

}  // namespace seasense::scene::linear_waves
