// OTW shading: Fresnel-weighted sky reflection, Cox–Munk sun glint and water-leaving radiance
// on the sea; Lambertian models lit by sun (shadowed) and sky; Koschmieder fog.
#include "channels/otw/otw_channel.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>

#include "channels/occlusion/occlusion.h"
#include "channels/otw/celestial.h"
#include "channels/otw/cloud_layer.h"
#include "channels/otw/entry_splat.h"
#include "channels/otw/lightning_overlay.h"
#include "channels/otw/quad_pixels.h"
#include "channels/otw/sea_glint.h"
#include "channels/otw/shore_shading.h"
#include "channels/otw/spray_overlay.h"
#include "channels/otw/triangle_lanes.h"
#include "channels/plume/plume_composite.h"
#include "radiometry/sky/analytic_sky.h"
#include "radiometry/surface/fresnel.h"
#include "scene/core/check.h"
#include "scene/core/simd4.h"
#include "scene/core/simd_lanes.h"

namespace seasense::channels {

namespace {

using namespace simd4;
using namespace triangle_lanes;

// Remote-sensing reflectance R_rs = L_w / E_d of clear oceanic (Case 1) water, sr⁻¹, at the
// Rec.709 primaries' dominant wavelengths (≈ 610, 550, 465 nm); order of magnitude from
// Mobley, "Light and Water" (1994), Fig. 11.x and Morel & Maritorena (2001) for chl ≈ 0.1 mg/m³.
constexpr glm::vec3 kSeaRrs{0.0003f, 0.0015f, 0.0050f};

// Diffuse attenuation coefficient K_d (m⁻¹) of coastal water at the Rec.709 primaries' dominant
// wavelengths (≈ 610, 550, 465 nm): Jerlov coastal type 1 (N. G. Jerlov, "Marine Optics",
// Elsevier 1976, the K_d spectra of the coastal water types; tabulated again by Solonenko &
// Mobley, Appl. Opt. 54(17), 5392, 2015). Coastal water is clearest in the green, unlike
// oceanic water (blue): the red is absorbed by water itself, the blue by dissolved matter.
constexpr glm::vec3 kCoastalK_perm{0.28f, 0.10f, 0.13f};

// Albedo of the sea for light reflected up onto models (Payne 1972, J. Atmos. Sci. 29: ≈ 0.06).
constexpr float kSeaAlbedo = 0.06f;

// Koschmieder: extinction coefficient for a 2 % contrast threshold, β = 3.912 / V.
double ExtinctionFromVisibility(double visibility_m) { return 3.912 / visibility_m; }

// Gaussian isotropic slope density of Cox & Munk (1954), J. Opt. Soc. Am. 44(11), with the
// mean-square slope σ² = 0.003 + 0.00512·W (W wind speed at 12.5 m, m/s); p(tan β) per unit
// slope area.
float CoxMunkSlopeVariance(double windSpeed_mps) {
    return float(0.003 + 0.00512 * std::max(windSpeed_mps, 0.0));
}

// Four- and eight-lane arithmetic for the sky and sea passes (simd4, simd). Each lane does the
// scalar code's operations in the scalar code's order, so a sample's result does not depend on
// its neighbours, the batch size, the lane count or the thread count.

// Normalizes the vectors (x, y, z) of the lanes: v · (1 / √(v·v)), as glm::normalize.
inline void NormalizeLanes(simd::VF& x, simd::VF& y, simd::VF& z) {
    using namespace simd;
    const VF inv = 1.0f / Sqrt(Dot(x, y, z, x, y, z));
    x = x * inv, y = y * inv, z = z * inv;
}

// Normalizes count directions in place (NormalizeLanes).
void Normalize(size_t count, float* x, float* y, float* z) {
    using namespace simd;
    for (size_t i = 0; i < count; i += kLanes) {
        const size_t lanes = std::min(kLanes, count - i);
        VF dx = Load(x + i, lanes, 0.0f), dy = Load(y + i, lanes, 0.0f),
           dz = Load(z + i, lanes, 1.0f);
        NormalizeLanes(dx, dy, dz);
        Store(x + i, dx, lanes);
        Store(y + i, dy, lanes);
        Store(z + i, dz, lanes);
    }
}

// Shadow-ray origin for surface point p with unit normal n: offset along the normal against
// self-shadowing by 1 mm plus 32 float ulps of the largest coordinate (4e-6 relative), which
// covers the rounding of positions rebuilt from float vertices and barycentrics. A larger
// offset would shorten shadows by offset / tan(sun elevation).
float ShadowOffset_m(const glm::vec3& p) {
    return 4e-6f * std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)}) + 1e-3f;
}
glm::vec3 ShadowRayOrigin(const glm::vec3& p, const glm::vec3& n) {
    return p + n * ShadowOffset_m(p);
}

// Step of the sun direction the sky table is built for: 0.01° in elevation and azimuth, so the
// table's sun is within 0.0071° of the true one. That changes sky radiance by < 0.05 %
// (computed in tests/radiometry/sky: analytic_sky_test, QuantizedSun…), a tenth of an 8-bit
// display step; at the five-channel run's time scale (10) the table is rebuilt every ~7 frames.
constexpr double kSkySunStep_rad = 0.01 * M_PI / 180.0;
// The moonlit sky's phase-angle and distance steps: within half a step of either its luminance
// changes by under 0.07 % (the moon's illuminance of Krisciunas & Schaefer 1991 eq. 20, as
// radiometry's MoonlitSky has it, changes by d ln I / dα ≤ 6.3 per rad, at new moon; 1/d² by
// 0.03 % for 50 km of the perigee's 356 000 km). The phase angle moves ~2.5e-6 rad per second
// of scene time, so the table is rebuilt for it every ~80 s of scene time.
constexpr double kSkyMoonPhaseStep_rad = 2e-4;
constexpr double kSkyMoonDistanceStep_m = 1.0e5;

// A distant light: unit direction toward it (ENU) and its illuminance on a surface normal to
// that direction (lx, Rec.709 RGB).
struct DirectionalLight {
    glm::vec3 dir{0.0f, 0.0f, 1.0f};
    glm::vec3 E{0.0f};
};

// Most fill lights of a frame: the dimmer of sun and moon, and lightning (OtwChannel::Render).
constexpr size_t kMaxFillLights = 2;

// Samples per shading chunk: the chunk's arrays stay in L1.
constexpr size_t kChunk = 256;

// Per-chunk intermediate arrays of the sea pass (and the sky pass's lookups).
struct SeaChunk {
    alignas(16) float rx[kChunk], ry[kChunk], rz[kChunk];  // reflected view ray, z ≥ 0
    alignas(16) float mvx[kChunk], mvy[kChunk];            // −v: toward the far airlight
    alignas(16) float range[kChunk], cosV[kChunk], cosS[kChunk];
    alignas(16) float cos2[kChunk], tan2[kChunk], sunVis[kChunk];
    bool glintLanes[kChunk / simd::kLanes];  // whether a lane group may glint (cos2, tan2, Fs)
    alignas(16) float F[kChunk], Fs[kChunk];
    alignas(16) float skyR[kChunk], skyG[kChunk], skyB[kChunk];
    alignas(16) float horR[kChunk], horG[kChunk], horB[kChunk];
    alignas(16) float outR[kChunk], outG[kChunk], outB[kChunk];
    // Surf zone: Lambertian irradiance without the key light, cos of the key light on the normal
    // (≥ 0).
    alignas(16) float ambR[kChunk], ambG[kChunk], ambB[kChunk], keyCos[kChunk];
};

// Sea radiance: Fresnel-weighted sky reflection plus water-leaving radiance, Cox–Munk glint of
// the key light (sun or moon), Koschmieder fog; the constants of one frame.
struct SeaShading {
    glm::vec3 eye, keyDir, keyE, downwelling;
    float beta, slopeVar;
    const radiometry::FresnelTable& fresnel;
    const radiometry::AnalyticSky& sky;
    // Surf zone and foam (channels/otw/shore_shading.h): sky irradiance on a level surface, the
    // fill lights, the optics of each colour channel.
    glm::vec3 skyE;
    const std::vector<DirectionalLight>* fill;
    ShoreChannel shore[3];

    // Shades count ≤ kChunk samples at positions p (m, world) with normals n (any length), sun
    // visibility ch.sunVis, water column depth (m), sand wetness and foam coverage; radiance
    // (cd/m²) to ch.outR/G/B.
    void Shade(size_t count, const float* px, const float* py, const float* pz, const float* nx,
               const float* ny, const float* nz, const float* depth, const float* wet,
               const float* foam, SeaChunk& ch) const {
        // On a local copy of the constants, which the loops' stores to the chunk's float arrays
        // cannot change: their lane broadcasts are then made once, not per lane group.
        const SeaShading local = *this;
        local.ShadeChunk(count, px, py, pz, nx, ny, nz, depth, wet, foam, ch);
    }

