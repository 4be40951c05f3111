// The scene core: built once from a Scenario, it yields an immutable SceneState per frame.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "scene/core/frames.h"
#include "scene/models/triangle_mesh.h"
#include "scene/ocean/ocean_surface.h"
#include "scene/scenario/scenario.h"
#include "scene/sky/clouds.h"
#include "scene/sky/ephemeris.h"
#include "scene/sky/lightning.h"

namespace seasense::scene {

// A placed model: its body-frame mesh, world pose and material, for one frame.
struct EntityState {
    std::string name;
    std::string material;
    glm::dvec3 reflectanceRgb{0.5};
    Pose pose;
    std::shared_ptr<const TriangleMesh> bodyMesh;  // shared, immutable
};

struct SunState {
    glm::dvec3 direction{0.0, 0.0, 1.0};  // unit ENU vector toward the sun
    double elevation_rad = 0.0;
    double azimuth_rad = 0.0;
    // On a surface normal to the sun, divided by the sky-condition divisor of the clouds along
    // the sun's direction from the eyepoint (World::SkyConditionDivisor).
    double illuminance_lux = 0.0;
};

// The moon as the observer sees it (always from the ephemeris and the scenario clock).
struct MoonState {
    glm::dvec3 direction{0.0, 0.0, -1.0};  // unit ENU vector toward the moon (apparent)
    double elevation_rad = -0.5 * 3.14159265358979323846;
    double azimuth_rad = 0.0;
    // Direct, on a surface normal to the moon, at the ground, divided by the sky-condition
    // divisor of the clouds along the moon's direction (World::SkyConditionDivisor).
    double illuminance_lux = 0.0;
    double phaseAngle_rad = 3.14159265358979323846;  // sun–moon–observer; 0 full, π new
    double distance_m = 3.844e8;                     // observer to the moon's centre
};

// The part of a frame's scene that changes with time: what the host of a run publishes to the
// channel renderers (scene/world's static content — meshes, materials — each builds itself).
struct FrameState {
    int64_t frame = 0;
    double time_s = 0.0;  // simulated seconds since frame 0
    UtcTime utc;
    SunState sun;
    MoonState moon;
    Pose eyepoint;
    std::vector<Pose> entityPoses;  // one per scenario entity, in scenario order
};

// Everything a channel needs to render frame `frame`, fixed for that frame.
struct SceneState {
    int64_t frame = 0;
    double time_s = 0.0;  // simulated seconds since frame 0
    UtcTime utc;
    SunState sun;
    MoonState moon;
    Pose eyepoint;
    std::vector<EntityState> entities;
};

class World {
  public:
    // Loads every model the scenario names (InputError on failure).
    explicit World(const Scenario& scenario);

    // The dynamic state of frame n: simulated time n · timeScale / frameRate after the start,
    // the sun, the moving eyepoint and entities.
    FrameState Advance(int64_t frame) const;
    // The full scene of a published dynamic state. InputError if the state does not fit this
    // world (entity count).
    SceneState Compose(const FrameState& frame) const;
    // Compose(Advance(frame)).
    SceneState State(int64_t frame) const { return Compose(Advance(frame)); }

    const Scenario& GetScenario() const { return scenario_; }
    // The scenario's thunderstorms (environment.lightning), or nullptr. Flashes are pure
    // functions of the scene time, so every channel sees the same ones.
    const Lightning* GetLightning() const { return lightning_.get(); }
    // The scenario's cloud layers (environment.clouds), or nullptr for a cloudless sky. Pure
    // functions of position and scene time, so every channel sees the same clouds.
    const CloudField* Clouds() const { return clouds_.get(); }
    // USNO Circular 171 sky-condition divisor of a body (sun or moon) in unit direction
    // toBody seen from from_m (ENU) at scene time t_s: CloudField::SkyConditionDivisor, 1
    // without clouds. Advance divides the sun's and moon's direct illuminance by it.
    double SkyConditionDivisor(const glm::dvec3& from_m, const glm::dvec3& toBody,
                               double t_s) const;
    // The sea surface (Gerstner or spectral), frames cached per time.
    const OceanSurface& Ocean() const { return ocean_; }

  private:
    Scenario scenario_;
    OceanSurface ocean_;
    std::vector<std::shared_ptr<const TriangleMesh>> models_;  // one per entity
    // Half length (body y) and half beam (body x) of each entity's mesh, for riding the waves.
    std::vector<glm::dvec2> halfExtent_m_;
    std::shared_ptr<const Lightning> lightning_;
    std::shared_ptr<const CloudField> clouds_;
};

}  // namespace seasense::scene
