// Fresnel reflectance of a smooth dielectric interface for unpolarized light.
#pragma once

#include <algorithm>
#include <cmath>

namespace seasense::radiometry {

// Reflectance for light arriving from a medium of index 1 onto a medium of real index n at
// incidence cosine cosI (Born & Wolf, "Principles of Optics", §1.5.2): mean of |r_s|², |r_p|².
inline double FresnelDielectric(double cosI, double n) {
    cosI = std::clamp(cosI, 0.0, 1.0);
    const double sinT2 = (1.0 - cosI * cosI) / (n * n);
    if (sinT2 >= 1.0) return 1.0;
    const double cosT = std::sqrt(1.0 - sinT2);
    const double rs = (cosI - n * cosT) / (cosI + n * cosT);
    const double rp = (n * cosI - cosT) / (n * cosI + cosT);
    return 0.5 * (rs * rs + rp * rp);
}

// Refractive index of sea water in the visible, 0.55 µm, 20 °C, S = 35 ‰
// (Quan & Fry 1995, Appl. Opt. 34(18): n ≈ 1.341).
inline constexpr double kSeaWaterIndexVisible = 1.341;

}  // namespace seasense::radiometry