  private:
    __attribute__((always_inline)) void ShadeChunk(size_t count, const float* px, const float* py,
                                                   const float* pz, const float* nx,
                                                   const float* ny, const float* nz,
                                                   const float* depth, const float* wet,
                                                   const float* foam, SeaChunk& ch) const {
        // Geometry: view vector v, reflected ray r, glint half vector h; simd::kLanes entries at
        // a time (the chunk's arrays hold kChunk, a multiple of kLanes: lanes past count are
        // computed from padding, then dropped).
        using namespace simd;
        static_assert(kChunk % kLanes == 0);
        const float tan2Limit = GlintTan2Limit(slopeVar);
        CHECK(tan2Limit < 1e5f);  // GlintPossible's bound
        const VF glintLimit = Splat(tan2Limit);
        const float glintCos2 = GlintCos2Bound(tan2Limit);
        // The key and fill lights' lane broadcasts, made once here: in the loop GCC made them
        // again for every lane group (an addition and a broadcast per component).
        const VF keyX = Splat(keyDir.x), keyY = Splat(keyDir.y), keyZ = Splat(keyDir.z);
        LightLanes fills[kMaxFillLights];
        const size_t fillCount = fill->size();
        CHECK(fillCount <= kMaxFillLights);
        for (size_t l = 0; l < fillCount; ++l) {
            const DirectionalLight& d = (*fill)[l];
            fills[l] = MakeLightLanes(d.dir.x, d.dir.y, d.dir.z, d.E.r, d.E.g, d.E.b);
        }
        for (size_t i = 0; i < count; i += kLanes) {
            const size_t lanes = std::min(kLanes, count - i);
            VF Nx = Load(nx + i, lanes, 0.0f), Ny = Load(ny + i, lanes, 0.0f),
               Nz = Load(nz + i, lanes, 1.0f);
            NormalizeLanes(Nx, Ny, Nz);
            const VF tx = eye.x - Load(px + i, lanes, 0.0f);
            const VF ty = eye.y - Load(py + i, lanes, 0.0f);
            const VF tz = eye.z - Load(pz + i, lanes, 0.0f);
            const VF range = Sqrt(Dot(tx, ty, tz, tx, ty, tz));
            // One division for the three components (differs from t / range by rounding).
            const VF invRange = 1.0f / range;
            const VF vx = tx * invRange, vy = ty * invRange, vz = tz * invRange;
            const VF ndv = Dot(Nx, Ny, Nz, vx, vy, vz);
            const VF twoNdv = 2.0f * ndv;
            const VF rz = twoNdv * Nz - vz;
            // A ray reflected into the sea meets the next wave's sky.
            Store(ch.rz + i, Select(rz < 0.0f, 0.0f - rz, rz));
            Store(ch.rx + i, twoNdv * Nx - vx);
            Store(ch.ry + i, twoNdv * Ny - vy);
            Store(ch.mvx + i, 0.0f - vx);
            Store(ch.mvy + i, 0.0f - vy);
            Store(ch.range + i, range);
            const VF cosV = Max(ndv, Splat(1e-3f));
            Store(ch.cosV + i, cosV);
            Store(ch.F + i, fresnel(cosV));
            const VF cosS = Dot(Nx, Ny, Nz, keyX, keyY, keyZ);
            Store(ch.cosS + i, cosS);
            // The glint facet's tilt only where a lane of the group may glint (GlintPossible):
            // a group without one skips a square root, two divisions and a Fresnel look-up, as
            // the second loop skips its glint (glintLanes).
            const VF wx = vx + keyDir.x, wy = vy + keyDir.y, wz = vz + keyDir.z;
            const VF ww = Dot(wx, wy, wz, wx, wy, wz);
            const bool mayGlint = Any(GlintPossible(cosS, Load(ch.sunVis + i),
                                                    Dot(wx, wy, wz, Nx, Ny, Nz), ww, glintCos2));
            ch.glintLanes[i / kLanes] = mayGlint;
            if (mayGlint) {
                const GlintTilt tilt = GlintFacetTilt(vx, vy, vz, wx, wy, wz, ww, Nx, Ny, Nz);
                Store(ch.cos2 + i, tilt.cos2);
                Store(ch.tan2 + i, tilt.tan2);
                Store(ch.Fs + i, fresnel(tilt.vDotH));
            }
            // Lambertian irradiance of sand and foam: sky as on a plane tilted to the normal,
            // (1 + n_z)/2 of the level-surface sky irradiance, and the fill lights.
            const VF skyView = 0.5f * (1.0f + Nz);
            VF aR = skyE.r * skyView, aG = skyE.g * skyView, aB = skyE.b * skyView;
            AddLambertianLights(fills, fillCount, Nx, Ny, Nz, aR, aG, aB);
            Store(ch.ambR + i, aR);
            Store(ch.ambG + i, aG);
            Store(ch.ambB + i, aB);
            Store(ch.keyCos + i, Max(cosS, Splat(0.0f)));
        }
        sky.LookUp(count, ch.rx, ch.ry, ch.rz, ch.skyR, ch.skyG, ch.skyB);
        sky.HorizonLookUp(count, ch.mvx, ch.mvy, ch.horR, ch.horG, ch.horB);

        // Reciprocals of the frame's constants: multiplications in the loop, not divisions.
        const float minusInvSlopeVar = -1.0f / slopeVar;
        const float invGlintNorm = 1.0f / (float(M_PI) * slopeVar);
        for (size_t i = 0; i < count; i += kLanes) {
            const VF F = Load(ch.F + i), oneMinusF = 1.0f - F;
            const VF cosV = Load(ch.cosV + i), sunVis = Load(ch.sunVis + i);
            // Cox–Munk glint: L = E_sun ρ(ω) p(β) / (4 cos θ_v cos⁴ β) (Cox & Munk 1954), β
            // the tilt of the reflecting facet from the local normal. Beyond e^-60 the glint
            // is below float precision next to the sky term.
            VI glint{};
            bool anyGlint = false;
            if (ch.glintLanes[i / kLanes]) {
                const VF tan2 = Load(ch.tan2 + i);
                glint = (Load(ch.cosS + i) > 0.0f) & (sunVis > 0.0f) & (tan2 < glintLimit);
                anyGlint = Any(glint);
            }
            // Lanes without glint drop g (Select below): skipped when no lane has it.
            VF g = Splat(0.0f);
            if (anyGlint) {
                const VF tan2 = Load(ch.tan2 + i), cos2 = Load(ch.cos2 + i);
                const VF p = ExpNonPositive(tan2 * minusInvSlopeVar) * invGlintNorm;
                g = (Load(ch.Fs + i) * p) / (((4.0f * cosV) * cos2) * cos2);
            }
            // Koschmieder: the horizon sky is the airlight a long path converges to.
            const VF t = ExpNonPositive(-beta * Load(ch.range + i));
            const VF oneMinusT = 1.0f - t;
            const size_t lanes = std::min(kLanes, count - i);
            const VF d = Load(depth + i, lanes, kDeepColumn_m);
            const VF w = Load(wet + i, lanes, 0.0f), c = Load(foam + i, lanes, 0.0f);
            // The water path factor 1 + 1/cos θ_t, from cos θ_v as stored above; over deep
            // water (most of the sea) its lower bound gives the same radiance.
            const VF path = BottomUnseenInEveryLane(shore, d)
                                ? Splat(kMinWaterPathFactor)
                                : WaterPathFactor(cosV, float(radiometry::kSeaWaterIndexVisible));
            const VF keyLit = Load(ch.keyCos + i) * sunVis;
            // Inlined, so the three channels share their common terms (the swash film, the
            // path through the column, the lane tests).
            const auto channel = [&](const ShoreChannel& sh, const float* skyC, const float* horC,
                                     const float* ambC, float dw, float sunEC, float* outC)
                __attribute__((always_inline)) {
                VF R = F * Load(skyC + i);
                if (anyGlint) R = Select(glint, R + (sunEC * g) * sunVis, R);
                const VF E = Load(ambC + i) + sunEC * keyLit;
                VF L = ShoreRadiance(sh, R, oneMinusF, path, d, w, c, E, Splat(dw));
                L = L * t + Load(horC + i) * oneMinusT;
                Store(outC + i, L);
            };
            channel(shore[0], ch.skyR, ch.horR, ch.ambR, downwelling.r, keyE.r, ch.outR);
            channel(shore[1], ch.skyG, ch.horG, ch.ambG, downwelling.g, keyE.g, ch.outG);
            channel(shore[2], ch.skyB, ch.horB, ch.ambB, downwelling.b, keyE.b, ch.outB);
        }
    }
};

// Shading entries: an entry is one sample, or — tagged with kPixelEntry — all N×N samples of a
// pixel (k is then the pixel's top-left sample), shaded once at the pixel's centre.
//
// Why pixel-rate shading is enough where a pixel sees one smooth surface: the detector
// integrates radiance over the pixel's footprint (sensors/detector), and for radiance L that
// is smooth across the pixel, shading at the centre (one-point midpoint rule) and the mean of
// the N×N samples both estimate that integral to second order; they differ by about
// (h²/24)(1 − 1/N²)·∇²L for pixel size h — a fraction of a percent of the sea's and sky's
// radiance, whose variation is set by the sea mesh's normals (vertices 6 pixels apart) and a
// sky table with texels a degree apart (measured against per-sample shading on the
// five-channel run: README, Performance). Where the signal is not smooth inside a pixel —
// edges between sky, sea and models, the sun's disc, depth jumps between waves — every
// sample is shaded as before, and shadow edges keep per-sample sun visibility (the pixel
// gets the lit fraction of its samples, which is exact because the sea's radiance is linear
// in sun visibility). The tag kPixelEntry and the writing of entries' radiance to their
// samples (SplatChunk): channels/otw/entry_splat.h.

// Tag of shadow-ray owners that are sea entries (indices into the sea arrays).
constexpr uint32_t kSeaOwner = 1u << 31;

// Largest supersampling factor (scene/scenario accepts 1 … 8).
constexpr int kMaxSupersampling = 8;

// A pixel whose samples all see the sea is shaded at pixel rate only where the sea's radiance
// is close to linear across it. Its nonlinearity is in the cosine c = n·v of the view angle
// to the interpolated normal (Fresnel reflectance, the 1/(4c) of the glint, the elevation of
// the reflected ray) and, for fog, in range. Shading the mean differs from the mean of the
// shaded samples by about ½|L''|·Var(c) ≤ ⅛|L''|·Δc² for a spread Δc of c; requiring Δc ≤
// 0.005 and Δc ≤ 0.1·c keeps that below 0.2 % even for the 1/c glint factor near grazing
// incidence, and excludes wave crests hiding farther troughs (c jumps there) and back-facing
// slopes (c ≤ 0). Depth within 10 % bounds fog's nonlinearity, exp(−βr) over a range span
// of 0.1·r, to (0.1·βr)²/8 ≈ 0.1 % where fog is strong (βr ≈ 1). Measured on the
// five-channel run against per-sample shading: README, Performance.
constexpr float kMaxSeaPixelCosSpread = 0.005f;
constexpr float kMaxSeaPixelRelativeCosSpread = 0.1f;
constexpr float kMaxSeaPixelDepthRatio = 1.1f;

// Vertex positions and normals of a triangle as SSE (x, y, z, 0), gathered once for the many
// samples that see it. 256 bytes (209 used): a cache slot's address is then the slot index
// shifted, where 224 took a multiplication of three instructions per look-up.
struct alignas(256) CachedTriangle {
    uint32_t prim = kNoPrimitive;  // kNoPrimitive: empty
    int mesh = 0;
    // Vertex v's position then its normal, adjacent: both are interpolated at once on eight
    // lanes (PN), with the same operations per lane as on four.
    F4 pn[3][2] = {};
    F4 a[3] = {};  // sea vertex attributes (ViewGeometry::OceanAttributes)
    // The normals' components x, y, z across the vertices, (c of n0, n1, n2, 0): their dot
    // products with one vector at once.
    F4 nT[3] = {};
    bool shadowable = false;  // a shadow ray from some point of it may meet a caster

    const F4& P(int v) const { return pn[v][0]; }
    const F4& N(int v) const { return pn[v][1]; }
    // Position in lanes 0–3, normal in lanes 4–7.
    F8 PN(int v) const {
        F8 r;
        std::memcpy(&r, pn[v], sizeof r);
        return r;
    }
};
static_assert(sizeof(CachedTriangle) == 256);

