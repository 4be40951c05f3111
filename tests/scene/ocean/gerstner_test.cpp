// Gerstner waves against linear wave theory: dispersion, trochoid geometry, truthful queries.
#include "scene/ocean/gerstner.h"

#include <gtest/gtest.h>

#include <cmath>

namespace seasense::scene {
namespace {

OceanSettings OneWave(double wavelength, double amplitude, double steepness, double depth,
                      double direction_deg = 90.0) {
    OceanSettings s;
    s.depth_m = depth;
    GerstnerWaveSettings w;
    w.direction_rad = direction_deg * M_PI / 180.0;
    w.wavelength_m = wavelength;
    w.amplitude_m = amplitude;
    w.steepness = steepness;
    s.waves.push_back(w);
    return s;
}

// s with a second, shorter wave crossing it (23 m, 0.2 m).
OceanSettings WithShortWave(OceanSettings s) {
    GerstnerWaveSettings w;
    w.direction_rad = 2.0;
    w.wavelength_m = 23.0;
    w.amplitude_m = 0.2;
    w.steepness = 0.3;
    w.phase_rad = 0.7;
    s.waves.push_back(w);
    return s;
}

// visit(x, y) at the centre (cx, cy) and at `spokes` points on each of `rings` circles out to
// radius r.
template <class Visit>
void ForEachPointInDisc(double cx, double cy, double r, int rings, int spokes, const Visit& visit) {
    for (int i = 0; i <= rings; ++i)
        for (int j = 0; j < (i == 0 ? 1 : spokes); ++j) {
            const double rho = r * i / rings, a = 2.0 * M_PI * j / spokes;
            visit(cx + rho * std::cos(a), cy + rho * std::sin(a));
        }
}

// Position of the crest nearest x_guess along a wave travelling east (+x), by golden-section
// search on the drawn height.
double CrestX(const GerstnerOcean& o, double xGuess, double halfWidth, double t) {
    double a = xGuess - halfWidth, b = xGuess + halfWidth;
    const double g = (std::sqrt(5.0) - 1.0) / 2.0;
    for (int i = 0; i < 200; ++i) {
        const double c = b - g * (b - a), d = a + g * (b - a);
        if (o.HeightAt(c, 0.0, t) > o.HeightAt(d, 0.0, t))
            b = d;
        else
            a = c;
    }
    return 0.5 * (a + b);
}

// The elevation bound over a disc holds at every rest position sampled in it (one wave and two,
// many times and discs); for one wave it is the sampled maximum but for the phase margin, so
// below the amplitude where no crest lies in the disc.
TEST(Gerstner, ElevationNearADiscBoundsEveryPointInIt) {
    const OceanSettings one = OneWave(60.0, 0.5, 0.6, 30.0, 20.0);
    const OceanSettings two = WithShortWave(one);
    for (const OceanSettings& s : {one, two}) {
        const GerstnerOcean o(s);
        int below = 0;
        for (int f = 0; f < 40; ++f) {
            const double t = 0.91 * f, cx = 13.0 * f - 200.0, cy = 7.0 * f;
            for (const double r : {0.0, 2.0, 8.0, 30.0}) {
                const double bound = o.MaxElevationNear_m(cx, cy, r, t);
                EXPECT_LE(bound, o.MaxAmplitude_m());
                double highest = -1.0;
                ForEachPointInDisc(cx, cy, r, 40, 144, [&](double x, double y) {
                    const SurfaceTerms terms = o.Terms(x, y, t);
                    highest = std::max(highest, terms.displacement.z);
                    EXPECT_LE(terms.displacement.z, bound + 1e-12) << f << " " << r;
                });
                if (s.waves.size() == 1) {
                    // The margin moves the phase by 0.01 rad (≤ 0.005 m at A = 0.5 m).
                    EXPECT_LE(bound, std::max(highest, 0.0) + 0.006) << f << " " << r;
                    if (bound < 0.9 * o.MaxAmplitude_m()) ++below;
                }
            }
        }
        if (s.waves.size() == 1) {
            EXPECT_GT(below, 20);
        }
    }
}

// The signed bound for a mesh's footprints holds at every rest position sampled in the disc for
// every footprint up to the largest (Terms' footprint weights), and follows the troughs: with
// one wave it is the sampled maximum (but for the phase margin) also where that is negative, and
// negative where the disc lies in a trough. With no footprint given it is MaxElevationNear_m.
TEST(Gerstner, SignedElevationBoundHoldsForEveryFootprintUpToTheLargest) {
    const OceanSettings one = OneWave(60.0, 0.5, 0.6, 30.0, 20.0);
    const OceanSettings two = WithShortWave(one);
    for (const OceanSettings& s : {one, two}) {
        const GerstnerOcean o(s);
        int negative = 0;
        for (int f = 0; f < 40; ++f) {
            const double t = 0.91 * f, cx = 13.0 * f - 200.0, cy = 7.0 * f;
            for (const double r : {0.0, 0.5, 2.0, 8.0}) {
                EXPECT_EQ(o.ElevationBoundNear_m(cx, cy, r, t, INFINITY),
                          o.MaxElevationNear_m(cx, cy, r, t));
                // 8 m footprints weight the 23 m wave by 3.14 / (k 8) − 1 ≈ 0.44.
                for (const double maxFootprint : {0.0, 2.0, 8.0}) {
                    const double bound = o.ElevationBoundNear_m(cx, cy, r, t, maxFootprint);
                    EXPECT_LE(bound, o.MaxElevationNear_m(cx, cy, r, t));
                    double highest = -1.0;
                    ForEachPointInDisc(cx, cy, r, 20, 72, [&](double x, double y) {
                        for (const double fp : {0.0, 0.5 * maxFootprint, maxFootprint}) {
                            const double z = o.Terms(x, y, t, fp).displacement.z;
                            highest = std::max(highest, z);
                            EXPECT_LE(z, bound + 1e-12) << f << " " << r << " " << fp;
                        }
                    });
                    if (s.waves.size() == 1) {
                        EXPECT_LE(bound, highest + 0.006) << f << " " << r;
                        if (bound < -0.1) ++negative;
                    }
                }
            }
        }
        if (s.waves.size() == 1) {
            EXPECT_GT(negative, 40);
        }
    }
}

TEST(Gerstner, DeepWaterCrestsTravelAtPhaseSpeed) {
    // Deep water: c = √(g λ / 2π) (Airy theory, e.g. Lamb, Hydrodynamics §229).
    const double lambda = 40.0;
    const GerstnerOcean o(OneWave(lambda, 0.5, 0.8, 1e4));
    const double expected = std::sqrt(kGravity_mps2 * lambda / (2.0 * M_PI));
    const double t = 3.0;
    const double x0 = CrestX(o, 0.0, 0.25 * lambda, 0.0);
    const double x1 = CrestX(o, expected * t, 0.25 * lambda, t);
    EXPECT_NEAR((x1 - x0) / t, expected, 1e-3 * expected);
}

TEST(Gerstner, ShallowWaterSpeedApproachesRootGh) {
    // kh ≪ 1: c → √(g h); for λ = 200 m, h = 1 m the exact value is within 0.2 % of it.
    const double h = 1.0, lambda = 200.0;
    const GerstnerOcean o(OneWave(lambda, 0.05, 0.0, h));
    const double t = 10.0;
    const double c = std::sqrt(kGravity_mps2 * h);
    const double x0 = CrestX(o, 0.0, 0.25 * lambda, 0.0);
    const double x1 = CrestX(o, c * t, 0.25 * lambda, t);
    EXPECT_NEAR((x1 - x0) / t, c, 2e-3 * c);
    const double k = 2.0 * M_PI / lambda;
    EXPECT_NEAR(GroupSpeed(k, h) / PhaseSpeed(k, h), 1.0, 2e-3);       // non-dispersive limit
    EXPECT_NEAR(GroupSpeed(k, 1e4) / PhaseSpeed(k, 1e4), 0.5, 1e-12);  // deep water: c_g = c/2
}

TEST(Gerstner, TrochoidMeanLevelLiesHalfKA2BelowStillWater) {
    // For a trochoid (Q = 1, deep water) the Eulerian mean of the surface over a wavelength is
    // −k A² / 2 (Lamb, Hydrodynamics §251): the orbit centres sit above the mean level.
    const double lambda = 20.0, A = 1.0;
    const GerstnerOcean o(OneWave(lambda, A, 1.0, 1e4));
    const int n = 4096;
    double sum = 0.0;
    for (int i = 0; i < n; ++i) sum += o.HeightAt(lambda * (i + 0.5) / n, 3.0, 1.7);
    const double k = 2.0 * M_PI / lambda;
    EXPECT_NEAR(sum / n, -0.5 * k * A * A, 1e-4);
}

TEST(Gerstner, SurfaceParticlesMoveOnCirclesOfRadiusAInDeepWater) {
    const double A = 0.7;
    const GerstnerOcean o(OneWave(30.0, A, 1.0, 1e4, 37.0));
    for (int i = 0; i < 32; ++i) {
        const SurfaceSample s = o.Evaluate(5.0, -2.0, 0.37 * i);
        EXPECT_NEAR(glm::length(s.position - glm::dvec3(5.0, -2.0, 0.0)), A, 1e-9);
    }
}

TEST(Gerstner, NormalIsPerpendicularToTheDrawnSurface) {
    OceanSettings s = OneWave(25.0, 0.4, 0.9, 30.0, 10.0);
    GerstnerWaveSettings w2;
    w2.direction_rad = 1.2;
    w2.wavelength_m = 9.0;
    w2.amplitude_m = 0.1;
    w2.steepness = 0.6;
    s.waves.push_back(w2);
    const GerstnerOcean o(s);
    const double e = 1e-5;
    for (int i = 0; i < 50; ++i) {
        const double x = 1.3 * i, y = -0.7 * i, t = 0.11 * i;
        const SurfaceSample c = o.Evaluate(x, y, t);
        const glm::dvec3 tx = (o.Evaluate(x + e, y, t).position - o.Evaluate(x - e, y, t).position);
        const glm::dvec3 ty = (o.Evaluate(x, y + e, t).position - o.Evaluate(x, y - e, t).position);
        EXPECT_NEAR(glm::dot(c.normal, glm::normalize(tx)), 0.0, 1e-6);
        EXPECT_NEAR(glm::dot(c.normal, glm::normalize(ty)), 0.0, 1e-6);
        EXPECT_NEAR(glm::length(c.normal), 1.0, 1e-12);
        EXPECT_GT(c.normal.z, 0.0);
    }
}

TEST(Gerstner, HeightQueryAnswersWhatIsDrawn) {
    OceanSettings s = OneWave(40.0, 0.6, 0.8, 50.0, 200.0);
    GerstnerWaveSettings w2;
    w2.direction_rad = 0.4;
    w2.wavelength_m = 12.0;
    w2.amplitude_m = 0.15;
    w2.steepness = 0.7;
    s.waves.push_back(w2);
    const GerstnerOcean o(s);
    for (int i = 0; i < 200; ++i) {
        const double x0 = 0.77 * i - 50.0, y0 = 0.31 * i, t = 0.05 * i;
        const SurfaceSample p = o.Evaluate(x0, y0, t);
        EXPECT_NEAR(o.HeightAt(p.position.x, p.position.y, t), p.position.z, 1e-7);
    }
}

TEST(Gerstner, SinglePrecisionLocalFrameMatchesDoubleEvaluationFarFromTheOrigin) {
    OceanSettings s = OneWave(40.0, 0.6, 0.8, 50.0, 200.0);
    GerstnerWaveSettings w2;
    w2.direction_rad = 0.4;
    w2.wavelength_m = 4.0;
    w2.amplitude_m = 0.02;
    w2.steepness = 0.7;
    s.waves.push_back(w2);
    const GerstnerOcean o(s);
    // Origin 3 km out and three hours into the run: phases in the thousands of radians.
    const double ox = 3000.0, oy = -1200.0, t = 10800.0;
    const GerstnerOcean::LocalFrame local = o.Local(ox, oy, t);
    for (int i = 0; i < 100; ++i) {
        const float rx = float(47.0 * i - 2300.0), ry = float(13.0 * i);
        glm::vec3 p, n;
        float jac;
        local.Evaluate(rx, ry, p, n, jac);
        const SurfaceSample ref = o.Evaluate(ox + rx, oy + ry, t);
        EXPECT_NEAR(p.z, ref.position.z, 2e-3);
        EXPECT_NEAR(ox + p.x, ref.position.x, 2e-3);
        EXPECT_NEAR(glm::dot(glm::dvec3(n), ref.normal), 1.0, 1e-4);
        EXPECT_NEAR(jac, ref.jacobian, 1e-3);
    }
}

}  // namespace
}  // namespace seasense::scene
