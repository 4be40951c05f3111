// NVG spectral basis: blackbody sub-band photon radiance against direct integration of Planck,
// photometry against the historical candela (blackbody at the platinum point).
#include "radiometry/nvg/nvg_spectrum.h"

#include <gtest/gtest.h>

#include <cmath>

#include "radiometry/bands/builtin_bands.h"
#include "radiometry/planck/planck.h"

namespace seasense::radiometry {
namespace {

// Simpson's rule of f over [a, b] with n (even) intervals.
template <typename F>
double Simpson(const F& f, double a, double b, int n) {
    const double h = (b - a) / n;
    double s = f(a) + f(b);
    for (int i = 1; i < n; ++i) s += (i % 2 ? 4.0 : 2.0) * f(a + i * h);
    return s * h / 3.0;
}

TEST(NvgSpectrum, BlackbodySubBandsMatchDirectPlanckPhotonIntegral) {
    const Band band = NvgGen3();
    const PhotonResponse response(band);
    // The relative QE: radiant sensitivity / λ, normalised to its maximum on a 0.01 nm grid.
    double peak = 0.0;
    for (double l = band.MinWavelength_m(); l <= band.MaxWavelength_m(); l += 0.01e-9)
        peak = std::max(peak, band.Response(l) / l);
    for (double T : {1300.0, 2856.0, 5778.0, 28000.0}) {
        const glm::dvec3 got = BlackbodySubBandPhotons(response, T);
        for (int k = 0; k < 3; ++k) {
            const double a = kNvgSubBandEdges_m[size_t(k)], b = kNvgSubBandEdges_m[size_t(k) + 1];
            // Piecewise-linear response: integrate each 1 nm cell with Simpson (20 intervals).
            double direct = 0.0;
            for (double l = a; l < b - 1e-12; l += 1e-9)
                direct += Simpson(
                    [&](double x) {
                        return band.Response(x) / x / peak * PlanckPhotonRadiance(x, T);
                    },
                    l, l + 1e-9, 20);
            EXPECT_NEAR(got[k] / direct, 1.0, 1e-4) << "T " << T << " sub-band " << k;
        }
    }
}

TEST(NvgSpectrum, PhotonResponsePeaksAtOne) {
    const PhotonResponse r(NvgGen2());
    double peak = 0.0;
    for (double l = 350e-9; l <= 950e-9; l += 0.1e-9) peak = std::max(peak, r(l));
    EXPECT_NEAR(peak, 1.0, 1e-3);
    EXPECT_EQ(r(300e-9), 0.0);
}

// The 1948–1979 candela: a blackbody at the freezing point of platinum (2042 K) has a
// luminance of 60 cd/cm² (CGPM 1946/1948), i.e. 6.0e5 cd/m².
TEST(NvgSpectrum, PhotometryOfPlatinumPointBlackbody) {
    const double L = Photometric(BlackbodySpectrum(2042.0));
    EXPECT_NEAR(L / 6.0e5, 1.0, 0.02);
}

// Published colours: the moon is redder than the sun (B−V 0.92 vs 0.65), the moonless night
// sky is brightest in the NIR (airglow; I band 1.9 mag brighter than V, Benn & Ellison 1998).
TEST(NvgSpectrum, NightSkyIsRedderThanMoonlightWhichIsRedderThanSunlight) {
    const PhotonResponse r(NvgGen3());
    const glm::dvec3 sun = PhotonsPerPhotometric(r, SunSpectrum());
    const glm::dvec3 moon = PhotonsPerPhotometric(r, MoonSpectrum());
    const glm::dvec3 night = PhotonsPerPhotometric(r, NightSkySpectrum());
    // Share of the NIR sub-band (750–950 nm) in the photocathode signal.
    const auto nirShare = [](const glm::dvec3& v) { return v[2] / (v[0] + v[1] + v[2]); };
    EXPECT_LT(nirShare(sun), nirShare(moon));
    EXPECT_LT(nirShare(moon), nirShare(night));
}

}  // namespace
}  // namespace seasense::radiometry
