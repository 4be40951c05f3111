// World: model loading, the frame clock and per-frame scene snapshots.
#include "scene/world/world.h"

#include <cmath>
#include <map>

#include "scene/core/error.h"

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
        if (!scenario_.FindMaterial(e.material))
            throw InputError(scenario_.file.string() + ": entity '" + e.name +
                             "' names unknown material '" + e.material + "'");
    }
}

SceneState World::State(int64_t frame) const {
    const WorldSettings& w = scenario_.world;
    SceneState s;
    s.frame = frame;
    s.time_s = double(frame) * w.timeScale / w.frameRate_hz;
    s.utc = w.start.PlusSeconds(s.time_s);

    const SunSettings& sun = scenario_.environment.sun;
    s.sun.azimuth_rad = sun.azimuth_rad;
    s.sun.elevation_rad = sun.elevation_rad;
    s.sun.direction = DirectionFromAzimuthElevation(sun.azimuth_rad, sun.elevation_rad);
    s.sun.illuminance_lux = sun.illuminance_lux;

    s.eyepoint = PoseFrom(scenario_.eyepoint.position_m, scenario_.eyepoint.attitude);
    for (size_t i = 0; i < scenario_.entities.size(); ++i) {
        const EntitySettings& e = scenario_.entities[i];
        EntityState es;
        es.name = e.name;
        es.material = e.material;
        es.reflectanceRgb = scenario_.FindMaterial(e.material)->reflectanceRgb;
        es.pose = PoseFrom(e.position_m, e.attitude);
        es.bodyMesh = models_[i];
        s.entities.push_back(std::move(es));
    }
    return s;
}

}  // namespace seasense::scene