// Per-thread scratch of the shading pass. The pixels of a row block are sorted into sky, sea
// and model entries so that each kind is shaded in a tight loop: sky and sea four lanes at a
// time in structure-of-arrays chunks (the bulk of the frame), the few model samples one by
// one. The sky and sea lists only grow (their used length is counted separately), so that a
// block never zero-fills them.
struct BlockScratch {
    std::vector<uint32_t> skyK, seaK, modelK;                     // see kPixelEntry
    std::vector<float> skyX, skyY, skyZ;                          // view directions of sky entries
    std::vector<float> seaPx, seaPy, seaPz, seaNx, seaNy, seaNz;  // normals (unit once shaded)
    std::vector<float> seaDepth, seaWet, seaFoam;                 // OceanAttributes interpolated
    std::vector<float> seaLit;  // lit fraction of a sea entry's samples (where seaUnlit > 0)
    // Samples of a sea entry found in shadow (not a character type, whose stores may alias any
    // object: the classifier would reload the lists' pointers after each).
    std::vector<uint16_t> seaUnlit;
    std::vector<glm::vec3> modelPosition, modelNormal;
    std::vector<int> modelMesh;
    std::vector<uint8_t> modelLit;  // sun visibility of model samples
    std::vector<glm::vec3> origins;
    // originOwner: model entry index, or kSeaOwner | sea entry index.
    std::vector<uint32_t> originOwner;
    std::vector<uint8_t> vis;
    size_t skyCount = 0, seaCount = 0;
    SeaChunk chunk{};  // zeroed: lanes past a chunk's end are computed, then dropped
    // Triangles met, direct-mapped by primitive id: neighbouring samples mostly see the same
    // few triangles (a strip's ids are consecutive), and the next pixel rows the same ones
    // again (sea vertices are ~6 pixels apart), so each is gathered about once per block.
    // Entries of another primitive are gathered anew. The cache is emptied when the thread's
    // first block of a frame starts (trianglesFrame), so that a look-up compares no frame tag.
    // The gathered values depend only on the frame and the primitive, so whatever the cache
    // holds the shading is the same. 2048 entries (512 kB) keep more of the previous block's
    // triangles than 1024: otw-center at frames 120-121 gathered 32.3 k triangles, not 41.8 k
    // (4096 entries: 30.1 k). A power of two (the slot is prim & (size − 1));
    // OtwChannel::SetTriangleCacheEntries sets another for tests.
    static constexpr uint32_t kTriangleCacheSize = 2048;
    std::vector<CachedTriangle> triangles = std::vector<CachedTriangle>(kTriangleCacheSize);
    uint64_t trianglesFrame = 0;  // the frame whose triangles the cache holds (FrameGeometry)
    // A pixel's triangles that could not take their slot in triangles (PixelGather).
    std::vector<CachedTriangle> pixelTriangles =
        std::vector<CachedTriangle>(kMaxSupersampling * kMaxSupersampling);

    // Empties the lists and makes the sky and sea lists hold at least n entries.
    void Reset(size_t n) {
        if (skyK.size() < n) {
            for (std::vector<float>* v : {&skyX, &skyY, &skyZ, &seaPx, &seaPy, &seaPz, &seaNx,
                                          &seaNy, &seaNz, &seaLit, &seaDepth, &seaWet, &seaFoam})
                v->resize(n);
            skyK.resize(n), seaK.resize(n), seaUnlit.resize(n);
        }
        skyCount = seaCount = 0;
        modelK.clear(), modelPosition.clear(), modelNormal.clear(), modelMesh.clear();
        modelLit.clear();
        origins.clear(), originOwner.clear();
    }
};

F4 Load3(const glm::vec3& v) { return _mm_setr_ps(v.x, v.y, v.z, 0.0f); }
glm::vec3 Store3(F4 v) {
    alignas(16) float f[4];
    _mm_store_ps(f, v);
    return {f[0], f[1], f[2]};
}

// a·b of (x, y, z, ·) vectors in glm::dot's order, (x + y) + z, in lane 0 (Dot3Lane) or as a
// float.
F4 Dot3Lane(F4 a, F4 b) {
    const F4 m = _mm_mul_ps(a, b);
    const F4 xy = _mm_add_ss(m, _mm_shuffle_ps(m, m, _MM_SHUFFLE(1, 1, 1, 1)));
    return _mm_add_ss(xy, _mm_shuffle_ps(m, m, _MM_SHUFFLE(2, 2, 2, 2)));
}
float Dot3(F4 a, F4 b) { return _mm_cvtss_f32(Dot3Lane(a, b)); }

// b0·a0 + b1·a1 + b2·a2 per component, in glm's order ((b0 a0 + b1 a1) + b2 a2).
F4 Interpolate3(F4 b0, F4 b1, F4 b2, F4 a0, F4 a1, F4 a2) {
    return _mm_add_ps(_mm_add_ps(_mm_mul_ps(b0, a0), _mm_mul_ps(b1, a1)), _mm_mul_ps(b2, a2));
}

// Mesh m's primitives are [primitiveBase[m], primitiveBase[m + 1]); mesh 0 is the sea.
struct MeshRef {
    const glm::vec3* P;
    const glm::vec3* N;
    const uint32_t* I;
    const glm::vec4* A = nullptr;  // per-vertex attributes (the sea only)
};

// One frame's visibility buffer, meshes and view rays.
struct FrameGeometry {
    const VisibilityBuffer& vis;
    std::vector<MeshRef> meshes;
    uint32_t firstModelPrimitive;
    int width, sampleWidth, sampleHeight, n;  // pixels across, samples across and down, N
    // View rays: direction = normalize(RowBase(ndcY) + x · colStep), x in samples from the
    // left edge (camera axes scaled by the pinhole geometry), so sky needs no trigonometry.
    glm::dmat3 R;
    glm::dvec3 forward;
    double tanH, tanV;
    glm::vec3 colStep;
    uint64_t frame = 0;  // OtwChannel's frame count, from 1 (BlockScratch::trianglesFrame)

    glm::vec3 RowBase(double ndcY) const {
        return glm::vec3(forward + R * glm::dvec3(-tanH, 0.0, ndcY * tanV));
    }
    // Loads the vertices of primitive prim into tri.
    void Fetch(uint32_t prim, CachedTriangle& tri) const {
        int mesh = 0;
        if (prim >= firstModelPrimitive) {
            mesh = 1;
            while (mesh + 1 < int(vis.primitiveBase.size()) &&
                   prim >= vis.primitiveBase[size_t(mesh) + 1])
                ++mesh;
        }
        const MeshRef& m = meshes[size_t(mesh)];
        const uint32_t t = prim - vis.primitiveBase[size_t(mesh)];
        const uint32_t i0 = m.I[3 * t], i1 = m.I[3 * t + 1], i2 = m.I[3 * t + 2];
        tri.prim = prim, tri.mesh = mesh;
        const uint32_t i[3] = {i0, i1, i2};
        for (int v = 0; v < 3; ++v) {
            tri.pn[v][0] = Load3(m.P[i[v]]), tri.pn[v][1] = Load3(m.N[i[v]]);
            if (m.A) tri.a[v] = _mm_loadu_ps(&m.A[i[v]].x);
        }
        F4 x = tri.N(0), y = tri.N(1), z = tri.N(2), unused = _mm_setzero_ps();
        _MM_TRANSPOSE4_PS(x, y, z, unused);
        tri.nT[0] = x, tri.nT[1] = y, tri.nT[2] = z;
    }
};

// Surface position and (unnormalized) interpolated normal at barycentrics (1 − b1 − b2, b1, b2)
// of triangle tri.
void Interpolate(const CachedTriangle& tri, float b1, float b2, F4& p, F4& nSum) {
    const F8 pn =
        Interpolate8(Set8(1.0f - b1 - b2), Set8(b1), Set8(b2), tri.PN(0), tri.PN(1), tri.PN(2));
    p = Low(pn), nSum = High(pn);
}

// Vertex attributes at barycentrics (1 − b1 − b2, b1, b2) of triangle tri.
F4 InterpolateAttributes(const CachedTriangle& tri, float b1, float b2) {
    // The weights as Interpolate broadcasts them (one broadcast each where both are made).
    return Interpolate3(Low(Set8(1.0f - b1 - b2)), Low(Set8(b1)), Low(Set8(b2)), tri.a[0], tri.a[1],
                        tri.a[2]);
}

// One frame's lighting and shading constants.
struct FrameShading {
    // The sun (its disc), the key light (the brighter of sun and moon: shadowed, glints), the
    // fill lights (the dimmer body and lightning flashes: unshadowed) and the sky.
    glm::vec3 eye, sunDir, sunL, keyDir, keyE, skyE, downwelling;
    std::vector<DirectionalLight> fill;
    F4 eye4;  // eye as (x, y, z, 0)
    float cosSunRadius;
    // A pixel whose centre ray is farther than the sun's radius plus the pixel's half diagonal
    // from the sun has no sample in the disc: cos of that angle (with a factor 2 margin).
    float cosNearSun;
    float beta;
    bool shadows;
    const radiometry::AnalyticSky& sky;
    const OcclusionScene& occlusion;
    // The casters' boxes grown (ViewGeometry::CasterBoxes), for whole triangles (Gather): a
    // sample on a triangle whose rays miss them all cannot be shadowed.
    RayBoxesTest casters;
    // occlusion.MayOcclude along keyDir (to 1e30 m), prepared once: a sample's shadow ray is
    // traced only where this passes. Each caster's box in it lies inside that caster's box in
    // casters (ViewGeometry::UpdateCasterBounds), so passing it implies casters.MayHit: that is
    // not tested again.
    OccluderBoundsTest occluders;
    SeaShading sea;
    const std::vector<glm::dvec3>& reflectance;  // per entity

    // Whether unnormalized direction d is within acos(cosNearSun) of the sun.
    bool NearSun(const glm::vec3& d) const {
        const float c = glm::dot(d, sunDir);
        return c > 0.0f && c * c >= cosNearSun * cosNearSun * glm::dot(d, d);
    }
};

// Pass 1 of a block of pixel rows [py0, py1): sorts its pixels into sky, sea and model
// entries (pixel-rate where the pixel is uniform, else per sample) with surface positions
// and normals, and collects the shadow rays that need tracing. kN is the supersampling factor
// when known at compile time (the default 2, whose per-pixel loops then unroll; the same
// operations in the same order), 0 for any other, read from the frame.
template <int kN>
class BlockClassifier {
  public:
    BlockClassifier(const FrameGeometry& g, const FrameShading& f, int py0, BlockScratch& sc)
        : g_(g),
          f_(f),
          sc_(sc),
          y0_(py0 * g.n),
          primitive_(g.vis.primitive.data()),
          depth_(g.vis.depth.data()),
          b1_(g.vis.b1.data()),
          b2_(g.vis.b2.data()),
          triangleMask_(uint32_t(sc.triangles.size()) - 1) {
        CHECK(kN == 0 || kN == g.n);
        CHECK(!sc.triangles.empty() && (sc.triangles.size() & triangleMask_) == 0);
        CHECK(sc.trianglesFrame == g.frame);
    }

