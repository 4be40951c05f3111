// Depth-aware surf waves: a few discrete components carried from deep water over the bathymetry
// with finite-depth dispersion, shoaling, refraction, depth-limited breaking and the seabed clamp.
//
// Design (why a handful of components and a cross-fade). The FFT cascades are periodic patches
// with one dispersion relation for the whole patch; they cannot slow down, shorten or turn their
// waves where the water shoals. So the sea is split by depth: in deep water (local depth above
// fadeDeep = ½ L_p, where tanh(kh) > 0.996 for the peak and shoaling is < 1 %) the surface is
// exactly the FFT + Gerstner sea of the scenario, bit for bit; below fadeShallow = ¼ L_p it is a
// sum of discrete components that carry the sea's whole variance (the FFT's mode variance and
// each Gerstner wave's A²/2) with local-depth physics; in between the two are cross-faded with
// weights cos and sin of the same angle, so the variance of the sum (the two are independent) is
// conserved through the fade: Hs does not dip. The fade is per FFT cascade: a cascade fades over
// ½ to ¼ of its own wavelength — the peak wavelength for a cascade holding the peak or longer
// waves, else the median wavelength of its slope variance (the chop that the shading shows) — so
// the short chop, deep water for its own wavelength even a metre or two deep, keeps its weight
// while the long cascade hands its variance to the surf components; the spectral surf components
// take exactly the variance the cascades give up (Σ var_c (1 − w_c²)), the Gerstner waves fade
// with the peak wavelength into their own components. 12 spectral components spaced in
// frequency around the peak (0.8–1.6 ω_p) beat against each other: wave groups and surf beat
// come for free.
//
// Each component keeps its frequency ω and (for parallel contours, Snell) its alongshore
// wavenumber k_u; its local wavenumber follows ω² = g k tanh(k h), its cross-shore wavenumber is
// k_s = −√(k² − k_u²) and its phase ∫ k_s ds is tabulated along the cross-shore profile of the
// plane beach; amplitude follows energy-flux conservation A = A0 √(cg0 / cg) √(cos θ0 / cos θ)
// with the local depth (so a bar raises the crests), and is capped by the depth-limited breaker
// criterion on the local wave-group envelope: 2|Σ A e^{iψ}| ≤ γ h (McCowan γ = 0.78), which tapers
// the height to zero at zero depth. Horizontal displacement (Gerstner, Q rising to 1 as the
// waves near breaking) steepens the fronts.
#pragma once

#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <limits>
#include <vector>

#include "scene/ocean/surface_terms.h"
#include "scene/surf/bathymetry.h"

