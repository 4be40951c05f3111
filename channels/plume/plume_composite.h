// Plumes in the rendered channels: the scenario's plume field committed at the frame's time,
// traced once per output pixel inside the plumes' screen bounds and composited over the
// channel's supersampled radiance (visible RGB for OTW, band radiance for FLIR).
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include "channels/camera/channel_camera.h"
#include "channels/plume/plume_bins.h"
#include "channels/raster/rasterizer.h"
#include "radiometry/planck/planck.h"
#include "radiometry/sky/analytic_sky.h"
#include "scene/core/image.h"
#include "scene/plumes/plume_field.h"
#include "scene/plumes/plume_system.h"
#include "scene/world/world.h"

namespace seasense::channels {

class FlirChannel;

// Henyey–Greenstein phase function (sr⁻¹, ∫ p dΩ = 1) at scattering-angle cosine cosTheta for
// asymmetry g in (−1, 1): p = (1 − g²) / (4π (1 + g² − 2 g cos θ)^(3/2)) (Henyey & Greenstein,
// Astrophys. J. 93 (1941) 70).
float HenyeyGreensteinPhase(float cosTheta, float g);

// Background radiance seen through a plume of transmittance T with a source function S that
// is constant along the path: L = L_bg·T + (1 − T)·S, the formal solution of the radiative
// transfer equation dL/dτ = S − L over optical depth τ = −ln T (Chandrasekhar, "Radiative
// Transfer" (1960) §1.8; Bohren & Clothiaux, "Fundamentals of Atmospheric Radiation" (2006)
// §5.3). Exactly L_bg when T = 1.
inline float CompositeThroughPlume(float background, float transmittance, float source) {
    return background * transmittance + (1.0f - transmittance) * source;
}

// Visible thermal emission of a blackbody (linear Rec.709 RGB, cd/m², Y = luminance):
// 683 lm/W × the CIE 1931 X, Y, Z band radiances of Planck's law (radiometry CieX/Y/Z), turned
// into Rec.709 by Rec709FromXyz; tabulated every 10 K on [500, 3000] K and linear between
// (zero below 500 K, where the luminance is below 1e-9 cd/m²; clamped above 3000 K).
class BlackbodyGlowTable {
  public:
    BlackbodyGlowTable();
    // The glow in another three-component basis (channels/nvg: photocathode sub-bands):
    // components(T_K) tabulated on the same grid, every kStep_K on [kMinT_K, kMaxT_K].
    static constexpr double kMinT_K = 500.0, kMaxT_K = 3000.0, kStep_K = 10.0;
    template <class Components>
    explicit BlackbodyGlowTable(const Components& components) {
        for (double T = kMinT_K; T <= kMaxT_K + 1e-9; T += kStep_K)
            rgb_.push_back(glm::vec3(components(T)));
    }
    glm::vec3 operator()(float T_K) const;