    // Classifies the pixels [pxBegin, pxEnd) of pixel row py.
    void Pixels(int py, int pxBegin, int pxEnd) {
        const int n = N(), sw = g_.sampleWidth;
        for (int j = 0; j < n; ++j) {
            const int y = py * n + j;
            sampleRow_[j] = g_.RowBase(1.0 - 2.0 * (y + 0.5) / g_.sampleHeight);
            rowIndex_[j] = g_.vis.Index(0, y);
        }
        const glm::vec3 pixelRow = g_.RowBase(1.0 - 2.0 * (py * n + 0.5 * n) / g_.sampleHeight);
        const uint32_t kRow = uint32_t(size_t(py * n - y0_) * size_t(sw));
        int px = pxBegin;
        if constexpr (kN == 2) {
            // Whole row segments of kLanes pixels, their decisions on lanes (QuadPixels); the
            // rest pixel by pixel below.
            for (; px + int(simd::kLanes) <= pxEnd; px += int(simd::kLanes))
                QuadGroup(px, kRow, pixelRow);
        }
        const uint32_t* prim = primitive_;
        for (; px < pxEnd; ++px) {
            const int x0 = px * n;
            const uint32_t prim0 = prim[rowIndex_[0] + size_t(x0)];
            bool same = true, allSea = true;
            if constexpr (kN == 2) {
                // The four ids as two 64-bit pairs.
                uint64_t row0, row1;
                std::memcpy(&row0, prim + rowIndex_[0] + size_t(x0), sizeof row0);
                std::memcpy(&row1, prim + rowIndex_[1] + size_t(x0), sizeof row1);
                same = row0 == row1 && uint32_t(row0 >> 32) == prim0;
                const uint32_t sea = g_.firstModelPrimitive;  // kNoPrimitive is not sea
                allSea = prim0 < sea && uint32_t(row0 >> 32) < sea && uint32_t(row1) < sea &&
                         uint32_t(row1 >> 32) < sea;
            } else {
                for (int j = 0; j < n; ++j) {
                    const uint32_t* row = prim + rowIndex_[j] + size_t(x0);
                    for (int i = 0; i < n; ++i) {
                        same &= row[i] == prim0;
                        allSea &= row[i] < g_.firstModelPrimitive;  // kNoPrimitive is not sea
                    }
                }
            }
            const uint32_t k = kRow + uint32_t(x0);
            if (same && prim0 == kNoPrimitive) {
                const glm::vec3 d = pixelRow + (float(x0) + 0.5f * float(n)) * g_.colStep;
                if (!f_.NearSun(d)) {
                    AddSky(k | kPixelEntry, d);
                    continue;
                }
            } else if (allSea && (same ? SeaTrianglePixel(x0, k, prim0) : SeaPixel(x0, k))) {
                continue;
            }
            Samples(x0, k);
        }
    }

  private:
    int N() const { return kN > 0 ? kN : g_.n; }

    // Every sample of the pixel with top-left sample x0 (entry k) on its own.
    void Samples(int x0, uint32_t k) {
        for (int j = 0; j < N(); ++j)
            for (int i = 0; i < N(); ++i) Sample(x0 + i, j, k + uint32_t(j * g_.sampleWidth + i));
    }

    // Pixels [px, px + kLanes) of the pixel row (N = 2) as Pixels classifies them one by one,
    // their decisions made on lanes; a segment of sky pixels away from the sun is added at once.
    void QuadGroup(int px, uint32_t kRow, const glm::vec3& pixelRow) {
        using namespace simd;
        const size_t i0 = rowIndex_[0] + size_t(2 * px), i1 = rowIndex_[1] + size_t(2 * px);
        const QuadPixels q = ClassifyQuadPixels(primitive_ + i0, primitive_ + i1, depth_ + i0,
                                                depth_ + i1, b1_ + i0, b1_ + i1, b2_ + i0, b2_ + i1,
                                                g_.firstModelPrimitive, kMaxSeaPixelDepthRatio);
        if (All(q.sky)) {
            // The pixels' centre rays and NearSun as the scalar code computes them, lane by lane
            // (glm::dot's (x + y) + z).
            VI xs;
            for (size_t l = 0; l < kLanes; ++l) xs[l] = int32_t(2 * l);
            xs += 2 * px;                                         // the pixels' first samples
            const VF u = __builtin_convertvector(xs, VF) + 1.0f;  // float(x0) + 0.5 · N
            const VF dx = pixelRow.x + u * g_.colStep.x, dy = pixelRow.y + u * g_.colStep.y,
                     dz = pixelRow.z + u * g_.colStep.z;
            const VF c =
                Dot(dx, dy, dz, Splat(f_.sunDir.x), Splat(f_.sunDir.y), Splat(f_.sunDir.z));
            const VI near = (c > 0.0f) & (c * c >= (f_.cosNearSun * f_.cosNearSun) *
                                                       Dot(dx, dy, dz, dx, dy, dz));
            if (!Any(near)) {
                const size_t e = sc_.skyCount;
                sc_.skyCount += kLanes;
                const VI keys = (xs + int32_t(kRow)) | int32_t(kPixelEntry);
                std::memcpy(&sc_.skyK[e], &keys, sizeof keys);
                Store(&sc_.skyX[e], dx), Store(&sc_.skyY[e], dy), Store(&sc_.skyZ[e], dz);
                return;
            }
        }
        // Sky and sea pixels are disjoint (kNoPrimitive is not sea): the sea, most of the
        // pixels here, is tested first.
        const VI sea = q.allSea & q.depthsClose;
        const unsigned sky = LaneBits(q.sky), seaSame = LaneBits(sea & q.same),
                       seaMixed = LaneBits(sea & ~q.same);
        alignas(32) float b1Sum[kLanes], b2Sum[kLanes];
        Store(b1Sum, q.b1Sum), Store(b2Sum, q.b2Sum);
        for (size_t l = 0; l < kLanes; ++l) {
            const unsigned bit = 1u << l;
            const int x0 = 2 * px + int(2 * l);
            const uint32_t k = kRow + uint32_t(x0);
            if (seaSame & bit) {
                SeaTriangleClosePixel(x0, k, primitive_[i0 + 2 * l], b1Sum[l], b2Sum[l]);
                continue;
            }
            if (seaMixed & bit) {
                SeaClosePixel(x0, k);
                continue;
            }
            if (sky & bit) {
                const glm::vec3 d = pixelRow + (float(x0) + 0.5f * float(kN)) * g_.colStep;
                if (!f_.NearSun(d)) {
                    AddSky(k | kPixelEntry, d);
                    continue;
                }
            }
            Samples(x0, k);
        }
    }

    // The cached triangle prim. The hit, most calls, is inlined; the gathering is not.
    __attribute__((always_inline)) const CachedTriangle& Triangle(uint32_t prim) {
        CachedTriangle& tri = sc_.triangles[prim & triangleMask_];
        if (tri.prim == prim) [[likely]]
            return tri;
        return Gather(prim, tri);
    }
    __attribute__((noinline)) const CachedTriangle& Gather(uint32_t prim, CachedTriangle& tri) {
        g_.Fetch(prim, tri);
        tri.shadowable = false;
        if (f_.shadows) {
            // Every shadow-ray origin on the triangle lies in its bounding box grown by the
            // largest ShadowRayOrigin offset (with as much again for rounding): a ray from the
            // box's centre that misses the caster box grown by that much cannot meet it from
            // any of them (Minkowski sum). This settles most triangles at once.
            const F4 lo = _mm_min_ps(_mm_min_ps(tri.P(0), tri.P(1)), tri.P(2));
            const F4 hi = _mm_max_ps(_mm_max_ps(tri.P(0), tri.P(1)), tri.P(2));
            const glm::vec3 l = Store3(lo), h = Store3(hi);
            const float far = std::max({std::abs(l.x), std::abs(l.y), std::abs(l.z), std::abs(h.x),
                                        std::abs(h.y), std::abs(h.z)});
            tri.shadowable =
                f_.casters.MayHit(0.5f * (l + h), 0.5f * (h - l) + (8e-6f * far + 2e-3f));
        }
        return tri;
    }

    // Gather(prim, tri) for sample s (j·N + i) of the pixel with top-left sample x0; but when
    // tri, prim's cache slot, holds the triangle of an earlier sample of the pixel (two of its
    // triangles with ids a multiple of the cache's size apart), prim is gathered into
    // sc_.pixelTriangles[s] instead, so that the entry stays as that sample read it.
    __attribute__((noinline)) const CachedTriangle& PixelGather(uint32_t prim, CachedTriangle& tri,
                                                                int x0, int s) {
        const int n = N();
        for (int t = 0; t < s; ++t)
            if (tri.prim == primitive_[rowIndex_[t / n] + size_t(x0 + t % n)])
                return Gather(prim, sc_.pixelTriangles[size_t(s)]);
        return Gather(prim, tri);
    }

    // The values of a pixel's samples (N = 2) from its two rows, sample (j, i) in lane 2j + i.
    static F4 PixelSamples(const float* row0, const float* row1) {
        return _mm_loadh_pi(_mm_loadl_pi(_mm_setzero_ps(), reinterpret_cast<const __m64*>(row0)),
                            reinterpret_cast<const __m64*>(row1));
    }

    // Whether depths of the pixel's samples are within kMaxSeaPixelDepthRatio.
    bool DepthsClose(int x0) const {
        float dMin = std::numeric_limits<float>::infinity(), dMax = 0.0f;
        for (int j = 0; j < N(); ++j) {
            const float* depth = depth_ + rowIndex_[j] + size_t(x0);
            for (int i = 0; i < N(); ++i)
                dMin = std::min(dMin, depth[i]), dMax = std::max(dMax, depth[i]);
        }
        return dMax <= kMaxSeaPixelDepthRatio * dMin;
    }

    // Whether a spread cMax − cMin of n·(eye − p) over a pixel's samples, range = |eye − p|,
    // allows pixel-rate shading (kMaxSeaPixelCosSpread).
    static bool CosSpreadSmall(float cMin, float cMax, float range) {
        const float spread = cMax - cMin;
        return spread <= kMaxSeaPixelCosSpread * range &&
               spread <= kMaxSeaPixelRelativeCosSpread * cMin;
    }

    void AddSky(uint32_t k, const glm::vec3& d) {
        const size_t e = sc_.skyCount++;
        sc_.skyK[e] = k;
        sc_.skyX[e] = d.x, sc_.skyY[e] = d.y, sc_.skyZ[e] = d.z;
    }

    // The pixel with top-left sample x0 (entry k), all of whose samples see sea triangle prim:
    // shaded at pixel rate (at the mean barycentrics) unless c = n·v varies too much across it
    // (then its samples are added one by one, as Sample adds them) or depth does (then returns
    // false, nothing added). On one triangle c is linear in the barycentrics.
    __attribute__((always_inline)) bool SeaTrianglePixel(int x0, uint32_t k, uint32_t prim) {
        if (!DepthsClose(x0)) return false;
        float b1Sum = 0.0f, b2Sum = 0.0f;
        for (int j = 0; j < N(); ++j) {
            const size_t index = rowIndex_[j] + size_t(x0);
            for (int i = 0; i < N(); ++i) {
                b1Sum += b1_[index + size_t(i)];
                b2Sum += b2_[index + size_t(i)];
            }
        }
        SeaTriangleClosePixel(x0, k, prim, b1Sum, b2Sum);
        return true;
    }

