// The sea surface of a scenario at any instant: FFT cascades (with band-limited lookups through
// mip chains of their fields) plus Gerstner waves, committed once per frame time and shared by
// the view meshes, the wave-riding entities and the truthful queries.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "scene/ocean/fft_ocean.h"
#include "scene/ocean/gerstner.h"
#include "scene/ocean/spectrum.h"
#include "scene/ocean/surface_terms.h"
#include "scene/scenario/scenario.h"
#include "scene/surf/surf_waves.h"

namespace seasense::scene {

// Geometry sums as the mesh builder accumulates them, in this order.
enum GeometryTerm : int {
    kTermHeight,  // η, m
    kTermDispX,   // Dx, m
    kTermDispY,   // Dy, m
    kTermSlopeX,  // ∂η/∂x0
    kTermSlopeY,  // ∂η/∂y0
    kTermDispXX,  // ∂Dx/∂x0
    kTermDispYY,  // ∂Dy/∂y0
    kTermDispXY,  // ∂Dx/∂y0
    kGeometryTerms
};
using GeometrySums = std::array<float, kGeometryTerms>;

// Upward unit normal from geometry sums (single precision, for meshes): the cross product of the
// tangents (1 + Dxx, Dxy, ηx) and (Dxy, 1 + Dyy, ηy).
inline glm::vec3 GeometryNormal(const GeometrySums& s) {
    const float a = 1.0f + s[kTermDispXX], d = 1.0f + s[kTermDispYY], b = s[kTermDispXY];
    const float sx = s[kTermSlopeX], sy = s[kTermSlopeY];
    glm::vec3 n(b * sy - sx * d, sx * b - a * sy, a * d - b * b);
    const float len2 = glm::dot(n, n);
    n = len2 > 0.0f ? n * (1.0f / std::sqrt(len2)) : glm::vec3(0.0f, 0.0f, 1.0f);
    return n.z < 0.0f ? -n : n;  // folded surface: keep the normal upward
}

// Determinant of the horizontal Jacobian [[1 + Dxx, Dxy], [Dxy, 1 + Dyy]].
inline float GeometryJacobian(const GeometrySums& s) {
    const float a = 1.0f + s[kTermDispXX], d = 1.0f + s[kTermDispYY], b = s[kTermDispXY];
    return a * d - b * b;
}

// The mip levels a footprint reads in each FFT cascade (see OceanSurfaceFrame::AccumulateFft):
// level[c] with weight 1 − frac[c] and level[c] + 1 with weight frac[c].
struct FftFilter {
    static constexpr int kMaxCascades = 8;
    std::array<int, kMaxCascades> level{};
    std::array<float, kMaxCascades> frac{};
    // What OceanSurfaceFrame::Filter derives for AccumulateFft (valid with the frame that made
    // it): the texel lookups in the order they add, per cascade level[c] with factor
    // 1 − frac[c], then level[c] + 1 with frac[c] where frac[c] > 0; per lookup its cascade,
    // texel size Δ and Δ/2, 2^−level, the level's size n (and as doubles n and 1/n) and texels
    // (row-major, kGeometryTerms floats each). Padded to a multiple of four lookups with copies
    // of the last, which are never added.
    static constexpr int kMaxLookups = 2 * kMaxCascades;
    int lookups = 0;
    std::array<double, kMaxLookups> texel{}, halfTexel{}, scale{}, size{}, invSize{};
    std::array<int, kMaxLookups> cascade{}, n{};
    std::array<float, kMaxLookups> factor{};
    std::array<const float*, kMaxLookups> texels{};
};

// The surface at one instant: an immutable snapshot once made by OceanSurface.
// Upper bounds of (part of) the sea surface at an instant: the highest point (ENU z, m) and the
// largest horizontal displacement from rest (m).
struct SurfaceBounds {
    double height_m = 0.0;
    double horizontal_m = 0.0;
};

class OceanSurfaceFrame {
  public:
    double Time_s() const { return t_s_; }

    // Unfiltered surface (all FFT modes, all Gerstner waves) at rest position (x0, y0), world m,
    // double precision. Velocity is NaN in frames made without velocities (OceanSurface::At).
    SurfaceTerms Terms(double x0, double y0) const;
    OceanSample Evaluate(double x0, double y0) const {
        return MakeOceanSample(x0, y0, Terms(x0, y0));
    }