  private:
    std::vector<glm::vec3> rgb_;
};

// The light on the plumes for one frame of one channel, and what the source function is.
struct PlumeLighting {
    enum class Kind { Visible, Infrared };
    Kind kind = Kind::Visible;
    // Visible: S = ω [E_sun p_HG(cos θ; g) + L_amb] + (1 − ω) L_glow(T), per colour: single
    // scattering of the direct sun (E_sun in lx on a surface normal to the sun, per Rec.709
    // colour) and of an isotropic ambient radiance L_amb (cd/m², the solid-angle mean of sky
    // and sea), plus the visible glow of the absorbing (emitting) particles at the trace's
    // absorption-weighted temperature. θ is the angle between the sun's light and the light
    // reaching the eye. The sun is not attenuated inside the plume (single scattering).
    glm::vec3 sunDirection{0.0f, 0.0f, 1.0f};  // unit ENU, toward the sun
    glm::vec3 sunIlluminance{0.0f};
    glm::vec3 ambientRgb{0.0f};
    const BlackbodyGlowTable* glow = nullptr;
    // Infrared: S = ω L_amb + (1 − ω) B_band(T) with the band's optical depth and albedo.
    scene::ObscurantBand band = scene::ObscurantBand::Lwir;
    float ambient = 0.0f;  // W·m⁻²·sr⁻¹
    const radiometry::BandRadianceTable* planck = nullptr;
};

// The per-pixel arithmetic of CompositePlumes, with the forms that do four pixels at once
// (SSE2; the same operations lane for lane in the same order and no fused multiply-add, so each
// lane has the bits of the one-pixel form: tested).
namespace plume_detail {
// Bilinear blend of four traces (corners 00, 10, 01, 11) at fractions fx, fy: optical depths
// blend linearly; albedo, temperatures and asymmetry as the matching depth-weighted means.
BandTrace Bilinear(const BandTrace* const t[4], float fx, float fy);
// Bilinear(t, fx[l], fy[l]) into out[l], l = 0 … 3.
void Bilinear4(const BandTrace* const t[4], const float fx[4], const float fy[4], BandTrace out[4]);
// The visible source function S of PlumeLighting for trace t seen along toEye (unit, from the
// plume to the eye).
glm::vec3 VisibleSource(const BandTrace& t, const glm::vec3& toEye, const PlumeLighting& light);
// VisibleSource(*t[l], −normalize(worldFromCamera · (a[l], 1, b[l])), light) into out[l] for
// l < n ≤ 4 (the direction as CompositePlumes makes a pixel's); lanes l ≥ n are computed from
// t[l], a[l], b[l] too and dropped.
void VisibleSource4(const BandTrace* const t[4], const glm::mat3& worldFromCamera, const float a[4],
                    const float b[4], int n, const PlumeLighting& light, glm::vec3 out[4]);
// For the n pixels l of a cell blended from its corners t: Bilinear(t, fx[l], fy[l])'s optical
// depth into tau[l] and its VisibleSource along −normalize(worldFromCamera · (a[l], 1, b[l]))
// into S[l], simd::kLanes pixels at a time with the blended traces kept in registers (the same
// operations lane for lane as Bilinear4 and VisibleSource4, so each pixel has the bits of the
// one-pixel forms: tested).
void BlendedVisibleSources(const BandTrace* const t[4], const float* fx, const float* fy,
                           const float* a, const float* b, int n, const glm::mat3& worldFromCamera,
                           const PlumeLighting& light, float* tau, glm::vec3* S);
// The infrared source function S of PlumeLighting for trace t.
float InfraredSource(const BandTrace& t, const PlumeLighting& light);
// For the n pixels l of a cell blended from its corners t: Bilinear(t, fx[l], fy[l])'s optical
// depth into tau[l] and, where it is positive, its InfraredSource into S[l] (else 0), the
// blends simd::kLanes pixels at a time (the bits of the one-pixel forms: tested).
void BlendedInfraredSources(const BandTrace* const t[4], const float* fx, const float* fy, int n,
                            const PlumeLighting& light, float* tau, float* S);
// A pixel's 2 × 2 RGB samples composited through a plume of transmittance T and source S (RGB):
// L_bg·T + (1 − T)·S per value, each sample row's six values (R G B R G B) at once (SSE2); o is
// the pixel's first sample, sampleRow the floats from one sample row to the next.
void CompositeRgb2x2(float* o, size_t sampleRow, float T, const float* S);
// CompositeRgb2x2(o + 6 l, sampleRow, T[l], S + 3 l) for the pixels l = 0 … 3 of a row with
// tau[l] > 0 and drop[l] == 0, all four at once where the build has AVX2 (the same bits: tested).
void CompositeRgb2x2Row4(float* o, size_t sampleRow, const float* T, const float* S,
                         const float* tau, const int32_t* drop);
// A whole 4 × 4-pixel cell with 2 × 2 RGB samples blended from its corners t and composited:
// BlendedVisibleSources of its 16 pixels in row order (pixel (lx, ly) at fx = colFx[lx],
// fy = rowFy[ly], a = colA[lx], b = rowB[ly]), T = simd4::Exp4(−τ), then CompositeRgb2x2Row4 of
// each pixel row ly at o + 2 ly sampleRow, with pixel drop (ly · 4 + lx; −1: none) dropped. Where
// the build has AVX2, two pixel rows at a time with every value kept in registers (the same
// operations lane for lane: the same bits, tested).
void BlendedVisibleCell2x2(const BandTrace* const t[4], const float colFx[4], const float rowFy[4],
                           const float colA[4], const float rowB[4], int drop,
                           const glm::mat3& worldFromCamera, const PlumeLighting& light, float* o,
                           size_t sampleRow);
// BlendedVisibleCell2x2 step by step, as its comment says (what it does without AVX2, and the
// reference its AVX2 form is tested against).
void BlendedVisibleCell2x2Steps(const BandTrace* const t[4], const float colFx[4],
                                const float rowFy[4], const float colA[4], const float rowB[4],
                                int drop, const glm::mat3& worldFromCamera,
                                const PlumeLighting& light, float* o, size_t sampleRow);
// Whether every sample of `rows` rows of eight visibility-buffer samples (row j at primitive and
// depth + j·stride) sees the sky: no primitive, or no depth in front (depth ≤ 0). Eight samples
// at a time where the build has AVX2 (tested against the one-sample test).
bool AllSky8(const uint32_t* primitive, const float* depth, size_t stride, int rows);
// Whether every such sample's depth, −1 where it sees the sky, is at least `least` (false at the
// first row with one that is not).
bool AllDepthsAtLeast8(const uint32_t* primitive, const float* depth, size_t stride, int rows,
                       float least);
}  // namespace plume_detail

struct PlumeCompositeStats {
    uint64_t pixelsCovered = 0;          // output pixels inside some plume's screen bounds
    uint64_t traces = 0;                 // rays traced (one per covered pixel, two at depth edges)
    uint64_t puffTests = 0;              // puffs looked at by those traces (their lists' lengths)
    uint64_t surfaceCellsFromNodes = 0;  // cells of surfaces blended from the nodes' pixels
    uint64_t coarseSkyCells = 0;         // cells of sky blended from the coarse grid
    double ms = 0.0;                     // bounds, traces and compositing
};

// Rays to the sky are traced this far (m).
inline constexpr float kPlumeSkyRange_m = 1.0e6f;

// Composites field over radiance, the channel's supersampled image (3 channels for Visible,
// 1 for Infrared) of camera with visibility buffer vis. The puffs are binned on the screen for
// the channel's band (PlumeScreenBins: each traced ray's transmittance within
// kPlumeTransmittanceTolerance of the exact sum over all puffs). Every 4×4-pixel cell takes
// the puffs whose screen rectangles reach it (none: the cell is left alone), and the nearest
// and farthest points of their boxes bound the ranges where they can matter. Per pixel of such
// a cell, with the ranges of its samples' surfaces (sky: kPlumeSkyRange_m):
//  - all surfaces nearer than the cell's puffs: nothing to do;
//  - all surfaces beyond them: the sky trace, bilinear from traces at the corners of the cell
//    when the puffs smaller than a cell reaching it could add at most 0.02 in optical depth and
//    either the corners' transmittances agree within 0.02 and their temperatures (where they
//    see absorbing puffs) within 10 K, or the corners' blend at the cell's centre pixel matches
//    that pixel's own trace within 0.005 and 5 K (a linear variation across the cell); else
//    refined on 2 × 2-pixel sub-cells by the same corner criteria, and traced through the pixel
//    centre where those fail. First, though, the whole cells of 2 × 2 cells (8 × 8 pixels,
//    from even cell indices) whose every sample sees the sky beyond their puffs are blended
//    from the traces at their corners (every other grid node) by the same criteria, with the
//    sum over the four cells of the puffs smaller than 8 pixels as the fine puffs and the
//    coarse cell's centre node (its own trace then) as the centre pixel; the nodes that only
//    such cells read are not traced;
//  - otherwise one ray through the pixel centre to the nearest surface and, when the ranges
//    differ by more than 10 %, to the farthest in the same pass; each sample takes the trace
//    whose end is nearer its own range. In a cell all of whose pixels take one such ray, with
//    no puff smaller than a cell, the rays are blended bilinearly instead: first from the
//    traces of the cell's grid nodes' pixels to their own nearest surfaces (made with the
//    nodes' sky traces, in the same pass, where a node's pixel lies in the image, its
//    samples see surfaces within 10 % of each other and its traces to 10 % before and beyond
//    its surface match within 0.005 and 5 K: no surface inside the puffs that a step in
//    range the 10 % admit would cut), when there is no depth edge (every
//    range within 10 % of the bilinear blend of the nodes' pixels') and either those traces'
//    transmittances agree within 0.02 and their temperatures within 10 K or their blend at the
//    centre pixel matches that pixel's own trace within 0.005 and 5 K (the centre pixel then
//    keeps its own); else from the traces of the cell's corner pixels, when every range is
//    within 10 % of the bilinear blend of theirs and the blend matches the own traces of
//    pixels (1, 1) and (2, 2) within 0.005 and 5 K.
// The pixels of whole cells blended from one set of corners take e^(−τ) from simd4::Exp4
// (within 2e-7 relative), the others from std::exp. Samples whose traces have no optical depth are
// left bit for bit as they were. With renderSpans (one per pixel row; empty: every pixel), a cell
// none of whose pixels lies in them is skipped as a cell wholly behind surfaces is: the pixels in
// the spans come out bit for bit as without them, the others of such cells are left alone (an NVG
// field stop passes no light there). Runs in the caller's oneTBB arena; bit-identical for any
// thread count.
PlumeCompositeStats CompositePlumes(const scene::PlumeField& field, const ChannelCamera& camera,
                                    const VisibilityBuffer& vis, const PlumeLighting& light,
                                    Image& radiance, std::span<const PixelSpan> renderSpans = {});

// One channel's plumes: the scenario's PlumeSystem (ambient from the scenario's wind, the sun
// elevation at frame 0 and a clear sky; air temperature from plumes.air_temperature_K, else
// environment.atmosphere's) and a field committed at each frame's time. Every channel process
// commits the same field for the same time (PlumeSystem::Commit is pure in t).
class ChannelPlumes {
  public:
    // InputError for plume settings PlumeSystem rejects.
    explicit ChannelPlumes(const scene::World& world);

