// Tests of the surf-zone shading: seabed through shallow water (Beer–Lambert along the refracted
// path), wet sand at zero depth, foam as a Lambertian layer.
#include "channels/otw/shore_shading.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <random>

namespace seasense::channels {
namespace {

using namespace simd;

float Lane0(VF v) { return v[0]; }

const ShoreChannel kChannel{0.0f, 0.2f, 0.25f, 0.40f, 0.55f};

// A flat sea over a plane sandy bottom seen at 40° from the normal: with no deep-water colour
// (R_rs = 0) and no reflected sky, the radiance is (1 − F) ρ_wet E/π e^{−K d (1 + 1/cos θ_t)},
// θ_t from Snell's law (sin θ_t = sin θ_v / n).
TEST(ShoreShading, BottomAttenuationFollowsRefractedPath) {
    const double thetaV = 40.0 * M_PI / 180.0, n = 1.34;
    const double thetaT = std::asin(std::sin(thetaV) / n);
    const float E = 50000.0f, oneMinusF = 0.97f;
    const VF path = WaterPathFactor(Splat(float(std::cos(thetaV))), float(n));
    for (double d : {0.5, 2.0, 5.0}) {
        const float L =
            Lane0(ShoreRadiance(kChannel, Splat(0.0f), Splat(oneMinusF), path, Splat(float(d)),
                                Splat(1.0f), Splat(0.0f), Splat(E), Splat(E)));
        const double expected =
            oneMinusF * 0.25 * E / M_PI * std::exp(-0.2 * (d + d / std::cos(thetaT)));
        EXPECT_NEAR(L / expected, 1.0, 0.01) << "depth " << d;
    }
    // Seen steeply the water is more transparent: the path is shorter.
    const VF steep = WaterPathFactor(Splat(1.0f), float(n));
    EXPECT_GT(Lane0(ShoreRadiance(kChannel, Splat(0.0f), Splat(oneMinusF), steep, Splat(2.0f),
                                  Splat(1.0f), Splat(0.0f), Splat(E), Splat(E))),
              Lane0(ShoreRadiance(kChannel, Splat(0.0f), Splat(oneMinusF), path, Splat(2.0f),
                                  Splat(1.0f), Splat(0.0f), Splat(E), Splat(E))));
}

// As the depth goes to 0 the water's radiance goes continuously to that of wet sand, ρ_wet E/π;
// in deep water it goes to the water-leaving radiance R_rs E_d plus the reflection.
TEST(ShoreShading, ShallowWaterTendsToWetSandAndDeepWaterToSeaColour) {
    ShoreChannel c = kChannel;
    c.rrs = 0.002f;
    const float E = 30000.0f, Ed = 28000.0f, reflected = 40.0f, oneMinusF = 0.95f;
    const VF path = WaterPathFactor(Splat(0.6f), 1.34f);
    const auto L = [&](float d) {
        return Lane0(ShoreRadiance(c, Splat(reflected), Splat(oneMinusF), path, Splat(d),
                                   Splat(1.0f), Splat(0.0f), Splat(E), Splat(Ed)));
    };
    const float wetSand = 0.25f * E / float(M_PI);
    EXPECT_NEAR(L(0.0f), wetSand, 1e-3f * wetSand);
    float previous = L(0.0f);
    for (float d = 0.001f; d < 0.1f; d += 0.001f) {
        // No jump: successive millimetres change the radiance by well under 10 %.
        EXPECT_LT(std::abs(L(d) - previous), 0.1f * wetSand) << d;
        previous = L(d);
    }
    EXPECT_NEAR(L(kDeepColumn_m), reflected + oneMinusF * c.rrs * Ed, 1e-3f);
    // Dry sand (wetness 0) is brighter than wet sand under the same light.
    EXPECT_NEAR(Lane0(ShoreRadiance(c, Splat(0.0f), Splat(1.0f), path, Splat(0.0f), Splat(0.0f),
                                    Splat(0.0f), Splat(E), Splat(Ed))),
                0.40f * E / float(M_PI), 1e-3f * E);
}

// Full foam coverage renders at the foam reflectance's Lambertian radiance ρ E / π whatever
// lies below; half coverage is the mean of foam and water.
TEST(ShoreShading, FoamIsLambertianLayer) {
    const float E = 80000.0f;
    const VF path = WaterPathFactor(Splat(0.8f), 1.34f);
    for (float d : {0.0f, 1.0f, kDeepColumn_m}) {
        const float L = Lane0(ShoreRadiance(kChannel, Splat(30.0f), Splat(0.97f), path, Splat(d),
                                            Splat(1.0f), Splat(1.0f), Splat(E), Splat(E)));
        EXPECT_NEAR(L, 0.55f * E / float(M_PI), 1e-5f * E);
    }
    const float water =
        Lane0(ShoreRadiance(kChannel, Splat(30.0f), Splat(0.97f), path, Splat(kDeepColumn_m),
                            Splat(1.0f), Splat(0.0f), Splat(E), Splat(E)));
    const float half =
        Lane0(ShoreRadiance(kChannel, Splat(30.0f), Splat(0.97f), path, Splat(kDeepColumn_m),
                            Splat(1.0f), Splat(0.5f), Splat(E), Splat(E)));
    EXPECT_NEAR(half, 0.5f * (water + 0.55f * E / float(M_PI)), 1e-4f * E);
}

// Where the bottom's attenuation e^{−K d (1 + 1/cos θ_t)} underflows in every lane (deep water,
// the common case) ShoreRadiance skips the exponential: each lane's radiance is the same bits as
// among lanes that need it (the first lane shallow here), whatever its neighbours.
TEST(ShoreShading, DeepWaterLanesEqualTheirValuesAmongShallowLanes) {
    ShoreChannel c = kChannel;
    c.rrs = 0.002f;
    VF cosV, depth, wet, foam, reflected, E, Ed;
    for (size_t l = 0; l < kLanes; ++l) {
        const float f = float(l);
        cosV[l] = 0.1f + 0.1f * f;
        // K d (1 + 1/cos θ_t) ≥ 0.2 · 250 · 2 = 100 > 87: e^x is 0 in float.
        depth[l] = l % 2 ? kDeepColumn_m : 250.0f + 3.0f * f;
        wet[l] = 0.1f * f;
        foam[l] = l == 3 ? 0.25f : 0.0f;
        reflected[l] = 3.0f * f;
        E[l] = 1000.0f * (f + 1.0f);
        Ed[l] = 900.0f * (f + 1.0f);
    }
    const VF path = WaterPathFactor(cosV, 1.34f);
    const VF deep = ShoreRadiance(c, reflected, Splat(0.97f), path, depth, wet, foam, E, Ed);
    VF shallow = depth;
    shallow[0] = 0.5f;
    const VF mixed = ShoreRadiance(c, reflected, Splat(0.97f), path, shallow, wet, foam, E, Ed);
    for (size_t l = 1; l < kLanes; ++l) EXPECT_EQ(deep[l], mixed[l]) << "lane " << l;
    EXPECT_NE(deep[0], mixed[0]);
    // No light returns from the bottom: the reflection plus the deep-water colour.
    EXPECT_NEAR(deep[1], 3.0f + 0.97f * c.rrs * 1800.0f, 1e-4f);
}

// Where BottomUnseenInEveryLane holds, ShoreRadiance gives the same bits with
// kMinWaterPathFactor as with the true path factor (so SeaShading skips WaterPathFactor), for
// view cosines from grazing to just above 1; and it holds over the deep column of the open sea
// but not over shallow water, where the bottom shows.
TEST(ShoreShading, PathFactorBoundGivesTheSameRadianceWhereTheBottomIsUnseen) {
    const ShoreChannel otw[3] = {{0.0003f, 0.28f, 0.28f, 0.45f, 0.50f},
                                 {0.0015f, 0.10f, 0.24f, 0.39f, 0.53f},
                                 {0.0050f, 0.13f, 0.17f, 0.30f, 0.55f}};
    const float cosines[] = {1e-3f,       0.05f, 0.3f, 0.7f, 1.0f, std::nextafter(1.0f, 2.0f),
                             1.0f + 1e-6f};
    for (float cosV : cosines)
        EXPECT_GE(WaterPathFactor(Splat(cosV), 1.341f)[0], kMinWaterPathFactor) << cosV;
    EXPECT_TRUE(BottomUnseenInEveryLane(otw, Splat(kDeepColumn_m)));
    EXPECT_FALSE(BottomUnseenInEveryLane(otw, Splat(5.0f)));
    // The same channels with the middle one's water far clearer (K = 0.01): the test must hold
    // for each channel, not only for the first.
    ShoreChannel clear[3] = {otw[0], otw[1], otw[2]};
    clear[1].K_perm = 0.01f;
    int unseen = 0, seen = 0;
    // Depths around the bound of the clearest channel (K = 0.10: −0.1 · 1.5 d < −87 from
    // d ≈ 580 m), negative and zero columns (sand) and the deep column.
    const auto check = [&](const ShoreChannel(&channels)[3]) {
        for (float d0 : {-3.0f, 0.0f, 0.3f, 5.0f, 20.0f, 50.0f, 100.0f, 400.0f, 575.0f, 579.0f,
                         580.0f, 581.0f, 590.0f, 2000.0f, kDeepColumn_m}) {
            for (float cosV : cosines) {
                VF depth, wet, foam, reflected, E, Ed;
                for (size_t l = 0; l < kLanes; ++l) {
                    const float f = float(l);
                    depth[l] = d0 * (1.0f + 0.001f * f);
                    wet[l] = 0.1f * f;
                    foam[l] = l == 3 ? 0.25f : 0.0f;
                    reflected[l] = 3.0f * f;
                    E[l] = 1000.0f * (f + 1.0f);
                    Ed[l] = 900.0f * (f + 1.0f);
                }
                if (!BottomUnseenInEveryLane(channels, depth)) {
                    ++seen;
                    continue;
                }
                ++unseen;
                const VF path = WaterPathFactor(Splat(cosV), 1.341f);
                for (const ShoreChannel& c : channels) {
                    const VF exact =
                        ShoreRadiance(c, reflected, Splat(0.97f), path, depth, wet, foam, E, Ed);
                    const VF bound =
                        ShoreRadiance(c, reflected, Splat(0.97f), Splat(kMinWaterPathFactor), depth,
                                      wet, foam, E, Ed);
                    for (size_t l = 0; l < kLanes; ++l)
                        EXPECT_EQ(exact[l], bound[l]) << "depth " << depth[l] << " cos " << cosV;
                }
            }
        }
    };
    check(otw);
    check(clear);
    EXPECT_GT(unseen, 0);
    EXPECT_GT(seen, 0);
}

// The fill lights' irradiance from lights broadcast once (MakeLightLanes, AddLambertianLights)
// equals, lane for lane and bit for bit, the scalar sum light by light with the direction's
// components as Splat makes them (0 + d: −0 becomes +0) and n·l in glm::dot's order: random
// normals and lights, signed zeros (a direction of −0 too), lights behind the surface, none, one
// and two lights.
TEST(ShoreShading, LambertianLightsOnLanesEqualTheScalarSumLightByLight) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f), e(0.0f, 2e4f);
    const float special[] = {0.0f, -0.0f, 1.0f, -1.0f, 1e-30f, -1e-30f};
    const auto pick = [&](int i) { return i % 3 == 0 ? special[size_t(i / 3) % 6] : u(rng); };
    int compared = 0;
    for (int round = 0; round < 400; ++round) {
        const size_t count = size_t(round % 3);
        float dir[2][3], E[2][3];
        LightLanes lights[2];
        for (size_t l = 0; l < count; ++l) {
            for (int c = 0; c < 3; ++c) dir[l][c] = pick(round + 5 * int(l) + c), E[l][c] = e(rng);
            // A direction of negative zeros: n·l is then +0 or −0 by Splat's sign of zero, which
            // an accumulator of −0 (odd lanes of green) shows.
            if (round % 4 == 1) dir[l][0] = dir[l][1] = dir[l][2] = -0.0f;
            lights[l] = MakeLightLanes(dir[l][0], dir[l][1], dir[l][2], E[l][0], E[l][1], E[l][2]);
        }
        VF nx, ny, nz, aR, aG, aB;
        for (size_t i = 0; i < kLanes; ++i) {
            nx[i] = pick(int(i) + round), ny[i] = pick(int(i) + round + 1), nz[i] = u(rng);
            aR[i] = e(rng), aG[i] = i % 2 ? -0.0f : e(rng), aB[i] = e(rng);
        }
        const VF a0[3] = {aR, aG, aB};
        AddLambertianLights(lights, count, nx, ny, nz, aR, aG, aB);
        const VF a1[3] = {aR, aG, aB};
        for (size_t i = 0; i < kLanes; ++i) {
            for (int c = 0; c < 3; ++c) {
                float expected = a0[c][i];
                for (size_t l = 0; l < count; ++l) {
                    const float lx = 0.0f + dir[l][0], ly = 0.0f + dir[l][1], lz = 0.0f + dir[l][2];
                    float cosine = (nx[i] * lx + ny[i] * ly) + nz[i] * lz;
                    cosine = 0.0f > cosine ? 0.0f : cosine;
                    expected = expected + E[l][c] * cosine;
                }
                ASSERT_EQ(std::bit_cast<uint32_t>(a1[c][i]), std::bit_cast<uint32_t>(expected))
                    << "round " << round << " lane " << i << " channel " << c;
                ++compared;
            }
        }
    }
    EXPECT_EQ(compared, 400 * int(kLanes) * 3);
}

}  // namespace
}  // namespace seasense::channels