    // The surface drawn above world point (x, y): the rest position whose displaced horizontal
    // position is (x, y), found by fixed-point iteration (a contraction while the surface does
    // not fold), written to rest if given.
    OceanSample SampleAt(double x, double y, glm::dvec2* rest = nullptr) const;
    double HeightAt(double x, double y) const { return SampleAt(x, y).position.z; }

    // Adds the FFT part of the surface at rest position (x0, y0), band-limited to a sampling
    // footprint (m), to sums: each cascade is read from the mip level whose texel matches the
    // footprint (trilinear between levels, box-filtered 2×2 mips), so a mesh with vertices
    // `footprint` apart does not alias waves shorter than it can hold. A footprint at or below a
    // cascade's grid spacing reads its full-resolution field (the same surface as Terms).
    void AccumulateFft(double x0, double y0, float footprint_m, GeometrySums& sums) const {
        AccumulateFft(x0, y0, Filter(footprint_m), sums);
    }
    // The same with the levels of a footprint resolved once (e.g. per mesh ring).
    FftFilter Filter(float footprint_m) const;
    // With cascadeWeights (one per cascade, e.g. SurfWeights::cascade) each cascade is scaled.
    // The lookups' coordinates and weights four at a time.
    void AccumulateFft(double x0, double y0, const FftFilter& filter, GeometrySums& sums,
                       const double* cascadeWeights = nullptr) const;
    // The same one lookup at a time (the scalar form; tests compare the two bit for bit).
    void AccumulateFftOneByOne(double x0, double y0, const FftFilter& filter, GeometrySums& sums,
                               const double* cascadeWeights = nullptr) const;

    // Unit upward normal of the surface at rest position (x0, y0) (world m) band-limited to a
    // footprint (m), FFT cascades and Gerstner waves together: for shading finer than the mesh
    // (per sample, with the sample's footprint on the sea), seed 001's normal-map idea.
    glm::vec3 DetailNormal(double x0, double y0, float footprint_m) const;

    // With a surf zone, the mesh path (Terms does the same): sums hold the deep sea at rest
    // position (x0, y0) already scaled by info.weights (AccumulateFft with the cascade weights,
    // the Gerstner waves times weights.gerstner); adds the surf components' terms (surfTerms
    // and info from Surf()->Terms at the frame time) and the tide, and clamps the height to the
    // seabed under the displaced point.
    void AddSurf(double x0, double y0, const SurfaceTerms& surfTerms, GeometrySums& sums) const;
    // AddSurf for a rest position seaward of OpenSeaFrom_m, the same bits: the surf terms there
    // are zero (the tide added to the height, +0 to the rest) and the clamp cannot apply.
    void AddOpenSea(GeometrySums& sums) const;
    // With a surf zone: whether rest position (x0, y0) is dry land that no water reaches at any
    // time (seabed above the tide plus the swash maximum), and if so the surface there, sums set
    // to exactly what the deep sea, the surf terms and AddSurf's seabed clamp give (the seabed
    // and its slope), without evaluating them. Where it is not, the seabed it looked up there
    // (as SurfWaves::Terms looks it up) is written to seabedZ_m if given, for
    // SurfWaves::TermsOptions::seabedZ_m.
    bool DryLandSums(double x0, double y0, GeometrySums& sums, double* seabedZ_m = nullptr) const;

    // With a surf zone: the cross-shore distance (shore frame s, m) seaward of which the mesh's
    // surf path at a rest position is the deep sea's alone, bit for bit: DryLandSums finds water,
    // SurfWaves::Terms finds every part of the sea at full weight, no surf component and no swash
    // (the depth is at least FadeDeep_m and twice the swash's run-up), and AddSurf's seabed clamp
    // cannot apply (the seabed under any point the deep sea can carry there lies lower than its
    // deepest trough). +∞ without a surf zone or with a depth grid. See Complete for the bounds.
    double OpenSeaFrom_m() const { return openSeaFrom_m_; }

    // The surf components (nullptr without environment.ocean.surf).
    const SurfWaves* Surf() const { return surf_.get(); }

    // The Gerstner part (possibly without waves) and, for the spectral model, the FFT fields.
    const GerstnerOcean& Gerstner() const { return gerstner_; }
    const FftOceanFrame* Fft() const { return hasFft_ ? &fft_ : nullptr; }

