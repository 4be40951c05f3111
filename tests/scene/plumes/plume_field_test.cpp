// Tests of the Gaussian puff line integral and the plume field's ray query: numerical
// quadrature, the analytic column mass, brute-force sums, Beer–Lambert bounds and determinism.
#include "scene/plumes/plume_field.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstring>
#include <numbers>
#include <vector>

#include "scene/core/rng.h"

namespace seasense::scene {
namespace {

constexpr double kPi = std::numbers::pi;

// Seed 004 Eq 2–3 evaluated directly.
double Concentration(const glm::dvec3& p, const glm::dvec3& c, double sh, double sz, double m) {
    const glm::dvec3 q = p - c;
    const double d2 = (q.x * q.x + q.y * q.y) / (sh * sh) + q.z * q.z / (sz * sz);
    return m / (std::pow(2 * kPi, 1.5) * sh * sh * sz) * std::exp(-0.5 * d2);
}

// Composite Simpson quadrature of C along the ray, fine enough to be exact to ~1e-10.
double Quadrature(const glm::dvec3& c, double sh, double sz, double m, const glm::dvec3& o,
                  const glm::dvec3& d, double S) {
    const int n = 200000;
    const double h = S / n;
    double sum = 0.0;
    for (int i = 0; i <= n; ++i) {
        const double w = (i == 0 || i == n) ? 1.0 : (i % 2 ? 4.0 : 2.0);
        sum += w * Concentration(o + (i * h) * d, c, sh, sz, m);
    }
    return sum * h / 3.0;
}

TEST(PuffLineIntegral, MatchesQuadrature) {
    const glm::dvec3 c{10.0, -4.0, 30.0};
    struct Case {
        glm::dvec3 origin, dir;
        double S;
    };
    const Case cases[] = {
        {{-50, -10, 25}, glm::normalize(glm::dvec3{1, 0.1, 0.05}), 150.0},  // through
        {{10, -4, 30}, glm::normalize(glm::dvec3{0.3, 0.4, 0.8}), 40.0},    // from the centre
        {{-20, -4, 30}, {1, 0, 0}, 25.0},                                   // stops near centre
        {{0, 20, 0}, glm::normalize(glm::dvec3{0.2, -0.5, 0.9}), 80.0},     // oblique, offset
    };
    for (const Case& k : cases) {
        const double exact = GaussianPuffLineIntegral_kgpm2(c, 6.0, 3.5, 2.0, k.origin, k.dir, k.S);
        const double numeric = Quadrature(c, 6.0, 3.5, 2.0, k.origin, k.dir, k.S);
        EXPECT_GT(numeric, 0.0);
        EXPECT_NEAR(exact / numeric, 1.0, 1e-6);
    }
}

TEST(PuffLineIntegral, ColumnThroughCentreIsMassOverTwoPiSigmaSquared) {
    // ∫ C dz through the centre of a Gaussian = M / (2π σh²), whatever σz.
    const glm::dvec3 c{3, 4, 100};
    for (double sz : {0.5, 5.0, 40.0}) {
        const double column =
            GaussianPuffLineIntegral_kgpm2(c, 7.0, sz, 3.0, {3, 4, -1000}, {0, 0, 1}, 3000.0);
        EXPECT_NEAR(column, 3.0 / (2 * kPi * 49.0), 1e-12);
    }
    // Half of it from the centre upward.
    EXPECT_NEAR(GaussianPuffLineIntegral_kgpm2(c, 7.0, 5.0, 3.0, c, {0, 0, 1}, 1e4),
                0.5 * 3.0 / (2 * kPi * 49.0), 1e-12);
}

ObscurantOptics UnitOptics() {
    ObscurantOptics o;
    o.massExtinction_m2pkg = {1.0, 1.0, 1.0, 1.0};
    o.albedo = {0.5, 0.5, 0.5, 0.5};
    return o;
}

TEST(PlumeField, ColumnOpticalDepthThroughCentre) {
    PlumeField field(4, 1);
    ObscurantOptics optics = KindOptics(PlumeKind::Smoke, 0.3);
    field.SetOptics(0, optics);
    field.Clear(0.0);
    Puff puff;
    puff.centre_m = {100, 200, 50};
    puff.sigmaH_m = 8.0;
    puff.sigmaZ_m = 4.0;
    puff.mass_kg = 0.05;
    field.Add(puff);
    field.Build();
    const PlumeTrace t = field.Trace({100, 200, 0}, {0, 0, 1}, 200.0f);
    for (int b = 0; b < kObscurantBands; ++b) {
        const double expected = optics.massExtinction_m2pkg[b] * puff.mass_kg / (2 * kPi * 64.0);
        EXPECT_NEAR(t.opticalDepth[b] / expected, 1.0, 1e-4) << b;
    }
    // Soot: α ∝ 1/λ, so visible / LWIR optical depth = 10 µm / 0.55 µm.
    EXPECT_NEAR(t.opticalDepth[0] / t.opticalDepth[3], 10.0 / 0.55, 1e-3);
    EXPECT_GT(t.opticalDepth[1], t.opticalDepth[2]);
    EXPECT_NEAR(t.Transmittance(ObscurantBand::Visible), std::exp(-t.opticalDepth[0]), 1e-7);
}

// Random puffs for brute-force comparisons.
std::vector<Puff> RandomPuffs(size_t n, uint32_t plumes) {
    std::vector<Puff> puffs(n);
    for (size_t i = 0; i < n; ++i) {
        auto u = [&](int k) { return Uniform01(42, i, uint64_t(k)); };
        puffs[i].centre_m = {400 * u(0) - 200, 400 * u(1) - 200, 150 * u(2)};
        puffs[i].sigmaH_m = 2 + 20 * u(3);
        puffs[i].sigmaZ_m = 1 + 10 * u(4);
        puffs[i].mass_kg = 0.01 * u(5);
        puffs[i].temperature_K = 280 + 600 * u(6);
        puffs[i].plume = uint32_t(i % plumes);
    }
    return puffs;
}

TEST(PlumeField, BvhTraceEqualsBruteForceSum) {
    const std::vector<Puff> puffs = RandomPuffs(700, 3);
    PlumeField field(puffs.size(), 3);
    const PlumeKind kinds[3] = {PlumeKind::Smoke, PlumeKind::Steam, PlumeKind::Dust};
    for (uint32_t p = 0; p < 3; ++p) field.SetOptics(p, KindOptics(kinds[p], 0.6));
    field.Clear(1.0);
    for (const Puff& p : puffs) field.Add(p);
    field.Build();
    EXPECT_EQ(field.PuffCount(), puffs.size());
    const double cutoff2 = double(kPuffCutoffSigmas) * kPuffCutoffSigmas;
    for (int r = 0; r < 60; ++r) {
        auto u = [&](int k) { return Uniform01(7, uint64_t(r), uint64_t(k)); };
        const glm::dvec3 o{-600 + 100 * u(0), -300 + 600 * u(1), 10 + 100 * u(2)};
        const glm::dvec3 target{400 * u(3) - 200, 400 * u(4) - 200, 150 * u(5)};
        const glm::dvec3 d = glm::normalize(target - o);
        const double S = 300 + 1200 * u(6);
        double tau[kObscurantBands] = {}, absT[kObscurantBands] = {}, abs[kObscurantBands] = {};
        for (const Puff& p : puffs) {
            // Same cutoff as the field: skip puffs whose closest approach is beyond 3.5 σ.
            const glm::dvec3 q = o - p.centre_m;
            const double ivh = 1 / (p.sigmaH_m * p.sigmaH_m), ivz = 1 / (p.sigmaZ_m * p.sigmaZ_m);
            const double A = (d.x * d.x + d.y * d.y) * ivh + d.z * d.z * ivz;
            const double B = (d.x * q.x + d.y * q.y) * ivh + d.z * q.z * ivz;
            const double C = (q.x * q.x + q.y * q.y) * ivh + q.z * q.z * ivz;
            if (C - B * B / A > cutoff2) continue;
            const double I = GaussianPuffLineIntegral_kgpm2(p.centre_m, p.sigmaH_m, p.sigmaZ_m,
                                                            p.mass_kg, o, d, S);
            const ObscurantOptics op = KindOptics(kinds[p.plume], 0.6);
            for (int b = 0; b < kObscurantBands; ++b) {
                tau[b] += op.massExtinction_m2pkg[b] * I;
                const double a = op.massExtinction_m2pkg[b] * (1 - op.albedo[b]) * I;
                abs[b] += a;
                absT[b] += a * p.temperature_K;
            }
        }
        const PlumeTrace t = field.Trace(glm::vec3(o), glm::vec3(d), float(S));
        for (int b = 0; b < kObscurantBands; ++b) {
            EXPECT_NEAR(t.opticalDepth[b], tau[b], 1e-4 * tau[b] + 1e-7) << r << " " << b;
            if (abs[b] > 1e-6) {
                EXPECT_NEAR(t.temperature_K[b], absT[b] / abs[b], 1e-3 * absT[b] / abs[b]);
            }
        }
    }
}

TEST(PlumeField, TemperatureIsAbsorptionWeightedMean) {
    PlumeField field(2, 1);
    field.SetOptics(0, UnitOptics());
    field.Clear(0.0);
    Puff hot;
    hot.centre_m = {0, 0, 10};
    hot.sigmaH_m = hot.sigmaZ_m = 2.0;
    hot.mass_kg = 3.0;
    hot.temperature_K = 1000.0;
    Puff cold = hot;
    cold.centre_m = {0, 30, 10};
    cold.mass_kg = 1.0;
    cold.temperature_K = 300.0;
    field.Add(hot);
    field.Add(cold);
    field.Build();
    // A ray along y through both centres sees each puff's full column M / (2π σ²).
    const PlumeTrace t = field.Trace({0, -100, 10}, {0, 1, 0}, 300.0f);
    EXPECT_NEAR(t.opticalDepth[0], 4.0 / (2 * kPi * 4.0), 1e-5);
    EXPECT_NEAR(t.temperature_K[0], (3.0 * 1000.0 + 1.0 * 300.0) / 4.0, 0.01);
    EXPECT_NEAR(t.albedo[0], 0.5, 1e-6);
    // The hot puff (≥ kHotPuff_K) carries 3/4 of the absorption, at its own temperature.
    EXPECT_NEAR(t.hotFraction[0], 0.75, 1e-5);
    EXPECT_NEAR(t.hotTemperature_K[0], 1000.0, 0.01);
}

TEST(PlumeField, TransmittanceBoundedAndMonotoneAlongRay) {
    const std::vector<Puff> puffs = RandomPuffs(300, 1);
    PlumeField field(puffs.size(), 1);
    field.SetOptics(0, KindOptics(PlumeKind::Smoke, 0.3));
    field.Clear(0.0);
    for (Puff p : puffs) {
        p.mass_kg *= 50.0;  // dense enough to take the visible transmittance near zero
        field.Add(p);
    }
    field.Build();
    for (int r = 0; r < 20; ++r) {
        const glm::vec3 o{-500.0f, float(20 * r - 200), 60.0f};
        const glm::vec3 d = glm::normalize(glm::vec3{1.0f, 0.05f * float(r % 5), 0.02f});
        float previous[kObscurantBands] = {1, 1, 1, 1};
        for (float S = 0.0f; S <= 1200.0f; S += 7.0f) {
            const PlumeTrace t = field.Trace(o, d, S);
            for (int b = 0; b < kObscurantBands; ++b) {
                const float T = t.Transmittance(ObscurantBand(b));
                EXPECT_GE(T, 0.0f);
                EXPECT_LE(T, 1.0f);
                EXPECT_LE(T, previous[b] * (1.0f + 1e-6f)) << "S " << S << " band " << b;
                previous[b] = T;
            }
        }
    }
}

TEST(PlumeField, BatchEqualsSingleRaysForAnyThreadCount) {
    const std::vector<Puff> puffs = RandomPuffs(500, 2);
    PlumeField field(puffs.size(), 2);
    field.SetOptics(0, KindOptics(PlumeKind::Smoke, 0.3));
    field.SetOptics(1, KindOptics(PlumeKind::Steam, 0.99));
    field.Clear(0.0);
    for (const Puff& p : puffs) field.Add(p);
    field.Build();
    const size_t n = 5000;
    std::vector<glm::vec3> dirs(n);
    std::vector<float> dist(n, 2000.0f);
    for (size_t i = 0; i < n; ++i)
        dirs[i] = glm::normalize(glm::vec3{1.0f, float(Uniform01(3, i, 0)) - 0.5f,
                                           float(Uniform01(3, i, 1)) * 0.3f - 0.05f});
    const glm::vec3 origin{-800, 0, 40};
    std::vector<PlumeTrace> one(n), two(n);
    tbb::task_arena(1).execute([&] { field.TraceBatch(origin, dirs, dist, one); });
    tbb::task_arena(2).execute([&] { field.TraceBatch(origin, dirs, dist, two); });
    size_t hits = 0;
    for (size_t i = 0; i < n; ++i) {
        const PlumeTrace single = field.Trace(origin, dirs[i], dist[i]);
        EXPECT_EQ(std::memcmp(&one[i], &single, sizeof(PlumeTrace)), 0) << i;
        EXPECT_EQ(std::memcmp(&two[i], &single, sizeof(PlumeTrace)), 0) << i;
        hits += single.opticalDepth[0] > 0.0f;
    }
    EXPECT_GT(hits, n / 10);  // the rays do cross the puffs
    std::vector<PlumeTrace> wrong(n - 1);
    EXPECT_THROW(field.TraceBatch(origin, dirs, dist, wrong), InputError);
}

TEST(PlumeField, EmptyFieldIsClear) {
    PlumeField field(0, 1);
    field.Clear(0.0);
    field.Build();
    const PlumeTrace t = field.Trace({0, 0, 0}, {1, 0, 0}, 1000.0f);
    for (int b = 0; b < kObscurantBands; ++b) EXPECT_EQ(t.Transmittance(ObscurantBand(b)), 1.0f);
}

}  // namespace
}  // namespace seasense::scene
