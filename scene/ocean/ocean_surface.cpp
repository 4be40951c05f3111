// Ocean surface frames: FFT fields repacked into mip chains for band-limited lookups, Gerstner
// waves, the inverse-displacement query, a per-time frame cache and the sea's statistics.
#include "scene/ocean/ocean_surface.h"

#include <immintrin.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <numbers>
#include <string>

#include "scene/core/check.h"
#include "scene/core/error.h"
#include "scene/core/rng.h"
#include "scene/core/simd_lanes.h"
#include "scene/ocean/sea_state.h"

namespace seasense::scene {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
// Frames kept by OceanSurface::At: the current frame time and the one before, so the host's
// wave riding and a renderer's mesh of one frame share a synthesis.
constexpr size_t kCachedFrames = 2;
// Random streams of the surf components (apart from the FFT's, which use small stream ids).
constexpr uint64_t kSurfDirectionStream = 0x53555246'00000001ULL;
constexpr uint64_t kSurfPhaseStream = 0x53555246'00000002ULL;

// Adds w00 a + w10 b + w01 d + w11 e to sums, the texels a = (i0, j0), b = (i1, j0),
// d = (i0, j1), e = (i1, j1) of a level of n × n texels (row-major, kGeometryTerms floats each):
// sums[k] += ((w00 a + w10 b) + w01 d) + w11 e, a vector of terms at a time (all eight with
// AVX, four with SSE2): the same single-precision operations in the same order as one term at
// a time, so the same bits.
void AddTexels(const float* texels, int n, int i0, int j0, float w00, float w10, float w01,
               float w11, GeometrySums& sums) {
    const int i1 = (i0 + 1) & (n - 1), j1 = (j0 + 1) & (n - 1);
    const float* a = texels + (size_t(i0) * size_t(n) + size_t(j0)) * kGeometryTerms;
    const float* b = texels + (size_t(i1) * size_t(n) + size_t(j0)) * kGeometryTerms;
    const float* d = texels + (size_t(i0) * size_t(n) + size_t(j1)) * kGeometryTerms;
    const float* e = texels + (size_t(i1) * size_t(n) + size_t(j1)) * kGeometryTerms;
    static_assert(kGeometryTerms % simd::kLanes == 0);
    const simd::VF v00 = simd::Splat(w00), v10 = simd::Splat(w10);
    const simd::VF v01 = simd::Splat(w01), v11 = simd::Splat(w11);
    for (size_t k = 0; k < size_t(kGeometryTerms); k += simd::kLanes) {
        const simd::VF term =
            ((v00 * simd::Load(a + k) + v10 * simd::Load(b + k)) + v01 * simd::Load(d + k)) +
            v11 * simd::Load(e + k);
        simd::Store(&sums[k], simd::Load(&sums[k]) + term);
    }
}

// Bilinear lookup of mip level `level` of a cascade texture at rest position (x0, y0), weighted
// by `weight`, added to sums. Texel i of level l is centred on the mean of the nodes it averages,
// (i 2^l + (2^l − 1)/2) Δ, hence the half-texel shifts: the lookup is at texel coordinates
// (x0 + Δ/2) / (2^l Δ) − ½, taken as ((x0 + Δ/2) / Δ) · 2^−l − ½ from (qx, qy) = (x0 + Δ/2) / Δ,
// which the levels of one cascade share. The same bits: a correctly rounded quotient scaled by a
// power of two is the correctly rounded quotient by the scaled divisor (no underflow here).
template <class Texture>
void AddBilinear(const Texture& c, int level, double qx, double qy, float weight,
                 GeometrySums& sums) {
    const int n = c.n >> level;
    const double scale = 1.0 / double(1 << level);
    const double u = qx * scale - 0.5;
    const double v = qy * scale - 0.5;
    const double fu = std::floor(u), fv = std::floor(v);
    const float wx = float(u - fu), wy = float(v - fv);
    // Power-of-two periodic wrap; two's complement makes the mask right for negative indices.
    const int i0 = int(int64_t(fu) & (n - 1)), j0 = int(int64_t(fv) & (n - 1));
    const float w00 = weight * (1.0f - wx) * (1.0f - wy), w10 = weight * wx * (1.0f - wy);
    const float w01 = weight * (1.0f - wx) * wy, w11 = weight * wx * wy;
    AddTexels(c.levels[size_t(level)].data()->v.data(), n, i0, j0, w00, w10, w01, w11, sums);
}

// Four doubles and four floats as GCC vectors (two SSE2 registers, or one AVX register, for
// the doubles): each operation is the IEEE operation per lane.
using D4 = double __attribute__((vector_size(32)));
using F4 = float __attribute__((vector_size(16)));

D4 LoadD4(const double* p) {
    D4 v;
    std::memcpy(&v, p, sizeof v);
    return v;
}

D4 Floor4(D4 v) {
#if defined(__AVX__)
    return _mm256_floor_pd(v);
#else
    for (int k = 0; k < 4; ++k) v[k] = std::floor(v[k]);
    return v;
#endif
}

}  // namespace

// ---- frame ------------------------------------------------------------------------------------

