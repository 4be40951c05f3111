// The sun glint's facet geometry for OTW sea shading, simd::kLanes at a time: the tilt β of the
// facet that reflects the key light to the eye (half vector h of the view and light directions)
// against the local normal, and a cheap test that rules out the glint before computing h.
#pragma once

#include "scene/core/simd_lanes.h"

namespace seasense::channels {

// Cox–Munk glint weight beyond which it is below float precision next to the sky term: tan² β
// at 60 slope variances (e^−60).
inline float GlintTan2Limit(float slopeVariance) { return 60.0f * slopeVariance; }

// Tilt of the glint facet at unit normal n for unit view vector v and light direction l: w = v
// + l, h = w / |w| (w·w given), cos β = max(h·n, 1e-3); cos² β, tan² β = (1 − cos² β) / cos² β
// and v·h (the Fresnel angle of the reflection).
struct GlintTilt {
    simd::VF cos2, tan2, vDotH;
};
inline GlintTilt GlintFacetTilt(simd::VF vx, simd::VF vy, simd::VF vz, simd::VF wx, simd::VF wy,
                                simd::VF wz, simd::VF ww, simd::VF nx, simd::VF ny, simd::VF nz) {
    using namespace simd;
    const VF inv = 1.0f / Sqrt(ww);
    const VF hx = wx * inv, hy = wy * inv, hz = wz * inv;
    const VF cosB = Max(Dot(hx, hy, hz, nx, ny, nz), Splat(1e-3f));
    const VF cos2 = cosB * cosB;
    return {cos2, (1.0f - cos2) / cos2, Dot(vx, vy, vz, hx, hy, hz)};
}

// GlintPossible's bound on (w·n)² / w·w: cos² β at the limit, 1 / (1 + tan2Limit), less 2 %.
inline float GlintCos2Bound(float tan2Limit) { return float(0.98 / (1.0 + double(tan2Limit))); }

// Lanes that may glint: lit (cosS = n·l > 0, sunVis > 0) with w·n > 0 and (w·n)² above
// cos2Bound · w·w. Every other lane fails the glint test cosS > 0, sunVis > 0 and
// GlintFacetTilt's tan² β < tan2Limit (for tan2Limit < 1e5 and unit n, v and l): its cos β is
// at least 1 % below the limit's (the rounding of these few products is ~1e-6 relative), or
// at the 1e-3 floor where h·n ≤ 0 (tan² β ≈ 1e6). So a group without such lanes needs no h.
inline simd::VI GlintPossible(simd::VF cosS, simd::VF sunVis, simd::VF wn, simd::VF ww,
                              float cos2Bound) {
    return (cosS > 0.0f) & (sunVis > 0.0f) & (wn > 0.0f) & (wn * wn > cos2Bound * ww);
}

}  // namespace seasense::channels
