// The OTW classification's eight-lane triangle helpers give the scalar forms' bits: a position
// and a normal interpolated at once (per sample, and component by component for a pixel's four
// samples) equal glm's (b0 a0 + b1 a1) + b2 a2 per float, and MinMax equals std::min /
// std::max taken in order from ±∞, NaN and signed zeros included.
#include "channels/otw/triangle_lanes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

namespace seasense::channels::triangle_lanes {
namespace {

uint32_t Bits(float f) {
    uint32_t u;
    std::memcpy(&u, &f, sizeof u);
    return u;
}

// Same bits, or both NaN (inf · 0 makes one).
bool Same(float a, float b) { return Bits(a) == Bits(b) || (std::isnan(a) && std::isnan(b)); }

// Values with the awkward cases among ordinary ones: signed zeros, subnormals, huge, infinite.
std::vector<float> Values(std::mt19937& rng, size_t count) {
    const float special[] = {0.0f,
                             -0.0f,
                             1.0f,
                             -1.0f,
                             1e-42f,
                             -1e-42f,
                             3.0e38f,
                             -3e38f,
                             0.5f,
                             1e-3f,
                             std::numeric_limits<float>::infinity(),
                             -std::numeric_limits<float>::infinity()};
    std::uniform_real_distribution<float> u(-1.0f, 1.0f), scale(-6.0f, 6.0f);
    std::uniform_int_distribution<int> pick(0, 15);
    std::vector<float> v(count);
    for (float& x : v) {
        const int k = pick(rng);
        x = k < int(std::size(special)) ? special[k] : u(rng) * std::pow(10.0f, scale(rng));
    }
    return v;
}

F8 Load8(const float* p) {
    F8 v;
    std::memcpy(&v, p, sizeof v);
    return v;
}
F4 Load4(const float* p) { return _mm_loadu_ps(p); }
float Lane(F4 v, int l) {
    alignas(16) float f[4];
    _mm_store_ps(f, v);
    return f[l];
}

float Scalar(float b0, float b1, float b2, float a0, float a1, float a2) {
    return (b0 * a0 + b1 * a1) + b2 * a2;
}

// One sample: weights broadcast, the vertices' position (lanes 0–3) and normal (4–7) at once.
TEST(TriangleLanes, PositionAndNormalOfASampleAtOnce) {
    std::mt19937 rng(5);
    for (int trial = 0; trial < 20000; ++trial) {
        const std::vector<float> w = Values(rng, 3), v = Values(rng, 24);
        const F8 r = Interpolate8(Set8(w[0]), Set8(w[1]), Set8(w[2]), Load8(&v[0]), Load8(&v[8]),
                                  Load8(&v[16]));
        for (int l = 0; l < 8; ++l) {
            const float expected = Scalar(w[0], w[1], w[2], v[l], v[8 + l], v[16 + l]);
            ASSERT_TRUE(Same(Lane(l < 4 ? Low(r) : High(r), l % 4), expected))
                << trial << " lane " << l;
        }
    }
}

// A pixel's four samples (weights in lanes 0–3, Twice), component c of the vertices' positions
// in lanes 0–3 and of their normals in lanes 4–7 (Spread): sample s of component c.
template <int c>
void ExpectComponent(const std::vector<float>& w, const std::vector<float>& v, int trial) {
    const F8 r =
        Interpolate8(Twice(Load4(&w[0])), Twice(Load4(&w[4])), Twice(Load4(&w[8])),
                     Spread<c>(Load8(&v[0])), Spread<c>(Load8(&v[8])), Spread<c>(Load8(&v[16])));
    for (int s = 0; s < 4; ++s) {
        for (int half = 0; half < 2; ++half) {
            const int i = 4 * half + c;  // position or normal component c
            const float expected = Scalar(w[s], w[4 + s], w[8 + s], v[i], v[8 + i], v[16 + i]);
            ASSERT_TRUE(Same(Lane(half == 0 ? Low(r) : High(r), s), expected))
                << trial << " component " << c << " sample " << s << " half " << half;
        }
    }
}
TEST(TriangleLanes, ComponentsOfFourSamplesAtOnce) {
    std::mt19937 rng(9);
    for (int trial = 0; trial < 20000; ++trial) {
        const std::vector<float> w = Values(rng, 12), v = Values(rng, 24);
        ExpectComponent<0>(w, v, trial);
        ExpectComponent<1>(w, v, trial);
        ExpectComponent<2>(w, v, trial);
    }
}

// MinMax over sequences with NaN at every place, ties of +0 and −0 in either order, infinities.
TEST(TriangleLanes, MinMaxEqualsStdMinMaxInOrder) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    const float pool[] = {0.0f, -0.0f, nan, inf, -inf, 1.0f, -1.0f, 2.5e-3f, 1e-42f};
    std::mt19937 rng(3);
    std::uniform_int_distribution<int> pick(0, int(std::size(pool)) - 1), length(1, 5);
    for (int trial = 0; trial < 50000; ++trial) {
        const int n = length(rng);
        MinMax lanes;
        float lo = inf, hi = -inf;
        for (int i = 0; i < n; ++i) {
            const float c = pool[pick(rng)];
            lanes.Take(simd4::Set4(c));
            lo = std::min(lo, c), hi = std::max(hi, c);
        }
        ASSERT_EQ(Bits(lanes.Min()), Bits(lo)) << trial;
        ASSERT_EQ(Bits(lanes.Max()), Bits(hi)) << trial;
    }
}

}  // namespace
}  // namespace seasense::channels::triangle_lanes