namespace seasense::scene {

// At most this many components (12 spectral + the scenario's 64 Gerstner waves at most).
inline constexpr size_t kMaxSurfComponents = 80;

// One deep-water wave train that the surf carries shoreward.
struct SurfComponent {
    double amplitude_m = 0.0;    // deep-water amplitude
    double omega_radps = 0.0;    // angular frequency
    double direction_rad = 0.0;  // deep-water direction of travel, azimuth from north clockwise
    double phase_rad = 0.0;  // phase at the world origin at t = 0: η = A cos(k·x − ωt + φ)
    // Carries the FFT cascades' variance (faded in as they fade out) rather than a Gerstner
    // wave of its own (faded in as the Gerstner waves fade out).
    bool spectral = false;
};

// An FFT cascade the surf fades out: its variance and the wavelength that sets its fade depths
// (½ and ¼ of it).
struct SurfCascade {
    double variance_m2 = 0.0;
    double wavelength_m = 0.0;
};
inline constexpr size_t kMaxSurfCascades = 8;

// Weights of the parts of the sea at a depth: deep² + surf² = 1 per part, so Hs is conserved.
struct SurfWeights {
    std::array<double, kMaxSurfCascades> cascade{1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0};
    double gerstner = 1.0;      // the scenario's Gerstner waves
    double spectralSurf = 0.0;  // the spectral surf components: √(Σ var_c (1 − w_c²) / Σ var_c)
    double gerstnerSurf = 0.0;  // the Gerstner waves' surf components: √(1 − gerstner²)
    bool AllDeep() const { return spectralSurf == 0.0 && gerstnerSurf == 0.0; }
};

// The breaking state at a point and instant.
struct SurfBreaking {
    // Fraction of the local wave energy lost to depth-limited breaking right now: 1 − (γh / 2A)²
    // where the local envelope height 2A exceeds γh, else 0; A is the wave-group envelope.
    double intensity = 0.0;
    // Whether the point lies shoreward of the mean breaker line (where H_rms of the unbroken
    // waves reaches γ h on the plane beach), and the group travel time from that line (s): foam
    // left by broken waves is that old at most. Negative seaward of the line.
    bool broken = false;
    double timeSinceBreaking_s = -1.0;
};

// What the surf adds at a rest position, beside the terms.
struct SurfPointInfo {
    double depth_m = 0.0;    // still-water depth (tide − seabed), negative on land
    double seabedZ_m = 0.0;  // ENU z of the seabed
    // Share of the sea's variance drawn by the deep sea (FFT + Gerstner) and by the surf
    // components, as amplitude weights (deep² + surf² = 1); the parts' weights in weights.
    double deepWeight = 1.0;
    double surfWeight = 0.0;
    SurfWeights weights;
    double envelope_m = 0.0;  // local wave-group envelope amplitude |Σ A e^{iψ}| (saturated)
    double unbrokenHeight_m = 0.0;  // 2 × envelope before the breaker cap
    SurfBreaking breaking;
    // The dominant (largest local amplitude) component: direction of travel (azimuth), phase
    // speed and group speed at the local depth, its phase (rad, in [0, 2π)).
    double direction_rad = 0.0;
    double phaseSpeed_mps = 0.0;
    double groupSpeed_mps = 0.0;
    double phase_rad = 0.0;
};

struct SurfWaveSettings {
    double breakerIndex = 0.78;  // McCowan (1894): H_b / h_b
    double deepSteepness = 0.5;  // Gerstner Q of the surf components in deep water
};

// Immutable after construction; pure and thread-safe.
class SurfWaves {
  public:
    // peakWavelength_m sets the fade depths (¼ and ½ of it) of the Gerstner waves, and of the
    // spectral components when no cascades are given; cascades (at most kMaxSurfCascades) fade
    // with their own wavelengths.
    SurfWaves(const Bathymetry& bathymetry, std::vector<SurfComponent> components,
              double peakWavelength_m, std::vector<SurfCascade> cascades = {},
              const SurfWaveSettings& settings = {});

    const Bathymetry& Bathy() const { return bathy_; }
    const std::vector<SurfComponent>& Components() const { return components_; }
    const std::vector<SurfCascade>& Cascades() const { return cascades_; }
    // Depth below which any part of the sea fades (the deepest fade), and the Gerstner waves'
    // (peak wavelength) fade depths.
    double FadeDeep_m() const { return fadeDeep_m_; }
    double PeakFadeDeep_m() const { return peakFadeDeep_m_; }
    double PeakFadeShallow_m() const { return peakFadeShallow_m_; }
    double BreakerIndex() const { return settings_.breakerIndex; }

    // Weights of the sea's parts at a still-water depth h (m).
    SurfWeights Weights(double depth_m) const;

    // Which points Terms describes the dominant component at (SurfPointInfo::direction_rad,
    // phaseSpeed_mps, groupSpeed_mps, phase_rad): everywhere, or only shoreward of the breaker
    // line (breaking.broken), the one place the surf foam reads them (SurfFoamCoverage's streaks
    // follow the broken water); elsewhere they are left 0, saving an atan2 and an fmod per point,
    // and breaking.timeSinceBreaking_s is left −1 there (the foam reads it only where broken),
    // saving a table lookup.
    enum class Dominant { kEverywhere, kWhereBroken };
    // What a caller that needs less than everything can leave out or hand in (TermsBatch, the
    // mesh's, runs with velocity and shareWeights false, kWhereBroken and the seabed handed
    // in). None of it changes a bit of the terms, nor of what the surf foam reads.
    struct TermsOptions {
        bool velocity = true;  // false: velocity_mps left 0 (three sums fewer per component)
        Dominant dominant = Dominant::kEverywhere;
        // false: SurfPointInfo::surfWeight and deepWeight left at their defaults (0 and 1), which
        // the mesh and the foam do not read (two square roots and a division per point).
        bool shareWeights = true;
        // Bathy().SeabedZAtShore_m at the point's shore coordinates when the caller has it
        // (OceanSurfaceFrame::DryLandSums), else NaN and Terms looks it up.
        double seabedZ_m = std::numeric_limits<double>::quiet_NaN();
    };