void OceanSurfaceFrame::BuildTextures() {
    const size_t cascades = fft_.CascadeCount();
    const int n = fft_.GridSize();
    const float l = float(fft_.Choppiness());
    const int levelCount = std::countr_zero(unsigned(n)) + 1;
    textures_.resize(cascades);
    cascadeBounds_.resize(cascades);
    maxHeight_m_ = maxHorizontal_m_ = 0.0;
    for (size_t c = 0; c < cascades; ++c) {
        CascadeTexture& tex = textures_[c];
        tex.patch_m = fft_.PatchSize_m(c);
        tex.texel_m = tex.patch_m / n;
        tex.n = n;
        tex.levels.resize(size_t(levelCount));
        for (int lv = 0; lv < levelCount; ++lv)
            tex.levels[size_t(lv)].resize(size_t(n >> lv) * size_t(n >> lv));
        // Level 0 from the transposed planes (row ix): {η, Dx}, {Dy, ηx}, {ηy, Dxx}, {Dyy, Dxy}.
        std::vector<float> rowHeight(static_cast<size_t>(n)), rowHorizontal(static_cast<size_t>(n));
        const cv::Mat* p[4];
        for (int q = 0; q < 4; ++q) p[q] = &fft_.FieldPlane(c, q);
        std::vector<Texel>& level0 = tex.levels[0];
        tbb::parallel_for(0, n, [&](int ix) {
            const cv::Vec2f* r0 = p[0]->ptr<cv::Vec2f>(ix);
            const cv::Vec2f* r1 = p[1]->ptr<cv::Vec2f>(ix);
            const cv::Vec2f* r2 = p[2]->ptr<cv::Vec2f>(ix);
            const cv::Vec2f* r3 = p[3]->ptr<cv::Vec2f>(ix);
            Texel* out = level0.data() + size_t(ix) * size_t(n);
            float maxH = 0.0f, maxD2 = 0.0f;
            for (int iy = 0; iy < n; ++iy) {
                out[iy].v = {r0[iy][0], l * r0[iy][1], l * r1[iy][0], r1[iy][1],
                             r2[iy][0], l * r2[iy][1], l * r3[iy][0], l * r3[iy][1]};
                maxH = std::max(maxH, std::abs(r0[iy][0]));
                maxD2 = std::max(maxD2, out[iy].v[kTermDispX] * out[iy].v[kTermDispX] +
                                            out[iy].v[kTermDispY] * out[iy].v[kTermDispY]);
            }
            rowHeight[size_t(ix)] = maxH;
            rowHorizontal[size_t(ix)] = std::sqrt(maxD2);
        });
        // The bilinear surface never exceeds its nodes; the cascades' maxima bound the sum.
        cascadeBounds_[c] = {*std::max_element(rowHeight.begin(), rowHeight.end()),
                             *std::max_element(rowHorizontal.begin(), rowHorizontal.end())};
        maxHeight_m_ += cascadeBounds_[c].height_m;
        maxHorizontal_m_ += cascadeBounds_[c].horizontal_m;
        for (int lv = 1; lv < levelCount; ++lv) {
            const int m = n >> lv;
            const std::vector<Texel>& fine = tex.levels[size_t(lv - 1)];
            std::vector<Texel>& coarse = tex.levels[size_t(lv)];
            tbb::parallel_for(0, m, [&](int i) {
                for (int j = 0; j < m; ++j) {
                    const size_t f = size_t(2 * i) * size_t(2 * m) + size_t(2 * j);
                    const size_t g = f + size_t(2 * m);
                    for (int k = 0; k < kGeometryTerms; ++k)
                        coarse[size_t(i) * size_t(m) + size_t(j)].v[size_t(k)] =
                            0.25f * ((fine[f].v[size_t(k)] + fine[f + 1].v[size_t(k)]) +
                                     (fine[g].v[size_t(k)] + fine[g + 1].v[size_t(k)]));
                }
            });
        }
    }
}

namespace {

// Half the step of SeabedWithSlope's differences, m.
constexpr double kSlopeStep_m = 0.05;

// Seabed under the displaced point and its slope (central differences over 0.1 m), for the clamp.
glm::dvec3 SeabedWithSlope(const Bathymetry& b, double x, double y) {
    constexpr double d = kSlopeStep_m;
    return {b.SeabedZ_m(x, y), (b.SeabedZ_m(x + d, y) - b.SeabedZ_m(x - d, y)) / (2.0 * d),
            (b.SeabedZ_m(x, y + d) - b.SeabedZ_m(x, y - d)) / (2.0 * d)};
}

}  // namespace

SurfaceTerms OceanSurfaceFrame::Terms(double x0, double y0) const {
    if (!surf_) {
        SurfaceTerms t = gerstner_.Terms(x0, y0, t_s_);
        if (hasFft_) t += fft_.Terms(x0, y0);
        return t;
    }
    SurfPointInfo info;
    const SurfaceTerms s = surf_->Terms(x0, y0, t_s_, &info);
    SurfaceTerms t = gerstner_.Terms(x0, y0, t_s_);
    if (const double w = info.weights.gerstner; w != 1.0) {
        t.displacement *= w;
        t.dxx *= w, t.dyy *= w, t.dxy *= w, t.sx *= w, t.sy *= w;
        t.velocity_mps *= w;
    }
    if (hasFft_) t += fft_.Terms(x0, y0, info.weights.cascade.data());
    t += s;
    t.displacement.z += surf_->Bathy().Tide_m();
    // The water never lies below the seabed (seed 003): where it would, it lies on it, still.
    const double zBed = surf_->Bathy().SeabedZ_m(x0 + t.displacement.x, y0 + t.displacement.y);
    if (t.displacement.z < zBed) {
        const glm::dvec3 bed =
            SeabedWithSlope(surf_->Bathy(), x0 + t.displacement.x, y0 + t.displacement.y);
        t.displacement.z = bed.x;
        t.sx = bed.y, t.sy = bed.z;
        t.velocity_mps = glm::dvec3(0.0);
    }
    return t;
}

