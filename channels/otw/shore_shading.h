// Shading of the surf zone in OTW, four lanes at a time: sand where the sea lies on the beach,
// the seabed seen through shallow water, and a Lambertian foam layer.
#pragma once

#include <cmath>

#include "scene/core/simd4.h"

namespace seasense::channels {

// e^x for x ≤ 0 (0 below −87, where e^x leaves float's normal range). Cody & Waite range
// reduction ("Software Manual for the Elementary Functions", 1980): x = k ln 2 + r with
// |r| ≤ ln 2 / 2 and ln 2 split into a 16-bit head (k·head exact) and a tail; e^r from its
// Taylor series to r⁷ (truncation < 1e-8 relative, below float precision); 2^k through the
// exponent bits. Within a few ulp of std::exp, and four lanes wide where libm is scalar.
inline simd4::F4 ExpNonPositive4(simd4::F4 x) {
    using namespace simd4;
    const F4 underflow = _mm_cmplt_ps(x, Set4(-87.0f));
    x = Max4(x, Set4(-87.0f));
    const I4 k = _mm_cvtps_epi32(_mm_mul_ps(x, Set4(1.44269504f)));  // round(x / ln 2)
    const F4 kf = _mm_cvtepi32_ps(k);
    const F4 r = _mm_sub_ps(_mm_sub_ps(x, _mm_mul_ps(kf, Set4(0.693145751953125f))),
                            _mm_mul_ps(kf, Set4(1.428606765330187e-6f)));
    F4 p = Set4(1.0f / 5040.0f);
    const float c[] = {1.0f / 720.0f, 1.0f / 120.0f, 1.0f / 24.0f, 1.0f / 6.0f, 0.5f, 1.0f, 1.0f};
    for (float ci : c) p = _mm_add_ps(_mm_mul_ps(p, r), Set4(ci));
    const F4 twoK = _mm_castsi128_ps(_mm_slli_epi32(_mm_add_epi32(k, _mm_set1_epi32(127)), 23));
    return _mm_andnot_ps(underflow, _mm_mul_ps(p, twoK));
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
inline simd4::F4 WaterPathFactor4(simd4::F4 cosV, float n) {
    using namespace simd4;
    const F4 sin2T =
        _mm_mul_ps(_mm_sub_ps(Set4(1.0f), _mm_mul_ps(cosV, cosV)), Set4(1.0f / (n * n)));
    const F4 cosT = _mm_sqrt_ps(Max4(_mm_sub_ps(Set4(1.0f), sin2T), Set4(1e-6f)));
    return _mm_add_ps(Set4(1.0f), _mm_div_ps(Set4(1.0f), cosT));
}

// Radiance (cd/m², one channel) of a surf-zone point before fog:
//   water:  reflected + (1 − F)·[ρ_wet E/π · T + R_rs E_d · (1 − T)],  T = e^{−K d (1 + 1/cos θ_t)}
//   sand:   ρ_sand E/π,  ρ_sand from dry to wet by wetness
//   surface = sand + (water − sand)·min(d / kSwashFilm_m, 1);  result = surface + (foam −
//   surface)·c
// reflected = F·L_sky + glint (the surface's specular part), oneMinusF the Fresnel
// transmittance, pathFactor from WaterPathFactor4, depth the column d (m), wet in [0, 1], foam
// coverage c in [0, 1], E the irradiance on the surface (Lambertian: key, fill and sky, lx),
// Ed the downwelling irradiance on a level surface (lx).
inline simd4::F4 ShoreRadiance4(const ShoreChannel& c, simd4::F4 reflected, simd4::F4 oneMinusF,
                                simd4::F4 pathFactor, simd4::F4 depth, simd4::F4 wet,
                                simd4::F4 foam, simd4::F4 E, simd4::F4 Ed) {
    using namespace simd4;
    const F4 invPi = Set4(float(1.0 / M_PI));
    const F4 lambert = _mm_mul_ps(E, invPi);
    const F4 T = ExpNonPositive4(_mm_mul_ps(Set4(-c.K_perm), _mm_mul_ps(depth, pathFactor)));
    const F4 bottom = _mm_mul_ps(Set4(c.rhoWet), lambert);
    const F4 deep = _mm_mul_ps(Set4(c.rrs), Ed);
    const F4 water = _mm_add_ps(
        reflected,
        _mm_mul_ps(oneMinusF, _mm_add_ps(deep, _mm_mul_ps(_mm_sub_ps(bottom, deep), T))));
    const F4 rhoSand = _mm_add_ps(Set4(c.rhoDry), _mm_mul_ps(Set4(c.rhoWet - c.rhoDry), wet));
    const F4 sand = _mm_mul_ps(rhoSand, lambert);
    const F4 film = _mm_min_ps(_mm_mul_ps(depth, Set4(1.0f / kSwashFilm_m)), Set4(1.0f));
    const F4 surface = _mm_add_ps(sand, _mm_mul_ps(_mm_sub_ps(water, sand), film));
    const F4 white = _mm_mul_ps(Set4(c.rhoFoam), lambert);
    return _mm_add_ps(surface, _mm_mul_ps(_mm_sub_ps(white, surface), foam));
}

}  // namespace seasense::channels