    // The surf components' terms at rest position (x0, y0), time t (already weighted by the surf
    // weight), and the point's information. Velocity is included unless options say otherwise.
    SurfaceTerms Terms(double x0, double y0, double t_s, SurfPointInfo* info = nullptr) const {
        return Terms(x0, y0, t_s, info, TermsOptions{});
    }
    SurfaceTerms Terms(double x0, double y0, double t_s, SurfPointInfo* info,
                       const TermsOptions& options) const;
    // Terms with its component loops four float lanes wide, as the SSE2 build runs them: the
    // reference the AVX2 build's eight-lane loops must equal bit for bit (tests).
    SurfaceTerms TermsFourLanes(double x0, double y0, double t_s, SurfPointInfo* info,
                                const TermsOptions& options) const;
    // Terms at count ≤ kBatch points at once with the options the mesh asks for (no velocity,
    // the dominant component where broken, no variance shares, each point's seabed handed in
    // as seabedZ_m[i]): the same bits as Terms at each point alone (tested). The depth weights
    // (Fade's sine-cosine) and the arithmetic after the component sums, scalar double code
    // that was most of a point's cost, run one point a lane on four double lanes with the
    // same operations in the same order; the component sums stay per point.
    static constexpr size_t kBatch = 4;
    void TermsBatch(const double* x0, const double* y0, const double* seabedZ_m, size_t count,
                    double t_s, SurfPointInfo* infos, SurfaceTerms* out) const;

    // Upper bounds of the sea at still-water depths ≥ minDepth_m: its height above the tide and
    // its horizontal displacement (m). The deep parts enter with their own bounds (each FFT
    // cascade's, in the order of the cascades given at construction, and the Gerstner waves')
    // times their fade weights; the surf components with their shoaled sum capped at γh/2 and
    // their horizontal excursion as Terms limits it. Between depth samples each factor is taken
    // at its larger end, so the bound holds at every depth, not only at the samples.
    struct Bound {
        double height_m = 0.0;
        double horizontal_m = 0.0;
    };
    static constexpr Bound kNoCap{std::numeric_limits<double>::infinity(),
                                  std::numeric_limits<double>::infinity()};
    // surfCap, when given, caps the surf components' height and horizontal excursion in every
    // interval (e.g. BoundNear's bounds for the points in question), and maxDepth_m bounds the
    // depths from above (no interval deeper, and the deep sea's own bound only if it reaches
    // FadeDeep_m). The Gerstner height may be negative (a signed bound, as from
    // GerstnerOcean::ElevationBoundNear_m): an interval then weights it with the smallest deep
    // weight its depths have (the weight at its shallow end), not the largest.
    Bound BoundAtDepths(double minDepth_m, const std::vector<Bound>& cascades,
                        const Bound& gerstner, const Bound& surfCap = kNoCap,
                        double maxDepth_m = std::numeric_limits<double>::infinity()) const;
    // The same for any minimum depth from one table per set of deep-sea bounds: each depth
    // interval's bound with its surf weights at its shallow end, and their running maximum from
    // the deep end; BoundAtDepths(minDepth, table) then costs one interval, and equals the
    // function above bit for bit.
    struct BoundTable {
        std::vector<Bound> cascades;
        Bound gerstner;
        Bound deep;
        std::vector<Bound> fromInterval;  // max over intervals ≥ i (a zero bound past the last)
    };
    BoundTable MakeBoundTable(const std::vector<Bound>& cascades, const Bound& gerstner) const;
    Bound BoundAtDepths(double minDepth_m, const BoundTable& table) const;