void OceanSurfaceFrame::AddSurf(double x0, double y0, const SurfaceTerms& s,
                                GeometrySums& sums) const {
    CHECK(surf_);
    sums[kTermHeight] += float(s.displacement.z + surf_->Bathy().Tide_m());
    sums[kTermDispX] += float(s.displacement.x);
    sums[kTermDispY] += float(s.displacement.y);
    sums[kTermSlopeX] += float(s.sx);
    sums[kTermSlopeY] += float(s.sy);
    sums[kTermDispXX] += float(s.dxx);
    sums[kTermDispYY] += float(s.dyy);
    sums[kTermDispXY] += float(s.dxy);
    const double x = x0 + double(sums[kTermDispX]), y = y0 + double(sums[kTermDispY]);
    const double zBed = surf_->Bathy().SeabedZ_m(x, y);
    if (double(sums[kTermHeight]) < zBed) {
        const glm::dvec3 bed = SeabedWithSlope(surf_->Bathy(), x, y);
        sums[kTermHeight] = float(bed.x);
        sums[kTermSlopeX] = float(bed.y);
        sums[kTermSlopeY] = float(bed.z);
    }
}

void OceanSurfaceFrame::AddOpenSea(GeometrySums& sums) const {
    CHECK(surf_);
    // AddSurf's additions of SurfWaves::Terms' all-deep result (SurfaceTerms{}, the swash's 0
    // added to its height), without the seabed lookup.
    const SurfaceTerms zero;
    sums[kTermHeight] += float(zero.displacement.z + surf_->Bathy().Tide_m());
    for (const GeometryTerm k :
         {kTermDispX, kTermDispY, kTermSlopeX, kTermSlopeY, kTermDispXX, kTermDispYY, kTermDispXY})
        sums[k] += float(0.0);
}

bool OceanSurfaceFrame::DryLandSums(double x0, double y0, GeometrySums& sums,
                                    double* seabedZ_m) const {
    CHECK(surf_);
    const Bathymetry& bathy = surf_->Bathy();
    // At depth ≤ 0 every part of the deep sea has faded out (fade weights 0 below half their
    // fade depths) and SurfWaves::Terms adds only the swash: the water stands at tide + ζ with
    // no horizontal displacement, ζ ≤ Swash().max_m. Above that (1 mm more for float rounding)
    // the seabed clamp always applies at the rest position itself.
    constexpr double kRoundingMargin_m = 1e-3;
    // The seabed as SurfWaves::Terms finds it (through the shore frame: the same bits as
    // SeabedZ_m but on a depth grid, where the two differ by the round trip's rounding, far
    // below the margin).
    const ShorePoint p = bathy.Frame().ShoreFromWorld(x0, y0);
    const double zBed = bathy.SeabedZAtShore_m(p.s_m, p.u_m);
    if (!(zBed > bathy.Tide_m() + surf_->Swash().max_m + kRoundingMargin_m)) {
        if (seabedZ_m) *seabedZ_m = zBed;
        return false;
    }
    // On the level land behind the beach the five seabed samples are one constant, zBed (the
    // same lookup at the same shore point), and both differences (z − z) / 0.1 = +0 exactly. The
    // samples lie within 0.05 m of the point; 0.1 m covers the shore frame's rounding.
    const glm::dvec3 bed = bathy.LevelLandAround(p.s_m, 2.0 * kSlopeStep_m)
                               ? glm::dvec3(zBed, 0.0, 0.0)
                               : SeabedWithSlope(bathy, x0, y0);
    sums = GeometrySums{};
    sums[kTermHeight] = float(bed.x);
    sums[kTermSlopeX] = float(bed.y);
    sums[kTermSlopeY] = float(bed.z);
    return true;
}

OceanSample OceanSurfaceFrame::SampleAt(double x, double y, glm::dvec2* rest) const {
    return InvertHorizontalDisplacement(
        x, y, [this](double x0, double y0) { return Evaluate(x0, y0); }, rest);
}

FftFilter OceanSurfaceFrame::Filter(float footprint_m) const {
    FftFilter f;
    CHECK(textures_.size() <= size_t(FftFilter::kMaxCascades));
    int lastLevel = 0;  // the level of the last lookup added
    const auto add = [&](size_t c, int level, float factor) {
        const CascadeTexture& t = textures_[c];
        const size_t l = size_t(f.lookups++);
        f.cascade[l] = int(c);
        f.texel[l] = t.texel_m;
        f.halfTexel[l] = 0.5 * t.texel_m;
        f.scale[l] = 1.0 / double(1 << level);
        f.n[l] = t.n >> level;
        f.size[l] = double(f.n[l]);
        f.invSize[l] = 1.0 / f.size[l];
        f.factor[l] = factor;
        f.texels[l] = t.levels[size_t(level)].data()->v.data();
        lastLevel = level;
    };
    for (size_t c = 0; c < textures_.size(); ++c) {
        const CascadeTexture& t = textures_[c];
        const int top = int(t.levels.size()) - 1;
        float lod =
            footprint_m > float(t.texel_m) ? std::log2(footprint_m / float(t.texel_m)) : 0.0f;
        lod = std::min(lod, float(top));
        f.level[c] = int(lod);
        f.frac[c] = lod - float(f.level[c]);
        add(c, f.level[c], 1.0f - f.frac[c]);
        if (f.frac[c] > 0.0f) add(c, f.level[c] + 1, f.frac[c]);
    }
    static_assert(sizeof(Texel) == sizeof(GeometrySums));  // texels read as rows of floats
    // Pad to whole groups of four with copies of the last lookup (read, never added).
    const int lookups = f.lookups;
    while (lookups > 0 && f.lookups % 4 != 0)
        add(size_t(f.cascade[size_t(lookups - 1)]), lastLevel, f.factor[size_t(lookups - 1)]);
    f.lookups = lookups;
    return f;
}