    // Bounds over the whole surface at this instant: highest surface point (ENU z, m; with a
    // surf zone the beach included) and largest horizontal displacement (m), for view culling
    // and the horizon.
    double MaxHeight_m() const { return maxHeight_m_; }
    double MaxHorizontal_m() const { return maxHorizontal_m_; }
    // The same bounds for the points whose rest positions lie within radius_m of world (x, y):
    // with a surf zone, waves over shallow water are capped by their depth, so the sea near an
    // eyepoint in deeper water is bounded far more tightly than the whole surface.
    SurfaceBounds BoundsNear(double x, double y, double radius_m) const;
    // BoundsNear taken from the waves near (x, y) rather than from their maxima over the whole
    // surface, for the points of a mesh whose rings there have footprints of at most
    // maxFootprint_m (∞: any): each FFT cascade bounded by the highest texel (and the longest
    // horizontal displacement) that a lookup within the disc can read at the mip levels such
    // footprints read (FilterLevels), the Gerstner waves' elevation by
    // GerstnerOcean::ElevationBoundNear_m (signed where the footprint bounds their weights from
    // below, following their troughs); the surf zone and the seabed as in BoundsNear. Never
    // above BoundsNear; the height includes kLocalBoundMargin_m.
    SurfaceBounds LocalBoundsNear(
        double x, double y, double radius_m,
        double maxFootprint_m = std::numeric_limits<double>::infinity()) const;
    // Added to LocalBoundsNear's height and reach: the float rounding of the mesh's sums (a few
    // ulp of metres) far below it.
    static constexpr double kLocalBoundMargin_m = 1e-3;
    // The mip levels [first, last] of cascade c that Filter's lookups read for every footprint
    // in [minFootprint_m, maxFootprint_m] (each reads level[c] and level[c] + 1).
    void FilterLevels(size_t c, double minFootprint_m, double maxFootprint_m, int& first,
                      int& last) const;
    // Significant wave height of the sea (time-independent; for mesh spacing choices), m.
    double SignificantHeight_m() const { return significantHeight_m_; }

  private:
    friend class OceanSurface;
    struct Texel {
        GeometrySums v;  // choppiness applied
    };
    // One cascade's geometry fields as a mip chain: level l has (N >> l)² texels, texel (i, j)
    // averaging the 2^l × 2^l full-resolution nodes from (i, j) · 2^l, stored at i (N >> l) + j.
    struct CascadeTexture {
        double patch_m = 0.0;
        double texel_m = 0.0;  // L / N
        int n = 0;
        std::vector<std::vector<Texel>> levels;
    };
    void BuildTextures();
    // Cascade c's bound over the lookups at rest positions within radius_m of (x, y) by
    // footprints of at most maxFootprint_m (the levels FilterLevels gives).
    SurfWaves::Bound CascadeBoundNear(size_t c, double x, double y, double radius_m,
                                      double maxFootprint_m) const;
    SurfWaves::Bound GerstnerBound() const;
    // OpenSeaFrom_m for the frame's bounds (surfBounds_ made).
    double OpenSeaFrom(const SurfWaves& surf) const;

    double t_s_ = 0.0;
    GerstnerOcean gerstner_;
    bool hasFft_ = false;
    FftOceanFrame fft_;
    std::shared_ptr<const SurfWaves> surf_;
    std::vector<CascadeTexture> textures_;
    double maxHeight_m_ = 0.0;
    double maxHorizontal_m_ = 0.0;
    std::vector<SurfWaves::Bound> cascadeBounds_;  // per cascade: max |η|, max |D|
    SurfWaves::BoundTable surfBounds_;  // SurfWaves::BoundAtDepths of this frame's bounds
    double surfReach_m_ = 0.0;          // largest horizontal displacement anywhere, with the surf
    double openSeaFrom_m_ = std::numeric_limits<double>::infinity();
    double significantHeight_m_ = 0.0;
};

// Statistics of the sea (time-independent).
struct SeaSummary {
    bool spectral = false;
    // 4 √(variance of the drawn surface): the synthesized modes' variance plus A²/2 per Gerstner
    // wave, m.
    double significantHeight_m = 0.0;
    // The dominant wave: for the spectral model the peak of the frequency spectrum (wind sea and
    // swell) and the direction of travel where the directional spectrum peaks at that frequency;
    // for Gerstner waves alone the wave of largest amplitude. NaN for a flat sea.
    double peakPeriod_s = 0.0;
    double peakWavelength_m = 0.0;
    double dominantDirection_rad = 0.0;  // of travel, azimuth from north clockwise
    double phaseSpeed_mps = 0.0;         // ω/k of the dominant wave at the depth
    double groupSpeed_mps = 0.0;         // ½ c (1 + 2kh / sinh 2kh)
    double depth_m = 0.0;                // still-water depth
    // The wind the spectral sea was made from (NaN for Gerstner waves alone).
    double windSpeed_mps = 0.0;
    double windDirection_rad = 0.0;  // toward, azimuth from north clockwise
};

// What a query at a world point answers.
struct OceanPointQuery {
    OceanSample surface;        // the particle drawn above (x, y): position.z is the height
    glm::dvec2 rest_m{0.0};     // its rest position
    double waterDepth_m = 0.0;  // still-water depth (seabed below mean sea level)
    // Foam coverage in [0, 1]: an instantaneous whitecap indicator from the horizontal
    // Jacobian, 0 where its smaller eigenvalue is at or above the scenario's foam_threshold τ,
    // rising linearly to 1 where the surface folds (eigenvalue ≤ 0): 1 − λ_min / τ, clamped.
    double foamCoverage = 0.0;
    // With a surf zone: the point's surf information (depth, weights, breaking, the local
    // dominant component's direction, phase and speeds); waterDepth_m is then the local depth.
    bool hasSurf = false;
    SurfPointInfo surf;
};

class OceanSurface {
  public:
    // Throws InputError for invalid spectral settings.
    explicit OceanSurface(const OceanSettings& settings);
    ~OceanSurface();
    OceanSurface(OceanSurface&&) noexcept;
    OceanSurface& operator=(OceanSurface&&) noexcept;

