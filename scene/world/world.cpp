// World: model loading, the frame clock and per-frame scene snapshots.
#include "scene/world/world.h"

#include <cmath>
#include <map>

#include "scene/core/error.h"
#include "scene/sky/illuminance.h"

namespace seasense::scene {

World::World(const Scenario& scenario) : scenario_(scenario), ocean_(scenario.environment.ocean) {
    // Entities that share a model file and scale share one loaded mesh.
    std::map<std::pair<std::string, double>, std::shared_ptr<const TriangleMesh>> cache;
    for (const EntitySettings& e : scenario_.entities) {
        auto key = std::make_pair(e.model.string(), e.scale);
        auto it = cache.find(key);
        if (it == cache.end()) {
            auto mesh = std::make_shared<const TriangleMesh>(LoadModel(e.model, e.scale));
            it = cache.emplace(key, std::move(mesh)).first;
        }
        models_.push_back(it->second);
        glm::dvec2 half(0.5);
        for (const glm::vec3& v : it->second->positions)
            half = glm::max(half, glm::dvec2(std::abs(v.x), std::abs(v.y)));
        halfExtent_m_.push_back(half);
        if (!scenario_.FindMaterial(e.material))
            throw InputError(scenario_.file.string() + ": entity '" + e.name +
                             "' names unknown material '" + e.material + "'");
    }
    if (scenario_.environment.lightning)
        lightning_ = std::make_shared<const Lightning>(*scenario_.environment.lightning,
                                                       scenario_.world.seed);
    if (!scenario_.environment.clouds.empty())
        clouds_ =
            std::make_shared<const CloudField>(scenario_.environment.clouds, scenario_.world.seed);
}

double World::SkyConditionDivisor(const glm::dvec3& from_m, const glm::dvec3& toBody,
                                  double t_s) const {
    return clouds_ ? clouds_->SkyConditionDivisor(from_m, toBody, t_s) : 1.0;
}

namespace {

// A pose moving at speed_mps along its heading on the horizontal plane.
Pose MovingPose(const glm::dvec3& start_m, const Attitude& attitude, double speed_mps, double t_s) {
    const glm::dvec3 heading{std::sin(attitude.heading_rad), std::cos(attitude.heading_rad), 0.0};
    return PoseFrom(start_m + heading * (speed_mps * t_s), attitude);
}

}  // namespace

FrameState World::Advance(int64_t frame) const {
    const WorldSettings& w = scenario_.world;
    FrameState s;
    s.frame = frame;
    s.time_s = double(frame) * w.timeScale / w.frameRate_hz;
    s.utc = w.start.PlusSeconds(s.time_s);

    const EyepointSettings& eye = scenario_.eyepoint;
    s.eyepoint = MovingPose(eye.position_m, eye.attitude, eye.speed_mps, s.time_s);

    Observer observer;
    observer.latitude_deg = w.latitude_deg;
    observer.longitude_deg = w.longitude_deg;
    observer.height_m = scenario_.eyepoint.position_m.z;
    {
        const CelestialPosition m = MoonPosition(s.utc, observer);
        s.moon.direction = m.direction;
        s.moon.elevation_rad = m.altitude_rad;
        s.moon.azimuth_rad = m.azimuth_rad;
        s.moon.distance_m = m.distance_m;
        s.moon.phaseAngle_rad = MoonPhase(s.utc, observer).phaseAngle_rad;
        s.moon.illuminance_lux = DirectNormalMoonIlluminance_lux(
            m.altitude_rad, s.moon.phaseAngle_rad, m.distance_m, observer.height_m);
    }
    const SunSettings& sun = scenario_.environment.sun;
    if (sun.fromEphemeris) {
        const CelestialPosition p = SunPosition(s.utc, observer);
        s.sun.azimuth_rad = p.azimuth_rad;
        s.sun.elevation_rad = p.altitude_rad;
        s.sun.direction = p.direction;
        s.sun.illuminance_lux = DirectNormalSunIlluminance_lux(p.altitude_rad, p.distance_m,
                                                               scenario_.environment.sky.turbidity);
    } else {
        s.sun.azimuth_rad = sun.azimuth_rad;
        s.sun.elevation_rad = sun.elevation_rad;
        s.sun.direction = DirectionFromAzimuthElevation(sun.azimuth_rad, sun.elevation_rad);
        s.sun.illuminance_lux = sun.illuminance_lux;
    }

    // Clouds between the eyepoint and the sun or moon lower their light (USNO Circular 171).
    if (clouds_) {
        s.sun.illuminance_lux /=
            clouds_->SkyConditionDivisor(s.eyepoint.position_m, s.sun.direction, s.time_s);
        s.moon.illuminance_lux /=
            clouds_->SkyConditionDivisor(s.eyepoint.position_m, s.moon.direction, s.time_s);
    }

    std::shared_ptr<const OceanSurfaceFrame> sea;  // made on first use: only riders need it
    for (size_t i = 0; i < scenario_.entities.size(); ++i) {
        const EntitySettings& e = scenario_.entities[i];
        Pose pose = MovingPose(e.position_m, e.attitude, e.speed_mps, s.time_s);
        if (e.rideWaves) {
            // Quasi-static wave following: heave at the origin, pitch and roll from the surface
            // heights under bow/stern and the beam ends (body y forward, x to starboard).
            const glm::dvec3 fwd = pose.worldFromBody[1], right = pose.worldFromBody[0];
            const glm::dvec2 half = halfExtent_m_[i];
            if (!sea) sea = ocean_.At(s.time_s);
            const auto h = [&](const glm::dvec3& p) { return sea->HeightAt(p.x, p.y); };
            const glm::dvec3 o = pose.position_m;
            const double bow = h(o + fwd * half.y), stern = h(o - fwd * half.y);
            const double stbd = h(o + right * half.x), port = h(o - right * half.x);
            Attitude a = e.attitude;
            a.pitch_rad += std::atan2(bow - stern, 2.0 * half.y);
            a.roll_rad += std::atan2(port - stbd, 2.0 * half.x);  // starboard down is positive
            pose = PoseFrom(o + glm::dvec3(0.0, 0.0, h(o)), a);
        }
        s.entityPoses.push_back(pose);
    }
    return s;
}

SceneState World::Compose(const FrameState& f) const {
    if (f.entityPoses.size() != scenario_.entities.size())
        throw InputError("scene state of frame " + std::to_string(f.frame) + " has " +
                         std::to_string(f.entityPoses.size()) + " entities; the scenario has " +
                         std::to_string(scenario_.entities.size()));
    SceneState s;
    s.frame = f.frame;
    s.time_s = f.time_s;
    s.utc = f.utc;
    s.sun = f.sun;
    s.moon = f.moon;
    s.eyepoint = f.eyepoint;
    for (size_t i = 0; i < scenario_.entities.size(); ++i) {
        const EntitySettings& e = scenario_.entities[i];
        EntityState es;
        es.name = e.name;
        es.material = e.material;
        es.reflectanceRgb = scenario_.FindMaterial(e.material)->reflectanceRgb;
        es.pose = f.entityPoses[i];
        es.bodyMesh = models_[i];
        s.entities.push_back(std::move(es));
    }
    return s;
}

}  // namespace seasense::scene