    // SeaTrianglePixel once the depths are close, with the sums of the samples' barycentrics.
    __attribute__((always_inline)) void SeaTriangleClosePixel(int x0, uint32_t k, uint32_t prim,
                                                              float b1Sum, float b2Sum) {
        const int n = N(), count = n * n;
        const CachedTriangle& tri = Triangle(prim);
        // The samples' barycentrics are read in place, row by row (a local copy of them cost a
        // memmove call per row).
        const float *b1[kMaxSupersampling], *b2[kMaxSupersampling];
        for (int j = 0; j < n; ++j) {
            const size_t index = rowIndex_[j] + size_t(x0);
            b1[j] = b1_ + index;
            b2[j] = b2_ + index;
        }
        // The mean (a power-of-two scale for N = 1, 2, 4: exact).
        const float inv = 1.0f / float(count);
        F4 p, nSum;
        Interpolate(tri, b1Sum * inv, b2Sum * inv, p, nSum);
        const F4 toEye = _mm_sub_ps(f_.eye4, p);
        // The vertex normals' n·toEye in lanes 0, 1, 2 (Dot3's operations), c0 and the
        // differences d1, d2 from it.
        const F4 dots = Dot4(tri.nT[0], tri.nT[1], tri.nT[2],
                             _mm_shuffle_ps(toEye, toEye, _MM_SHUFFLE(0, 0, 0, 0)),
                             _mm_shuffle_ps(toEye, toEye, _MM_SHUFFLE(1, 1, 1, 1)),
                             _mm_shuffle_ps(toEye, toEye, _MM_SHUFFLE(2, 2, 2, 2)));
        const F4 c0s = _mm_shuffle_ps(dots, dots, _MM_SHUFFLE(0, 0, 0, 0));
        const F4 ds = _mm_sub_ps(dots, c0s);
        const F4 d1s = _mm_shuffle_ps(ds, ds, _MM_SHUFFLE(1, 1, 1, 1)),
                 d2s = _mm_shuffle_ps(ds, ds, _MM_SHUFFLE(2, 2, 2, 2));
        const float c0 = _mm_cvtss_f32(c0s), d1 = _mm_cvtss_f32(d1s), d2 = _mm_cvtss_f32(d2s);
        MinMax c;
        if constexpr (kN == 2) {
            // The four samples' c on lanes (the same operations), then min and max in order.
            const F4 cs = _mm_add_ps(_mm_add_ps(c0s, _mm_mul_ps(PixelSamples(b1[0], b1[1]), d1s)),
                                     _mm_mul_ps(PixelSamples(b2[0], b2[1]), d2s));
            c.Take(cs), c.Take(_mm_shuffle_ps(cs, cs, _MM_SHUFFLE(1, 1, 1, 1)));
            c.Take(_mm_movehl_ps(cs, cs)), c.Take(_mm_shuffle_ps(cs, cs, _MM_SHUFFLE(3, 3, 3, 3)));
        } else {
            for (int j = 0; j < n; ++j)
                for (int i = 0; i < n; ++i) c.Take(Set4(c0 + b1[j][i] * d1 + b2[j][i] * d2));
        }
        if (!CosSpreadSmall(c.Min(), c.Max(), std::sqrt(Dot3(toEye, toEye)))) {
            if constexpr (kN == 2) {
                if (!tri.shadowable) {
                    SeaSamplesOnTriangle(tri, b1[0], b1[1], b2[0], b2[1], k);
                    return;
                }
            }
            for (int j = 0; j < n; ++j)
                for (int i = 0; i < n; ++i)
                    SeaSample(tri, b1[j][i], b2[j][i], k + uint32_t(j * g_.sampleWidth + i));
            return;
        }
        const size_t e =
            AddSea(k | kPixelEntry, p, nSum, InterpolateAttributes(tri, b1Sum * inv, b2Sum * inv));
        if (tri.shadowable) {
            F4 samples[kMaxSupersampling * kMaxSupersampling], unused;
            for (int j = 0; j < n; ++j)
                for (int i = 0; i < n; ++i)
                    Interpolate(tri, b1[j][i], b2[j][i], samples[j * n + i], unused);
            SeaShadowRays(e, samples, count);
        }
    }

    // As SeaTrianglePixel, for a pixel whose sea samples lie on different triangles: the
    // samples' positions and normals are interpolated one by one and averaged.
    bool SeaPixel(int x0, uint32_t k) {
        if (!DepthsClose(x0)) return false;
        SeaClosePixel(x0, k);
        return true;
    }

    // SeaPixel once the depths are close.
    void SeaClosePixel(int x0, uint32_t k) {
        const int n = N(), count = n * n;
        constexpr int kMaxSamples = kMaxSupersampling * kMaxSupersampling;
        F4 p[kMaxSamples], nrm[kMaxSamples], a[kMaxSamples];
        bool sampleShadowable[kMaxSamples];
        F4 pSum = _mm_setzero_ps(), nSum = _mm_setzero_ps(), aSum = _mm_setzero_ps();
        bool shadowable = false;
        // The samples' triangles first (a gathering call spills no interpolated value), each
        // looked up once for a run of samples on it.
        const CachedTriangle* tris[kMaxSamples];
        uint32_t lastPrim = kNoPrimitive;  // not a sea triangle
        F4 w0s{}, w1s{}, w2s{};            // N = 2: the samples' barycentric weights, lane 2j + i
        if constexpr (kN == 2) {
            const size_t i0 = rowIndex_[0] + size_t(x0), i1 = rowIndex_[1] + size_t(x0);
            w1s = PixelSamples(b1_ + i0, b1_ + i1), w2s = PixelSamples(b2_ + i0, b2_ + i1);
            w0s = _mm_sub_ps(_mm_sub_ps(Set4(1.0f), w1s), w2s);
        }
        // (Unrolled for N = 2: kept rolled by the call in it, the loop cost ~45 instructions
        // more a pixel.)
#pragma GCC unroll 4
        for (int j = 0; j < n; ++j) {
#pragma GCC unroll 4
            for (int i = 0; i < n; ++i) {
                const uint32_t prim = primitive_[rowIndex_[j] + size_t(x0 + i)];
                const int s = j * n + i;
                if (s > 0 && prim == lastPrim) {
                    tris[s] = tris[s - 1];
                } else {
                    // Triangle(prim), except that a miss must not replace an entry an earlier
                    // sample of the pixel holds (PixelGather).
                    CachedTriangle& tri = sc_.triangles[prim & triangleMask_];
                    tris[s] = tri.prim == prim ? &tri : &PixelGather(prim, tri, x0, s);
                }
                lastPrim = prim;
            }
        }
        for (int j = 0; j < n; ++j) {
            for (int i = 0; i < n; ++i) {
                const size_t index = rowIndex_[j] + size_t(x0 + i);
                const int s = j * n + i;
                const CachedTriangle& tri = *tris[s];
                if constexpr (kN == 2) {
                    // The weights of the four samples at once, broadcast from their lanes.
                    const F4 w0 = Set4(w0s[s]), w1 = Set4(w1s[s]), w2 = Set4(w2s[s]);
                    p[s] = Interpolate3(w0, w1, w2, tri.P(0), tri.P(1), tri.P(2));
                    nrm[s] = Interpolate3(w0, w1, w2, tri.N(0), tri.N(1), tri.N(2));
                    a[s] = Interpolate3(w0, w1, w2, tri.a[0], tri.a[1], tri.a[2]);
                } else {
                    const float b1 = b1_[index], b2 = b2_[index];
                    Interpolate(tri, b1, b2, p[s], nrm[s]);
                    a[s] = InterpolateAttributes(tri, b1, b2);
                }
                aSum = _mm_add_ps(aSum, a[s]);
                sampleShadowable[s] = tri.shadowable;
                shadowable |= tri.shadowable;
                pSum = _mm_add_ps(pSum, p[s]);
                nSum = _mm_add_ps(nSum, nrm[s]);
            }
        }
        const F4 mean = _mm_mul_ps(pSum, Set4(1.0f / float(count)));
        const F4 toEye = _mm_sub_ps(f_.eye4, mean);
        MinMax c;
        for (int s = 0; s < count; ++s) c.Take(Dot3Lane(nrm[s], toEye));
        if (!CosSpreadSmall(c.Min(), c.Max(), std::sqrt(Dot3(toEye, toEye)))) {
            // The samples one by one, from the values just interpolated.
            if constexpr (kN == 2) {
                if (!shadowable) {
                    // Their components sample by sample on lanes: the same values, stored at once.
                    const auto Components = [](const F4* v, F4(&c)[3]) {
                        F4 r0 = v[0], r1 = v[1], r2 = v[2], r3 = v[3];
                        _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
                        c[0] = r0, c[1] = r1, c[2] = r2;
                    };
                    F4 pc[3], nc[3], ac[3];
                    Components(p, pc), Components(nrm, nc), Components(a, ac);
                    AddSeaSamples(k, pc, nc, ac);
                    return;
                }
            }
            for (int j = 0; j < n; ++j) {
                for (int i = 0; i < n; ++i) {
                    const int s = j * n + i;
                    const size_t e =
                        AddSea(k + uint32_t(j * g_.sampleWidth + i), p[s], nrm[s], a[s]);
                    if (sampleShadowable[s]) SeaShadowRays(e, &p[s], 1);
                }
            }
            return;
        }
        const size_t e =
            AddSea(k | kPixelEntry, mean, nSum, _mm_mul_ps(aSum, Set4(1.0f / float(count))));
        if (shadowable) SeaShadowRays(e, p, count);
    }

    // A lit sea entry at position p with normal nSum (unnormalized: SeaShading::Shade normalizes
    // it with the block's others, simd::kLanes at a time, off this loop's critical path);
    // returns its index.
    __attribute__((always_inline)) size_t AddSea(uint32_t k, F4 p, F4 nSum, F4 attributes) {
        alignas(16) float pf[4], nf[4], af[4];
        _mm_store_ps(pf, p);
        _mm_store_ps(af, attributes);
        _mm_store_ps(nf, nSum);
        const size_t e = sc_.seaCount++;
        sc_.seaK[e] = k;
        sc_.seaPx[e] = pf[0], sc_.seaPy[e] = pf[1], sc_.seaPz[e] = pf[2];
        sc_.seaNx[e] = nf[0], sc_.seaNy[e] = nf[1], sc_.seaNz[e] = nf[2];
        sc_.seaDepth[e] = af[0], sc_.seaWet[e] = af[1], sc_.seaFoam[e] = af[2];
        sc_.seaUnlit[e] = 0;
        return e;
    }

    // Shadow rays of sea entry e, one per sample at positions samples[0..count), offset along
    // the entry's normal.
    void SeaShadowRays(size_t e, const F4* samples, int count) {
        // The entry's unit normal as SeaShading::Shade makes it: glm::normalize's
        // v · (1 / √(v·v)) with v·v summed (x + y) + z, the same operations lane for lane.
        const glm::vec3 v(sc_.seaNx[e], sc_.seaNy[e], sc_.seaNz[e]);
        const glm::vec3 nrm = v * (1.0f / std::sqrt((v.x * v.x + v.y * v.y) + v.z * v.z));
        for (int s = 0; s < count; ++s) {
            const glm::vec3 origin = ShadowRayOrigin(Store3(samples[s]), nrm);
            if (f_.occluders.MayOcclude(origin)) {
                sc_.origins.push_back(origin);
                sc_.originOwner.push_back(kSeaOwner | uint32_t(e));
            }
        }
    }

