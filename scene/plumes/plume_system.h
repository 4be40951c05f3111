// Plume sources as Reeves particle systems of Gaussian puffs in seed 004's five-column
// footprint, each puff a closed-form function of its birth time so that the plume state at a
// simulated time t depends only on (settings, seeds, t).
#pragma once

#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "scene/plumes/plume_field.h"
#include "scene/plumes/plume_physics.h"
#include "scene/plumes/plume_settings.h"

namespace seasense::scene {

// Seed 004: each plume is five columns of puffs.
inline constexpr int kPlumeColumns = 5;

// Most puff slots a PlumeSystem may need (a bound on memory, 64 MB of field storage).
inline constexpr size_t kMaxPlumePuffs = size_t(1) << 20;

// What one commit produced.
struct PlumeCommitStats {
    size_t puffs = 0;        // real puffs
    size_t imagePuffs = 0;   // mirror images at the ground, floor or lid (method of images)
    double puffMass_kg = 0;  // total mass of the real puffs
};

// Puff i of a plume is born at t_i = start_s + i / rate_hz where the (possibly moving) source
// is then, and at age a = t − t_i sits where the plume model puts it (Briggs rise and
// Pasquill–Gifford spread for smoke, exhaust and steam; buoyant rise against drag for flames;
// wind drift behind the moving vehicle for dust), all as functions of the age (so a moving
// source needs nothing more than the birth place),
// with mass M0 · M(a)/M0 (seed 004 Eq 4) and a random jitter keyed by (seed, column, i). Older
// puffs are merged in pairs, fours, … (level of detail) once their spread exceeds the spacing
// of the merged puffs, and from groups of four on the five columns merge into one puff; the
// merge blends by each member's age, so the summed mass stays exactly that of the individual
// puffs and no puff pops.
class PlumeSystem {
  public:
    // Throws InputError for settings outside their documented ranges (naming the source index)
    // or when the puff pool would exceed kMaxPlumePuffs.
    PlumeSystem(const PlumesSettings& settings, const PlumeAmbient& ambient);

    size_t PlumeCount() const { return plumes_.size(); }
    StabilityClass Stability() const { return stability_; }
    PlumeBehaviour Behaviour(size_t plume) const;
    // Initial mass of one puff of one column (kg).
    double PuffMass_kg(size_t plume) const;
    // Lifetime of the plume's puffs (s); derived from the flame height for flames.
    double PuffLifetime_s(size_t plume) const;
    // Briggs buoyancy flux (m⁴/s³), wind speed at the source (m/s) and final rise (m); zero
    // flux and rise for dust.
    double BuoyancyFlux_m4ps3(size_t plume) const;
    double SourceWind_mps(size_t plume) const;
    double FinalRise_m(size_t plume) const;

    // Puff slots a field needs for any t (the pool size).
    size_t Capacity() const { return capacity_; }
    // A field sized for this system with the plumes' optics filled in.
    PlumeField MakeField() const;
    // Fills field (made by MakeField) with the puffs alive at simulated time t_s and builds
    // its BVH. Pure in t_s; allocates nothing.
    PlumeCommitStats Commit(double t_s, PlumeField& field) const;

  private:
    struct Plume {
        PlumeSourceSettings s;
        PlumeBehaviour behaviour = PlumeBehaviour::Coning;
        StabilityClass verticalClass = StabilityClass::D;  // σz class (D above an inversion)
        glm::dvec3 downwind{0.0, 1.0, 0.0};
        glm::dvec3 crosswind{1.0, 0.0, 0.0};
        glm::dvec3 footprintA{1.0, 0.0, 0.0};  // footprint axes of the outer columns
        glm::dvec3 footprintB{0.0, 0.0, 1.0};
        glm::dvec3 sourceVelocity_mps{0.0};  // dust: the vehicle; others: velocity_mps
        double wind_mps = 1.0;
        double baseHeight_m = 0.0;  // release height after stack-tip downwash
        double ground_m = 0.0;
        double floor_m = -1e30;   // lofting: the inversion below the plume
        double ceiling_m = 1e30;  // trapping / fumigation: the lid
        double F = 0.0;           // buoyancy flux, m⁴/s³
        double Fm = 0.0;          // momentum flux, m⁴/s²
        double betaJet = 1.0;
        double finalRise_m = 0.0;
        double sigma0_m = 1.0;
        double sourceExcess_K = 0.0;       // gas temperature above the air at the source
        double reducedGravity_mps2 = 0.0;  // flames
        double drag_1pm = 1.0;             // flames
        double puffMass_kg = 0.0;
        double lifetime_s = 1.0;
        double spacingSpeed_mps = 1.0;  // separation speed of consecutive puffs
        // Level-of-detail transitions: level k starts blending in at age levelStart[k] over
        // levelWindow[k] seconds; levels >= levels are unused.
        int levels = 1;
        std::array<double, 16> levelStart{};
        std::array<double, 16> levelWindow{};
    };
    struct Envelope {
        glm::dvec3 centre_m{0.0};
        double sigmaH_m = 1.0;
        double sigmaZ_m = 1.0;
        double temperature_K = 288.15;
    };

    Envelope EnvelopeAt(const Plume& p, double age_s, double birth_s) const;
    double LevelWeight(const Plume& p, int level, double age_s) const;
    // One puff of a column (or, merged, the single puff standing for all five columns).
    void EmitPuff(const Plume& p, uint32_t plumeIndex, int column, bool merged, const Envelope& env,
                  double extraVarH_m2, double mass_kg, uint64_t jitterKey, PlumeField& field,
                  PlumeCommitStats& stats) const;

    std::vector<Plume> plumes_;
    StabilityClass stability_ = StabilityClass::D;
    double airTemperature_K_ = 288.15;
    size_t capacity_ = 0;
};

}  // namespace seasense::scene
