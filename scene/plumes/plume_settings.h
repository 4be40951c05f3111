// User-facing plume settings (smoke, flame, vehicle dust, stack exhaust, steam) in SI units,
// with per-kind defaults and a validating reader from a configuration mapping.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "scene/config/config.h"
#include "scene/plumes/plume_physics.h"

namespace seasense::scene {

enum class PlumeKind : uint8_t { Smoke, Flame, Dust, Exhaust, Steam };
inline constexpr int kPlumeKinds = 5;
std::string_view ToString(PlumeKind kind);  // "smoke", "flame", "dust", "exhaust", "steam"

// Seed 004 Appendix Table 1: dust type index 0 (no dust), 0.5 (dry clay), 1 (light sand) and
// road type index 0 (paved), 0.5 (clay), 1 (sand).
enum class SoilType : uint8_t { None, DryClay, LightSand };
enum class RoadType : uint8_t { Paved, Clay, Sand };
double SeedIndex(SoilType soil);
double SeedIndex(RoadType road);

// One plume source. Times are seconds of simulated time since the start of the run; the plume
// emits puffs for t in [start_s, start_s + duration_s]. Only the fields of its kind are used.
struct PlumeSourceSettings {
    PlumeKind kind = PlumeKind::Smoke;
    glm::dvec3 position_m{0.0};  // ENU, the base of the fire / stack exit / vehicle at start_s
    // Horizontal velocity of the source (ENU m/s, z = 0) for every kind but dust, whose vehicle
    // moves by speed_mps and heading_rad: the source at time t is position_m + velocity_mps ·
    // (t − start_s), and each puff is born where the source was at its birth.
    glm::dvec3 velocity_mps{0.0};
    // Set when the source rides on a scenario entity (`attach_to`): the entity's name and the
    // source's offset in the entity's body frame (x right, y forward, z up; metres). The
    // scenario loader turns them into position_m and velocity_mps (speed and heading for dust).
    std::string attachTo;
    glm::dvec3 attachOffset_m{0.0};
    double start_s = 0.0;
    double duration_s = std::numeric_limits<double>::infinity();
    double rate_hz = 1.0;           // puffs born per second in each of the five columns
    double lifetime_s = 240.0;      // puffs retire at this age (faded over its last tenth)
    double massRate_kgps = 0.02;    // obscurant (soot, droplets) emitted; dust derives its own
    double longTermFraction = 1.0;  // seed 004 Eq 4 f_d
    double decayRate_hz = 0.0;      // seed 004 Eq 4 δ (1/s)
    double albedo = 0.3;            // single-scattering albedo in the visible band
    uint64_t seed = 1;              // keys each puff's random jitter

    // Smoke and flame: the fire.
    double heatRelease_W = 2.0e7;  // convective heat release
    double sourceRadius_m = 3.0;   // fire radius (smoke, flame), stack radius (exhaust, steam)
    // Smoke, exhaust, steam: gas temperature at the source (caps the puff temperature).
    double exitTemperature_K = 700.0;
    // Exhaust and steam: stack exit velocity.
    double exitVelocity_mps = 15.0;
    // Flame: luminous flame temperature.
    double flameTemperature_K = 1200.0;
    // Dust: the vehicle moves from position_m along heading_rad (azimuth from north,
    // clockwise) at speed_mps; emission after US EPA AP-42 13.2.2 scaled by the seed indices.
    double speed_mps = 10.0;
    double heading_rad = 0.0;
    SoilType soil = SoilType::LightSand;
    RoadType road = RoadType::Sand;
    double siltPercent = 12.0;     // AP-42's reference silt content
    double moisturePercent = 0.5;  // AP-42's reference surface moisture
};

// Defaults for a kind (documented per field in the .cpp).
PlumeSourceSettings DefaultPlumeSource(PlumeKind kind);

// All plumes of a scenario plus the atmosphere settings only plumes use.
struct PlumesSettings {
    std::optional<StabilityClass> stability;  // nullopt: from wind, sun and cloud (Turner)
    double inversionHeight_m = std::numeric_limits<double>::infinity();  // ENU z; +∞: none
    double airTemperature_K = 288.15;
    // Whether air_temperature_K was given; if not, renderers take the scenario atmosphere's.
    bool airTemperatureGiven = false;
    std::vector<PlumeSourceSettings> sources;
};

// What plumes take from the rest of the scene: wind at 10 m, sun elevation, cloud cover.
struct PlumeAmbient {
    double windSpeed_mps = 5.0;
    double windDirection_rad = 0.0;  // direction the wind blows toward, from north clockwise
    double sunElevation_rad = 0.5;
    double cloudCover = 0.0;  // fraction of sky, 0..1
};

// Most sources a scenario may list.
inline constexpr size_t kMaxPlumeSources = 256;

// What the plumes reader needs from the rest of the scenario.
struct PlumeParseContext {
    std::vector<std::string> entityNames;  // the names `attach_to` may take
    double airTemperature_K = 288.15;      // default of air_temperature_K
};

// Reads the plumes section:
//   stability: auto | A | B | C | D | E | F        (default auto)
//   inversion_height_m: 800                        (default: none)
//   air_temperature_K: 288.15                      (default: context.airTemperature_K)
//   sources:
//     - kind: smoke | flame | dust | exhaust | steam
//       position_m: [x, y, z]      or   attach_to: <entity name>, offset_m: [x, y, z]
//       start_s, duration_s, rate_hz, lifetime_s, mass_rate_kgps (not dust),
//       long_term_fraction, decay_rate_hz, albedo, seed
//       smoke: heat_release_W, source_radius_m, exit_temperature_K
//       flame: heat_release_W, source_radius_m, flame_temperature_K
//       exhaust, steam: source_radius_m, exit_temperature_K, exit_velocity_mps
//       dust: speed_mps, heading_deg, soil (none|dry_clay|light_sand),
//             road (paved|clay|sand), silt_percent, moisture_percent
// Keys of another kind are rejected as unknown; position_m together with attach_to, and a dust
// source's speed_mps or heading_deg together with attach_to, are errors (the entity sets them).
// Calls map.Finish(). Throws ConfigError naming the key path.
PlumesSettings ParsePlumesSettings(ConfigMap& map, const PlumeParseContext& context = {});

// Places an attached source on its entity's planned track: the entity at time t is at
// entityPosition_m + entityVelocity_mps · t with rotation worldFromBody (ENU from body), so the
// source is at entityPosition_m + entityVelocity_mps · start_s + worldFromBody · attachOffset_m
// at start_s and moves with entityVelocity_mps (horizontal). Dust takes it as the vehicle's
// speed and heading. The entity's wave-riding heave, pitch and roll are not followed.
void PlaceAttachedSource(PlumeSourceSettings& source, const glm::dvec3& entityPosition_m,
                         const glm::dmat3& worldFromBody, const glm::dvec3& entityVelocity_mps);

}  // namespace seasense::scene