    // The four samples of a pixel (N = 2, entry k) on unshadowable triangle tri as SeaSample
    // adds them one by one, on four lanes (sample (j, i) in lane 2j + i, the barycentrics of
    // row j from b1j, b2j): Interpolate's and InterpolateAttributes' operations per component
    // in the same order, stored to the sea arrays at once.
    __attribute__((always_inline)) void SeaSamplesOnTriangle(const CachedTriangle& tri,
                                                             const float* b10, const float* b11,
                                                             const float* b20, const float* b21,
                                                             uint32_t k) {
        // The weights twice over: component c of the positions in lanes 0–3 and of the normals
        // in lanes 4–7 at once.
        const F8 w1 = Twice(PixelSamples(b10, b11)), w2 = Twice(PixelSamples(b20, b21));
        const F8 w0 = (1.0f - w1) - w2;
        const F8 pn0 = tri.PN(0), pn1 = tri.PN(1), pn2 = tri.PN(2);
        F4 p[3], nrm[3], a[3];
        const auto PositionNormal = [&](F8 v, int c) { p[c] = Low(v), nrm[c] = High(v); };
        PositionNormal(Interpolate8(w0, w1, w2, Spread<0>(pn0), Spread<0>(pn1), Spread<0>(pn2)), 0);
        PositionNormal(Interpolate8(w0, w1, w2, Spread<1>(pn0), Spread<1>(pn1), Spread<1>(pn2)), 1);
        PositionNormal(Interpolate8(w0, w1, w2, Spread<2>(pn0), Spread<2>(pn1), Spread<2>(pn2)), 2);
        // The attributes' components x and y at once, then z.
        const auto XY = [](F4 v) { return __builtin_shufflevector(v, v, 0, 0, 0, 0, 1, 1, 1, 1); };
        const F8 axy = Interpolate8(w0, w1, w2, XY(tri.a[0]), XY(tri.a[1]), XY(tri.a[2]));
        a[0] = Low(axy), a[1] = High(axy);
        a[2] = Interpolate3(Low(w0), Low(w1), Low(w2), Set4(tri.a[0][2]), Set4(tri.a[1][2]),
                            Set4(tri.a[2][2]));
        AddSeaSamples(k, p, nrm, a);
    }

    // The four samples of a pixel (N = 2, entry k) as four lit sea entries, as AddSea adds
    // them one by one: sample (j, i) in lane 2j + i of the positions', normals' and
    // attributes' components (x, y, z).
    __attribute__((always_inline)) void AddSeaSamples(uint32_t k, const F4 (&p)[3],
                                                      const F4 (&nrm)[3], const F4 (&a)[3]) {
        // The scratch by a local reference: a vector store may alias anything (__m128_u), this
        // object's member sc_ too, which would be read again after each.
        BlockScratch& sc = sc_;
        const size_t e = sc.seaCount;
        sc.seaCount += 4;
        _mm_storeu_ps(&sc.seaPx[e], p[0]), _mm_storeu_ps(&sc.seaPy[e], p[1]);
        _mm_storeu_ps(&sc.seaPz[e], p[2]);
        _mm_storeu_ps(&sc.seaNx[e], nrm[0]), _mm_storeu_ps(&sc.seaNy[e], nrm[1]);
        _mm_storeu_ps(&sc.seaNz[e], nrm[2]);
        _mm_storeu_ps(&sc.seaDepth[e], a[0]), _mm_storeu_ps(&sc.seaWet[e], a[1]);
        _mm_storeu_ps(&sc.seaFoam[e], a[2]);
        const uint32_t sw = uint32_t(g_.sampleWidth);
        const uint32_t keys[4] = {k, k + 1, k + sw, k + sw + 1};
        std::memcpy(&sc.seaK[e], keys, sizeof keys);
        std::memset(&sc.seaUnlit[e], 0, 4 * sizeof(uint16_t));
    }

    // Sea sample k at barycentrics (1 − b1 − b2, b1, b2) of triangle tri, shaded on its own.
    void SeaSample(const CachedTriangle& tri, float b1, float b2, uint32_t k) {
        F4 p, nSum;
        Interpolate(tri, b1, b2, p, nSum);
        const size_t e = AddSea(k, p, nSum, InterpolateAttributes(tri, b1, b2));
        if (tri.shadowable) SeaShadowRays(e, &p, 1);
    }

    // One sample (x, row j of the pixel row) shaded on its own.
    void Sample(int x, int j, uint32_t k) {
        const size_t index = rowIndex_[j] + size_t(x);
        const uint32_t prim = primitive_[index];
        if (prim == kNoPrimitive) {
            // View direction, normalized in the sky pass.
            AddSky(k, sampleRow_[j] + (float(x) + 0.5f) * g_.colStep);
            return;
        }
        const CachedTriangle& tri = Triangle(prim);
        if (tri.mesh == 0) {
            SeaSample(tri, b1_[index], b2_[index], k);
            return;
        }
        F4 p, nSum;
        Interpolate(tri, b1_[index], b2_[index], p, nSum);
        const glm::vec3 position = Store3(p);
        glm::vec3 nrm = glm::normalize(Store3(nSum));
        if (glm::dot(nrm, f_.eye - position) < 0.0f) nrm = -nrm;
        const size_t e = sc_.modelK.size();
        sc_.modelK.push_back(k);
        sc_.modelPosition.push_back(position);
        sc_.modelNormal.push_back(nrm);
        sc_.modelMesh.push_back(tri.mesh);
        sc_.modelLit.push_back(1);
        if (tri.shadowable) {
            const glm::vec3 o = ShadowRayOrigin(position, nrm);
            if (f_.occluders.MayOcclude(o)) {
                sc_.origins.push_back(o);
                sc_.originOwner.push_back(uint32_t(e));
            }
        }
    }

    const FrameGeometry& g_;
    const FrameShading& f_;
    BlockScratch& sc_;
    const int y0_;  // first sample row of the block
    // The visibility buffer's arrays, read per sample: one load away here, not three through g_.
    const uint32_t* const primitive_;
    const float *const depth_, *const b1_, *const b2_;
    const uint32_t triangleMask_;             // triangle cache slots − 1
    glm::vec3 sampleRow_[kMaxSupersampling];  // RowBase of the pixel row's sample rows
    size_t rowIndex_[kMaxSupersampling];      // visibility index of their first sample
};

// Traces the block's shadow rays and stores the sun visibility of its sea and model entries;
// returns the number of rays traced.
uint64_t TraceSunVisibility(const FrameShading& f, int n, BlockScratch& sc) {
    if (sc.origins.empty()) return 0;
    sc.vis.resize(sc.origins.size());
    // Every origin passed f.occluders (BlockClassifier): not tested again.
    f.occlusion.DirectionalVisibility(sc.origins, f.keyDir, 0.0f, sc.vis, true);
    for (size_t r = 0; r < sc.origins.size(); ++r) {
        const uint32_t owner = sc.originOwner[r];
        if (owner & kSeaOwner)
            sc.seaUnlit[owner & ~kSeaOwner] += sc.vis[r] ? 0 : 1;
        else
            sc.modelLit[owner] = sc.vis[r];
    }
    for (size_t e = 0; e < sc.seaCount; ++e) {
        if (sc.seaUnlit[e] == 0) continue;
        const int samples = (sc.seaK[e] & kPixelEntry) ? n * n : 1;
        sc.seaLit[e] = float(samples - sc.seaUnlit[e]) / float(samples);
    }
    return sc.origins.size();
}

// Sky radiance of the block's sky entries, with the sun's disc.
void ShadeSky(const FrameShading& f, const FrameGeometry& g, BlockScratch& sc, float* out) {
    for (size_t c = 0; c < sc.skyCount; c += kChunk) {
        const size_t count = std::min(kChunk, sc.skyCount - c);
        float *dx = &sc.skyX[c], *dy = &sc.skyY[c], *dz = &sc.skyZ[c];
        Normalize(count, dx, dy, dz);
        SeaChunk& ch = sc.chunk;
        f.sky.LookUp(count, dx, dy, dz, ch.skyR, ch.skyG, ch.skyB);
        // The sun's disc, simd::kLanes at a time (glm::dot's order; lanes past count are
        // dropped). Pixel entries are never near the sun (BlockClassifier): the test is per
        // sample.
        {
            using namespace simd;
            for (size_t i = 0; i < count; i += kLanes) {
                const size_t lanes = std::min(kLanes, count - i);
                const VI disc = Dot(Load(dx + i, lanes), Load(dy + i, lanes), Load(dz + i, lanes),
                                    simd::Splat(f.sunDir.x), simd::Splat(f.sunDir.y),
                                    simd::Splat(f.sunDir.z)) >= f.cosSunRadius;
                if (!Any(disc)) continue;
                const auto add = [&](float* L, float sunL) {
                    const VF v = Load(L + i);
                    Store(L + i, Select(disc, v + sunL, v));
                };
                add(ch.skyR, f.sunL.r);
                add(ch.skyG, f.sunL.g);
                add(ch.skyB, f.sunL.b);
            }
        }
        SplatChunk(out, &sc.skyK[c], count, ch.skyR, ch.skyG, ch.skyB, g.sampleWidth, g.n);
    }
}

// Sea radiance of the block's sea entries (SeaShading).
void ShadeSea(const FrameShading& f, const FrameGeometry& g, BlockScratch& sc, float* out) {
    for (size_t c = 0; c < sc.seaCount; c += kChunk) {
        const size_t count = std::min(kChunk, sc.seaCount - c);
        SeaChunk& ch = sc.chunk;
        if (sc.origins.empty()) {
            std::fill_n(ch.sunVis, count, 1.0f);
        } else {
            for (size_t i = 0; i < count; ++i)
                ch.sunVis[i] = sc.seaUnlit[c + i] ? sc.seaLit[c + i] : 1.0f;
        }
        f.sea.Shade(count, &sc.seaPx[c], &sc.seaPy[c], &sc.seaPz[c], &sc.seaNx[c], &sc.seaNy[c],
                    &sc.seaNz[c], &sc.seaDepth[c], &sc.seaWet[c], &sc.seaFoam[c], ch);
        SplatChunk(out, &sc.seaK[c], count, ch.outR, ch.outG, ch.outB, g.sampleWidth, g.n);
    }
}

