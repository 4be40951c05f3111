// Spray from breaking waves: clumps of droplets thrown from breaking crests near the eyepoint,
// moved by gravity and linear wind drag; stateless (a pure function of the time).
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "scene/surf/surf_settings.h"
#include "scene/surf/surf_waves.h"

namespace seasense::scene {

// Trajectory of a particle under dv/dt = g + (w − v)/τ (gravity g = (0, 0, −g0), wind w, linear
// drag with relaxation time τ), from position p0 and velocity v0 at age 0: with the terminal
// velocity v∞ = w + g τ,
//   v(a) = v∞ + (v0 − v∞) e^{−a/τ},   p(a) = p0 + v∞ a + (v0 − v∞) τ (1 − e^{−a/τ}).
// ENU m, m/s, s.
struct SprayState {
    glm::dvec3 position_m{0.0};
    glm::dvec3 velocity_mps{0.0};
};
SprayState SprayTrajectory(const glm::dvec3& p0_m, const glm::dvec3& v0_mps,
                           const glm::dvec3& wind_mps, double dragTime_s, double age_s);

// One live particle (a clump of droplets).
struct SprayParticle {
    glm::dvec3 position_m{0.0};  // ENU
    glm::dvec3 velocity_mps{0.0};
    double age_s = 0.0;
    double lifeFraction = 0.0;  // age / lifetime, in [0, 1]
    // Identity: emission cell, slot and droplet index (for deterministic ordering).
    uint64_t id = 0;
};

// Counts of one evaluation.
struct SprayStats {
    size_t cells = 0;     // lattice cells within the radius in water shallow enough to break
    size_t bursts = 0;    // emissions whose particles may still be alive
    size_t alive = 0;     // particles alive before the pool bound
    size_t returned = 0;  // after it
};

// Emission (every emission a pure function of (seed, cell, slot)): the world is covered by a
// lattice of cells cell_m square; for each cell within radius_m of the eyepoint whose still-water
// depth is positive and below the deepest depth at which the surf components can break at all,
// slot n of length interval_s has its instant t_n = (n + U) interval_s and a seeded point in
// the cell. If at t_n the point is breaking (SurfBreaking::intensity > 0), lies on the crest of
// its wave group (surf height about the swash level ≥ ½ the envelope) and a seeded U < probability
// × intensity, the slot throws dropletsPerBurst particles from the crest, spread along it over the
// cell, with the local dominant component's group velocity (direction, group speed, ±20 % seeded)
// plus a seeded upward speed. The particles alive at t are those of slots with t_n in [t −
// lifetime_s, t] that are still above the trough (tide + swash − envelope): the run and a capture
// of the same frame see the same particles, for any thread count.
class SprayField {
  public:
    // wind_mps: the wind (ENU, m/s) the droplets relax to.
    SprayField(const SurfWaves& surf, const SpraySettings& settings, const glm::dvec3& wind_mps);

    // Particles alive at t_s around the eyepoint (ENU m), at most maxParticles: the nearest to
    // the eye (ties by id), sorted by distance then id. Parallel over lattice rows (oneTBB);
    // bit-identical for any thread count.
    std::vector<SprayParticle> Particles(const glm::dvec3& eye_m, double t_s,
                                         SprayStats* stats = nullptr) const;

    // Deepest still-water depth (m) at which 2 Σ A_j (each shoaled by energy flux at that depth)
    // reaches γ h: no breaking deeper (SurfWaves::MaxBreakingDepth_m).
    double MaxBreakingDepth_m() const { return surf_.MaxBreakingDepth_m(); }
    const SpraySettings& Settings() const { return settings_; }

  private:
    const SurfWaves& surf_;
    SpraySettings settings_;
    glm::dvec3 wind_mps_;
};

}  // namespace seasense::scene
