// Wave spectra and spreading against published relations: Pierson–Moskowitz Hs and peak,
// JONSWAP and TMA limits, normalisation, and variance conservation in wavenumber space.
#include "scene/ocean/spectrum.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "scene/core/error.h"
#include "scene/ocean/gerstner.h"

namespace seasense::scene {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double g = kGravity_mps2;

SpectrumSettings Sea(SpectrumModel model, double u10) {
    SpectrumSettings s;
    s.model = model;
    s.windSpeed_mps = u10;
    return s;
}

// ∫_{−π}^{π} f(θ) dθ by the midpoint rule (spectrally accurate for smooth periodic integrands;
// cos^2s with s ≪ 1 has a cusp at ±π that limits it to ~1e-6).
template <class F>
double IntegrateCircle(F&& f, int n = 20000) {
    double sum = 0.0;
    for (int i = 0; i < n; ++i) sum += f(-kPi + 2.0 * kPi * (i + 0.5) / n);
    return sum * 2.0 * kPi / n;
}

// ∫∫ F(kx, ky) dkx dky in polar coordinates, k on a logarithmic grid.
double IntegrateWavenumberPlane(const WaveSpectrum& s, double kLo, double kHi) {
    const int nk = 800, nt = 256;
    const double a = std::log(kLo), h = (std::log(kHi) - a) / nk;
    double sum = 0.0;
    for (int i = 0; i < nk; ++i) {
        const double k = std::exp(a + h * (i + 0.5));
        const double ring = IntegrateCircle(
            [&](double t) { return s.DensityK(k * std::sin(t), k * std::cos(t)); }, nt);
        sum += ring * k * k * h;  // dkx dky = k dk dθ, dk = k d(ln k)
    }
    return sum;
}

TEST(Spectrum, PiersonMoskowitzSignificantHeightIs0_21USquaredOverG) {
    // physics.md: Hs = 4√m0 ≈ 0.21 U19.5²/g; exactly m0 = α U⁴ / (4 β g²).
    for (double u10 : {5.0, 10.0, 20.0}) {
        const WaveSpectrum s(Sea(SpectrumModel::PiersonMoskowitz, u10));
        const double u = WindSpeed19_5(u10);
        EXPECT_NEAR(s.SignificantHeight_m(), 0.21 * u * u / g, 0.01 * 0.21 * u * u / g) << u10;
        EXPECT_NEAR(s.Variance_m2(), 8.1e-3 * std::pow(u, 4) / (4 * 0.74 * g * g),
                    1e-6 * s.Variance_m2());
    }
}

TEST(Spectrum, PiersonMoskowitzPeaksAt0_877GOverU) {
    for (double u10 : {5.0, 12.0, 25.0}) {
        const double u = WindSpeed19_5(u10);
        // Golden-section search for the maximum of S(ω).
        double a = 0.1 * g / u, b = 3.0 * g / u;
        const double r = (std::sqrt(5.0) - 1.0) / 2.0;
        for (int i = 0; i < 200; ++i) {
            const double c = b - r * (b - a), d = a + r * (b - a);
            if (PiersonMoskowitzSpectrum(c, u) > PiersonMoskowitzSpectrum(d, u))
                b = d;
            else
                a = c;
        }
        const double peak = 0.5 * (a + b);
        EXPECT_NEAR(peak, 0.877 * g / u, 1e-3 * peak);
        EXPECT_NEAR(PiersonMoskowitzPeakOmega(u10), peak, 1e-6 * peak);
        EXPECT_NEAR(WaveSpectrum(Sea(SpectrumModel::PiersonMoskowitz, u10)).PeakOmega_radps(), peak,
                    1e-6 * peak);
    }
}

TEST(Spectrum, JonswapWithGammaOneIsPiersonMoskowitz) {
    // With γ = 1 the enhancement factor is 1 and the JONSWAP form is the PM form with
    // α = 8.1e-3 and 5/4 ω_p⁴ = β ω₀⁴ (Hasselmann et al. 1973).
    const double u10 = 11.0;
    const double wp = PiersonMoskowitzPeakOmega(u10);
    for (double r = 0.5; r < 6.0; r *= 1.1) {
        const double w = r * wp;
        const double pm = PiersonMoskowitzSpectrum(w, WindSpeed19_5(u10));
        EXPECT_NEAR(JonswapSpectrum(w, 8.1e-3, wp, 1.0), pm, 1e-12 * pm + 1e-300) << r;
        // γ > 1 only raises the spectrum, most at the peak.
        EXPECT_GE(JonswapSpectrum(w, 8.1e-3, wp, 3.3), pm * (1.0 - 1e-12));
    }
    EXPECT_NEAR(
        JonswapSpectrum(wp, 8.1e-3, wp, 3.3) / PiersonMoskowitzSpectrum(wp, WindSpeed19_5(u10)),
        3.3, 1e-12);
}

TEST(Spectrum, FetchLimitedGrowthStopsAtFullDevelopment) {
    const double u10 = 15.0;
    // Unlimited fetch: the Pierson–Moskowitz peak.
    EXPECT_NEAR(JonswapFromFetch(u10, 1e9).omegaPeak_radps, PiersonMoskowitzPeakOmega(u10), 1e-12);
    // Short fetch: higher peak frequency and a smaller sea (Hasselmann et al. 1973).
    SpectrumSettings shortFetch = Sea(SpectrumModel::Jonswap, u10), longFetch = shortFetch;
    shortFetch.fetch_m = 20e3;
    longFetch.fetch_m = 200e3;
    const WaveSpectrum a(shortFetch), b(longFetch);
    EXPECT_GT(a.PeakOmega_radps(), b.PeakOmega_radps());
    EXPECT_LT(a.SignificantHeight_m(), b.SignificantHeight_m());
    // JONSWAP growth law g Hs / U² = 1.6e-3 (g F / U²)^½ (Hasselmann et al. 1973, energy
    // ε = 1.6e-7 ξ; Shore Protection Manual 1984, eq. 3-33). It and the α(ξ), ω_p(ξ) fits are
    // separate regressions of the same data (Hs from the fits grows as ξ^0.56, not ξ^0.5), so
    // the integrated spectrum agrees only within about 30 %.
    for (double fetch : {10e3, 50e3, 150e3}) {
        SpectrumSettings s = Sea(SpectrumModel::Jonswap, u10);
        s.fetch_m = fetch;
        const double expected = 1.6e-3 * std::sqrt(g * fetch / (u10 * u10)) * u10 * u10 / g;
        EXPECT_NEAR(WaveSpectrum(s).SignificantHeight_m(), expected, 0.35 * expected) << fetch;
    }
}

TEST(Spectrum, KitaigorodskiiFactorLimits) {
    // Deep water: Φ = 1. Shallow water (ω √(h/g) ≪ 1): Φ → ½ ω² h / g (Bouws et al. 1985).
    EXPECT_EQ(KitaigorodskiiFactor(1.0, 1e4), 1.0);
    EXPECT_NEAR(KitaigorodskiiFactor(2.0, 50.0), 1.0, 1e-12);
    const double h = 1.0;
    const double w = 0.02 * std::sqrt(g / h);
    EXPECT_NEAR(KitaigorodskiiFactor(w, h), 0.5 * w * w * h / g, 2e-3 * 0.5 * w * w * h / g);
    // Monotone in between.
    double prev = 0.0;
    for (double wh = 0.05; wh < 3.0; wh += 0.05) {
        const double phi = KitaigorodskiiFactor(wh * std::sqrt(g / h), h);
        EXPECT_GT(phi, prev);
        EXPECT_LE(phi, 1.0 + 1e-12);
        prev = phi;
    }
}

TEST(Spectrum, TmaTendsToJonswapInDeepWater) {
    SpectrumSettings jonswap = Sea(SpectrumModel::Jonswap, 10.0);
    jonswap.fetch_m = 100e3;
    SpectrumSettings tma = jonswap;
    tma.model = SpectrumModel::Tma;
    tma.depth_m = 500.0;
    const WaveSpectrum j(jonswap), t(tma);
    for (double r = 0.6; r < 5.0; r *= 1.2) {
        const double w = r * j.PeakOmega_radps();
        EXPECT_NEAR(t.DensityOmega(w), j.DensityOmega(w), 1e-9 * j.DensityOmega(w)) << r;
    }
    EXPECT_NEAR(t.Variance_m2(), j.Variance_m2(), 1e-9 * j.Variance_m2());
    // In 5 m of water the depth factor removes energy.
    tma.depth_m = 5.0;
    EXPECT_LT(WaveSpectrum(tma).Variance_m2(), 0.8 * j.Variance_m2());
}

TEST(Spectrum, WavenumberSolvesTheDispersionRelation) {
    for (double h : {0.5, 2.0, 10.0, 100.0, 1e4})
        for (double w : {0.05, 0.3, 1.0, 3.0, 10.0}) {
            const double k = WavenumberForOmega(w, h);
            EXPECT_NEAR(DispersionOmega(k, h), w, 1e-12 * w) << h << " " << w;
        }
    // Shallow water: ω = k √(g h).
    EXPECT_NEAR(WavenumberForOmega(0.01, 1.0), 0.01 / std::sqrt(g), 1e-4 * 0.01 / std::sqrt(g));
}

TEST(Spectrum, SpreadingFunctionsIntegrateToOne) {
    for (double s : {0.0, 0.5, 1.0, 5.0, 20.0, 300.0})
        EXPECT_NEAR(IntegrateCircle([&](double t) { return Cos2sSpreading(t, s); }), 1.0, 1e-8)
            << s;
    const double wp = 0.8, u = 12.0;
    for (double r : {0.3, 0.7, 0.95, 1.0, 1.3, 1.6, 2.5, 8.0})
        for (SpreadingModel m :
             {SpreadingModel::Mitsuyasu, SpreadingModel::Hasselmann, SpreadingModel::DonelanBanner})
            EXPECT_NEAR(IntegrateCircle(
                            [&](double t) { return DirectionalSpreading(m, t, r * wp, wp, u); }),
                        1.0, 1e-5)
                << int(m) << " " << r;
    // s = 1: D = (1 + cos θ) / 2π (Longuet-Higgins et al. 1963 normalisation).
    for (double t : {-3.0, -1.0, 0.0, 0.4, 2.0})
        EXPECT_NEAR(Cos2sSpreading(t, 1.0), (1.0 + std::cos(t)) / (2.0 * kPi), 1e-14);
}

TEST(Spectrum, DirectionalDensityConservesVariance) {
    // ∫∫ F dkx dky = ∫ S dω: checks the c_g / k Jacobian, here in finite depth with swell.
    SpectrumSettings s = Sea(SpectrumModel::Tma, 9.0);
    s.depth_m = 15.0;
    s.fetch_m = 60e3;
    s.swell = SwellSettings{};
    s.swell->significantHeight_m = 0.8;
    s.swell->peakPeriod_s = 11.0;
    s.swell->direction_rad = 1.0;
    s.swell->spreadingPeak = 25.0;
    for (SpreadingModel m :
         {SpreadingModel::Mitsuyasu, SpreadingModel::Hasselmann, SpreadingModel::DonelanBanner}) {
        s.spreading = m;
        const WaveSpectrum w(s);
        const double kp = WavenumberForOmega(w.PeakOmega_radps(), s.depth_m);
        EXPECT_NEAR(IntegrateWavenumberPlane(w, 0.02 * kp, 500.0 * kp), w.Variance_m2(),
                    2e-3 * w.Variance_m2())
            << int(m);
    }
}

TEST(Spectrum, SwellAloneHasItsRequestedHeightAndPeak) {
    SpectrumSettings s = Sea(SpectrumModel::Jonswap, 0.0);
    s.swell = SwellSettings{};
    s.swell->significantHeight_m = 1.7;
    s.swell->peakPeriod_s = 13.0;
    const WaveSpectrum w(s);
    EXPECT_NEAR(w.SignificantHeight_m(), 1.7, 1e-9);
    const double wp = 2.0 * kPi / 13.0;
    EXPECT_GT(w.DensityOmega(wp), w.DensityOmega(0.97 * wp));
    EXPECT_GT(w.DensityOmega(wp), w.DensityOmega(1.03 * wp));
    // Deep water peak wavelength g T² / 2π.
    EXPECT_NEAR(w.LongestPeakWavelength_m(), g * 13.0 * 13.0 / (2.0 * kPi), 1e-6);
}

TEST(Spectrum, PhillipsIsTessendorfsFormAndMatchesThePmSaturationRange) {
    // p = 4, n = 2, f = 1: A exp(−1/(kL)²) / k⁴ |k̂·ŵ|², L = U²/g (Tessendorf 2001, eq. 40).
    SpectrumSettings s = Sea(SpectrumModel::Phillips, 8.0);
    s.windDirection_rad = 0.5;
    s.phillips.againstWindFactor = 1.0;
    const WaveSpectrum w(s);
    const double a = s.phillips.alpha, l = 64.0 / g;
    for (double k : {0.05, 0.2, 1.0})
        for (double az : {0.0, 1.0, 2.5, -2.0}) {
            const double kx = k * std::sin(az), ky = k * std::cos(az);
            const double c = std::cos(az - 0.5);
            const double expected = a * std::exp(-1.0 / (k * l * k * l)) / std::pow(k, 4) * c * c;
            EXPECT_NEAR(w.DensityK(kx, ky), expected, 1e-12 * expected + 1e-300);
        }
    // Against-wind suppression (seed 003): f = 0 removes waves against the wind.
    s.phillips.againstWindFactor = 0.0;
    const WaveSpectrum one(s);
    EXPECT_EQ(one.DensityK(-std::sin(0.5), -std::cos(0.5)), 0.0);
    EXPECT_NEAR(one.Variance_m2(), 0.5 * w.Variance_m2(), 1e-9 * w.Variance_m2());
    // Far above the peak the default α gives the Pierson–Moskowitz tail α_PM g² ω⁻⁵.
    const WaveSpectrum pm(Sea(SpectrumModel::PiersonMoskowitz, 8.0));
    const double omega = 30.0 * pm.PeakOmega_radps();
    EXPECT_NEAR(one.DensityOmega(omega) / pm.DensityOmega(omega), 1.0, 1e-3);
    // A steeper power law has less energy in short waves (seed 003's exponent).
    s.phillips.exponent = 5.0;
    EXPECT_LT(WaveSpectrum(s).DensityOmega(omega), one.DensityOmega(omega));
}

TEST(Spectrum, RequestedSignificantHeightRescalesTheWindSea) {
    SpectrumSettings s = Sea(SpectrumModel::Jonswap, 10.0);
    s.significantHeight_m = 3.0;
    s.peakPeriod_s = 9.0;
    const WaveSpectrum w(s);
    EXPECT_NEAR(w.SignificantHeight_m(), 3.0, 1e-9);
    EXPECT_NEAR(w.PeakOmega_radps(), 2.0 * kPi / 9.0, 1e-12);
}

TEST(Spectrum, RejectsBadParameters) {
    SpectrumSettings s = Sea(SpectrumModel::Jonswap, -1.0);
    EXPECT_THROW(WaveSpectrum{s}, InputError);
    s = Sea(SpectrumModel::Jonswap, 0.0);
    s.significantHeight_m = 2.0;  // a height with no wind to shape it
    EXPECT_THROW(WaveSpectrum{s}, InputError);
    s = Sea(SpectrumModel::Tma, 10.0);
    s.depth_m = 0.0;
    EXPECT_THROW(WaveSpectrum{s}, InputError);
    s = Sea(SpectrumModel::Phillips, 10.0);
    s.phillips.exponent = 2.0;
    EXPECT_THROW(WaveSpectrum{s}, InputError);
    try {
        s = Sea(SpectrumModel::Jonswap, 10.0);
        s.gamma = 0.5;
        WaveSpectrum{s};
        ADD_FAILURE() << "no InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("gamma"), std::string::npos) << e.what();
    }
}

TEST(Spectrum, CalmSeaHasNoWaves) {
    const WaveSpectrum w(Sea(SpectrumModel::Jonswap, 0.0));
    EXPECT_EQ(w.Variance_m2(), 0.0);
    EXPECT_EQ(w.DensityK(0.1, 0.2), 0.0);
}

}  // namespace
}  // namespace seasense::scene