    // Upper bounds (m) of the height and of the horizontal excursion the surf components add at
    // time t_s over every rest position within radius_m of world (x, y), whose still-water
    // depths lie in [minDepth_m, maxDepth_m] (Terms; the swash apart).
    // Height, cap · Re Σ a e^{iψ} (0 < cap ≤ 1): the positive part of Re Σ a e^{iψ} at (x, y)
    // itself plus the lesser of two bounds on its change across the disc, (1) per component
    // the spread of its weighted, shoaled amplitude over those depths and its amplitude times
    // min(2, |Δψ|) for the largest phase change (|k_u| + max |k_s|) · radius; (2) the
    // first-order change |G · d| ≤ radius ‖G‖ of the sum with the centre's amplitudes (G =
    // Σ a e^{iψ} ∇ψ at the centre, the cross-shore slope taken mid-way between the phase
    // table's slopes over the disc) plus, per component, the amplitude spread and its amplitude
    // times the Taylor remainder (phase-slope spread × radius + (|∇ψ| radius)²/2, at most
    // 2 + |∇ψ| radius).
    // Horizontal, q · cap · |Σ P sin ψ| shrunk by the orbit limit (P = a / tanh(kh) times the
    // unit direction of travel): |Σ P sin ψ| at (x, y) plus radius ‖M‖ (M = Σ P cos ψ ∇ψᵀ at the
    // centre, Frobenius norm) plus per component |P| times the same remainder and the extent of
    // P's box over those depths.
    // Local in time as well as in space, unlike Σ a, which all components reach only together;
    // they grow with the radius and are worth taking only over a few metres (the sea under an
    // eye). +∞ where (x, y) is dry or all deep (no sum there to start from).
    Bound BoundNear(double x, double y, double t_s, double radius_m, double minDepth_m,
                    double maxDepth_m) const;

    // Mean breaker line (cross-shore s, m) of the plane beach: +∞ if no component, −∞ if the waves
    // never break before the shore.
    double BreakerLine_m() const { return sBreak_m_; }

    // Deepest still-water depth (m, in 0.1 m steps; 0 if none) at which 2 Σ A_j, each deep-water
    // amplitude shoaled by energy flux to that depth, reaches γ h: no component breaks deeper (the
    // envelope 2A ≤ 2 Σ A_j, refraction only lowers it). Made once here rather than per spray
    // field: each channel's frame made a SprayField (~1.2 M instructions of dispersion solves).
    double MaxBreakingDepth_m() const { return maxBreakDepth_m_; }

    // --- Swash run-up (seed 003: "the cusp surf sporadically washes farther up inland in various
    // places and then retreats"). Published scale (Stockdon, Holman, Howd & Sallenger, Coastal
    // Eng. 53, 573 (2006), eqs. 10-12, deep-water Hs H0, peak wavelength L0 = g Tp²/2π,
    // foreshore slope β_f): setup η̄ = 0.35 β_f √(H0 L0), significant swash height
    // S = √(H0 L0 (0.563 β_f² + 0.004)), 2 % run-up R2 = 1.1 (η̄ + S/2).
    // The water level the swash adds is ζ = w · (η̄ + S/4 · g(t, u) · m(u)):
    //  g, the surf beat: the incoming wave-group envelope 2A at the mean breaker line (the surf
    //    components shoaled there, at alongshore u) as (2A/H_rms − √π/2) / √(1 − π/4), zero mean
    //    and unit variance for a Rayleigh-distributed envelope (Longuet-Higgins 1952), so ζ has
    //    mean η̄ and significant height 4σ = S;
    //  m, the cusps: (1 + c cos 2πu/λ) / √(1 + c²/2) (mean square 1) with the cusp spacing λ and
    //    amplitude c of environment.ocean.surf.swash;
    //  w, where: 1 on the beach (up to 2 R2 / β_f + 10 m landward of the still-water line, where
    //    the swash can never reach), falling linearly to 0 at depth 2 R2 seaward.
    // On the beach the water is flat at tide + ζ and the seabed clamp puts the waterline where the
    // sand rises above it. 0 without swash (disabled, no components, no breaker line).
    struct SwashParameters {
        bool active = false;
        double H0_m = 0.0, L0_m = 0.0, foreshoreSlope = 0.0;
        double setup_m = 0.0, significant_m = 0.0, runup2_m = 0.0;  // η̄, S, R2
        double cuspSpacing_m = 0.0, cuspAmplitude = 0.0;
        double shoreline_m = 0.0;   // cross-shore s of the still-water line (plane beach)
        double breakerRms_m = 0.0;  // H_rms of the surf components at the breaker line
        // Largest ζ anywhere, ever (for surface bounds): the envelope at most 2 Σ A_j there, the
        // cusp factor at most (1 + c) / √(1 + c²/2).
        double max_m = 0.0;
    };
    const SwashParameters& Swash() const { return swash_; }
    // ζ (m, added to the surface height) at shore point (s, u), time t, still-water depth h.
    double Swash_m(double s_m, double u_m, double t_s, double depth_m) const;
    // False where Swash_m is +0 whatever s, u and t (inactive, or still water at least twice the
    // run-up deep: most of the surf zone), so that Terms can skip the call there.
    bool SwashReaches(double depth_m) const {
        return swash_.active && !(depth_m > 0.0 && depth_m >= 2.0 * swash_.runup2_m);
    }
    // --- end swash