void OceanSurfaceFrame::AccumulateFft(double x0, double y0, const FftFilter& filter,
                                      GeometrySums& sums, const double* cascadeWeights) const {
    // AddBilinear's operations, lane for lane, four lookups at a time; the texels are then added
    // one lookup after the other in AccumulateFftOneByOne's order.
    for (int g = 0; g < filter.lookups; g += 4) {
        const size_t l = size_t(g);
        const D4 texel = LoadD4(&filter.texel[l]), half = LoadD4(&filter.halfTexel[l]);
        const D4 scale = LoadD4(&filter.scale[l]);
        const D4 u = ((x0 + half) / texel) * scale - 0.5;
        const D4 v = ((y0 + half) / texel) * scale - 0.5;
        const D4 fu = Floor4(u), fv = Floor4(v);
        const F4 wx = __builtin_convertvector(u - fu, F4), wy = __builtin_convertvector(v - fv, F4);
        // int64_t(fu) & (n − 1) exactly, in double: fu − n ⌊fu · 1/n⌋ (n a power of two, fu a
        // whole number: every step is exact), in [0, n).
        const D4 size = LoadD4(&filter.size[l]), invSize = LoadD4(&filter.invSize[l]);
        const D4 iu = fu - size * Floor4(fu * invSize), iv = fv - size * Floor4(fv * invSize);
        // × 1 is exact: unweighted cascades add the same bits as without weights.
        F4 w, weight;
        for (int k = 0; k < 4; ++k) {
            w[k] = cascadeWeights ? float(cascadeWeights[filter.cascade[l + size_t(k)]]) : 1.0f;
            weight[k] = filter.factor[l + size_t(k)] * w[k];
        }
        const F4 one = F4{} + 1.0f;
        const F4 w00 = weight * (one - wx) * (one - wy), w10 = weight * wx * (one - wy);
        const F4 w01 = weight * (one - wx) * wy, w11 = weight * wx * wy;
        const int end = std::min(4, filter.lookups - g);
        for (int k = 0; k < end; ++k) {
            if (w[k] == 0.0f) continue;
            AddTexels(filter.texels[l + size_t(k)], filter.n[l + size_t(k)], int(iu[k]), int(iv[k]),
                      w00[k], w10[k], w01[k], w11[k], sums);
        }
    }
}

void OceanSurfaceFrame::AccumulateFftOneByOne(double x0, double y0, const FftFilter& filter,
                                              GeometrySums& sums,
                                              const double* cascadeWeights) const {
    for (size_t c = 0; c < textures_.size(); ++c) {
        // × 1 is exact: unweighted cascades add the same bits as without weights.
        const float w = cascadeWeights ? float(cascadeWeights[c]) : 1.0f;
        if (w == 0.0f) continue;
        const float f = filter.frac[c];
        const CascadeTexture& t = textures_[c];
        const double qx = (x0 + 0.5 * t.texel_m) / t.texel_m;
        const double qy = (y0 + 0.5 * t.texel_m) / t.texel_m;
        AddBilinear(t, filter.level[c], qx, qy, (1.0f - f) * w, sums);
        if (f > 0.0f) AddBilinear(t, filter.level[c] + 1, qx, qy, f * w, sums);
    }
}

glm::vec3 OceanSurfaceFrame::DetailNormal(double x0, double y0, float footprint_m) const {
    GeometrySums sums{};
    // In a surf zone the parts carry their depth weights, as in the mesh, plus the surf
    // components' own slopes (long waves: unfiltered).
    SurfPointInfo info;
    SurfaceTerms surfTerms;
    if (surf_) surfTerms = surf_->Terms(x0, y0, t_s_, &info);
    AccumulateFft(x0, y0, Filter(footprint_m), sums, surf_ ? info.weights.cascade.data() : nullptr);
    const double wg = info.weights.gerstner;
    if (gerstner_.WaveCount() > 0 && wg > 0.0) {
        const SurfaceTerms g = gerstner_.Terms(x0, y0, t_s_, footprint_m);
        sums[kTermSlopeX] += float(wg * g.sx);
        sums[kTermSlopeY] += float(wg * g.sy);
        sums[kTermDispXX] += float(wg * g.dxx);
        sums[kTermDispYY] += float(wg * g.dyy);
        sums[kTermDispXY] += float(wg * g.dxy);
    }
    if (surf_ && !info.weights.AllDeep()) {
        sums[kTermSlopeX] += float(surfTerms.sx);
        sums[kTermSlopeY] += float(surfTerms.sy);
        sums[kTermDispXX] += float(surfTerms.dxx);
        sums[kTermDispYY] += float(surfTerms.dyy);
        sums[kTermDispXY] += float(surfTerms.dxy);
    }
    return GeometryNormal(sums);
}

// ---- surface ----------------------------------------------------------------------------------

struct OceanSurface::Cache {
    std::mutex mutex;
    std::vector<std::shared_ptr<OceanSurfaceFrame>> frames;  // oldest first
};

OceanSurface::OceanSurface(const OceanSettings& settings)
    : settings_(settings), gerstner_(settings), cache_(std::make_unique<Cache>()) {
    if (settings_.spectral) {
        SpectrumSettings sea = ResolveSeaState(settings_.spectral->sea);
        sea.depth_m = settings_.depth_m;  // one water depth for every wave
        spectrum_ = std::make_unique<const WaveSpectrum>(sea);
        fft_ = std::make_unique<const FftOcean>(*spectrum_, settings_.spectral->fft);
    }
    Summarize();
    if (settings_.surf) surf_ = MakeSurfWaves();
}

