// Tests of spectral band validation and the piecewise-linear response.
#include "radiometry/bands/band.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "scene/core/error.h"

namespace seasense::radiometry {
namespace {

TEST(Band, BuiltInWindowsHaveSharpEdges) {
    const Band mwir = Band::Mwir(), lwir = Band::Lwir();
    EXPECT_EQ(mwir.MinWavelength_m(), 3e-6);
    EXPECT_EQ(mwir.MaxWavelength_m(), 5e-6);
    EXPECT_EQ(lwir.MinWavelength_m(), 8e-6);
    EXPECT_EQ(lwir.MaxWavelength_m(), 12e-6);
    for (double lambda : {8e-6, 9e-6, 10.5e-6, 12e-6}) EXPECT_EQ(lwir.Response(lambda), 1.0);
    for (double lambda : {7.999e-6, 12.001e-6, 4e-6, 1.0}) EXPECT_EQ(lwir.Response(lambda), 0.0);
    EXPECT_EQ(mwir.Response(4e-6), 1.0);
    EXPECT_EQ(mwir.Response(5.0001e-6), 0.0);
}

TEST(Band, ResponseIsLinearBetweenSamples) {
    const Band tri("triangle", {{1e-6, 0.0}, {2e-6, 1.0}, {4e-6, 0.0}});
    EXPECT_EQ(tri.Name(), "triangle");
    EXPECT_NEAR(tri.Response(1.5e-6), 0.5, 1e-15);
    EXPECT_NEAR(tri.Response(2e-6), 1.0, 1e-15);
    EXPECT_NEAR(tri.Response(3e-6), 0.5, 1e-15);
    EXPECT_NEAR(tri.Response(3.5e-6), 0.25, 1e-15);
    EXPECT_EQ(tri.Response(0.5e-6), 0.0);
    EXPECT_EQ(tri.Response(std::numeric_limits<double>::quiet_NaN()), 0.0);
}

TEST(Band, FlatBandCoversItsInterval) {
    const Band b = Band::Flat("ideal", 0.4e-6, 0.7e-6);
    EXPECT_EQ(b.Wavelengths_m().size(), 2u);
    EXPECT_EQ(b.Response(0.55e-6), 1.0);
    EXPECT_EQ(b.Response(0.39e-6), 0.0);
}

TEST(Band, RejectsInvalidCurves) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    EXPECT_THROW(Band("", {1e-6, 2e-6}, {1.0, 1.0}), InputError);
    EXPECT_THROW(Band("size", {1e-6, 2e-6}, {1.0}), InputError);
    EXPECT_THROW(Band("one", {1e-6}, {1.0}), InputError);
    EXPECT_THROW(Band("decreasing", {2e-6, 1e-6}, {1.0, 1.0}), InputError);
    EXPECT_THROW(Band("repeated", {1e-6, 1e-6, 2e-6}, {1.0, 1.0, 1.0}), InputError);
    EXPECT_THROW(Band("zero", {0.0, 1e-6}, {1.0, 1.0}), InputError);
    EXPECT_THROW(Band("negative", {-1e-6, 1e-6}, {1.0, 1.0}), InputError);
    EXPECT_THROW(Band("inf", {1e-6, inf}, {1.0, 1.0}), InputError);
    EXPECT_THROW(Band("nan", {1e-6, nan}, {1.0, 1.0}), InputError);
    EXPECT_THROW(Band("negweight", {1e-6, 2e-6}, {1.0, -0.1}), InputError);
    EXPECT_THROW(Band("nanweight", {1e-6, 2e-6}, {nan, 1.0}), InputError);
    EXPECT_THROW(Band("infweight", {1e-6, 2e-6}, {inf, 1.0}), InputError);
    EXPECT_THROW(Band("allzero", {1e-6, 2e-6}, {0.0, 0.0}), InputError);
    EXPECT_THROW(Band::Flat("flip", 12e-6, 8e-6), InputError);
    EXPECT_NO_THROW(Band("ok", {1e-6, 2e-6}, {0.0, 1.0}));
}

TEST(Band, ErrorMessageNamesTheBandAndSample) {
    try {
        Band("myband", {1e-6, 2e-6, 1.5e-6}, {1.0, 1.0, 1.0});
        FAIL() << "expected InputError";
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("myband"), std::string::npos) << what;
        EXPECT_NE(what.find("sample 2"), std::string::npos) << what;
        EXPECT_NE(what.find("increasing"), std::string::npos) << what;
    }
}

}  // namespace
}  // namespace seasense::radiometry
