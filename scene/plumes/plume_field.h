// The plume puffs alive at one instant as Gaussian obscurant blobs, with a BVH over their
// bounds and per-ray optical depth, single-scattering albedo and emitting temperature per band.
#pragma once

#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <span>
#include <vector>

#include "scene/plumes/plume_settings.h"

namespace seasense::scene {

// The bands in which plumes are characterised (band centres in BandCentre_m).
enum class ObscurantBand : uint8_t { Visible, Nir, Mwir, Lwir };
inline constexpr int kObscurantBands = 4;

// Representative wavelength (m): visible 0.55 µm, near-IR 0.85 µm (image-intensifier band),
// MWIR 4 µm (3–5 µm window), LWIR 10 µm (8–12 µm window).
double BandCentre_m(ObscurantBand band);

// Mass extinction coefficient α (m²/kg, seed 004 Eq 1) and single-scattering albedo per band,
// and the Henyey–Greenstein asymmetry parameter g of the particles in sunlight (visible and
// near-IR; the infrared channels scatter no sunlight).
struct ObscurantOptics {
    std::array<double, kObscurantBands> massExtinction_m2pkg{};
    std::array<double, kObscurantBands> albedo{};
    double asymmetry = 0.0;
};

// Optics of a plume kind with the given visible single-scattering albedo (the other bands
// keep the kind's ratio to the visible). Sources in the .cpp.
ObscurantOptics KindOptics(PlumeKind kind, double visibleAlbedo);

// ∫ C dl (kg/m²) along origin + s·dir, s in [0, maxDistance_m], through the Gaussian puff of
// seed 004 Eq 2–3 with mass mass_kg, centre centre_m, horizontal σ sigmaH_m (both horizontal
// axes) and vertical σ sigmaZ_m; dir must be a unit vector. Exact (erf), in double.
double GaussianPuffLineIntegral_kgpm2(const glm::dvec3& centre_m, double sigmaH_m, double sigmaZ_m,
                                      double mass_kg, const glm::dvec3& origin_m,
                                      const glm::dvec3& dir, double maxDistance_m);

// One Gaussian puff, ENU metres.
struct Puff {
    glm::dvec3 centre_m{0.0};
    double sigmaH_m = 1.0;  // along both horizontal axes
    double sigmaZ_m = 1.0;  // vertical
    double mass_kg = 0.0;
    double temperature_K = 288.15;
    uint32_t plume = 0;  // index into the field's optics table
};

// What a ray meets in the plumes, per band: optical depth τ = Σ α ∫C dl, the optical-depth
// weighted single-scattering albedo, and the mean temperature of the absorbing (hence, by
// Kirchhoff, emitting) puffs weighted by their absorption optical depth (0 when none); the
// radiometry layer turns the latter into Planck radiance.
struct PlumeTrace {
    std::array<float, kObscurantBands> opticalDepth{};
    std::array<float, kObscurantBands> albedo{};
    std::array<float, kObscurantBands> temperature_K{};
    // The part of the absorption optical depth from puffs at or above kHotPuff_K (flames) and
    // their absorption-weighted mean temperature (0 when none): emission is steeply
    // nonlinear in temperature, so renderers weight B(T_hot) and B(T_rest) separately rather
    // than take B of the mean.
    std::array<float, kObscurantBands> hotFraction{};
    std::array<float, kObscurantBands> hotTemperature_K{};
    // Henyey–Greenstein asymmetry of the visible scattering, weighted by scattering depth.
    float asymmetry = 0.0f;

    float Transmittance(ObscurantBand band) const;  // exp(−τ), seed 004 Eq 1
};

// Puffs beyond this many σ (Mahalanobis distance) from a ray are skipped: e^(−3.5²/2) ≈ 0.2 %
// of the peak line integral.
inline constexpr float kPuffCutoffSigmas = 3.5f;

// Puffs at or above this temperature count as hot (PlumeTrace::hotFraction): well above any
// smoke, exhaust or steam puff after its first metres, below luminous flames.
inline constexpr float kHotPuff_K = 700.0f;

// A committed, immutable-after-Build set of puffs. Storage is sized once (capacity); Clear,
// Add and Build reuse it, so committing a frame allocates nothing.
class PlumeField {
  public:
    PlumeField() = default;
    // capacity puffs at most; plumeCount entries in the optics table.
    PlumeField(size_t capacity, size_t plumeCount);