// The surf components: the spectral sea's variance carried by 12 components around its peak,
// plus every Gerstner wave as itself (see surf_waves.h for why).
std::shared_ptr<const SurfWaves> OceanSurface::MakeSurfWaves() const {
    const Bathymetry bathy(*settings_.surf, settings_.depth_m);
    std::vector<SurfComponent> components;
    double peakWavelength = summary_.peakWavelength_m;
    if (fft_ && spectrum_ && fft_->ModeVariance_m2() > 0.0 &&
        std::isfinite(summary_.peakPeriod_s)) {
        constexpr int kComponents = 12;
        // ±20° about the dominant direction: the half-width of cos^2s spreading with s ≈ 10–25
        // near the peak (Mitsuyasu et al. 1975; Goda, Random Seas and Design of Maritime
        // Structures, 2000, §2.3).
        constexpr double kSpread_rad = 20.0 * std::numbers::pi / 180.0;
        const double wp = kTwoPi / summary_.peakPeriod_s;
        const uint64_t seed = settings_.spectral->fft.seed;
        std::vector<double> weight(kComponents);
        double total = 0.0;
        for (int j = 0; j < kComponents; ++j) {
            const double w = wp * (0.8 + 0.8 * (j + 0.5) / kComponents);
            weight[size_t(j)] = spectrum_->DensityOmega(w);
            total += weight[size_t(j)];
        }
        for (int j = 0; j < kComponents && total > 0.0; ++j) {
            SurfComponent c;
            c.omega_radps = wp * (0.8 + 0.8 * (j + 0.5) / kComponents);
            // Σ A²/2 = the FFT's variance, shared in proportion to S(ω).
            c.amplitude_m = std::sqrt(2.0 * fft_->ModeVariance_m2() * weight[size_t(j)] / total);
            c.direction_rad =
                summary_.dominantDirection_rad +
                kSpread_rad * (2.0 * Uniform01(seed, kSurfDirectionStream, uint64_t(j)) - 1.0);
            c.phase_rad = kTwoPi * Uniform01(seed, kSurfPhaseStream, uint64_t(j));
            c.spectral = true;
            components.push_back(c);
        }
    }
    for (size_t i = 0; i < gerstner_.WaveCount(); ++i) {
        SurfComponent c;
        c.amplitude_m = gerstner_.Amplitude_m(i);
        c.omega_radps = gerstner_.Omega_radps(i);
        c.direction_rad = gerstner_.Direction_rad(i);
        c.phase_rad = settings_.waves[i].phase_rad;
        components.push_back(c);
    }
    if (!(peakWavelength > 0.0)) peakWavelength = 100.0;  // flat sea: any fade depth will do
    // Each cascade fades with its own wavelength (see surf_waves.h): the peak wavelength for a
    // cascade holding the peak or longer waves, else the median wavelength of its slopes.
    std::vector<SurfCascade> cascades;
    if (fft_) {
        const double kPeak = kTwoPi / peakWavelength;
        for (const CascadeBand& b : fft_->Cascades()) {
            SurfCascade c;
            c.variance_m2 = b.variance_m2;
            c.wavelength_m = b.kMin_radpm <= kPeak || !(b.slopeMedian_radpm > 0.0)
                                 ? peakWavelength
                                 : kTwoPi / b.slopeMedian_radpm;
            cascades.push_back(c);
        }
    }
    return std::make_shared<const SurfWaves>(bathy, std::move(components), peakWavelength,
                                             std::move(cascades));
}

OceanSurface::~OceanSurface() = default;
OceanSurface::OceanSurface(OceanSurface&&) noexcept = default;
OceanSurface& OceanSurface::operator=(OceanSurface&&) noexcept = default;

void OceanSurface::Fill(OceanSurfaceFrame& frame, double t, bool withVelocity) const {
    if (fft_) fft_->Synthesize(t, frame.fft_, withVelocity);
    Complete(frame, t);
}

void OceanSurface::Complete(OceanSurfaceFrame& frame, double t) const {
    frame.t_s_ = t;
    frame.gerstner_ = gerstner_;
    frame.significantHeight_m_ = summary_.significantHeight_m;
    frame.hasFft_ = fft_ != nullptr;
    frame.maxHeight_m_ = frame.maxHorizontal_m_ = 0.0;
    if (!fft_) {
        frame.textures_.clear();  // else rebuilt in place, reusing the buffers
        frame.cascadeBounds_.clear();
    }
    if (fft_) frame.BuildTextures();
    frame.maxHeight_m_ += gerstner_.MaxAmplitude_m();
    frame.maxHorizontal_m_ += gerstner_.MaxHorizontal_m();
    frame.surf_ = surf_;
    frame.surfReach_m_ = 0.0;
    frame.openSeaFrom_m_ = kInf;
    if (surf_) {
        // Over the whole surface: the surf bound at every depth, the whole seabed.
        // One table per frame serves every BoundsNear (each view asks for a few discs).
        frame.surfBounds_ = surf_->MakeBoundTable(frame.cascadeBounds_, frame.GerstnerBound());
        frame.surfReach_m_ = surf_->BoundAtDepths(-kInf, frame.surfBounds_).horizontal_m;
        frame.openSeaFrom_m_ = frame.OpenSeaFrom(*surf_);
        const SurfaceBounds all = frame.BoundsNear(0.0, 0.0, kInf);
        frame.maxHeight_m_ = all.height_m;
        frame.maxHorizontal_m_ = all.horizontal_m;
    }
}