// Model radiance, sample by sample (a small fraction of the frame): Lambertian under the key
// light (shadowed), the fill lights, sky and light reflected by the sea; Koschmieder fog.
void ShadeModels(const FrameShading& f, const FrameGeometry& g, const BlockScratch& sc,
                 float* out) {
    for (size_t i = 0; i < sc.modelK.size(); ++i) {
        const glm::vec3 p = sc.modelPosition[i], nrm = sc.modelNormal[i];
        const glm::vec3 toEye = f.eye - p;
        const float range = glm::length(toEye);
        const glm::vec3 v = toEye / range;
        const float sunVis = float(sc.modelLit[i]);
        const glm::vec3 rho(f.reflectance[size_t(sc.modelMesh[i]) - 1]);
        glm::vec3 E = f.keyE * std::max(glm::dot(nrm, f.keyDir), 0.0f) * sunVis +
                      f.skyE * (0.5f * (1.0f + nrm.z)) +
                      kSeaAlbedo * f.downwelling * (0.5f * (1.0f - nrm.z));
        for (const DirectionalLight& l : f.fill) E += l.E * std::max(glm::dot(nrm, l.dir), 0.0f);
        glm::vec3 L = rho * E * float(1.0 / M_PI);
        // Koschmieder: the horizon sky is the airlight a long path converges to.
        const float t = std::exp(-f.beta * range);
        const glm::vec3 horizon = f.sky.HorizonLookUp(-v);
        L = L * t + horizon * (1.0f - t);
        SplatEntry(out, sc.modelK[i], g.sampleWidth, g.n, L.r, L.g, L.b);
    }
}

// The plumes' light in a band basis (channels/nvg), where ChannelPlumes::CompositeOtw's
// Rec.709 sun and blackbody glow do not apply: the key light (sun or moon, whichever is
// brighter, in the basis) scatters once off the particles; the ambient radiance is
// VisibleAmbientRadiance's split, half the sky's solid-angle mean and half the sea's diffuse
// reflection, with the sea lit by the channel's downwelling irradiance (key, fill lights and sky
// in the basis); glow the basis's blackbody table.
PlumeLighting BasisPlumeLighting(const DirectionalLight& key, const glm::vec3& downwelling,
                                 const radiometry::AnalyticSky& sky,
                                 const BlackbodyGlowTable* glow) {
    PlumeLighting light;
    light.kind = PlumeLighting::Kind::Visible;
    light.sunDirection = key.dir;
    light.sunIlluminance = key.dir.z > 0.0f ? key.E : glm::vec3(0.0f);
    light.ambientRgb = glm::vec3(
        0.5 * (SkyMeanRadiance(sky) + double(kSeaAlbedo) * glm::dvec3(downwelling) / M_PI));
    light.glow = glow;
    return light;
}

}  // namespace

OtwChannel::OtwChannel(const scene::World& world, const scene::ChannelSettings& settings)
    : world_(world),
      settings_(settings),
      geometry_(world, settings),
      plumes_(std::make_unique<ChannelPlumes>(world)) {
    for (const scene::EntityState& e : world.State(0).entities)
        reflectance_.push_back(e.reflectanceRgb);
    // Surf-zone optics per colour channel. Reflectances from configs/materials.yaml (sand_wet,
    // sand_dry: Oke 1987; foam: Whitlock, Bartlett & Gurganus 1982) when the scenario's material
    // library has them, else the same published values.
    const scene::Scenario& scenario = world.GetScenario();
    const auto reflectance = [&](const char* name, glm::dvec3 published) {
        const scene::MaterialSettings* m = scenario.FindMaterial(name);
        return m ? m->reflectanceRgb : published;
    };
    const glm::dvec3 wet = reflectance("sand_wet", {0.28, 0.24, 0.17});
    const glm::dvec3 dry = reflectance("sand_dry", {0.45, 0.39, 0.30});
    const glm::dvec3 foam = reflectance("foam", {0.50, 0.53, 0.55});
    for (int c = 0; c < 3; ++c)
        shore_[c] = {kSeaRrs[c], kCoastalK_perm[c], float(wet[c]), float(dry[c]), float(foam[c])};
    stars_ =
        std::make_unique<StarsNearView>(scene::LoadStarCatalog(scene::DefaultStarCatalogPath()));
}

OtwChannel::OtwChannel(const scene::World& world, const scene::ChannelSettings& settings,
                       const OtwBandBasis& basis, std::vector<PixelSpan> renderSpans)
    : OtwChannel(world, settings) {
    CHECK(basis.reflectance.size() == reflectance_.size());
    CHECK(renderSpans.empty() || renderSpans.size() == size_t(settings.height));
    for (const PixelSpan& span : renderSpans)
        CHECK(0 <= span.begin && span.begin <= span.end && span.end <= settings.width);
    renderSpans_ = std::move(renderSpans);
    geometry_.SetRenderSpans(renderSpans_);
    basis_ = std::make_unique<OtwBandBasis>(basis);
    reflectance_ = basis.reflectance;
    for (int c = 0; c < 3; ++c) shore_[c] = basis.shore[c];
}

struct OtwChannel::ShadeScratch {
    tbb::enumerable_thread_specific<BlockScratch> perThread;
};

OtwChannel::~OtwChannel() = default;

void OtwChannel::SetTriangleCacheEntries(uint32_t entries) {
    CHECK(entries > 0 && (entries & (entries - 1)) == 0);
    triangleCacheEntries_ = entries;
}

