// Tests of Planck radiometry against published constants, the Stefan–Boltzmann and Wien
// laws, adaptive numerical quadrature and finite differences.
#include "radiometry/planck/planck.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <random>
#include <vector>

#include "scene/core/error.h"

namespace seasense::radiometry {
namespace {

// Stefan–Boltzmann constant, CODATA 2018 (exact in the 2019 SI, quoted to 10 digits).
constexpr double kStefanBoltzmann_W_m2_K4 = 5.670374419e-8;
// Wien displacement law constant for L_λ, CODATA 2018.
constexpr double kWienB_m_K = 2.897771955e-3;

// Adaptive Simpson quadrature (Lyness 1969 error estimate |S2 − S1|/15) of f over [a, b]
// to absolute tolerance eps.
double SimpsonStep(const std::function<double(double)>& f, double a, double b, double fa, double fm,
                   double fb, double whole, double eps, int depth) {
    const double m = 0.5 * (a + b), lm = 0.5 * (a + m), rm = 0.5 * (m + b);
    const double flm = f(lm), frm = f(rm);
    const double left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
    const double right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
    const double delta = left + right - whole;
    if (depth <= 0 || std::abs(delta) <= 15.0 * eps) return left + right + delta / 15.0;
    return SimpsonStep(f, a, m, fa, flm, fm, left, 0.5 * eps, depth - 1) +
           SimpsonStep(f, m, b, fm, frm, fb, right, 0.5 * eps, depth - 1);
}

double AdaptiveSimpson(const std::function<double(double)>& f, double a, double b, double eps) {
    const double fa = f(a), fb = f(b), fm = f(0.5 * (a + b));
    return SimpsonStep(f, a, b, fa, fm, fb, (b - a) / 6.0 * (fa + 4.0 * fm + fb), eps, 40);
}

// ∫ R(λ) g(λ) dλ segment by segment (R has kinks at the samples), relative tolerance ~1e-11.
double QuadratureOverBand(const Band& band, const std::function<double(double)>& g) {
    const auto f = [&](double lambda) { return band.Response(lambda) * g(lambda); };
    const auto& lambda = band.Wavelengths_m();
    double rough = 0.0;
    for (size_t i = 0; i + 1 < lambda.size(); ++i)
        rough += AdaptiveSimpson(
            f, lambda[i], lambda[i + 1],
            1e-3 * std::abs(f(0.5 * (lambda[i] + lambda[i + 1]))) * (lambda[i + 1] - lambda[i]));
    double sum = 0.0;
    for (size_t i = 0; i + 1 < lambda.size(); ++i)
        sum += AdaptiveSimpson(f, lambda[i], lambda[i + 1], 1e-12 * std::abs(rough));
    return sum;
}

// A photocathode-like curve with sloped segments, to exercise the linear-response moments.
Band SlopedBand() {
    return Band("sloped", {{0.45e-6, 0.0},
                           {0.55e-6, 0.6},
                           {0.7e-6, 1.0},
                           {0.8e-6, 0.9},
                           {0.85e-6, 0.9},
                           {0.92e-6, 0.0}});
}

TEST(Planck, RadiationConstantsMatchCodata2018) {
    EXPECT_NEAR(kPlanckC1_W_m2_sr, 1.191042972e-16, 1e-25);
    EXPECT_NEAR(kPlanckC2_m_K, 1.438776877e-2, 1e-11);
}

TEST(Planck, LwirReferenceAt300K) {
    // physics.md: 8–12 µm at 300 K → 38.50 W·m⁻²·sr⁻¹, dL/dT ≈ 0.630 W·m⁻²·sr⁻¹·K⁻¹.
    const Band lwir = Band::Lwir();
    EXPECT_NEAR(BandRadiance(lwir, 300.0), 38.50, 0.005);
    EXPECT_NEAR(BandRadianceDerivative(lwir, 300.0), 0.630, 0.0005);
}

TEST(Planck, StefanBoltzmannLaw) {
    // 0.1 µm – 1 mm holds all but ~6e-6 of the 300 K blackbody's radiance.
    const Band all = Band::Flat("all", 0.1e-6, 1e-3);
    for (double T : {300.0, 1000.0}) {
        const double expected = kStefanBoltzmann_W_m2_K4 * std::pow(T, 4) / M_PI;
        EXPECT_NEAR(BandRadiance(all, T) / expected, 1.0, 1e-4) << T;
        // d(σT⁴/π)/dT = 4σT³/π.
        const double expectedDerivative = 4.0 * kStefanBoltzmann_W_m2_K4 * std::pow(T, 3) / M_PI;
        EXPECT_NEAR(BandRadianceDerivative(all, T) / expectedDerivative, 1.0, 1e-4) << T;
    }
}

TEST(Planck, PhotonStefanBoltzmannLaw) {
    // Total photon exitance σ_Q T³ with σ_Q = 1.52046e15 s⁻¹·m⁻²·K⁻³ (the photon-flux analogue
    // of σ, 4πζ(3)k³/(h³c²)); radiance is exitance / π. Photon radiance has a heavier
    // long-wave tail, so the band reaches 1 cm.
    const Band all = Band::Flat("all", 0.1e-6, 1e-2);
    const double T = 1000.0;
    EXPECT_NEAR(BandPhotonRadiance(all, T) / (1.52046e15 * T * T * T / M_PI), 1.0, 1e-4);
}

// Golden-section search for the maximum of f on [a, b].
double ArgMax(const std::function<double(double)>& f, double a, double b) {
    const double g = 0.5 * (std::sqrt(5.0) - 1.0);
    double c = b - g * (b - a), d = a + g * (b - a);
    for (int i = 0; i < 200 && (b - a) > 1e-12 * b; ++i) {
        if (f(c) > f(d))
            b = d;
        else
            a = c;
        c = b - g * (b - a);
        d = a + g * (b - a);
    }
    return 0.5 * (a + b);
}

TEST(Planck, WienDisplacementLaw) {
    for (double T : {200.0, 300.0, 1000.0, 5772.0}) {
        const double peak = ArgMax([T](double l) { return PlanckRadiance(l, T); },
                                   0.2 * kWienB_m_K / T, 5.0 * kWienB_m_K / T);
        EXPECT_NEAR(peak * T / kWienB_m_K, 1.0, 1e-7) << T;
        // Photon radiance per wavelength peaks at x = c2/(λT) solving (x − 4)eˣ + 4 = 0,
        // x = 3.920690395 (the photon Wien law, λT = 3669.7 µm·K).
        const double photonPeak = ArgMax([T](double l) { return PlanckPhotonRadiance(l, T); },
                                         0.2 * kWienB_m_K / T, 5.0 * kWienB_m_K / T);
        EXPECT_NEAR(kPlanckC2_m_K / (photonPeak * T), 3.920690395, 1e-6) << T;
    }
}

TEST(Planck, RayleighJeansAndWienLimits) {
    // Long wavelength: L_λ → 2ckT/λ⁴. Short wavelength: L_λ → c1 λ⁻⁵ e^{−c2/(λT)}.
    const double T = 300.0;
    const double lambdaLong = 1.0;  // x ≈ 4.8e-5
    EXPECT_NEAR(PlanckRadiance(lambdaLong, T) /
                    (2.0 * kSpeedOfLight_m_s * kBoltzmann_J_K * T / std::pow(lambdaLong, 4)),
                1.0, 1e-4);
    const double lambdaShort = 0.5e-6;  // x ≈ 96
    EXPECT_NEAR(PlanckRadiance(lambdaShort, T) / (kPlanckC1_W_m2_sr / std::pow(lambdaShort, 5) *
                                                  std::exp(-kPlanckC2_m_K / (lambdaShort * T))),
                1.0, 1e-15);
    EXPECT_EQ(PlanckRadiance(1e-8, 10.0), 0.0);  // underflows cleanly, no NaN
    EXPECT_EQ(PlanckRadianceDerivative(1e-8, 10.0), 0.0);
}

TEST(Planck, SpectralDerivativesMatchFiniteDifferences) {
    for (double lambda : {0.5e-6, 4e-6, 10e-6, 100e-6})
        for (double T : {200.0, 300.0, 1200.0}) {
            const double h = 1e-5 * T;
            const double fd =
                (PlanckRadiance(lambda, T + h) - PlanckRadiance(lambda, T - h)) / (2.0 * h);
            EXPECT_NEAR(PlanckRadianceDerivative(lambda, T) / fd, 1.0, 1e-5) << lambda << " " << T;
            const double fdp =
                (PlanckPhotonRadiance(lambda, T + h) - PlanckPhotonRadiance(lambda, T - h)) /
                (2.0 * h);
            EXPECT_NEAR(PlanckPhotonRadianceDerivative(lambda, T) / fdp, 1.0, 1e-5);
        }
}

TEST(Planck, PhotonRadianceIsEnergyOverPhotonEnergy) {
    const double lambda = 0.6e-6, T = 2856.0;  // CIE illuminant A temperature
    const double photonEnergy_J = kPlanck_J_s * kSpeedOfLight_m_s / lambda;
    EXPECT_NEAR(PlanckPhotonRadiance(lambda, T) * photonEnergy_J / PlanckRadiance(lambda, T), 1.0,
                1e-14);
}

TEST(Planck, BandRadianceMatchesAdaptiveQuadrature) {
    struct Case {
        Band band;
        double T_K;
    };
    const Case cases[] = {
        {Band::Lwir(), 200.0},  {Band::Lwir(), 300.0},
        {Band::Lwir(), 1500.0}, {Band::Lwir(), 2500.0},
        {Band::Mwir(), 150.0},  {Band::Mwir(), 300.0},
        {Band::Mwir(), 1000.0}, {SlopedBand(), 2856.0},
        {SlopedBand(), 800.0},  {Band("ramp", {{7e-6, 1.0}, {14e-6, 0.2}}), 290.0}};
    for (const Case& c : cases) {
        const double T = c.T_K;
        const double energy =
            QuadratureOverBand(c.band, [T](double l) { return PlanckRadiance(l, T); });
        EXPECT_NEAR(BandRadiance(c.band, T) / energy, 1.0, 1e-8) << c.band.Name() << " " << T;
        const double photons =
            QuadratureOverBand(c.band, [T](double l) { return PlanckPhotonRadiance(l, T); });
        EXPECT_NEAR(BandPhotonRadiance(c.band, T) / photons, 1.0, 1e-8)
            << c.band.Name() << " " << T;
        const double dEnergy =
            QuadratureOverBand(c.band, [T](double l) { return PlanckRadianceDerivative(l, T); });
        EXPECT_NEAR(BandRadianceDerivative(c.band, T) / dEnergy, 1.0, 1e-8)
            << c.band.Name() << " " << T;
        const double dPhotons = QuadratureOverBand(
            c.band, [T](double l) { return PlanckPhotonRadianceDerivative(l, T); });
        EXPECT_NEAR(BandPhotonRadianceDerivative(c.band, T) / dPhotons, 1.0, 1e-8)
            << c.band.Name() << " " << T;
    }
}

TEST(Planck, BandDerivativesMatchFiniteDifferences) {
    for (const Band& band : {Band::Lwir(), Band::Mwir(), SlopedBand()})
        for (double T : {250.0, 300.0, 900.0, 2000.0}) {
            const double h = 1e-5 * T;
            const double fd = (BandRadiance(band, T + h) - BandRadiance(band, T - h)) / (2.0 * h);
            EXPECT_NEAR(BandRadianceDerivative(band, T) / fd, 1.0, 1e-5) << band.Name() << " " << T;
            const double fdp =
                (BandPhotonRadiance(band, T + h) - BandPhotonRadiance(band, T - h)) / (2.0 * h);
            EXPECT_NEAR(BandPhotonRadianceDerivative(band, T) / fdp, 1.0, 1e-5);
        }
}

TEST(Planck, BandTemperatureInvertsBandRadiance) {
    for (const Band& band : {Band::Lwir(), Band::Mwir(), SlopedBand()})
        for (double T : {120.0, 200.0, 273.15, 300.0, 650.0, 1500.0, 2500.0, 6000.0}) {
            const double L = BandRadiance(band, T);
            EXPECT_NEAR(BandTemperature(band, L), T, 1e-9 * T) << band.Name() << " " << T;
        }
}

TEST(Planck, RejectsBadInput) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const Band lwir = Band::Lwir();
    EXPECT_THROW(PlanckRadiance(-1e-6, 300.0), InputError);
    EXPECT_THROW(PlanckRadiance(10e-6, 0.0), InputError);
    EXPECT_THROW(PlanckRadiance(nan, 300.0), InputError);
    EXPECT_THROW(BandRadiance(lwir, -5.0), InputError);
    EXPECT_THROW(BandRadianceDerivative(lwir, nan), InputError);
    EXPECT_THROW(BandTemperature(lwir, 0.0), InputError);
    EXPECT_THROW(BandTemperature(lwir, -1.0), InputError);
    EXPECT_THROW(BandTemperature(lwir, std::numeric_limits<double>::infinity()), InputError);
    EXPECT_THROW(BandTemperature(lwir, 1e300), InputError);  // hotter than 1e9 K
    EXPECT_THROW(BandRadianceTable(lwir, 300.0, 200.0), InputError);
    EXPECT_THROW(BandRadianceTable(lwir, 0.0, 200.0), InputError);
    EXPECT_THROW(BandRadianceTable(lwir, 150.0, 200.0, 0.0), InputError);
    EXPECT_THROW(BandRadianceTable(lwir, 150.0, 200.0, 100.0), InputError);
    // A visible band emits nothing representable at 10 K (x ≈ 2900).
    EXPECT_THROW(BandRadianceTable(Band::Flat("vis", 0.4e-6, 0.5e-6), 10.0, 100.0), InputError);
    const BandRadianceTable table(lwir);
    EXPECT_THROW(table.Radiance(nan), InputError);
    EXPECT_THROW(table.Temperature(0.0), InputError);
}

TEST(BandRadianceTable, MatchesDirectIntegrationTo1e5) {
    for (const Band& band : {Band::Lwir(), Band::Mwir(), SlopedBand()}) {
        const BandRadianceTable table(band);
        double worst = 0.0, worstDerivative = 0.0;
        for (double T = 200.0; T <= 1500.0; T += 0.37) {
            worst = std::max(worst, std::abs(table.Radiance(T) / BandRadiance(band, T) - 1.0));
            worstDerivative = std::max(
                worstDerivative,
                std::abs(table.RadianceDerivative(T) / BandRadianceDerivative(band, T) - 1.0));
        }
        EXPECT_LT(worst, 1e-5) << band.Name();
        EXPECT_LT(worstDerivative, 1e-4) << band.Name();
        // Nodes reproduce the direct values.
        EXPECT_NEAR(table.Radiance(150.0) / BandRadiance(band, 150.0), 1.0, 1e-13);
        EXPECT_NEAR(table.Radiance(2500.0) / BandRadiance(band, 2500.0), 1.0, 1e-13);
    }
}

TEST(BandRadianceTable, EqualsTheCubicHermiteOfItsNodesBitForBit) {
    // The interpolant written out from its definition: ln L_B and d(ln L_B)/dT at the two nodes
    // around T (cells of 2 K from 150 K), the Hermite cubic in t with slopes scaled to the cell,
    // formed for each call; the table must give these bits for the radiance and its derivative.
    const Band band = Band::Lwir();
    const BandRadianceTable table(band, 150.0, 2500.0, 2.0);
    const double step = 2.0;
    for (double T = 150.0; T <= 2500.0; T += 0.731) {
        const double u = (T - 150.0) / step;
        const size_t i = std::min(size_t(u), size_t(1174));
        const double t = u - double(i);
        const auto Node = [&](size_t k, double& lnL, double& dlnLdT) {
            const double Tk = k == 1175 ? 2500.0 : 150.0 + double(k) * step;
            const double L = BandRadiance(band, Tk);
            lnL = std::log(L);
            dlnLdT = BandRadianceDerivative(band, Tk) / L;
        };
        double y0, d0, y1, d1;
        Node(i, y0, d0);
        Node(i + 1, y1, d1);
        const double m0 = d0 * step, m1 = d1 * step, dy = y1 - y0;
        const double c2 = 3.0 * dy - 2.0 * m0 - m1, c3 = m0 + m1 - 2.0 * dy;
        const double lnL = y0 + t * (m0 + t * (c2 + t * c3));
        const double slope = m0 + t * (2.0 * c2 + 3.0 * t * c3);
        ASSERT_EQ(table.Radiance(T), std::exp(lnL)) << T;
        ASSERT_EQ(table.RadianceDerivative(T), std::exp(lnL) * slope / step) << T;
    }
}

// The batch form gives each value the bits of its own Radiance call: in the range (its ends, a
// node, between nodes, as float temperatures as the plumes pass them) and outside it (direct
// evaluation), in one call with the values mixed.
TEST(BandRadianceTable, RadiancesEqualRadianceBitForBit) {
    for (const Band& band : {Band::Lwir(), Band::Mwir()}) {
        const BandRadianceTable table(band, 200.0, 1200.0, 2.0);
        std::vector<double> T = {200.0, 1200.0, 202.0, 50.0, 199.999, 1200.001, 3000.0};
        for (double t = 150.0; t <= 1300.0; t += 0.6133) T.push_back(double(float(t)));
        std::vector<double> out(T.size(), -1.0);
        table.Radiances(T.size(), T.data(), out.data());
        for (size_t k = 0; k < T.size(); ++k) {
            const double expected = table.Radiance(T[k]);
            EXPECT_EQ(std::memcmp(&out[k], &expected, sizeof(double)), 0)
                << band.Name() << " " << T[k];
        }
    }
}

// Every count and every position within a group of four values (the batch is made four values
// at a time where the build has AVX2, the rest one by one): each value in or out of the range,
// at its ends, on a node, in the last cell and just past it, gets its own Radiance's bits.
TEST(BandRadianceTable, RadiancesOfAnyCountAndLaneEqualRadiance) {
    const BandRadianceTable table(Band::Lwir(), 200.0, 1200.0, 2.0);
    const std::vector<double> pool = {200.0, 1200.0,      1199.999,  1198.0, 1199.0,    202.0,
                                      201.0, 50.0,        199.9999,  1200.5, 3000.0,    733.25,
                                      640.0, 1000.000001, 300.30303, 455.5,  1198.9999, 900.1};
    std::mt19937 rng(3);
    for (size_t n = 0; n <= 13; ++n)
        for (int trial = 0; trial < 40; ++trial) {
            std::vector<double> T(n);
            for (double& t : T) t = pool[rng() % pool.size()];
            std::vector<double> out(n + 1, -1.0);
            table.Radiances(n, T.data(), out.data());
            for (size_t k = 0; k < n; ++k) {
                const double expected = table.Radiance(T[k]);
                ASSERT_EQ(std::memcmp(&out[k], &expected, sizeof(double)), 0)
                    << "n " << n << " k " << k << " T " << T[k];
            }
            EXPECT_EQ(out[n], -1.0) << "n " << n;  // nothing past the count
        }
}

TEST(BandRadianceTable, InverseRoundTripsTo10mK) {
    for (const Band& band : {Band::Lwir(), Band::Mwir()}) {
        const BandRadianceTable table(band);
        double worst_K = 0.0;
        for (double T = 200.0; T <= 1500.0; T += 0.37)
            worst_K = std::max(worst_K, std::abs(table.Temperature(BandRadiance(band, T)) - T));
        EXPECT_LT(worst_K, 0.01) << band.Name();
    }
}

TEST(BandRadianceTable, OutOfRangeFallsBackToDirectEvaluation) {
    const Band lwir = Band::Lwir();
    const BandRadianceTable table(lwir, 200.0, 400.0, 2.0);
    EXPECT_EQ(table.MinTemperature_K(), 200.0);
    EXPECT_EQ(table.MaxTemperature_K(), 400.0);
    for (double T : {50.0, 199.9, 400.1, 3000.0}) {
        EXPECT_EQ(table.Radiance(T), BandRadiance(lwir, T)) << T;
        EXPECT_EQ(table.RadianceDerivative(T), BandRadianceDerivative(lwir, T)) << T;
        EXPECT_NEAR(table.Temperature(BandRadiance(lwir, T)), T, 1e-9 * T) << T;
    }
}

}  // namespace
}  // namespace seasense::radiometry