double OceanSurfaceFrame::OpenSeaFrom(const SurfWaves& surf) const {
    // The deep sea (FFT cascades and Gerstner waves at full weight) moves a point at most D
    // horizontally and lowers it at most H below the tide: each cascade's largest |η| and |D|
    // over its full-resolution texels (its mips and the bilinear and trilinear blends average
    // them; BuildTextures), each Gerstner wave's A and Q A / tanh kh. The mesh sums them in
    // float, ~1e-6 relative: the margin is far above that.
    const SurfWaves::Bound deep = surfBounds_.deep;
    const double margin = 0.01 + 1e-3 * (deep.height_m + deep.horizontal_m);
    // Seaward of s1 the still-water depth is at least h everywhere (Bathymetry::DeepSeawardOf_m):
    // there DryLandSums finds water (h > 0), Weights(h) are the deep defaults and AllDeep
    // (h ≥ FadeDeep_m), Swash_m is 0 (h ≥ 2 R2), and the seabed lies below tide − H − margin,
    // under the lowest the deep sea reaches. A rest position D + margin seaward of s1 then has
    // its displaced point (within D of it) seaward of s1 too, where the clamp cannot apply.
    double h = std::max(surf.FadeDeep_m(), deep.height_m + margin);
    if (surf.Swash().active) h = std::max(h, 2.0 * surf.Swash().runup2_m);
    return surf.Bathy().DeepSeawardOf_m(h) + deep.horizontal_m + margin;
}

SurfWaves::Bound OceanSurfaceFrame::GerstnerBound() const {
    return {gerstner_.MaxAmplitude_m(), gerstner_.MaxHorizontal_m()};
}

SurfaceBounds OceanSurfaceFrame::BoundsNear(double x, double y, double radius_m) const {
    CHECK(radius_m >= 0.0);
    if (!surf_) return {maxHeight_m_, maxHorizontal_m_};
    // Rest positions within the radius; the seabed clamp looks under the displaced points.
    const double tide = surf_->Bathy().Tide_m();
    const double zBed = surf_->Bathy().MaxSeabedZWithin_m(x, y, radius_m + surfReach_m_);
    const SurfWaves::Bound b = surf_->BoundAtDepths(tide - zBed, surfBounds_);
    return {std::max({tide + b.height_m, zBed, 0.0}), b.horizontal_m};
}

void OceanSurfaceFrame::FilterLevels(size_t c, double minFootprint_m, double maxFootprint_m,
                                     int& first, int& last) const {
    const CascadeTexture& t = textures_[c];
    // Filter's level(f) is the whole part of its float level of detail, which grows with f: the
    // range's ends taken 0.1 % further out (for log2f's rounding), and level(max) + 1.
    const int top = int(t.levels.size()) - 1;
    const auto levelOf = [&](double footprint_m) {
        const float f = float(footprint_m);
        const float lod = f > float(t.texel_m) ? std::log2(f / float(t.texel_m)) : 0.0f;
        return int(std::min(lod, float(top)));
    };
    first = levelOf(minFootprint_m / 1.001);
    last = std::isfinite(maxFootprint_m) ? std::min(levelOf(maxFootprint_m * 1.001) + 1, top) : top;
}

SurfWaves::Bound OceanSurfaceFrame::CascadeBoundNear(size_t c, double x, double y, double radius_m,
                                                     double maxFootprint_m) const {
    const CascadeTexture& t = textures_[c];
    int first = 0, last = 0;
    FilterLevels(c, 0.0, maxFootprint_m, first, last);
    SurfWaves::Bound b;
    for (size_t level = size_t(first); level <= size_t(last); ++level) {
        // AddBilinear at rest position x0 reads texels floor(u) and floor(u) + 1 of the level,
        // u = ((x0 + Δ/2) / Δ) 2^−l − ½, which grows with x0: the disc's bounding box reads
        // those from its low edge to its high edge, one more on each side for rounding.
        const int n = t.n >> level;
        const double scale = 1.0 / double(1 << level);
        const auto texels = [&](double centre, int64_t& lo, int64_t& hi) {
            const auto u = [&](double x0) {
                return ((x0 + 0.5 * t.texel_m) / t.texel_m) * scale - 0.5;
            };
            lo = int64_t(std::floor(u(centre - radius_m))) - 1;
            hi = int64_t(std::floor(u(centre + radius_m))) + 2;
            if (hi - lo + 1 >= n) lo = 0, hi = n - 1;  // every texel of the periodic level
        };
        int64_t i0 = 0, i1 = 0, j0 = 0, j1 = 0;
        texels(x, i0, i1);
        texels(y, j0, j1);
        const std::vector<Texel>& texture = t.levels[level];
        float maxHeight = 0.0f;  // 0: a cascade weighted by w ∈ [0, 1] adds at most w · max(0, η)
        double maxD2 = 0.0;
        for (int64_t i = i0; i <= i1; ++i) {
            const Texel* row = texture.data() + size_t(i & (n - 1)) * size_t(n);
            for (int64_t j = j0; j <= j1; ++j) {
                const GeometrySums& v = row[size_t(j & (n - 1))].v;
                maxHeight = std::max(maxHeight, v[kTermHeight]);
                maxD2 = std::max(maxD2, double(v[kTermDispX]) * double(v[kTermDispX]) +
                                            double(v[kTermDispY]) * double(v[kTermDispY]));
            }
        }
        // A lookup blends two levels' bilinear interpolations, each within its texels' maxima
        // (the vector's length by the triangle inequality).
        b.height_m = std::max(b.height_m, double(maxHeight));
        b.horizontal_m = std::max(b.horizontal_m, std::sqrt(maxD2));
    }
    return b;
}

