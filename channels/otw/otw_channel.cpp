// OTW shading: Fresnel-weighted sky reflection, Cox–Munk sun glint and water-leaving radiance
// on the sea; Lambertian models lit by sun (shadowed) and sky; Koschmieder fog.
#include "channels/otw/otw_channel.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "channels/plume/plume_composite.h"
#include "radiometry/sky/analytic_sky.h"
#include "radiometry/surface/fresnel.h"
#include "scene/core/simd4.h"

namespace seasense::channels {

namespace {

using namespace simd4;

// Remote-sensing reflectance R_rs = L_w / E_d of clear oceanic (Case 1) water, sr⁻¹, at the
// Rec.709 primaries' dominant wavelengths (≈ 610, 550, 465 nm); order of magnitude from
// Mobley, "Light and Water" (1994), Fig. 11.x and Morel & Maritorena (2001) for chl ≈ 0.1 mg/m³.
constexpr glm::vec3 kSeaRrs{0.0003f, 0.0015f, 0.0050f};

// Albedo of the sea for light reflected up onto models (Payne 1972, J. Atmos. Sci. 29: ≈ 0.06).
constexpr float kSeaAlbedo = 0.06f;

// Koschmieder: extinction coefficient for a 2 % contrast threshold, β = 3.912 / V.
double ExtinctionFromVisibility(double visibility_m) { return 3.912 / visibility_m; }

// Whether the ray origin + t·direction, t ≥ 0, meets the box [lo, hi] (slab test; Kay & Kajiya,
// SIGGRAPH 1986). Inline for the per-sample shadow-caster prefilter.
struct RayBoxTest {
    glm::vec3 lo, hi, direction, inverse;
    RayBoxTest(const glm::vec3& boxMin, const glm::vec3& boxMax, const glm::vec3& d)
        : lo(boxMin), hi(boxMax), direction(d) {
        // Components below 1e-20 count as parallel, as in OcclusionScene (no inf·0 below).
        for (int a = 0; a < 3; ++a) inverse[a] = Parallel(d[a]) ? 0.0f : 1.0f / d[a];
    }
    bool MayHit(const glm::vec3& o) const {
        float t0 = 0.0f, t1 = std::numeric_limits<float>::infinity();
        for (int a = 0; a < 3; ++a) {
            if (Parallel(direction[a])) {
                if (o[a] < lo[a] || o[a] > hi[a]) return false;
                continue;
            }
            const float tA = (lo[a] - o[a]) * inverse[a], tB = (hi[a] - o[a]) * inverse[a];
            t0 = std::max(t0, std::min(tA, tB));
            t1 = std::min(t1, std::max(tA, tB));
        }
        return t0 <= t1;
    }
    static bool Parallel(float d) { return std::abs(d) < 1e-20f; }
};

// Gaussian isotropic slope density of Cox & Munk (1954), J. Opt. Soc. Am. 44(11), with the
// mean-square slope σ² = 0.003 + 0.00512·W (W wind speed at 12.5 m, m/s); p(tan β) per unit
// slope area.
float CoxMunkSlopeVariance(double windSpeed_mps) {
    return float(0.003 + 0.00512 * std::max(windSpeed_mps, 0.0));
}

// Four-lane (SSE2, the x86-64 baseline) arithmetic for the sky and sea passes. Each lane does
// the scalar code's operations in the scalar code's order, so a sample's result does not
// depend on its neighbours, the batch size or the thread count.

// e^x for x ≤ 0 (0 below −87, where e^x leaves float's normal range). Cody & Waite range
// reduction ("Software Manual for the Elementary Functions", 1980): x = k ln 2 + r with
// |r| ≤ ln 2 / 2 and ln 2 split into a 16-bit head (k·head exact) and a tail; e^r from its
// Taylor series to r⁷ (truncation < 1e-8 relative, below float precision); 2^k through the
// exponent bits. Within a few ulp of std::exp, and four lanes wide where libm is scalar.
F4 ExpNonPositive4(F4 x) {
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

// Normalizes count directions in place: v · (1 / √(v·v)), as glm::normalize.
void Normalize(size_t count, float* x, float* y, float* z) {
    for (size_t i = 0; i < count; i += 4) {
        const size_t lanes = std::min<size_t>(4, count - i);
        const F4 dx = LoadLanes(x + i, lanes, 0.0f), dy = LoadLanes(y + i, lanes, 0.0f),
                 dz = LoadLanes(z + i, lanes, 1.0f);
        const F4 inv = _mm_div_ps(Set4(1.0f), _mm_sqrt_ps(Dot4(dx, dy, dz, dx, dy, dz)));
        StoreLanes(x + i, lanes, _mm_mul_ps(dx, inv));
        StoreLanes(y + i, lanes, _mm_mul_ps(dy, inv));
        StoreLanes(z + i, lanes, _mm_mul_ps(dz, inv));
    }
}

// Four-lane RayBoxTest::MayHit: bit l of the result set when lane l may hit.
int MayHit4(const RayBoxTest& box, F4 ox, F4 oy, F4 oz) {
    const F4 o[3] = {ox, oy, oz};
    F4 t0 = _mm_setzero_ps(), t1 = Set4(std::numeric_limits<float>::infinity());
    F4 inside = _mm_castsi128_ps(_mm_set1_epi32(-1));
    for (int a = 0; a < 3; ++a) {
        if (RayBoxTest::Parallel(box.direction[a])) {
            inside = _mm_and_ps(inside, _mm_and_ps(_mm_cmpge_ps(o[a], Set4(box.lo[a])),
                                                   _mm_cmple_ps(o[a], Set4(box.hi[a]))));
            continue;
        }
        const F4 tA = _mm_mul_ps(_mm_sub_ps(Set4(box.lo[a]), o[a]), Set4(box.inverse[a]));
        const F4 tB = _mm_mul_ps(_mm_sub_ps(Set4(box.hi[a]), o[a]), Set4(box.inverse[a]));
        t0 = _mm_max_ps(t0, _mm_min_ps(tA, tB));
        t1 = _mm_min_ps(t1, _mm_max_ps(tA, tB));
    }
    return _mm_movemask_ps(_mm_and_ps(inside, _mm_cmple_ps(t0, t1)));
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

// Tag of shadow-ray owners that are sea samples (indices into the sea arrays).
constexpr uint32_t kSeaOwner = 1u << 31;

// Samples per shading chunk: the chunk's arrays stay in L1.
constexpr size_t kChunk = 256;

// Per-chunk intermediate arrays of the sea pass (and the sky pass's lookups).
struct SeaChunk {
    alignas(16) float rx[kChunk], ry[kChunk], rz[kChunk];  // reflected view ray, z ≥ 0
    alignas(16) float mvx[kChunk], mvy[kChunk];            // −v: toward the far airlight
    alignas(16) float range[kChunk], cosV[kChunk], cosS[kChunk], vh[kChunk];
    alignas(16) float cos2[kChunk], tan2[kChunk], sunVis[kChunk];
    alignas(16) float F[kChunk], Fs[kChunk];
    alignas(16) float skyR[kChunk], skyG[kChunk], skyB[kChunk];
    alignas(16) float horR[kChunk], horG[kChunk], horB[kChunk];
    alignas(16) float outR[kChunk], outG[kChunk], outB[kChunk];
};

// Sea radiance: Fresnel-weighted sky reflection plus water-leaving radiance, Cox–Munk sun
// glint, Koschmieder fog; the constants of one frame.
struct SeaShading {
    glm::vec3 eye, sunDir, sunE, downwelling;
    float beta, slopeVar;
    const radiometry::FresnelTable& fresnel;
    const radiometry::AnalyticSky& sky;

    // Shades count ≤ kChunk samples at positions p (m, world) with unit normals n, sun
    // visibility ch.sunVis; radiance (cd/m²) to ch.outR/G/B.
    void Shade(size_t count, const float* px, const float* py, const float* pz, const float* nx,
               const float* ny, const float* nz, SeaChunk& ch) const {
        // Geometry: view vector v, reflected ray r, glint half vector h.
        for (size_t i = 0; i < count; i += 4) {
            const size_t lanes = std::min<size_t>(4, count - i);
            const F4 Nx = LoadLanes(nx + i, lanes, 0.0f), Ny = LoadLanes(ny + i, lanes, 0.0f),
                     Nz = LoadLanes(nz + i, lanes, 1.0f);
            const F4 tx = _mm_sub_ps(Set4(eye.x), LoadLanes(px + i, lanes, 0.0f));
            const F4 ty = _mm_sub_ps(Set4(eye.y), LoadLanes(py + i, lanes, 0.0f));
            const F4 tz = _mm_sub_ps(Set4(eye.z), LoadLanes(pz + i, lanes, 0.0f));
            const F4 range = _mm_sqrt_ps(Dot4(tx, ty, tz, tx, ty, tz));
            // One division for the three components (differs from t / range by rounding).
            const F4 invRange = _mm_div_ps(Set4(1.0f), range);
            const F4 vx = _mm_mul_ps(tx, invRange), vy = _mm_mul_ps(ty, invRange),
                     vz = _mm_mul_ps(tz, invRange);
            const F4 ndv = Dot4(Nx, Ny, Nz, vx, vy, vz);
            const F4 twoNdv = _mm_mul_ps(Set4(2.0f), ndv);
            const F4 rz = _mm_sub_ps(_mm_mul_ps(twoNdv, Nz), vz);
            // A ray reflected into the sea meets the next wave's sky.
            _mm_store_ps(ch.rz + i, Select4(_mm_cmplt_ps(rz, _mm_setzero_ps()),
                                            _mm_sub_ps(_mm_setzero_ps(), rz), rz));
            _mm_store_ps(ch.rx + i, _mm_sub_ps(_mm_mul_ps(twoNdv, Nx), vx));
            _mm_store_ps(ch.ry + i, _mm_sub_ps(_mm_mul_ps(twoNdv, Ny), vy));
            _mm_store_ps(ch.mvx + i, _mm_sub_ps(_mm_setzero_ps(), vx));
            _mm_store_ps(ch.mvy + i, _mm_sub_ps(_mm_setzero_ps(), vy));
            _mm_store_ps(ch.range + i, range);
            _mm_store_ps(ch.cosV + i, Max4(ndv, Set4(1e-3f)));
            _mm_store_ps(ch.cosS + i,
                         Dot4(Nx, Ny, Nz, Set4(sunDir.x), Set4(sunDir.y), Set4(sunDir.z)));
            const F4 wx = _mm_add_ps(vx, Set4(sunDir.x)), wy = _mm_add_ps(vy, Set4(sunDir.y)),
                     wz = _mm_add_ps(vz, Set4(sunDir.z));
            const F4 inv = _mm_div_ps(Set4(1.0f), _mm_sqrt_ps(Dot4(wx, wy, wz, wx, wy, wz)));
            const F4 hx = _mm_mul_ps(wx, inv), hy = _mm_mul_ps(wy, inv), hz = _mm_mul_ps(wz, inv);
            const F4 cosB = Max4(Dot4(hx, hy, hz, Nx, Ny, Nz), Set4(1e-3f));
            const F4 cos2 = _mm_mul_ps(cosB, cosB);
            _mm_store_ps(ch.cos2 + i, cos2);
            _mm_store_ps(ch.tan2 + i, _mm_div_ps(_mm_sub_ps(Set4(1.0f), cos2), cos2));
            _mm_store_ps(ch.vh + i, Dot4(vx, vy, vz, hx, hy, hz));
        }
        sky.LookUp(count, ch.rx, ch.ry, ch.rz, ch.skyR, ch.skyG, ch.skyB);
        sky.HorizonLookUp(count, ch.mvx, ch.mvy, ch.horR, ch.horG, ch.horB);
        fresnel(count, ch.cosV, ch.F);
        fresnel(count, ch.vh, ch.Fs);

        const F4 zero = _mm_setzero_ps(), one = Set4(1.0f);
        const F4 glintLimit = Set4(60.0f * slopeVar);
        // Reciprocals of the frame's constants: multiplications in the loop, not divisions.
        const F4 minusInvSlopeVar = Set4(-1.0f / slopeVar);
        const F4 invGlintNorm = Set4(1.0f / (float(M_PI) * slopeVar));
        for (size_t i = 0; i < count; i += 4) {
            const F4 F = _mm_load_ps(ch.F + i), oneMinusF = _mm_sub_ps(one, F);
            const F4 cosV = _mm_load_ps(ch.cosV + i), cos2 = _mm_load_ps(ch.cos2 + i);
            const F4 tan2 = _mm_load_ps(ch.tan2 + i), sunVis = _mm_load_ps(ch.sunVis + i);
            // Cox–Munk glint: L = E_sun ρ(ω) p(β) / (4 cos θ_v cos⁴ β) (Cox & Munk 1954), β
            // the tilt of the reflecting facet from the local normal. Beyond e^-60 the glint
            // is below float precision next to the sky term.
            const F4 glint = _mm_and_ps(_mm_and_ps(_mm_cmpgt_ps(_mm_load_ps(ch.cosS + i), zero),
                                                   _mm_cmpgt_ps(sunVis, zero)),
                                        _mm_cmplt_ps(tan2, glintLimit));
            const F4 p =
                _mm_mul_ps(ExpNonPositive4(_mm_mul_ps(tan2, minusInvSlopeVar)), invGlintNorm);
            const F4 g =
                _mm_div_ps(_mm_mul_ps(_mm_load_ps(ch.Fs + i), p),
                           _mm_mul_ps(_mm_mul_ps(_mm_mul_ps(Set4(4.0f), cosV), cos2), cos2));
            // Koschmieder: the horizon sky is the airlight a long path converges to.
            const F4 t = ExpNonPositive4(_mm_mul_ps(Set4(-beta), _mm_load_ps(ch.range + i)));
            const F4 oneMinusT = _mm_sub_ps(one, t);
            const auto channel = [&](const float* skyC, const float* horC, float rrs, float dw,
                                     float sunEC, float* outC) {
                F4 L = _mm_add_ps(_mm_mul_ps(F, _mm_load_ps(skyC + i)),
                                  _mm_mul_ps(_mm_mul_ps(oneMinusF, Set4(rrs)), Set4(dw)));
                L = Select4(glint, _mm_add_ps(L, _mm_mul_ps(_mm_mul_ps(Set4(sunEC), g), sunVis)),
                            L);
                L = _mm_add_ps(_mm_mul_ps(L, t), _mm_mul_ps(_mm_load_ps(horC + i), oneMinusT));
                _mm_store_ps(outC + i, L);
            };
            channel(ch.skyR, ch.horR, kSeaRrs.r, downwelling.r, sunE.r, ch.outR);
            channel(ch.skyG, ch.horG, kSeaRrs.g, downwelling.g, sunE.g, ch.outG);
            channel(ch.skyB, ch.horB, kSeaRrs.b, downwelling.b, sunE.b, ch.outB);
        }
    }
};

// Per-thread scratch of the shading pass. Samples of a row block are sorted into sky, sea and
// model lists so that each kind is shaded in a tight loop: sky and sea four lanes at a time in
// structure-of-arrays chunks (the bulk of the frame), the few model samples one by one. The
// sky and sea lists only grow (their used length is counted separately), so that a block
// never zero-fills them.
struct BlockScratch {
    std::vector<uint32_t> skyK, seaK, modelK;                     // sample index within the block
    std::vector<float> skyX, skyY, skyZ;                          // view directions of sky samples
    std::vector<float> seaPx, seaPy, seaPz, seaNx, seaNy, seaNz;  // unit normals
    std::vector<glm::vec3> modelPosition, modelNormal;
    std::vector<int> modelMesh;
    std::vector<glm::vec3> origins;
    std::vector<uint8_t> lit, vis;  // lit: sun visibility of model samples, by k
    std::vector<float> seaLit;      // sun visibility of sea samples
    // originOwner: sample index k of a model sample, or kSeaOwner | sea index.
    std::vector<uint32_t> originOwner;
    SeaChunk chunk{};  // zeroed: lanes past a chunk's end are computed, then dropped

    // Makes the sky and sea lists hold at least n samples.
    void Reserve(size_t n) {
        if (skyK.size() >= n) return;
        for (std::vector<float>* v :
             {&skyX, &skyY, &skyZ, &seaPx, &seaPy, &seaPz, &seaNx, &seaNy, &seaNz})
            v->resize(n);
        skyK.resize(n), seaK.resize(n);
    }
};

// Vertex positions and normals of the triangle last met in a sample row, as SSE (x, y, z, 0):
// neighbouring samples mostly see the same triangle, so its six vertices are gathered once.
struct CachedTriangle {
    uint32_t prim = kNoPrimitive;
    int mesh = 0;
    F4 p0 = _mm_setzero_ps(), p1 = p0, p2 = p0, n0 = p0, n1 = p0, n2 = p0;
};

F4 Load3(const glm::vec3& v) { return _mm_setr_ps(v.x, v.y, v.z, 0.0f); }

// b0·a0 + b1·a1 + b2·a2 per component, in glm's order ((b0 a0 + b1 a1) + b2 a2).
F4 Interpolate3(F4 b0, F4 b1, F4 b2, F4 a0, F4 a1, F4 a2) {
    return _mm_add_ps(_mm_add_ps(_mm_mul_ps(b0, a0), _mm_mul_ps(b1, a1)), _mm_mul_ps(b2, a2));
}

}  // namespace

OtwChannel::OtwChannel(const scene::World& world, const scene::ChannelSettings& settings)
    : world_(world),
      settings_(settings),
      geometry_(world, settings),
      plumes_(std::make_unique<ChannelPlumes>(world)) {
    for (const scene::EntityState& e : world.State(0).entities)
        reflectance_.push_back(e.reflectanceRgb);
}

struct OtwChannel::ShadeScratch {
    tbb::enumerable_thread_specific<BlockScratch> perThread;
};

OtwChannel::~OtwChannel() = default;

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
    const scene::OceanMesh& ocean = geometry_.Ocean();
    const std::vector<scene::TriangleMesh>& entityMeshes = geometry_.EntityMeshes();
    const VisibilityBuffer& vis = geometry_.Visibility();
    const OcclusionScene& occlusion = geometry_.Occlusion();
    const ViewFrameStats& view = geometry_.Stats();

    stats_ = {};
    stats_.raster = view.raster;
    stats_.meshMs = view.meshMs;
    stats_.rasterMs = view.rasterMs;
    stats_.oceanTriangles = view.oceanTriangles;
    stats_.modelTriangles = view.modelTriangles;

    if (!sky_ || skySun_ != state.sun.direction || skySunLux_ != state.sun.illuminance_lux) {
        sky_ = std::make_unique<radiometry::AnalyticSky>(
            state.sun.direction, state.sun.illuminance_lux, env.sky.turbidity);
        skySun_ = state.sun.direction;
        skySunLux_ = state.sun.illuminance_lux;
    }
    const radiometry::AnalyticSky& sky = *sky_;
    const glm::vec3 sunDir(state.sun.direction);
    const glm::vec3 sunE(sky.SunIlluminance());
    const glm::vec3 sunL(sky.SunRadiance());
    const glm::vec3 skyE(sky.HorizontalSkyIlluminance());
    // Downwelling irradiance on the sea surface (lx): direct sun on a level surface plus sky.
    const glm::vec3 downwelling = sunE * std::max(sunDir.z, 0.0f) + skyE;
    const float cosSunRadius = float(std::cos(radiometry::kSunAngularRadius_rad));
    const float beta = float(ExtinctionFromVisibility(env.visibility_m));
    const float slopeVar = CoxMunkSlopeVariance(env.windSpeed_mps);
    static const radiometry::FresnelTable fresnel(radiometry::kSeaWaterIndexVisible);
    const glm::vec3 eye(cam.worldFromCamera.position_m);
    const bool shadows = settings_.shadows && !occlusion.Empty() && sunDir.z > 0.0f;

    if (radiance.width != sw || radiance.height != sh || radiance.channels != 3)
        radiance = Image(sw, sh, 3);
    constexpr int kRowsPerBlock = 8;
    const int blocks = (sh + kRowsPerBlock - 1) / kRowsPerBlock;
    std::vector<uint64_t> blockRays(size_t(blocks), 0);
    // View rays: direction = normalize(rowBase + x · colStep) (camera axes scaled by the
    // pinhole geometry), so sky samples need no trigonometry.
    const glm::dmat3& R = cam.worldFromCamera.worldFromBody;
    const double tanH = cam.TanHalfH(), tanV = cam.TanHalfV();
    const glm::vec3 colStep(R * glm::dvec3(2.0 * tanH / sw, 0.0, 0.0));
    const glm::dvec3 forward = R * glm::dvec3(0.0, 1.0, 0.0);

    // Per-thread scratch (see BlockScratch), created on the first frame.
    if (!scratch_) scratch_ = std::make_unique<ShadeScratch>();
    tbb::enumerable_thread_specific<BlockScratch>& scratch = scratch_->perThread;

    // Mesh m's primitives are [primitiveBase[m], primitiveBase[m + 1]); mesh 0 is the sea.
    struct MeshRef {
        const glm::vec3* P;
        const glm::vec3* N;
        const uint32_t* I;
    };
    std::vector<MeshRef> meshRefs;
    meshRefs.push_back({ocean.positions.data(), ocean.normals.data(), ocean.indices.data()});
    for (const scene::TriangleMesh& m : entityMeshes)
        meshRefs.push_back({m.positions.data(), m.normals.data(), m.indices.data()});
    const uint32_t firstModelPrimitive =
        vis.primitiveBase.size() > 1 ? vis.primitiveBase[1] : kNoPrimitive;

    const SeaShading seaShading{eye, sunDir, sunE, downwelling, beta, slopeVar, fresnel, sky};

    const RayBoxTest casters(geometry_.CasterMin(), geometry_.CasterMax(), sunDir);

    tbb::parallel_for(0, blocks, [&](int block) {
        const int y0 = block * kRowsPerBlock, y1 = std::min(sh, y0 + kRowsPerBlock);
        const size_t n = size_t(y1 - y0) * size_t(sw);
        BlockScratch& sc = scratch.local();
        sc.Reserve(n);
        sc.modelK.clear(), sc.modelPosition.clear(), sc.modelNormal.clear(), sc.modelMesh.clear();
        sc.lit.assign(n, 1);
        sc.origins.clear();
        sc.originOwner.clear();

        glm::vec3 rowBase[kRowsPerBlock];
        for (int y = y0; y < y1; ++y) {
            const double ndcY = 1.0 - 2.0 * (y + 0.5) / sh;
            rowBase[y - y0] = glm::vec3(forward + R * glm::dvec3(-tanH, 0.0, ndcY * tanV));
        }

        // Pass 1: sort samples by kind; surface position and normal.
        size_t skyCount = 0, seaCount = 0;
        CachedTriangle tri;
        for (int y = y0; y < y1; ++y) {
            const size_t rowIdx = vis.Index(0, y);
            const uint32_t* primRow = vis.primitive.data() + rowIdx;
            const float* b1Row = vis.b1.data() + rowIdx;
            const float* b2Row = vis.b2.data() + rowIdx;
            const uint32_t kRow = uint32_t(size_t(y - y0) * size_t(sw));
            for (int x = 0; x < sw; ++x) {
                const uint32_t k = kRow + uint32_t(x);
                const uint32_t prim = primRow[x];
                if (prim == kNoPrimitive) {
                    // View direction, normalized in the sky pass.
                    const glm::vec3 d = rowBase[y - y0] + (float(x) + 0.5f) * colStep;
                    sc.skyK[skyCount] = k;
                    sc.skyX[skyCount] = d.x, sc.skyY[skyCount] = d.y, sc.skyZ[skyCount] = d.z;
                    ++skyCount;
                    continue;
                }
                if (prim != tri.prim) {
                    int mesh = 0;
                    if (prim >= firstModelPrimitive) {
                        mesh = 1;
                        while (mesh + 1 < int(vis.primitiveBase.size()) &&
                               prim >= vis.primitiveBase[size_t(mesh) + 1])
                            ++mesh;
                    }
                    const MeshRef& m = meshRefs[size_t(mesh)];
                    const uint32_t t = prim - vis.primitiveBase[size_t(mesh)];
                    const uint32_t i0 = m.I[3 * t], i1 = m.I[3 * t + 1], i2 = m.I[3 * t + 2];
                    tri.prim = prim, tri.mesh = mesh;
                    tri.p0 = Load3(m.P[i0]), tri.p1 = Load3(m.P[i1]), tri.p2 = Load3(m.P[i2]);
                    tri.n0 = Load3(m.N[i0]), tri.n1 = Load3(m.N[i1]), tri.n2 = Load3(m.N[i2]);
                }
                const float b1 = b1Row[x], b2 = b2Row[x], b0 = 1.0f - b1 - b2;
                const F4 w0 = Set4(b0), w1 = Set4(b1), w2 = Set4(b2);
                alignas(16) float p[4], nSum[4];
                _mm_store_ps(p, Interpolate3(w0, w1, w2, tri.p0, tri.p1, tri.p2));
                _mm_store_ps(nSum, Interpolate3(w0, w1, w2, tri.n0, tri.n1, tri.n2));
                if (tri.mesh == 0) {
                    // Normalized, and shadow origins found, four lanes at a time below.
                    sc.seaK[seaCount] = k;
                    sc.seaPx[seaCount] = p[0], sc.seaPy[seaCount] = p[1], sc.seaPz[seaCount] = p[2];
                    sc.seaNx[seaCount] = nSum[0], sc.seaNy[seaCount] = nSum[1];
                    sc.seaNz[seaCount] = nSum[2];
                    ++seaCount;
                    continue;
                }
                const glm::vec3 position(p[0], p[1], p[2]);
                glm::vec3 nrm = glm::normalize(glm::vec3(nSum[0], nSum[1], nSum[2]));
                if (glm::dot(nrm, eye - position) < 0.0f) nrm = -nrm;
                sc.modelK.push_back(k);
                sc.modelPosition.push_back(position);
                sc.modelNormal.push_back(nrm);
                sc.modelMesh.push_back(tri.mesh);
                if (shadows) {
                    const glm::vec3 o = ShadowRayOrigin(position, nrm);
                    if (casters.MayHit(o) && occlusion.MayOcclude(o, sunDir, 1e30f)) {
                        sc.origins.push_back(o);
                        sc.originOwner.push_back(k);
                    }
                }
            }
        }
        sc.seaLit.assign(seaCount, 1.0f);
        Normalize(seaCount, sc.seaNx.data(), sc.seaNy.data(), sc.seaNz.data());
        if (shadows) {
            // Sea shadow-ray origins: ShadowRayOrigin and the caster prefilter, four lanes
            // wide; the few candidates go through MayOcclude.
            for (size_t i = 0; i < seaCount; i += 4) {
                const size_t lanes = std::min<size_t>(4, seaCount - i);
                const F4 px = LoadLanes(&sc.seaPx[i], lanes, eye.x);
                const F4 py = LoadLanes(&sc.seaPy[i], lanes, eye.y);
                const F4 pz = LoadLanes(&sc.seaPz[i], lanes, eye.z);
                // ShadowOffset_m, four lanes.
                const F4 maxAbs = _mm_max_ps(_mm_max_ps(Abs4(px), Abs4(py)), Abs4(pz));
                const F4 offset = _mm_add_ps(_mm_mul_ps(Set4(4e-6f), maxAbs), Set4(1e-3f));
                alignas(16) float o[3][4];
                _mm_store_ps(
                    o[0], _mm_add_ps(px, _mm_mul_ps(LoadLanes(&sc.seaNx[i], lanes, 0.0f), offset)));
                _mm_store_ps(
                    o[1], _mm_add_ps(py, _mm_mul_ps(LoadLanes(&sc.seaNy[i], lanes, 0.0f), offset)));
                _mm_store_ps(
                    o[2], _mm_add_ps(pz, _mm_mul_ps(LoadLanes(&sc.seaNz[i], lanes, 1.0f), offset)));
                int hit = MayHit4(casters, _mm_load_ps(o[0]), _mm_load_ps(o[1]), _mm_load_ps(o[2]));
                hit &= (1 << lanes) - 1;
                for (; hit != 0; hit &= hit - 1) {
                    const int l = __builtin_ctz(unsigned(hit));
                    const glm::vec3 origin(o[0][l], o[1][l], o[2][l]);
                    if (occlusion.MayOcclude(origin, sunDir, 1e30f)) {
                        sc.origins.push_back(origin);
                        sc.originOwner.push_back(kSeaOwner | uint32_t(i + size_t(l)));
                    }
                }
            }
        }
        if (!sc.origins.empty()) {
            sc.vis.resize(sc.origins.size());
            occlusion.DirectionalVisibility(sc.origins, sunDir, 0.0f, sc.vis);
            for (size_t r = 0; r < sc.origins.size(); ++r) {
                const uint32_t owner = sc.originOwner[r];
                if (owner & kSeaOwner)
                    sc.seaLit[owner & ~kSeaOwner] = float(sc.vis[r]);
                else
                    sc.lit[owner] = sc.vis[r];
            }
            blockRays[size_t(block)] = sc.origins.size();
        }

        // The block's rows are contiguous in the image: sample k is at out + 3k.
        float* out = radiance.At(0, y0);

        // Pass 2a: sky samples.
        for (size_t c = 0; c < skyCount; c += kChunk) {
            const size_t count = std::min(kChunk, skyCount - c);
            float *dx = &sc.skyX[c], *dy = &sc.skyY[c], *dz = &sc.skyZ[c];
            Normalize(count, dx, dy, dz);
            SeaChunk& ch = sc.chunk;
            sky.LookUp(count, dx, dy, dz, ch.skyR, ch.skyG, ch.skyB);
            for (size_t i = 0; i < count; ++i) {
                glm::vec3 L(ch.skyR[i], ch.skyG[i], ch.skyB[i]);
                if (glm::dot(glm::vec3(dx[i], dy[i], dz[i]), sunDir) >= cosSunRadius) L += sunL;
                float* o = out + 3 * size_t(sc.skyK[c + i]);
                o[0] = L.r, o[1] = L.g, o[2] = L.b;
            }
        }

        // Pass 2b: sea samples.
        for (size_t c = 0; c < seaCount; c += kChunk) {
            const size_t count = std::min(kChunk, seaCount - c);
            SeaChunk& ch = sc.chunk;
            std::copy_n(&sc.seaLit[c], count, ch.sunVis);
            seaShading.Shade(count, &sc.seaPx[c], &sc.seaPy[c], &sc.seaPz[c], &sc.seaNx[c],
                             &sc.seaNy[c], &sc.seaNz[c], ch);
            for (size_t i = 0; i < count; ++i) {
                float* o = out + 3 * size_t(sc.seaK[c + i]);
                o[0] = ch.outR[i], o[1] = ch.outG[i], o[2] = ch.outB[i];
            }
        }

        // Pass 2c: model samples (a small fraction of the frame).
        for (size_t i = 0; i < sc.modelK.size(); ++i) {
            const glm::vec3 p = sc.modelPosition[i], nrm = sc.modelNormal[i];
            const glm::vec3 toEye = eye - p;
            const float range = glm::length(toEye);
            const glm::vec3 v = toEye / range;
            const float sunVis = float(sc.lit[sc.modelK[i]]);
            const glm::vec3 rho(reflectance_[size_t(sc.modelMesh[i]) - 1]);
            const glm::vec3 E = sunE * std::max(glm::dot(nrm, sunDir), 0.0f) * sunVis +
                                skyE * (0.5f * (1.0f + nrm.z)) +
                                kSeaAlbedo * downwelling * (0.5f * (1.0f - nrm.z));
            glm::vec3 L = rho * E * float(1.0 / M_PI);
            // Koschmieder: the horizon sky is the airlight a long path converges to.
            const float t = std::exp(-beta * range);
            const glm::vec3 horizon = sky.HorizonLookUp(-v);
            L = L * t + horizon * (1.0f - t);
            float* o = out + 3 * size_t(sc.modelK[i]);
            o[0] = L.r, o[1] = L.g, o[2] = L.b;
        }
    });
    for (uint64_t r : blockRays) stats_.shadowRays += r;
    stats_.shadeMs = Ms(t2, Clock::now());

    // Plumes (channels/plume) over the finished radiance.
    plumes_->CompositeOtw(state, cam, vis, sky, radiance);
}

}  // namespace seasense::channels
