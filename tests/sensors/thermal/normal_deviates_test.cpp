// Normal deviates against the normal distribution's moments, tail probabilities, quantiles.
#include "sensors/thermal/normal_deviates.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <numbers>
#include <vector>

#include "scene/core/rng.h"

namespace seasense::sensors {
namespace {

TEST(NormalDeviates, MomentsAndTailProbabilitiesMatchTheNormalDistribution) {
    const int pairs = 1 << 19;
    double sum = 0, sum2 = 0, sum4 = 0;
    int beyond1 = 0, beyond2 = 0, beyond3 = 0;
    for (int i = 0; i < pairs; ++i) {
        float z[2];
        NormalPair(scene::HashBits(7, 11, uint64_t(i)), z[0], z[1]);
        for (float v : z) {
            sum += v;
            sum2 += double(v) * v;
            sum4 += double(v) * v * v * v;
            beyond1 += std::abs(v) > 1.0f;
            beyond2 += std::abs(v) > 2.0f;
            beyond3 += std::abs(v) > 3.0f;
        }
    }
    const double n = 2.0 * pairs;
    // Standard errors for n = 2²⁰: mean 0.001, variance 0.0014, kurtosis ~0.005.
    EXPECT_NEAR(sum / n, 0.0, 0.005);
    EXPECT_NEAR(sum2 / n, 1.0, 0.007);
    EXPECT_NEAR(sum4 / n, 3.0, 0.03);
    // P(|Z| > k) = erfc(k/√2): 0.317311, 0.0455003, 0.0026998.
    EXPECT_NEAR(beyond1 / n, 0.317311, 0.0025);
    EXPECT_NEAR(beyond2 / n, 0.0455003, 0.0010);
    EXPECT_NEAR(beyond3 / n, 0.0026998, 0.00025);
}

TEST(NormalDeviates, QuantilesAreExactAtTableNodesAndInTheTail) {
    // Bits with v = ½ (sign bit clear): |z| = Φ⁻¹(¾) = 0.6744897501960817 (A&S 26.2.23 /
    // table 26.1), and the sign bit negates it.
    EXPECT_NEAR(NormalFromBits(1u << 31), 0.6744897501960817, 1e-6);
    EXPECT_NEAR(NormalFromBits((1u << 31) | 1u), -0.6744897501960817, 1e-6);
    EXPECT_EQ(NormalFromBits(0u), 0.0f);
    // Deep in the tail (the exact Newton branch): v = 1 − k·2⁻³¹ ⇒ erfc(|z|/√2) = k·2⁻³¹.
    for (uint32_t k : {1u, 7u, 1000u, 200000u}) {
        const uint32_t v = (1u << 31) - k;
        const double z = NormalFromBits(v << 1);
        EXPECT_NEAR(std::erfc(z / std::numbers::sqrt2) / (k * 0x1.0p-31), 1.0, 1e-5) << k;
    }
}

TEST(NormalDeviates, RowOfPairsEqualsPairByPair) {
    // Rows around the eight-deviate groups of the AVX2 build (partial groups, odd counts) and a
    // long one whose 2·10⁵ deviates reach the tail past the table's last node (|z| ≈ 3.84 at
    // P(|Z| > z) = 2⁻¹³; the scalar Newton branch, which a lane group hands back) ~24 times
    // beyond 3.85 (P ≈ 1.2e-4).
    const uint64_t key = scene::Mix64(12345), counter0 = uint64_t(17) << 32;
    for (size_t count : {size_t(1), size_t(2), size_t(7), size_t(8), size_t(9), size_t(15),
                         size_t(16), size_t(17), size_t(640), size_t(200000)}) {
        std::vector<float> row(count);
        NormalPairsRow(key, counter0, count, row.data());
        size_t tail = 0;
        for (size_t i = 0; i < count; ++i) {
            float z[2];
            NormalPair(scene::Mix64(key ^ (counter0 + i / 2)), z[0], z[1]);
            ASSERT_EQ(row[i], z[i % 2]) << count << " " << i;
            tail += std::abs(row[i]) > 3.85f;
        }
        if (count == 200000) {
            EXPECT_GT(tail, 5u);
        }
    }
}

// NormalsFromBits (on simd lanes, a table gather) against NormalFromBits one by one: hashed
// bits, the ends of the table (v = 0, the last interval's draws of both signs, which the lanes
// hand to the scalar form) and counts that leave a partial group.
TEST(NormalDeviates, RowFromBitsEqualsOneByOne) {
    std::vector<uint32_t> bits;
    for (uint64_t i = 0; i < 4000; ++i) bits.push_back(uint32_t(scene::Mix64(i)));
    for (uint32_t b : {0u, 1u, 0xFFFFFFFFu, 0xFFFFFFFEu, 0x7FFFFFFFu, 0xFFFC0000u, 0xFFFBFFFFu,
                       0xFFF80000u, 0xFFF7FFFFu, 0xFFF80001u})
        bits.insert(bits.begin() + 37, b);
    for (size_t count : {size_t(0), size_t(1), size_t(7), size_t(13), bits.size()}) {
        std::vector<float> z(count, -1.0f);
        NormalsFromBits(bits.data(), count, z.data());
        for (size_t i = 0; i < count; ++i)
            EXPECT_EQ(std::bit_cast<uint32_t>(z[i]),
                      std::bit_cast<uint32_t>(NormalFromBits(bits[i])))
                << count << " " << i << " " << bits[i];
    }
}

}  // namespace
}  // namespace seasense::sensors