SurfaceBounds OceanSurfaceFrame::LocalBoundsNear(double x, double y, double radius_m,
                                                 double maxFootprint_m) const {
    CHECK(radius_m >= 0.0 && maxFootprint_m >= 0.0);
    const SurfaceBounds global = BoundsNear(x, y, radius_m);
    std::vector<SurfWaves::Bound> cascades(textures_.size());
    for (size_t c = 0; c < textures_.size(); ++c)
        cascades[c] = CascadeBoundNear(c, x, y, radius_m, maxFootprint_m);
    SurfWaves::Bound gerstner = GerstnerBound();
    gerstner.height_m = gerstner_.ElevationBoundNear_m(x, y, radius_m, t_s_, maxFootprint_m);
    SurfaceBounds local;
    if (!surf_) {
        local.height_m = gerstner.height_m, local.horizontal_m = gerstner.horizontal_m;
        for (const SurfWaves::Bound& b : cascades)
            local.height_m += b.height_m, local.horizontal_m += b.horizontal_m;
    } else {
        // As BoundsNear, with the local parts in place of the whole surface's: in water deeper
        // than the surf's deepest fade the sum of the parts, nearer the shore each depth
        // interval's faded parts plus the surf components (BoundAtDepths over the intervals,
        // whose depth-dependent parts SurfWaves makes once). Taking BoundsNear there instead put
        // the bound above a 2 m eye over 15 m of water (configs/five-channel.yaml from frame
        // ~105), so that no sea near the eye could be culled: the FLIR's mesh grew from 51 k
        // to 133 k vertices, all surf vertices, none visible.
        const Bathymetry& bathy = surf_->Bathy();
        const double tide = bathy.Tide_m();
        const double zBed = bathy.MaxSeabedZWithin_m(x, y, radius_m + surfReach_m_);
        // The surf components' height and reach over the disc's rest positions also bounded by
        // their sums here and now (SurfWaves::BoundNear): over a few metres about an eye above
        // the fade zone they are well below the sums of their amplitudes and orbits, which from
        // frame ~145 of the five-channel demo put the crests' bound within 0.3 m of the 2 m eye
        // and widened the FLIR's rings near the eye to over twice its sector.
        // The rest positions' depths lie in [shallow, deep]; the seabed clamp below looks under
        // displaced points (zBed, the disc grown by the reach).
        const double shallow = tide - bathy.MaxSeabedZWithin_m(x, y, radius_m);
        const double deep = tide - bathy.MinSeabedZWithin_m(x, y, radius_m);
        const SurfWaves::Bound surfNear = surf_->BoundNear(x, y, t_s_, radius_m, shallow, deep);
        const SurfWaves::Bound b =
            surf_->BoundAtDepths(tide - zBed, cascades, gerstner, surfNear, deep);
        local = {std::max({tide + b.height_m, zBed, 0.0}), b.horizontal_m};
    }
    return {std::min(local.height_m + kLocalBoundMargin_m, global.height_m),
            std::min(local.horizontal_m + kLocalBoundMargin_m, global.horizontal_m)};
}

std::shared_ptr<OceanSurfaceFrame> OceanSurface::Cached(double t) const {
    for (const std::shared_ptr<OceanSurfaceFrame>& f : cache_->frames)
        if (std::bit_cast<uint64_t>(f->t_s_) == std::bit_cast<uint64_t>(t)) return f;
    return nullptr;
}

std::shared_ptr<OceanSurfaceFrame> OceanSurface::FreeFrame() const {
    std::vector<std::shared_ptr<OceanSurfaceFrame>>& frames = cache_->frames;
    std::shared_ptr<OceanSurfaceFrame> frame;
    if (frames.size() >= kCachedFrames) {
        // Reuse the oldest frame's buffers when no one else holds it.
        if (frames.front().use_count() == 1) frame = std::move(frames.front());
        frames.erase(frames.begin());
    }
    if (!frame) frame = std::make_shared<OceanSurfaceFrame>();
    return frame;
}

std::shared_ptr<const OceanSurfaceFrame> OceanSurface::At(double t) const {
    CHECK(std::isfinite(t));
    std::lock_guard<std::mutex> lock(cache_->mutex);
    if (std::shared_ptr<OceanSurfaceFrame> cached = Cached(t)) return cached;
    std::shared_ptr<OceanSurfaceFrame> frame = FreeFrame();
    // Isolated: while this thread waits inside the synthesis' parallel loops it must not pick
    // up an outer task that could ask for a frame and block on the held lock.
    tbb::this_task_arena::isolate([&] { Fill(*frame, t, false); });
    cache_->frames.push_back(frame);
    return frame;
}

size_t OceanSurface::SharedFieldBytes() const {
    return fft_ ? FftOceanFrame::EncodedBytesFor(fft_->GridSize(), fft_->Cascades().size(), false)
                : 0;
}

void OceanSurface::Adopt(double t, std::span<const uint8_t> fields) const {
    CHECK(std::isfinite(t));
    if (!fft_) {
        if (!fields.empty())
            throw RuntimeError("sea fields handed to a scenario without a spectral sea");
        return;
    }
    std::lock_guard<std::mutex> lock(cache_->mutex);
    if (Cached(t)) return;
    // The oldest frame's buffers when free; decoded and checked before it enters the cache.
    std::shared_ptr<OceanSurfaceFrame> frame = FreeFrame();
    FftOceanFrame& in = frame->fft_;
    in.Decode(fields.data(), fields.size());
    const std::span<const CascadeBand> bands = fft_->Cascades();
    bool same = in.GridSize() == fft_->GridSize() && in.CascadeCount() == bands.size() &&
                !in.HasRates() && in.Choppiness() == fft_->Choppiness() &&
                std::bit_cast<uint64_t>(in.Time_s()) == std::bit_cast<uint64_t>(t);
    for (size_t c = 0; same && c < bands.size(); ++c) same = in.PatchSize_m(c) == bands[c].patch_m;
    if (!same)
        throw RuntimeError(
            "sea fields for t = " + std::to_string(in.Time_s()) + " s (" +
            std::to_string(in.CascadeCount()) + " cascades of " + std::to_string(in.GridSize()) +
            "² nodes) do not match this scenario's sea at t = " + std::to_string(t) + " s");
    // Isolated as in At: the textures' parallel loops must not run an outer task that could ask
    // for a frame while this thread holds the lock.
    tbb::this_task_arena::isolate([&] { Complete(*frame, t); });
    cache_->frames.push_back(frame);
}