    // Whether the scenario has any plume source.
    bool Active() const { return system_ != nullptr; }
    // The field at time_s (committed when the time changed).
    const scene::PlumeField& FieldAt(double time_s);

    // The one call in OtwChannel::Render: composites onto the OTW radiance (cd/m², RGB) with
    // the frame's sky. No-op without plumes.
    void CompositeOtw(const scene::SceneState& state, const ChannelCamera& camera,
                      const VisibilityBuffer& vis, const radiometry::AnalyticSky& sky,
                      Image& radiance);
    // The one call in FlirChannel::Render: composites onto the band radiance with the
    // channel's atmosphere, sea and Planck table. No-op without plumes.
    void CompositeFlir(const scene::SceneState& state, const ChannelCamera& camera,
                       const VisibilityBuffer& vis, const FlirChannel& channel, Image& radiance);

    const PlumeCompositeStats& Stats() const { return stats_; }

  private:
    std::unique_ptr<scene::PlumeSystem> system_;
    scene::PlumeField field_;
    double committed_s_ = std::numeric_limits<double>::quiet_NaN();
    std::unique_ptr<BlackbodyGlowTable> glow_;  // OTW only, made on first use
    PlumeCompositeStats stats_;
};

// Solid-angle mean radiance (cd/m², RGB) of the sky model's upper hemisphere (midpoint
// quadrature in cos zenith and azimuth, 16 × 32 directions).
glm::dvec3 SkyMeanRadiance(const radiometry::AnalyticSky& sky);

// Solid-angle mean radiance (cd/m², RGB) of sky and sea around a plume: the upper hemisphere
// SkyMeanRadiance, the lower the sea's diffuse reflection of the downwelling light (albedo 0.06,
// Payne, J. Atmos. Sci. 29 (1972) 959, as a Lambertian reflector): the sky model's dome and the
// frame's own sun, sunIlluminanceRgb (lx on a surface normal to it, per Rec.709 component) from
// sunDirection (unit ENU). The sun is the frame's, not the sky model's: a sky table is reused
// over a quantized step of the sun's path, and the frame's light must not depend on which
// earlier frame built it.
glm::vec3 VisibleAmbientRadiance(const radiometry::AnalyticSky& sky, const glm::dvec3& sunDirection,
                                 const glm::dvec3& sunIlluminanceRgb);

}  // namespace seasense::channels
