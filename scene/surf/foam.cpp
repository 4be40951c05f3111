// Surf-zone foam coverage (see foam.h).
#include "scene/surf/foam.h"

#include <algorithm>
#include <cmath>

namespace seasense::scene {

namespace {

// SplitMix64 finalizer (Steele, Lea & Flood, OOPSLA 2014): a well-mixed hash of a lattice cell.
uint64_t Mix(uint64_t z) {
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

double LatticeValue(int64_t i, int64_t j, uint64_t seed) {
    const uint64_t h = Mix(seed * 0x9e3779b97f4a7c15ull ^ Mix(uint64_t(i) * 0x632be59bd9b4e019ull ^
                                                              uint64_t(j) * 0x85ebca6b0000001bull));
    return double(h >> 11) * 0x1.0p-53;  // [0, 1)
}

double SmoothStep(double t) { return t * t * (3.0 - 2.0 * t); }

double ValueNoise(double x, double y, uint64_t seed) {
    const double fx = std::floor(x), fy = std::floor(y);
    const int64_t i = int64_t(fx), j = int64_t(fy);
    const double u = SmoothStep(x - fx), v = SmoothStep(y - fy);
    const double a = LatticeValue(i, j, seed), b = LatticeValue(i + 1, j, seed);
    const double c = LatticeValue(i, j + 1, seed), d = LatticeValue(i + 1, j + 1, seed);
    return (a + (b - a) * u) + ((c + (d - c) * u) - (a + (b - a) * u)) * v;
}

}  // namespace

double FoamNoise(double x, double y, uint64_t seed) {
    // Two octaves, the second at twice the frequency and half the weight: normalized to [0, 1].
    return (ValueNoise(x, y, seed) + 0.5 * ValueNoise(2.0 * x + 17.3, 2.0 * y - 5.1, seed + 1)) /
           1.5;
}

double FoamStreaks(double x0, double y0, double t_s, double direction_rad, double drift_mps,
                   const FoamSettings& s) {
    // Unit vector of travel (azimuth from north, clockwise) and the across-travel axis.
    const double ex = std::sin(direction_rad), ey = std::cos(direction_rad);
    const double along = x0 * ex + y0 * ey - drift_mps * t_s;
    const double across = -x0 * ey + y0 * ex;
    const double n =
        FoamNoise(along / (s.streakWidth_m * s.streakElongation), across / s.streakWidth_m, s.seed);
    // Soft threshold: noise below 0.35 is a gap, above 0.6 full foam.
    const double t = std::clamp((n - 0.35) / 0.25, 0.0, 1.0);
    return SmoothStep(t);
}

double ResidualFoam(const SurfBreaking& b, const FoamSettings& s) {
    if (!b.broken || b.timeSinceBreaking_s < 0.0) return 0.0;
    return std::exp(-b.timeSinceBreaking_s / s.persistence_s);
}

double SurfFoamCoverage(const SurfPointInfo& info, double x0, double y0, double t_s,
                        const FoamSettings& s) {
    const double residual = ResidualFoam(info.breaking, s);
    double c = std::clamp(info.breaking.intensity, 0.0, 1.0);
    if (residual > 0.0) {
        // Broken water drifts shoreward with the bores' mass transport, a small fraction of the
        // phase speed; a tenth of the group speed keeps the streaks visibly moving with the surf.
        const double streaks =
            FoamStreaks(x0, y0, t_s, info.direction_rad, 0.1 * info.groupSpeed_mps, s);
        c = std::max(c, residual * streaks);
    }
    return c;
}

double WhitecapCoverage(double jacobian, double threshold) {
    if (!(threshold > 0.0)) return 0.0;
    return std::clamp(1.0 - jacobian / threshold, 0.0, 1.0);
}

}  // namespace seasense::scene