    size_t Capacity() const { return capacity_; }
    size_t PuffCount() const { return count_; }
    double Time_s() const { return time_s_; }

    void SetOptics(uint32_t plume, const ObscurantOptics& optics);
    // Starts a new set of puffs for simulated time t_s.
    void Clear(double t_s);
    // Adds one puff; throws InternalError beyond capacity or for a bad plume index.
    void Add(const Puff& puff);
    // Builds the BVH; call after the last Add and before tracing.
    void Build();

    // The i-th puff (after Build, in BVH order).
    Puff PuffAt(size_t i) const;

    // The committed puffs as float arrays (PuffCount() entries each, BVH order), for renderers
    // that walk every puff: centre (ENU m), 1/σh², 1/σz² (m⁻²), peak concentration
    // M / ((2π)^(3/2) σh² σz) (kg/m³), temperature (K) and plume index.
    struct PuffArrays {
        std::span<const float> x, y, z, invVarH, invVarZ, peak_kgpm3, temperature_K;
        std::span<const uint32_t> plume;
    };
    PuffArrays Puffs() const;
    size_t PlumeCount() const { return optics_.size(); }
    // The optics set for plume (SetOptics).
    const ObscurantOptics& Optics(uint32_t plume) const;

    // Along origin + s·dir, s in [0, maxDistance_m]; dir must be a unit vector.
    PlumeTrace Trace(const glm::vec3& origin_m, const glm::vec3& dir, float maxDistance_m) const;
    // One ray per entry, in parallel (oneTBB); each result depends only on its own ray.
    void TraceBatch(std::span<const glm::vec3> origins_m, std::span<const glm::vec3> dirs,
                    std::span<const float> maxDistances_m, std::span<PlumeTrace> out) const;
    // All rays from one origin (a camera).
    void TraceBatch(const glm::vec3& origin_m, std::span<const glm::vec3> dirs,
                    std::span<const float> maxDistances_m, std::span<PlumeTrace> out) const;

  private:
    struct Node {
        float lo[3];
        uint32_t offset;  // leaf: first puff; interior: index of the right child (left = +1)
        float hi[3];
        uint32_t count;  // leaf: number of puffs (> 0); interior: 0
    };
    struct PlumeOptics {
        float extinction[kObscurantBands];  // α, m²/kg
        float scattering[kObscurantBands];  // α ω
        float absorption[kObscurantBands];  // α (1 − ω)
        float scatteringG;                  // α ω g, visible
    };

    uint32_t BuildNode(uint32_t begin, uint32_t end);
    void Permute();

    size_t capacity_ = 0;
    size_t count_ = 0;
    double time_s_ = 0.0;
    // Structure of arrays, float for the ray loop.
    std::vector<float> cx_, cy_, cz_;
    std::vector<float> invVarH_, invVarZ_;  // 1/σ²
    std::vector<float> peak_;               // M / ((2π)^(3/2) σh² σz), kg/m³
    std::vector<float> temperature_K_;
    std::vector<uint32_t> plume_;
    std::vector<PlumeOptics> optics_;
    std::vector<ObscurantOptics> sourceOptics_;  // as given to SetOptics
    std::vector<Node> nodes_;
    size_t nodeCount_ = 0;
    // Build scratch, sized with the capacity.
    std::vector<uint32_t> order_;
    std::vector<float> scratchF_;
    std::vector<uint32_t> scratchU_;
    std::vector<float> lo_, hi_;  // per-puff bounds, 3 per puff
};

}  // namespace seasense::scene
