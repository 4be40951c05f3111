// Sum-of-Gerstner-waves sea surface: trochoidal displacement, normals, folding and truthful
// height queries, with finite-depth dispersion ω² = g k tanh(k h).
#pragma once

#include <glm/glm.hpp>
#include <vector>

#include "scene/ocean/surface_terms.h"
#include "scene/scenario/scenario.h"

namespace seasense::scene {

// Standard gravity, m/s² (CGPM 1901; BIPM SI Brochure, 9th ed.).
inline constexpr double kGravity_mps2 = 9.80665;

// Most wave components a GerstnerOcean holds (the scenario schema's limit).
inline constexpr size_t kMaxWaves = 64;

// Angular frequency of a linear surface gravity wave of wavenumber k (rad/m) in water of
// depth h (m): ω² = g k tanh(k h) (Airy theory; physics.md).
double DispersionOmega(double k_radpm, double depth_m);

// Phase speed ω/k and group speed ½ c (1 + 2kh / sinh 2kh), m/s.
double PhaseSpeed(double k_radpm, double depth_m);
double GroupSpeed(double k_radpm, double depth_m);

// Weight of a wave of wavenumber k (rad/m) on a surface sampled with footprint s (m): 1 for
// wavelengths 2π/k ≥ 4 s, 0 at and below the Nyquist wavelength 2 s, linear in between, so that
// sampling at spacing s does not alias it (and the wave fades in smoothly as s shrinks).
template <class Real>
Real GerstnerFootprintWeight(Real k_radpm, Real footprint_m) {
    const Real w = Real(3.141592653589793) / (k_radpm * footprint_m) - Real(1);
    return w < Real(0) ? Real(0) : w > Real(1) ? Real(1) : w;
}

// A displaced surface point: the horizontal rest position x0 = (x, y) in the world ENU frame
// moves to position; normal is the unit upward surface normal there.
struct SurfaceSample {
    glm::dvec3 position{0.0};
    glm::dvec3 normal{0.0, 0.0, 1.0};
    double jacobian = 1.0;  // det ∂(x,y)/∂(x0,y0): < 0 where the surface folds over
};

// Precomputed per-wave constants, structure of arrays for the hot loops.
class GerstnerOcean {
  public:
    GerstnerOcean() = default;
    explicit GerstnerOcean(const OceanSettings& settings);

    // Surface at rest position (x0, y0) in world metres at time t_s (seconds since frame 0).
    SurfaceSample Evaluate(double x0, double y0, double t_s) const;

    // Vertical elevation of the drawn surface above the world point (x, y) at time t_s: solves
    // for the rest position whose displaced horizontal position is (x, y) by fixed-point
    // iteration, so the answer is the surface the renderer draws.
    double HeightAt(double x, double y, double t_s) const;
    SurfaceSample SampleAt(double x, double y, double t_s) const;

    // Displacement, derivatives and velocity at rest position (x0, y0) at time t_s, each wave
    // weighted by GerstnerFootprintWeight for footprint_m > 0 (0: unfiltered).
    SurfaceTerms Terms(double x0, double y0, double t_s, double footprint_m = 0.0) const;

    // Single-precision evaluation for mesh building, relative to a local origin: the
    // per-wave phase of the origin and of time is reduced modulo 2π in double once, so float
    // keeps ~1e-4 rad of phase anywhere within tens of km of the origin at any time.
    class LocalFrame {
      public:
        // Position (relative to the origin, m), normal and Jacobian at rest offset (rx, ry).
        void Evaluate(float rx, float ry, glm::vec3& position, glm::vec3& normal,
                      float& jacobian) const;
        // Adds the band-limited terms at rest offset (rx, ry) for footprint_m (0: unfiltered)
        // to sums = {η, Dx, Dy, ∂η/∂x, ∂η/∂y, ∂Dx/∂x, ∂Dy/∂y, ∂Dx/∂y}.
        void Accumulate(float rx, float ry, float footprint_m, float sums[8]) const;
        // The same with the waves' footprint weights from FootprintWeights (WaveCount() floats),
        // for many points of one footprint (a mesh ring): the same bits.
        void FootprintWeights(float footprint_m, float* weights) const;
        void Accumulate(float rx, float ry, const float* weights, float sums[8]) const;

      private:
        friend class GerstnerOcean;
        std::vector<float> dirX_, dirY_, k_, amplitude_, horizontal_, phase0_;
    };
    LocalFrame Local(double originX, double originY, double t_s) const;

    size_t WaveCount() const { return k_.size(); }
    double Wavenumber_radpm(size_t i) const { return k_[i]; }
    double Omega_radps(size_t i) const { return omega_[i]; }
    double Amplitude_m(size_t i) const { return amplitude_[i]; }
    // Direction of travel as an azimuth from north, clockwise (rad).
    double Direction_rad(size_t i) const { return std::atan2(dirX_[i], dirY_[i]); }
    // Largest |elevation| the waves can reach: Σ A_i (m).
    double MaxAmplitude_m() const { return maxAmplitude_m_; }
    // An upper bound (m, ≥ 0) of the elevation at time t_s of the rest positions within radius_m
    // of world (x, y), for any footprint weights in [0, 1]: Σ A_i max(0, max cos θ_i) over the
    // phase interval θ_i(centre) ± (k_i radius + kPhaseMargin_rad) that the disc spans. Never
    // above MaxAmplitude_m().
    double MaxElevationNear_m(double x, double y, double radius_m, double t_s) const;
    // The same for footprint weights of at least GerstnerFootprintWeight(k_i, maxFootprint_m)
    // (the weights of a mesh whose rings there have footprints ≤ maxFootprint_m; ∞: any), and
    // signed: a wave whose largest cos θ_i over the interval is negative adds its smallest
    // weight times A_i cos θ_i. Below 0 where the waves' troughs cover the disc.
    double ElevationBoundNear_m(double x, double y, double radius_m, double t_s,
                                double maxFootprint_m) const;
    // Phase slack of MaxElevationNear_m: far above the float rounding of LocalFrame's phases
    // (~1e-4 rad, see LocalFrame), so that the bound also holds for the float mesh path.
    static constexpr double kPhaseMargin_rad = 1e-2;
    // Largest horizontal displacement the waves can cause: Σ Q A / tanh(kh) (m).
    double MaxHorizontal_m() const { return maxHorizontal_m_; }
    // Shortest wavelength among the waves (m), for mesh resolution choices.
    double MinWavelength_m() const { return minWavelength_m_; }

  private:
    std::vector<double> dirX_, dirY_;  // unit direction of travel (east, north)
    std::vector<double> k_;            // wavenumber, rad/m
    std::vector<double> omega_;        // angular frequency, rad/s
    std::vector<double> amplitude_;    // vertical amplitude A, m
    std::vector<double> horizontal_;   // horizontal orbit semi-axis Q·A / tanh(kh), m
    std::vector<double> phase_;        // rad
    double maxAmplitude_m_ = 0.0;
    double maxHorizontal_m_ = 0.0;
    double minWavelength_m_ = 1e30;
};

}  // namespace seasense::scene
