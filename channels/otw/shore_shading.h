// Shading of the surf zone in OTW, simd::kLanes at a time: sand where the sea lies on the beach,
// the seabed seen through shallow water, and a Lambertian foam layer.
#pragma once

#include <cmath>
#include <cstddef>

#include "scene/core/simd_lanes.h"

namespace seasense::channels {

// e^x for x ≤ 0 (0 below −87, where e^x leaves float's normal range). Cody & Waite range
// reduction ("Software Manual for the Elementary Functions", 1980): x = k ln 2 + r with
// |r| ≤ ln 2 / 2 and ln 2 split into a 16-bit head (k·head exact) and a tail; e^r from its
// Taylor series to r⁷ (truncation < 1e-8 relative, below float precision); 2^k through the
// exponent bits. Within a few ulp of std::exp, and simd::kLanes wide where libm is scalar.
inline simd::VF ExpNonPositive(simd::VF x) {
    using namespace simd;
    const VI underflow = x < -87.0f;
    x = Max(x, Splat(-87.0f));
    const VI k = RoundToInt(x * 1.44269504f);  // round(x / ln 2)
    const VF kf = __builtin_convertvector(k, VF);
    const VF r = (x - kf * 0.693145751953125f) - kf * 1.428606765330187e-6f;
    VF p = Splat(1.0f / 5040.0f);
    const float c[] = {1.0f / 720.0f, 1.0f / 120.0f, 1.0f / 24.0f, 1.0f / 6.0f, 0.5f, 1.0f, 1.0f};
    for (float ci : c) p = p * r + ci;
    const VF twoK = (VF)((k + 127) << 23);
    return Select(underflow, Splat(0.0f), p * twoK);
}

// Water column (m) given to sea vertices without a surf zone: deeper than any light returns
// from (e^{−0.1·2e4} = 0).
inline constexpr float kDeepColumn_m = 1.0e4f;

// Depth (m) of water over which the water surface (Fresnel reflection, glint) fades in above
// bare sand: the swash film; below it the sand is seen as wet sand without a surface.
inline constexpr float kSwashFilm_m = 0.02f;

// One colour channel's optics of the surf zone.
struct ShoreChannel {
    float rrs = 0.0f;      // remote-sensing reflectance of optically deep water, sr⁻¹
    float K_perm = 0.0f;   // diffuse attenuation coefficient of the water, m⁻¹
    float rhoWet = 0.0f;   // wet sand reflectance (the seabed under water, sand below high water)
    float rhoDry = 0.0f;   // dry sand reflectance
    float rhoFoam = 0.0f;  // foam reflectance
};

// 1 + 1/cos θ_t: the path through a column of depth d, down (d, the diffuse light) and back up
// to the eye along the refracted view ray (d / cos θ_t), per unit depth. cos θ_t from Snell's
// law for a view ray at cos θ_v = cosV to the surface normal, water index n.
inline simd::VF WaterPathFactor(simd::VF cosV, float n) {
    using namespace simd;
    const VF sin2T = (1.0f - cosV * cosV) * (1.0f / (n * n));
    const VF cosT = Sqrt(Max(1.0f - sin2T, Splat(1e-6f)));
    return 1.0f + 1.0f / cosT;
}

// A lower bound of WaterPathFactor for any cosV in (0, 1 + 1e-6]: 1 + 1/cos θ_t ≥ 2 but for
// the rounding of a cosine just above 1.
inline constexpr float kMinWaterPathFactor = 1.5f;

// Whether ShoreRadiance's bottom term e^{−K d (1 + 1/cos θ_t)} is 0 in every lane of each
// channel for any path factor p ≥ kMinWaterPathFactor: where −K·(d·kMinWaterPathFactor) < −87,
// −K·(d·p) has the same sign and a magnitude at least as large (float rounding is monotone), so
// it is below −87 too. There ShoreRadiance gives the same bits with kMinWaterPathFactor for the
// path factor, and WaterPathFactor (a square root and a division) need not be computed.
inline bool BottomUnseenInEveryLane(const ShoreChannel (&c)[3], simd::VF depth) {
    using namespace simd;
    const VF d = depth * kMinWaterPathFactor;
    return All((-c[0].K_perm * d < -87.0f) & (-c[1].K_perm * d < -87.0f) &
               (-c[2].K_perm * d < -87.0f));
}

// A distant light on lanes: its direction as the operands of a dot product (Splat, as
// Splat(d.x) in the dot product per lane group made them) and its illuminance (lx, one value a
// colour channel) bit for bit. Made once for the many lane groups a chunk shades.
struct LightLanes {
    simd::VF x, y, z, r, g, b;
};
inline LightLanes MakeLightLanes(float dx, float dy, float dz, float Er, float Eg, float Eb) {
    using namespace simd;
    return {Splat(dx), Splat(dy), Splat(dz), Broadcast(Er), Broadcast(Eg), Broadcast(Eb)};
}

// Adds the Lambertian irradiance E·max(n·l, 0) of lights[0, count) on normals (nx, ny, nz) to
// (aR, aG, aB), light by light in order, n·l in glm::dot's order.
inline void AddLambertianLights(const LightLanes* lights, size_t count, simd::VF nx, simd::VF ny,
                                simd::VF nz, simd::VF& aR, simd::VF& aG, simd::VF& aB) {
    using namespace simd;
    for (size_t l = 0; l < count; ++l) {
        const LightLanes& light = lights[l];
        const VF c = Max(Dot(nx, ny, nz, light.x, light.y, light.z), Splat(0.0f));
        aR = aR + light.r * c;
        aG = aG + light.g * c;
        aB = aB + light.b * c;
    }
}

// Radiance (cd/m², one channel) of a surf-zone point before fog:
//   water:  reflected + (1 − F)·[ρ_wet E/π · T + R_rs E_d · (1 − T)],  T = e^{−K d (1 + 1/cos θ_t)}
//   sand:   ρ_sand E/π,  ρ_sand from dry to wet by wetness
//   surface = sand + (water − sand)·min(d / kSwashFilm_m, 1);  result = surface + (foam −
//   surface)·c
// reflected = F·L_sky + glint (the surface's specular part), oneMinusF the Fresnel
// transmittance, pathFactor from WaterPathFactor, depth the column d (m), wet in [0, 1], foam
// coverage c in [0, 1], E the irradiance on the surface (Lambertian: key, fill and sky, lx),
// Ed the downwelling irradiance on a level surface (lx).
inline simd::VF ShoreRadiance(const ShoreChannel& c, simd::VF reflected, simd::VF oneMinusF,
                              simd::VF pathFactor, simd::VF depth, simd::VF wet, simd::VF foam,
                              simd::VF E, simd::VF Ed) {
    using namespace simd;
    const VF lambert = E * float(1.0 / M_PI);
    // Deep water in every lane (the common case away from the beach): e^x underflows to the
    // 0 that ExpNonPositive returns below −87.
    const VF x = -c.K_perm * (depth * pathFactor);
    const VF T = All(x < -87.0f) ? Splat(0.0f) : ExpNonPositive(x);
    const VF bottom = c.rhoWet * lambert;
    const VF deep = c.rrs * Ed;
    const VF water = reflected + oneMinusF * (deep + (bottom - deep) * T);
    const VF rhoSand = c.rhoDry + (c.rhoWet - c.rhoDry) * wet;
    const VF sand = rhoSand * lambert;
    const VF film = Min(Splat(1.0f), depth * (1.0f / kSwashFilm_m));  // _mm_min_ps(·, 1)
    const VF surface = sand + (water - sand) * film;
    const VF white = c.rhoFoam * lambert;
    return surface + (white - surface) * foam;
}

}  // namespace seasense::channels