std::shared_ptr<const OceanSurfaceFrame> OceanSurface::AtWithVelocity(double t) const {
    CHECK(std::isfinite(t));
    auto frame = std::make_shared<OceanSurfaceFrame>();
    Fill(*frame, t, true);
    return frame;
}

double OceanSurface::FoamCoverage(const OceanSample& s) const {
    return std::clamp(1.0 - s.minEigenvalue / settings_.foamThreshold, 0.0, 1.0);
}

OceanPointQuery OceanSurface::Query(double x, double y, double t) const {
    const std::shared_ptr<const OceanSurfaceFrame> frame = AtWithVelocity(t);
    OceanPointQuery q;
    q.surface = frame->SampleAt(x, y, &q.rest_m);
    q.waterDepth_m = settings_.depth_m;
    q.foamCoverage = FoamCoverage(q.surface);
    if (surf_) {
        surf_->Terms(q.rest_m.x, q.rest_m.y, t, &q.surf);
        q.hasSurf = true;
        q.waterDepth_m = surf_->Bathy().Depth_m(x, y);
        // Breaking white water: the larger of the depth-limited breaking and the Jacobian foam.
        q.foamCoverage = std::max(q.foamCoverage, q.surf.breaking.intensity);
    }
    return q;
}

void OceanSurface::Summarize() {
    SeaSummary s;
    s.spectral = fft_ != nullptr;
    s.depth_m = settings_.depth_m;
    s.peakPeriod_s = s.peakWavelength_m = s.dominantDirection_rad = kNaN;
    s.phaseSpeed_mps = s.groupSpeed_mps = kNaN;
    s.windSpeed_mps = s.windDirection_rad = kNaN;
    double variance = 0.0;
    for (size_t i = 0; i < gerstner_.WaveCount(); ++i)
        variance += 0.5 * gerstner_.Amplitude_m(i) * gerstner_.Amplitude_m(i);
    if (fft_) variance += fft_->ModeVariance_m2();
    s.significantHeight_m = 4.0 * std::sqrt(variance);

    double omega = 0.0, k = 0.0;
    if (spectrum_) {
        s.windSpeed_mps = spectrum_->Settings().windSpeed_mps;
        s.windDirection_rad = spectrum_->Settings().windDirection_rad;
        if (spectrum_->Variance_m2() > 0.0) {
            // Peak of S(ω): a log-spaced scan (0.15 % steps), then golden-section refinement.
            constexpr int kSteps = 6000;
            const double lo = 0.01, ratio = std::pow(100.0 / lo, 1.0 / kSteps);
            int best = 0;
            double bestS = -1.0, w = lo;
            for (int i = 0; i <= kSteps; ++i, w *= ratio) {
                const double v = spectrum_->DensityOmega(w);
                if (v > bestS) bestS = v, best = i;
            }
            double a = lo * std::pow(ratio, best - 1), b = lo * std::pow(ratio, best + 1);
            const double phi = 0.5 * (std::sqrt(5.0) - 1.0);
            for (int it = 0; it < 60; ++it) {
                const double c = b - phi * (b - a), d = a + phi * (b - a);
                if (spectrum_->DensityOmega(c) >= spectrum_->DensityOmega(d))
                    b = d;
                else
                    a = c;
            }
            omega = 0.5 * (a + b);
            k = WavenumberForOmega(omega, settings_.depth_m);
            // Direction of travel where the directional spectrum at the peak is largest: a scan
            // in 0.25° steps refined by the parabola through the best three.
            constexpr int kAngles = 1440;
            const auto density = [&](double az) {
                return spectrum_->DensityK(k * std::sin(az), k * std::cos(az));
            };
            int bestA = 0;
            double bestD = -1.0;
            for (int i = 0; i < kAngles; ++i) {
                const double v = density(kTwoPi * i / kAngles);
                if (v > bestD) bestD = v, bestA = i;
            }
            const double h = kTwoPi / kAngles, az = h * bestA;
            const double fm = density(az - h), f0 = bestD, fp = density(az + h);
            const double curvature = fm - 2.0 * f0 + fp;
            const double shift = curvature < 0.0 ? 0.5 * (fm - fp) / curvature : 0.0;
            s.dominantDirection_rad = std::remainder(az + std::clamp(shift, -1.0, 1.0) * h, kTwoPi);
            if (s.dominantDirection_rad < 0.0) s.dominantDirection_rad += kTwoPi;
        }
    } else if (gerstner_.WaveCount() > 0) {
        size_t best = 0;
        for (size_t i = 1; i < gerstner_.WaveCount(); ++i)
            if (gerstner_.Amplitude_m(i) > gerstner_.Amplitude_m(best)) best = i;
        if (gerstner_.Amplitude_m(best) > 0.0) {
            omega = gerstner_.Omega_radps(best);
            k = gerstner_.Wavenumber_radpm(best);
            s.dominantDirection_rad = std::remainder(gerstner_.Direction_rad(best), kTwoPi);
            if (s.dominantDirection_rad < 0.0) s.dominantDirection_rad += kTwoPi;
        }
    }
    if (omega > 0.0 && k > 0.0) {
        s.peakPeriod_s = kTwoPi / omega;
        s.peakWavelength_m = kTwoPi / k;
        s.phaseSpeed_mps = omega / k;
        s.groupSpeed_mps = GroupSpeed(k, settings_.depth_m);
    }
    summary_ = s;
}

}  // namespace seasense::scene
