// Counter-based RNG: SplitMix64 reference outputs and basic uniformity.
#include "scene/core/rng.h"

#include <gtest/gtest.h>

#include <cmath>

namespace seasense::scene {
namespace {

TEST(Rng, Mix64ReproducesSplitMix64ReferenceOutputs) {
    // Vigna's splitmix64.c seeded with 0 yields 0xe220a8397b1dcdaf, 0x6e789e6aa1b965f4,
    // 0x06c45d188009454f: output n is Mix64(n · 0x9e3779b97f4a7c15).
    EXPECT_EQ(Mix64(0), 0xe220a8397b1dcdafULL);
    EXPECT_EQ(Mix64(0x9e3779b97f4a7c15ULL), 0x6e789e6aa1b965f4ULL);
    EXPECT_EQ(Mix64(2 * 0x9e3779b97f4a7c15ULL), 0x06c45d188009454fULL);
}

TEST(Rng, UniformIsUniformAndStreamsDiffer) {
    const int n = 200000;
    double sum = 0.0, sum2 = 0.0;
    int bins[10] = {};
    for (int i = 0; i < n; ++i) {
        const double u = Uniform01(42, 7, uint64_t(i));
        ASSERT_GE(u, 0.0);
        ASSERT_LT(u, 1.0);
        sum += u;
        sum2 += u * u;
        ++bins[int(u * 10)];
    }
    // Mean 1/2 and variance 1/12 within 5 standard errors.
    EXPECT_NEAR(sum / n, 0.5, 5.0 * std::sqrt(1.0 / 12.0 / n));
    EXPECT_NEAR(sum2 / n - (sum / n) * (sum / n), 1.0 / 12.0, 2e-3);
    // χ² over 10 bins, 9 degrees of freedom: 27.9 is the 0.1 % critical value.
    double chi2 = 0.0;
    for (int b : bins) chi2 += (b - n / 10.0) * (b - n / 10.0) / (n / 10.0);
    EXPECT_LT(chi2, 27.9);
    EXPECT_NE(HashBits(42, 7, 0), HashBits(42, 8, 0));
    EXPECT_NE(HashBits(42, 7, 0), HashBits(43, 7, 0));
    EXPECT_EQ(HashBits(42, 7, 5), HashBits(42, 7, 5));
}

}  // namespace
}  // namespace seasense::scene
