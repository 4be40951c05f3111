// Thermal-infrared shading of the surf zone, four lanes at a time: sea water, the beach (dry and
// wet sand) where the sea lies on it, and a foam layer over both.
#pragma once

#include "channels/otw/shore_shading.h"
#include "scene/core/simd4.h"

namespace seasense::channels {

// Frame constants of the surf zone in the channel's band (W·m⁻²·sr⁻¹ for radiances).
struct SurfInfrared {
    // Foam emissivity (hemispherical; taken as independent of the view angle): sea foam is
    // nearly black in the windows, LWIR ~0.99, MWIR ~0.98 (J. W. Salisbury and D. M. D'Aria,
    // Remote Sens. Environ. 42, 83-106 (1992), the source of configs/materials.yaml's foam;
    // R. Niclòs et al., "Foam effect on the sea surface emissivity in the 8-14 um region",
    // J. Geophys. Res. 112, C12020 (2007): foam raises the sea's emissivity toward 0.99 and
    // flattens its fall with view angle). The default stands for a table without `foam`.
    float foamEmissivity = 0.99f;
    float foamB = 0.0f;  // B(T_foam): foam is sea water at the sea temperature
    // Surface-leaving radiance of level dry and wet sand: ε B(T) + (1 − ε) L_sky,hemi (sand is a
    // rough, diffuse reflector, so it reflects the cosine-weighted hemispherical sky).
    float sandDry = 0.0f, sandWet = 0.0f;
};

// The water term of SurfInfraredRadiance (below), per lane of a GCC float vector type V.
template <class V>
inline V SurfWaterRadiance(V epsWater, V seaB, V skyR) {
    const V one = V{} + 1.0f;
    return epsWater * seaB + (one - epsWater) * skyR;
}

// Surface-leaving band radiance of a sea-mesh sample:
//   water   = ε_w B(T_sea) + (1 − ε_w) L_sky,r      (ε_w at the view angle, L_sky,r the sky about
//                                                   the resolved normal)
//   foam    = ε_f B(T_foam) + (1 − ε_f) L_sky,r
//   sand    = L_dry + (L_wet − L_dry)·wet
//   surface = water + (sand − water)·(1 − min(d / kSwashFilm_m, 1))
//   result  = surface + (foam − surface)·c
// Water is opaque in the thermal infrared (absorption length ~10 µm at 10 µm, ~1 µm at 3 µm:
// Hale & Querry, Appl. Opt. 12, 555 (1973)), so the seabed never shows through shallow water:
// sand appears only where the column d is thinner than the swash film that OTW uses for the
// waterline, and the two channels put the waterline in the same place. Written so that without
// sand (film 1) and foam (c = 0) the result is the water term bit for bit.
// V: a GCC float vector type (simd::VF of the shading loops, or simd4::F4), the same operations
// per lane at any width.
template <class V>
inline V SurfInfraredRadiance(const SurfInfrared& s, V epsWater, V seaB, V skyR, V depth, V wet,
                              V foam) {
    const V one = V{} + 1.0f;
    const V water = SurfWaterRadiance(epsWater, seaB, skyR);
    const V epsF = V{} + s.foamEmissivity;
    const V white = epsF * s.foamB + (one - epsF) * skyR;
    const V sand = s.sandDry + (s.sandWet - s.sandDry) * wet;
    const V d = depth * (1.0f / kSwashFilm_m);
    const V film = d < one ? d : one;  // _mm_min_ps(d, 1)
    const V surface = water + (sand - water) * (one - film);
    return surface + (white - surface) * foam;
}

// The vertex column (m) from which the FLIR's SeaGather writes a sea sample's attributes as deep
// water (kMaxVertexAttribute, 0, 0) instead of their sums (channels/view/surface_gather.h): the
// sample's own column is then ≥ 2·kSwashFilm_m·(1 − 2^-22), so film = 1 and (sand − water)·0
// adds ±0 for the finite wet sum, and its foam sum is ±0, adding ±0 again: SurfInfraredRadiance
// is the water term for both, the same bits (water, a sum of non-negative products, is not −0).
// So a lane group of deep records alone is SurfWaterRadiance's, which ShadeSea takes for a chunk
// of them (SeaSamples::sums false).
inline constexpr float kSurfDeepColumn_m = 2.0f * kSwashFilm_m;

inline simd4::F4 SurfInfraredRadiance4(const SurfInfrared& s, simd4::F4 epsWater, simd4::F4 seaB,
                                       simd4::F4 skyR, simd4::F4 depth, simd4::F4 wet,
                                       simd4::F4 foam) {
    return SurfInfraredRadiance(s, epsWater, seaB, skyR, depth, wet, foam);
}

}  // namespace seasense::channels