void OtwChannel::Render(const scene::SceneState& state, Image& radiance) {
    const scene::Scenario& sc = world_.GetScenario();
    const scene::EnvironmentSettings& env = sc.environment;
    using Clock = std::chrono::steady_clock;
    const auto Ms = [](Clock::time_point a, Clock::time_point b) {
        return std::chrono::duration<double, std::milli>(b - a).count();
    };
    geometry_.Update(state);
    const Clock::time_point t2 = Clock::now();
    const ChannelCamera& cam = geometry_.Camera();
    const int sw = cam.SampleWidth(), sh = cam.SampleHeight();
    const int n = cam.supersampling;
    CHECK(n >= 1 && n <= kMaxSupersampling);
    const scene::OceanMesh& ocean = geometry_.Ocean();
    const VisibilityBuffer& vis = geometry_.Visibility();
    const OcclusionScene& occlusion = geometry_.Occlusion();
    const ViewFrameStats& view = geometry_.Stats();

    stats_ = {};
    stats_.raster = view.raster;
    stats_.meshMs = view.meshMs;
    stats_.rasterMs = view.rasterMs;
    stats_.oceanTriangles = view.oceanTriangles;
    stats_.modelTriangles = view.modelTriangles;

    // The sky table (~2.6 ms to build) follows the sun rounded to kSkySunStep_rad, so an
    // ephemeris sun that moves every frame rebuilds it only every few frames; the sun itself
    // (disc, glint, direct light) stays exact.
    const glm::dvec3 skySun =
        radiometry::QuantizeSunDirection(state.sun.direction, kSkySunStep_rad);
    const glm::dvec3 skyMoon =
        radiometry::QuantizeSunDirection(state.moon.direction, kSkySunStep_rad);
    // The moonlit sky's phase angle and distance rounded too (steps below), so that the table
    // is a function of the rounded values alone: a frame's sky does not depend on which earlier
    // frame built the table (a capture from any first frame gives the run's frames). The sun's
    // illuminance it keeps (SunIlluminance) is the building frame's: per-frame light takes the
    // frame's own sun (ChannelPlumes::CompositeOtw).
    const double moonPhase_rad =
        kSkyMoonPhaseStep_rad * std::round(state.moon.phaseAngle_rad / kSkyMoonPhaseStep_rad);
    const double moonDistance_m =
        kSkyMoonDistanceStep_m * std::round(state.moon.distance_m / kSkyMoonDistanceStep_m);
    if (!sky_ || skySun_ != skySun || skyMoon_ != skyMoon || skyMoonPhase_rad_ != moonPhase_rad ||
        skyMoonDistance_m_ != moonDistance_m) {
        radiometry::SkyConditions c;
        c.sunDirection = skySun;
        c.sunIlluminance_lux = state.sun.illuminance_lux;
        c.turbidity = env.sky.turbidity;
        c.extinctionV_magPerAirmass = scene::ZenithExtinctionV_mag(sc.eyepoint.position_m.z);
        c.moon = true;
        c.moonDirection = skyMoon;
        c.moonPhaseAngle_rad = moonPhase_rad;
        c.moonDistance_m = moonDistance_m;
        if (basis_) c.basis = basis_->sky;
        sky_ = std::make_unique<radiometry::AnalyticSky>(c);
        skySun_ = skySun;
        skyMoon_ = skyMoon;
        skyMoonPhase_rad_ = moonPhase_rad;
        skyMoonDistance_m_ = moonDistance_m;
    }
    const radiometry::AnalyticSky& sky = *sky_;
    const glm::vec3 sunDir(state.sun.direction);
    // Band basis: a grey (equal-component) Rec.709 light of E lx is E × the light's vector.
    const auto inBasis = [&](const glm::dvec3& greyRgb, const glm::dvec3& perLux) {
        return basis_ ? greyRgb.g * perLux : greyRgb;
    };
    const glm::dvec3 sunLux =
        radiometry::SunIlluminanceRgb(state.sun.direction, state.sun.illuminance_lux);
    const glm::dvec3 sunIlluminance = inBasis(sunLux, basis_ ? basis_->sun : glm::dvec3(1.0));
    // Clouds (world.Clouds()): the world divided the direct sun and moon by their sky-condition
    // divisors (USNO Circular 171); the sky dome's light is divided by the divisor of the sky
    // overhead, and the sun's disc keeps its light above the clouds (the cloud pass attenuates
    // it by e^−τ). Without clouds both divisors are 1.
    const glm::dvec3 up(0.0, 0.0, 1.0);
    const double domeDivisor =
        world_.SkyConditionDivisor(state.eyepoint.position_m, up, state.time_s);
    const double sunDivisor =
        world_.SkyConditionDivisor(state.eyepoint.position_m, state.sun.direction, state.time_s);
    const glm::dvec3 sunAboveClouds = sunIlluminance * sunDivisor;
    const float beta = float(ExtinctionFromVisibility(env.visibility_m));
    const glm::vec3 eye(cam.worldFromCamera.position_m);

    // Direct light: the brighter of sun and moon is the key light (shadows, glint); the dimmer
    // one is a fill light without shadow or glint — by day the moon is 1e-6 of the sun, and
    // once the sun is down its direct light is 0, so the key light is always the one that
    // matters. The moon's light is given the sun's colour; the moon is in fact redder (B−V 0.92
    // against the sun's 0.65, Allen's Astrophysical Quantities), so moonlit blue is about 20 %
    // too strong against green here.
    const DirectionalLight sunLight{sunDir, glm::vec3(sunIlluminance)};
    const glm::dvec3 moonLux =
        radiometry::SunIlluminanceRgb(state.moon.direction, state.moon.illuminance_lux);
    const DirectionalLight moonLight{
        glm::vec3(state.moon.direction),
        glm::vec3(inBasis(moonLux, basis_ ? basis_->moon : glm::dvec3(1.0)))};
    const bool moonKey = moonLux.g > sunLux.g;
    const DirectionalLight& key = moonKey ? moonLight : sunLight;
    std::vector<DirectionalLight> fill;
    if (const DirectionalLight& dim = moonKey ? sunLight : moonLight; dim.E.g > 0.0f)
        fill.push_back(dim);
    // Lightning lit during the frame's exposure (one frame period of scene time ending at this
    // frame's instant): its light at the eye lights the scene as one more fill light, from the
    // illuminance-weighted direction of the bolts (channels/otw/lightning_overlay).
    const scene::Lightning* lightning = world_.GetLightning();
    const double exposure_s = sc.world.timeScale / sc.world.frameRate_hz;
    LitFlashes flashes;
    if (lightning) {
        flashes = FindLitFlashes(*lightning, state.time_s - exposure_s, state.time_s);
        const FlashLight flash =
            FlashLightAt(*lightning, flashes, glm::dvec3(eye), beta, world_.Clouds());
        if (flash.illuminance_lux > 0.0)
            fill.push_back({glm::vec3(flash.direction),
                            basis_ ? glm::vec3(flash.illuminance_lux * basis_->lightning)
                                   : glm::vec3(float(flash.illuminance_lux))});
    }
    const glm::vec3 skyE(sky.HorizontalSkyIlluminance() / domeDivisor);
    // Downwelling irradiance on the sea surface (lx): direct light on a level surface plus sky.
    glm::vec3 downwelling = key.E * std::max(key.dir.z, 0.0f) + skyE;
    for (const DirectionalLight& l : fill) downwelling += l.E * std::max(l.dir.z, 0.0f);
    static const radiometry::FresnelTable fresnel(radiometry::kSeaWaterIndexVisible);

    FrameGeometry g{vis,
                    {},
                    vis.primitiveBase.size() > 1 ? vis.primitiveBase[1] : kNoPrimitive,
                    cam.width,
                    sw,
                    sh,
                    n,
                    cam.worldFromCamera.worldFromBody,
                    cam.worldFromCamera.worldFromBody * glm::dvec3(0.0, 1.0, 0.0),
                    cam.TanHalfH(),
                    cam.TanHalfV(),
                    glm::vec3(0.0f)};
    g.colStep = glm::vec3(g.R * glm::dvec3(2.0 * g.tanH / sw, 0.0, 0.0));
    g.frame = ++frames_;
    CHECK(geometry_.OceanAttributes().size() == ocean.positions.size());
    g.meshes.push_back({ocean.positions.data(), ocean.normals.data(), ocean.indices.data(),
                        geometry_.OceanAttributes().data()});
    for (const scene::TriangleMesh& m : geometry_.EntityMeshes())
        g.meshes.push_back({m.positions.data(), m.normals.data(), m.indices.data()});

    // Pixel size on the image plane at unit distance bounds the angle between a pixel's
    // centre ray and its samples' (the plane is at least that far from the eye).
    const double pixelTan = n * (2.0 * g.tanH / sw + 2.0 * g.tanV / sh);
    const RayBoxesTest casters(geometry_.CasterBoxes(), key.dir,
                               std::numeric_limits<float>::infinity());
    const FrameShading f{eye,
                         sunDir,
                         glm::vec3(sunAboveClouds / radiometry::SunDiscSolidAngle_sr()),
                         key.dir,
                         key.E,
                         skyE,
                         downwelling,
                         fill,
                         Load3(eye),
                         float(std::cos(radiometry::kSunAngularRadius_rad)),
                         float(std::cos(radiometry::kSunAngularRadius_rad + pixelTan)),
                         beta,
                         settings_.shadows && !occlusion.Empty() && key.dir.z > 0.0f,
                         sky,
                         occlusion,
                         casters,
                         occlusion.BoundsTest(key.dir, 1e30f),
                         SeaShading{eye,
                                    key.dir,
                                    key.E,
                                    downwelling,
                                    beta,
                                    CoxMunkSlopeVariance(env.windSpeed_mps),
                                    fresnel,
                                    sky,
                                    skyE,
                                    &fill,
                                    {shore_[0], shore_[1], shore_[2]}},
                         reflectance_};

    if (radiance.width != sw || radiance.height != sh || radiance.channels != 3)
        radiance = Image(sw, sh, 3);
    // Blocks of about eight sample rows (whole pixel rows); every pixel is shaded on its own,
    // so the result does not depend on the partition or the thread count.
    const int pixelRowsPerBlock = std::max(1, 8 / n);
    const int blocks = (cam.height + pixelRowsPerBlock - 1) / pixelRowsPerBlock;
    std::vector<uint64_t> blockRays(size_t(blocks), 0);
    // Per-thread scratch (see BlockScratch), created on the first frame.
    if (!scratch_) scratch_ = std::make_unique<ShadeScratch>();
    tbb::enumerable_thread_specific<BlockScratch>& scratch = scratch_->perThread;

    tbb::parallel_for(0, blocks, [&](int block) {
        const int py0 = block * pixelRowsPerBlock;
        const int py1 = std::min(cam.height, py0 + pixelRowsPerBlock);
        BlockScratch& s = scratch.local();
        s.Reset(size_t(py1 - py0) * size_t(n) * size_t(sw));
        if (const uint32_t entries = triangleCacheEntries_ > 0 ? triangleCacheEntries_
                                                               : BlockScratch::kTriangleCacheSize;
            s.triangles.size() != entries)
            s.triangles.assign(entries, CachedTriangle{});
        if (s.trianglesFrame != g.frame) {
            for (CachedTriangle& t : s.triangles) t.prim = kNoPrimitive;
            s.trianglesFrame = g.frame;
        }
        const auto span = [&](int py) {
            return renderSpans_.empty() ? PixelSpan{0, cam.width} : renderSpans_[size_t(py)];
        };
        if (n == 2 && !classifyPixelByPixel_) {
            BlockClassifier<2> classify(g, f, py0, s);
            for (int py = py0; py < py1; ++py) classify.Pixels(py, span(py).begin, span(py).end);
        } else {
            BlockClassifier<0> classify(g, f, py0, s);
            for (int py = py0; py < py1; ++py) classify.Pixels(py, span(py).begin, span(py).end);
        }
        blockRays[size_t(block)] = TraceSunVisibility(f, n, s);
        // The block's rows are contiguous in the image: sample k is at out + 3k.
        float* out = radiance.At(0, py0 * n);
        ShadeSky(f, g, s, out);
        ShadeSea(f, g, s, out);
        ShadeModels(f, g, s, out);
        // Samples of pixels outside the spans: 0 (the overlays below add onto them).
        if (!renderSpans_.empty())
            for (int py = py0; py < py1; ++py)
                for (int j = 0; j < n; ++j) {
                    float* row = radiance.At(0, py * n + j);
                    std::fill(row, row + size_t(3 * n * span(py).begin), 0.0f);
                    std::fill(row + size_t(3 * n * span(py).end), row + size_t(3 * sw), 0.0f);
                }
    });
    for (uint64_t r : blockRays) stats_.shadowRays += r;
    stats_.shadeMs = Ms(t2, Clock::now());

    // The moon's disc, the stars and lightning bolts over the sky, before the plumes that may
    // hide them (channels/otw/celestial, lightning_overlay).
    scene::Observer observer;
    observer.latitude_deg = sc.world.latitude_deg;
    observer.longitude_deg = sc.world.longitude_deg;
    observer.height_m = state.eyepoint.position_m.z;
    scene::MoonState moonAboveClouds = state.moon;
    moonAboveClouds.illuminance_lux *=
        world_.SkyConditionDivisor(state.eyepoint.position_m, state.moon.direction, state.time_s);
    // Band basis: a grey overlay drawn alone, then added in its light's vector; Rec.709: drawn
    // straight into radiance.
    const auto overlay = [&](const auto& draw, const glm::dvec3& perCdm2) {
        if (!basis_) {
            draw(radiance, nullptr);
            return;
        }
        // overlay_ is all zeros between uses: each use clears the samples it drew on. Only the
        // sample rows drawn on are visited (a few stars, the moon, bolts), not the whole image.
        if (overlay_.width != sw || overlay_.height != sh) overlay_ = Image(sw, sh, 3);
        overlayRows_.assign(size_t(sh), 0);
        draw(overlay_, &overlayRows_);
        const glm::vec3 v(perCdm2);
        const size_t rowValues = 3 * size_t(sw);
        for (size_t row = 0; row < size_t(sh); ++row) {
            if (!overlayRows_[row]) continue;
            for (size_t i = row * rowValues; i < (row + 1) * rowValues; i += 3) {
                const float y = overlay_.pixels[i + 1];
                if (y == 0.0f) continue;
                for (int c = 0; c < 3; ++c) {
                    radiance.pixels[i + size_t(c)] += y * v[c];
                    overlay_.pixels[i + size_t(c)] = 0.0f;
                }
            }
        }
    };
    if (basis_) {
        // The moon and the stars have different colours.
        overlay(
            [&](Image& img, std::vector<uint8_t>* rows) {
                AddMoonAndStars(cam, vis, MakeMoonDisc(moonAboveClouds, state.sun), {}, img, rows);
            },
            basis_->moon);
        overlay(
            [&](Image& img, std::vector<uint8_t>* rows) {
                AddMoonAndStars(cam, vis, MoonDisc{}, stars_->Visible(cam, state.utc, observer),
                                img, rows);
            },
            basis_->stars);
    } else {
        AddMoonAndStars(cam, vis, MakeMoonDisc(moonAboveClouds, state.sun),
                        stars_->Visible(cam, state.utc, observer), radiance);
    }
    // --- Cloud layers (channels/otw/cloud_layer) over the sky, sun, moon and stars. ---
    if (world_.Clouds()) {
        if (!clouds_) clouds_ = std::make_unique<CloudSky>();
        const CloudSkyStats cloud =
            basis_ ? DrawOtwClouds(*clouds_, world_, state, cam, vis, sky, beta, radiance,
                                   basis_->sun, basis_->moon)
                   : DrawOtwClouds(*clouds_, world_, state, cam, vis, sky, beta, radiance);
        stats_.cloudMs = cloud.ms;
        stats_.cloudTraces = cloud.gridTraces + cloud.exactTraces;
    }
    // --- end of cloud layers ---
    if (lightning)
        overlay(
            [&](Image& img, std::vector<uint8_t>* rows) {
                DrawLightning(cam, vis, *lightning, flashes, beta, img, rows);
            },
            basis_ ? basis_->lightning : glm::dvec3(1.0));
    // --- Surf spray (channels/otw/spray_overlay): foam-white droplet clumps, depth-tested (the
    // foam reflectance and the downwelling light are in the basis's components). ---
    DrawSpray(world_, state, cam, vis, {shore_[0].rhoFoam, shore_[1].rhoFoam, shore_[2].rhoFoam},
              downwelling, beta, radiance);

    // Plumes (channels/plume) over the finished radiance.
    if (!basis_) {
        plumes_->CompositeOtw(state, cam, vis, sky, radiance);
        stats_.plumes = plumes_->Stats();
        return;
    }
    if (!plumes_->Active()) return;
    if (!basisGlow_ && basis_->blackbody)
        basisGlow_ = std::make_unique<BlackbodyGlowTable>(basis_->blackbody);
    const PlumeLighting light = BasisPlumeLighting(key, downwelling, sky, basisGlow_.get());
    const auto start = std::chrono::steady_clock::now();
    stats_.plumes =
        CompositePlumes(plumes_->FieldAt(state.time_s), cam, vis, light, radiance, renderSpans_);
    stats_.plumes.ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace seasense::channels