  private:
    Bound DeepBound(const std::vector<Bound>& cascades, const Bound& gerstner) const;
    // What interval i's (depths i·dh … (i+1)·dh) bound takes from the depth, with the surf
    // weights at surfDepth_m: the deep parts' weights (at the deep end), the surf components'
    // height and horizontal excursion, and the swash's maximum where it reaches (else 0).
    struct IntervalParts {
        SurfWeights deep;
        // The Gerstner waves' deep weight at the interval's surf depth: the smallest on it.
        double gerstnerShallow = 0.0;
        double surfHeight_m = 0.0, swash_m = 0.0, surfHorizontal_m = 0.0;
    };
    IntervalParts Parts(int i, double surfDepth_m) const;
    // Interval i's bound with the surf weights at surfDepth_m.
    Bound IntervalBound(int i, double surfDepth_m, const std::vector<Bound>& cascades,
                        const Bound& gerstner, const Bound& surfCap = kNoCap) const;
    std::vector<IntervalParts> intervalParts_;  // Parts(i, i·dh) per interval
    // kWide: the per-component loops eight float (four double) lanes at a time where the build
    // targets AVX2, else four (two) as in the SSE2 build.
    template <bool kVelocity, bool kWide>
    SurfaceTerms TermsImpl(double x0, double y0, double t_s, SurfPointInfo* info,
                           const TermsOptions& options) const;
    // What Terms' component loops give at a point (TermsImpl and TermsBatch share them): the
    // sums reduced in double (re, im, slopeS, slopeU, dispS, dispU, tSS, tUU, tSU, orbit, velZ,
    // velS; velU apart), the largest 1/tanh kh, the depth interpolation and, for the dominant
    // component, each component's phase and amplitude.
    struct PointSums {
        alignas(32) std::array<double, 12> total;
        double velU, longestInvTanh;
        size_t di;
        double df;
        alignas(32) std::array<double, kMaxSurfComponents> psis;
        alignas(32) std::array<float, kMaxSurfComponents> amplitudes;
    };
    template <bool kVelocity, bool kWide>
    void SumComponents(double s_m, double u_m, double h, double t_s, double tableIndex,
                       const SurfWeights& weights, PointSums& sums) const;
    // The dominant component's fields of info (direction, speeds, phase).
    void DominantInto(const PointSums& sums, SurfPointInfo& info) const;
    void BuildSwash();
    SwashParameters swash_;
    std::vector<double> swashAmplitude_, swashPhase_;  // per component at the breaker line

    struct Track {                             // per component
        double k0 = 0.0, ks0 = 0.0, ku = 0.0;  // deep wavenumber and its shore components
        double cg0 = 0.0, cos0 = 1.0;
        double phaseOrigin = 0.0;  // k0 · shoreline origin + φ
        bool incoming = false;
        std::vector<double> phase;  // ∫ k_s ds from sRef_m_ at s = sRef − i ds
        std::vector<double> k;      // k at depth index (h = i dh)
        std::vector<double> cg;     // group speed at depth index
    };
    // What Terms needs of an incoming component at one depth sample, derived once from k and cg
    // so that a vertex costs one interpolation per quantity and no sqrt or tanh: the wavenumber,
    // its cross-shore part k_s, the shoaled and refracted amplitude A0 √(cg0/cg) √(cos θ0/cos θ)
    // (before the fade weight), 1/tanh(kh) and the group speed.
    struct DepthSample {
        double k, kx, amplitude, invTanh, cg;
    };
    double DepthTable(const std::vector<double>& t, double h) const;