    // The surface at time t_s (seconds since frame 0), without velocities. Frames are cached
    // (the two most recent times), so every user of one frame time shares one synthesis;
    // thread-safe; the result is bit-identical for any thread count.
    std::shared_ptr<const OceanSurfaceFrame> At(double t_s) const;
    // Bytes of the encoded fields of At's frames (FftOceanFrame::EncodedBytes, geometry only);
    // 0 without a spectral sea.
    size_t SharedFieldBytes() const;
    // Caches the frame at t_s made from fields synthesized elsewhere: `fields` is what
    // FftOceanFrame::Encode wrote of At(t_s)->Fft() of an OceanSurface with the same settings
    // (the run's host, so that its renderers do not each synthesize the same fields). At(t_s)
    // then returns it without a synthesis, bit for bit the frame it would have made. No-op when
    // the cache holds t_s already. RuntimeError, and nothing cached, when the bytes are not
    // such fields (another grid, cascade patches, choppiness or time, or rates).
    void Adopt(double t_s, std::span<const uint8_t> fields) const;
    // The surface at t_s with surface velocities (a fresh synthesis, not cached).
    std::shared_ptr<const OceanSurfaceFrame> AtWithVelocity(double t_s) const;

    double HeightAt(double x, double y, double t_s) const { return At(t_s)->HeightAt(x, y); }

    // Height, normal, orbital velocity, foam and depth at world point (x, y) at time t_s.
    OceanPointQuery Query(double x, double y, double t_s) const;
    // Foam coverage (OceanPointQuery::foamCoverage) of a sample.
    double FoamCoverage(const OceanSample& sample) const;

    const SeaSummary& Summary() const { return summary_; }
    const OceanSettings& Settings() const { return settings_; }
    bool Spectral() const { return fft_ != nullptr; }
    const WaveSpectrum* Spectrum() const { return spectrum_.get(); }
    const FftOcean* Fft() const { return fft_.get(); }
    const GerstnerOcean& Gerstner() const { return gerstner_; }
    const SurfWaves* Surf() const { return surf_.get(); }

  private:
    void Fill(OceanSurfaceFrame& frame, double t_s, bool withVelocity) const;
    // Everything of Fill after the synthesis of frame.fft_ (made or adopted).
    void Complete(OceanSurfaceFrame& frame, double t_s) const;
    // The cached frame at t_s (times compared bit for bit), else null; the cache's mutex must
    // be held.
    std::shared_ptr<OceanSurfaceFrame> Cached(double t_s) const;
    // A frame to fill for the cache (the oldest one's buffers when no one holds it); the
    // cache's mutex must be held.
    std::shared_ptr<OceanSurfaceFrame> FreeFrame() const;
    void Summarize();
    std::shared_ptr<const SurfWaves> MakeSurfWaves() const;

    OceanSettings settings_;
    GerstnerOcean gerstner_;
    std::unique_ptr<const WaveSpectrum> spectrum_;
    std::unique_ptr<const FftOcean> fft_;
    std::shared_ptr<const SurfWaves> surf_;
    SeaSummary summary_;
    struct Cache;
    std::unique_ptr<Cache> cache_;
};

}  // namespace seasense::scene
