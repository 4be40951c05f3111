// Tests of the built-in bands against CIE 1931 colorimetric facts and the MIL-STD-3009
// definition of minus-blue filter cut-on.
#include "radiometry/bands/builtin_bands.h"

#include <gtest/gtest.h>

#include <string>

#include "scene/core/error.h"

namespace seasense::radiometry {
namespace {

// ∫ R(λ) dλ of the piecewise-linear response (trapezoid rule is exact), in nm.
double Integral_nm(const Band& band) {
    const auto& l = band.Wavelengths_m();
    const auto& w = band.Weights();
    double sum = 0.0;
    for (size_t i = 0; i + 1 < l.size(); ++i) sum += 0.5 * (w[i] + w[i + 1]) * (l[i + 1] - l[i]);
    return sum * 1e9;
}

TEST(BuiltinBands, CieYIntegralMatchesCie1931Table) {
    // Σ ȳ(λ) Δλ over the CIE 1931 table at 5 nm (CIE 015:2004) = 106.857 nm.
    EXPECT_NEAR(Integral_nm(CieY()), 106.857, 0.01 * 106.857);
}

TEST(BuiltinBands, CieXyzIntegralsAreEqualForTheEqualEnergyWhite) {
    // Illuminant E has chromaticity (1/3, 1/3): the three matching functions have equal areas.
    const double y = Integral_nm(CieY());
    EXPECT_NEAR(Integral_nm(CieX()) / y, 1.0, 0.02);
    EXPECT_NEAR(Integral_nm(CieZ()) / y, 1.0, 0.02);
}

TEST(BuiltinBands, CieYPeaksAt555nm) {
    // The photopic luminous efficiency V(λ) = ȳ(λ) is maximal at 555 nm (CIE 1924).
    const Band y = CieY();
    double best = 0.0, bestLambda = 0.0;
    for (double nm = 500.0; nm <= 600.0; nm += 1.0)
        if (y.Response(nm * 1e-9) > best) best = y.Response(nm * 1e-9), bestLambda = nm;
    EXPECT_NEAR(bestLambda, 555.0, 5.0);
    EXPECT_NEAR(best, 1.0, 0.02);
}

TEST(BuiltinBands, PhotocathodesCoverTheirPublishedRanges) {
    // physics.md: Gen II ≈ 400–850 nm, Gen III ≈ 500–900 nm (response well above zero there).
    const Band gen2 = NvgGen2(), gen3 = NvgGen3();
    for (double nm = 400.0; nm <= 850.0; nm += 10.0) EXPECT_GT(gen2.Response(nm * 1e-9), 0.1) << nm;
    for (double nm = 500.0; nm <= 900.0; nm += 10.0) EXPECT_GT(gen3.Response(nm * 1e-9), 0.1) << nm;
    // GaAs band gap 1.42 eV → 873 nm: nothing beyond ~950 nm; no blue through GaAs below 450 nm.
    EXPECT_EQ(gen3.Response(950e-9), 0.0);
    EXPECT_EQ(gen3.Response(440e-9), 0.0);
}

TEST(BuiltinBands, MinusBlueFiltersTransmitHalfAtTheirCutOn) {
    // MIL-STD-3009 defines the class A and B cut-on as the 50 % transmission wavelength.
    for (MinusBlueClass c : {MinusBlueClass::A, MinusBlueClass::B}) {
        const double cut = MinusBlueCutOn_m(c);
        EXPECT_DOUBLE_EQ(MinusBlueTransmission(c, cut), 0.5);
        EXPECT_EQ(MinusBlueTransmission(c, cut - 20e-9), 0.0);
        EXPECT_EQ(MinusBlueTransmission(c, cut + 20e-9), 1.0);
        const Band filtered = WithMinusBlue(NvgGen3(), c);
        EXPECT_NEAR(filtered.Response(cut), 0.5 * NvgGen3().Response(cut), 1e-3);
        EXPECT_NEAR(filtered.Response(800e-9), NvgGen3().Response(800e-9), 1e-12);
    }
    EXPECT_NEAR(MinusBlueCutOn_m(MinusBlueClass::A), 625e-9, 1e-15);
    EXPECT_NEAR(MinusBlueCutOn_m(MinusBlueClass::B), 665e-9, 1e-15);
    // The class B filter removes more than class A, which removes some of the bare tube.
    EXPECT_LT(Integral_nm(NvgGen3ClassB()), Integral_nm(NvgGen3ClassA()));
    EXPECT_LT(Integral_nm(NvgGen3ClassA()), Integral_nm(NvgGen3()));
}

TEST(BuiltinBands, LookupByNameRoundTripsAndRejectsUnknownNames) {
    for (const std::string& name : BuiltinBandNames()) EXPECT_EQ(BuiltinBand(name).Name(), name);
    try {
        BuiltinBand("SWIR");
        FAIL() << "no InputError";
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("'SWIR'"), std::string::npos) << what;
        EXPECT_NE(what.find("NVG_GEN3_CLASS_B"), std::string::npos) << what;
    }
}

}  // namespace
}  // namespace seasense::radiometry