    // --- Sandbar shelter (seed 003, "Sandbars"): waves that broke on a bar arrive shoreward of
    // it with only the energy flux the bar let through. Per sandbar region a table over the bar's
    // alongshore extent and its cross-shore span from the seaward foot to the shoreline holds the
    // running minimum, walking landward, of the saturated breakers' energy-flux proxy h √cg(h)
    // ((γh)² cg ∝ E cg at the breaker cap; the dominant component's group speed). Shelter is
    // that minimum over the local value, at most 1: the local breaker cap γ h becomes
    // γ h · Shelter. On a plane beach (h √cg falls monotonically shoreward) it is exactly 1.
    struct BarShelter {
        double u0_m = 0.0, du_m = 1.0;  // first column's offset in its region, column step
        double s0_m = 0.0;              // seaward foot of the bar (row 0), rows ds_m_ landward
        int nu = 0, ns = 0;
        std::vector<double> fluxMin;  // [column * ns + row]
    };
    void BuildShelters();
    double FluxProxy(double h) const;
    double Shelter(double s_m, double u_m, double h) const;
    double ShelterBehindBar(double s_m, double u_m, double h) const;  // Shelter's lookup
    // Weights into w, which holds SurfWeights' defaults (inlined into Terms).
    void WeightsInto(double depth_m, SurfWeights& w) const;
    std::vector<int> shelterOfRegion_;  // index into shelters_ or −1
    std::vector<BarShelter> shelters_;
    size_t dominant_ = 0;
    // --- end sandbar shelter

    Bathymetry bathy_;
    std::vector<SurfComponent> components_;
    std::vector<SurfCascade> cascades_;
    SurfWaveSettings settings_;
    double fadeDeep_m_ = 0.0, peakFadeDeep_m_ = 0.0, peakFadeShallow_m_ = 0.0;
    double cascadeVariance_m2_ = 0.0;
    bool cascadeFade_ = false;  // cascades given with variance: each fades with its own depth
    double spectralVariance_m2_ = 0.0, gerstnerVariance_m2_ = 0.0;  // of the components
    double sRef_m_ = 0.0, sShore_m_ = 0.0, ds_m_ = 0.5;
    size_t phaseSamples_ = 0;  // cross-shore samples of lanePhase_ (lanePhase_.size() / lanes_)
    // The shore frame's seaward and alongshore unit vectors in the world, as
    // Frame().WorldFromShoreDirection gives them for (1, 0) and (0, 1).
    glm::dvec2 seawardWorld_{1.0, 0.0}, alongshoreWorld_{0.0, 1.0};
    double dh_m_ = 0.02;
    int depthSamples_ = 0;
    std::vector<Track> tracks_;
    // Incoming components (indices into components_), and their depth samples interleaved by
    // sample: depth_[i · n + j] for n incoming.
    std::vector<size_t> incoming_;
    std::vector<DepthSample> depth_;
    // For Terms, the phases two components at a time in double (SSE2 lanes), the rest four at
    // a time in float: the incoming count padded to a multiple of 4, lanes_, with silent
    // components (zero amplitude, zero 1/tanh kh); per component its constants (the phase's in
    // double, the sums' in float), per depth sample the interpolated fields (kLaneFields,
    // field-major, float), per cross-shore sample the phases ∫ k_s ds.
    static constexpr size_t kLaneFields = 4;  // amplitude, 1/k, k_s, 1/tanh kh
    size_t lanes_ = 0;
    std::vector<double> laneOrigin_, laneKu_, laneOmega_, laneKs0_;
    std::vector<float> laneKuF_, laneOmegaF_, laneSpectral_;
    std::vector<float> laneDepth_;   // [(i · kLaneFields + field) · lanes_ + m]
    std::vector<double> lanePhase_;  // [i · lanes_ + m]
    double shelterSeaward_m_ = 0.0;  // with shelters: none seaward of this cross-shore s
    double sBreak_m_ = 0.0;
    double maxBreakDepth_m_ = 0.0;
    std::vector<double> breakTime_s_;  // group travel time from the breaker line, per s sample
    bool breakingLine_ = false;        // a finite breaker line with its travel times
};

}  // namespace seasense::scene
