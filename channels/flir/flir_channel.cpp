// FLIR shading: sky from the atmosphere's band sky radiance, sea from its angle- and
// wind-dependent emissivity and reflected sky, models from material emissivity and temperature
// (heat balance per orientation class, sunlit or shaded by Embree), all through the path.
#include "channels/flir/flir_channel.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "channels/plume/plume_composite.h"
#include "scene/core/check.h"
#include "scene/core/error.h"
#include "scene/sky/ephemeris.h"
#include "scene/sky/illuminance.h"

namespace seasense::channels {

namespace {

// Luminous efficacy of direct-beam sunlight, lm/W: about 93 for a clear sky at moderate
// elevations (Littlefair, "The luminous efficacy of daylight: a review", Lighting Res.
// Technol. 17, 162 (1985)); converts the scene's sun illuminance to irradiance.
constexpr double kSunEfficacy_lm_W = 93.0;

// Shadow-ray offset along the normal: 1 mm plus 4e-6 of the largest coordinate (as the OTW
// channel), clear of float self-intersection.
glm::vec3 ShadowRayOrigin(const glm::vec3& p, const glm::vec3& n) {
    return p + n * (4e-6f * std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)}) + 1e-3f);
}

}  // namespace

radiometry::Band InfraredBandOf(scene::InfraredBand band) {
    return band == scene::InfraredBand::Mwir ? radiometry::Band::Mwir() : radiometry::Band::Lwir();
}

double SunIrradiance_W_m2(const scene::Scenario& scenario, double time_s, glm::dvec3& sunDir) {
    const scene::SunSettings& sun = scenario.environment.sun;
    if (!sun.fromEphemeris) {
        const double ce = std::cos(sun.elevation_rad);
        sunDir = glm::dvec3(ce * std::sin(sun.azimuth_rad), ce * std::cos(sun.azimuth_rad),
                            std::sin(sun.elevation_rad));
        return sun.elevation_rad > 0.0 ? sun.illuminance_lux / kSunEfficacy_lm_W : 0.0;
    }
    scene::Observer observer;
    observer.latitude_deg = scenario.world.latitude_deg;
    observer.longitude_deg = scenario.world.longitude_deg;
    const scene::CelestialPosition p =
        scene::SunPosition(scenario.world.start.PlusSeconds(time_s), observer);
    sunDir = p.direction;
    return scene::DirectNormalSunIlluminance_lux(p.altitude_rad, p.distance_m,
                                                 scenario.environment.sky.turbidity) /
           kSunEfficacy_lm_W;
}

OrientationTemperatures::OrientationTemperatures(
    const radiometry::HeatBalanceParameters& parameters, const Environment& environment,
    const scene::Scenario& scenario)
    : parameters_(parameters), environment_(environment), scenario_(scenario) {}

glm::dvec3 OrientationTemperatures::ClassNormal(int o) {
    if (o == 0) return {0.0, 0.0, 1.0};
    if (o == kOrientations - 1) return {0.0, 0.0, -1.0};
    const double az = double(o - 1) * M_PI / 4.0;
    return {std::sin(az), std::cos(az), 0.0};
}

radiometry::ThermalDrivers OrientationTemperatures::DriversAt(int cls, double time_s) const {
    const int o = cls % kOrientations;
    const bool sunlit = cls >= kOrientations;
    const glm::dvec3 n = ClassNormal(o);
    radiometry::ThermalDrivers d;
    d.time_s = time_s;
    glm::dvec3 sunDir;
    const double E = SunIrradiance_W_m2(scenario_, time_s, sunDir);
    d.solarIrradiance_W_m2 = sunlit ? E * std::max(glm::dot(n, sunDir), 0.0) : 0.0;
    d.longwaveIrradiance_W_m2 = radiometry::TiltedLongwaveIrradiance_W_m2(
        environment_.skyLongwave_W_m2, std::acos(std::clamp(n.z, -1.0, 1.0)),
        environment_.seaTemperature_K);
    d.airTemperature_K = environment_.airTemperature_K;
    d.windSpeed_mps = environment_.windSpeed_mps;
    return d;
}

std::array<double, OrientationTemperatures::kClasses> OrientationTemperatures::At(double time_s) {
    CHECK(time_s >= -kSpinUp_s);
    const auto NodeTime = [](size_t k) { return -kSpinUp_s + double(k) * kGridStep_s; };
    const size_t k = size_t(std::floor((time_s + kSpinUp_s) / kGridStep_s));
    if (nodes_.empty()) {
        std::array<double, kClasses> first;
        for (int c = 0; c < kClasses; ++c)
            first[size_t(c)] =
                radiometry::EquilibriumTemperature_K(parameters_, DriversAt(c, NodeTime(0)));
        nodes_.push_back(first);
    }
    // Extend the grid node by node: each interval is integrated on its own, so a node's value
    // does not depend on how far earlier calls went.
    while (nodes_.size() <= k) {
        const size_t j = nodes_.size();
        std::array<double, kClasses> next;
        for (int c = 0; c < kClasses; ++c) {
            const std::vector<radiometry::ThermalDrivers> d = {DriversAt(c, NodeTime(j - 1)),
                                                               DriversAt(c, NodeTime(j))};
            next[size_t(c)] =
                radiometry::IntegrateSurfaceTemperature(parameters_, d, nodes_[j - 1][size_t(c)])
                    .back();
        }
        nodes_.push_back(next);
    }
    std::array<double, kClasses> out = nodes_[k];
    if (time_s > NodeTime(k)) {
        for (int c = 0; c < kClasses; ++c) {
            const std::vector<radiometry::ThermalDrivers> d = {DriversAt(c, NodeTime(k)),
                                                               DriversAt(c, time_s)};
            out[size_t(c)] =
                radiometry::IntegrateSurfaceTemperature(parameters_, d, nodes_[k][size_t(c)])
                    .back();
        }
    }
    return out;
}

FlirChannel::FlirChannel(const scene::World& world, const scene::ChannelSettings& settings)
    : world_(world),
      settings_(settings),
      geometry_(world, settings),
      air_(world.GetScenario().environment.atmosphere
               ? radiometry::ParseAtmosphereSettings(*world.GetScenario().environment.atmosphere)
               : radiometry::AtmosphereSettings{}),
      sea_(world.GetScenario().environment.sea
               ? radiometry::ParseSeaSettings(*world.GetScenario().environment.sea)
               : radiometry::SeaSettings{}),
      table_(InfraredBandOf(settings.band)),
      atmosphere_(table_.GetBand(), air_, world.GetScenario().environment.visibility_m),
      seaCurve_(radiometry::SeaEmissivityTable(radiometry::SeaSurfaceEmissivity(table_.GetBand()))
                    .Curve(world.GetScenario().environment.windSpeed_mps)),
      plumes_(std::make_unique<ChannelPlumes>(world)) {
    const scene::Scenario& sc = world.GetScenario();
    if (!sc.materialTable)
        throw InputError("scenario " + sc.file.string() +
                         ": the flir channel needs the material table's emissivities and "
                         "thermal models, but no material table was loaded");
    const radiometry::MaterialTable materials = radiometry::ParseMaterialTable(*sc.materialTable);
    radiometry::ThermalEnvironment thermalEnv;
    thermalEnv.airTemperature_K = air_.airTemperature_K;
    thermalEnv.seaTemperature_K = sea_.temperature_K;
    OrientationTemperatures::Environment env;
    env.airTemperature_K = air_.airTemperature_K;
    env.seaTemperature_K = sea_.temperature_K;
    env.windSpeed_mps = sc.environment.windSpeed_mps;
    env.skyLongwave_W_m2 = atmosphere_.SkyLongwaveIrradiance_W_m2();
    for (const scene::EntitySettings& e : sc.entities) {
        const radiometry::Material& m = materials.Get(e.material);
        EntityThermal t;
        t.emissivity =
            settings.band == scene::InfraredBand::Mwir ? m.emissivityMwir : m.emissivityLwir;
        if (m.thermal.kind == radiometry::ThermalModelKind::HeatBalance) {
            radiometry::HeatBalanceParameters p = m.thermal.heatBalance;
            p.emissivity = m.emissivityLwir;
            t.heatBalance = std::make_unique<OrientationTemperatures>(p, env, world.GetScenario());
        } else {
            t.staticT_K = m.StaticTemperature_K(thermalEnv);
        }
        entities_.push_back(std::move(t));
    }
}

FlirChannel::~FlirChannel() = default;

std::array<double, OrientationTemperatures::kClasses> FlirChannel::EntityTemperatures_K(
    size_t entity, double time_s) {
    CHECK(entity < entities_.size());
    EntityThermal& t = entities_[entity];
    if (t.heatBalance) return t.heatBalance->At(time_s);
    std::array<double, OrientationTemperatures::kClasses> out;
    out.fill(t.staticT_K);
    return out;
}

void FlirChannel::Render(const scene::SceneState& state, Image& radiance) {
    using Clock = std::chrono::steady_clock;
    const auto Ms = [](Clock::time_point a, Clock::time_point b) {
        return std::chrono::duration<double, std::milli>(b - a).count();
    };
    geometry_.Update(state);
    stats_ = {};
    stats_.view = geometry_.Stats();
    const Clock::time_point t0 = Clock::now();

    // Band blackbody radiance of each entity's orientation classes for this frame.
    constexpr int kC = OrientationTemperatures::kClasses,
                  kO = OrientationTemperatures::kOrientations;
    std::vector<std::array<float, kC>> entityB(entities_.size());
    for (size_t i = 0; i < entities_.size(); ++i) {
        const std::array<double, kC> T = EntityTemperatures_K(i, state.time_s);
        for (int c = 0; c < kC; ++c) entityB[i][size_t(c)] = float(table_.Radiance(T[size_t(c)]));
    }
    const Clock::time_point t1 = Clock::now();
    stats_.thermalMs = Ms(t0, t1);

    const ChannelCamera& cam = geometry_.Camera();
    const VisibilityBuffer& vis = geometry_.Visibility();
    const OcclusionScene& occlusion = geometry_.Occlusion();
    const scene::OceanMesh& ocean = geometry_.Ocean();
    const std::vector<scene::TriangleMesh>& meshes = geometry_.EntityMeshes();
    const int sw = cam.SampleWidth(), sh = cam.SampleHeight();
    if (radiance.width != sw || radiance.height != sh || radiance.channels != 1)
        radiance = Image(sw, sh, 1);

    const glm::vec3 sunDir(state.sun.direction);
    const bool shadows = settings_.shadows && !occlusion.Empty() && sunDir.z > 0.0f;
    const glm::vec3 eye(cam.worldFromCamera.position_m);
    const float seaB = float(table_.Radiance(sea_.temperature_K));
    const float airB = float(atmosphere_.AirRadiance());
    const glm::dmat3& R = cam.worldFromCamera.worldFromBody;
    const double tanH = cam.TanHalfH(), tanV = cam.TanHalfV();
    const glm::dvec3 forward = R * glm::dvec3(0.0, 1.0, 0.0);

    struct MeshRef {
        const glm::vec3* P;
        const glm::vec3* N;
        const uint32_t* I;
    };
    std::vector<MeshRef> refs;
    refs.push_back({ocean.positions.data(), ocean.normals.data(), ocean.indices.data()});
    for (const scene::TriangleMesh& m : meshes)
        refs.push_back({m.positions.data(), m.normals.data(), m.indices.data()});

    // Sky band radiance toward zenith cosine cosZenith (the horizon's at and below 0).
    const auto Sky = [&](float cosZenith) { return atmosphere_.SkyLookUp(cosZenith); };

    constexpr int kRowsPerBlock = 8;
    const int blocks = (sh + kRowsPerBlock - 1) / kRowsPerBlock;
    std::vector<uint64_t> blockRays(size_t(blocks), 0);
    tbb::parallel_for(0, blocks, [&](int block) {
        const int y0 = block * kRowsPerBlock, y1 = std::min(sh, y0 + kRowsPerBlock);
        // Model samples wait for their shadow rays: sample index, position, normal, mesh.
        std::vector<uint32_t> modelK;
        std::vector<glm::vec3> modelP, modelN;
        std::vector<int> modelMesh;
        std::vector<glm::vec3> origins;
        std::vector<uint32_t> originOwner;
        float* out = radiance.At(0, y0);
        for (int y = y0; y < y1; ++y) {
            const double ndcY = 1.0 - 2.0 * (y + 0.5) / sh;
            for (int x = 0; x < sw; ++x) {
                const uint32_t k = uint32_t(size_t(y - y0) * size_t(sw) + size_t(x));
                const size_t idx = vis.Index(x, y);
                const uint32_t prim = vis.primitive[idx];
                if (prim == kNoPrimitive) {
                    const double ndcX = 2.0 * (x + 0.5) / sw - 1.0;
                    const glm::dvec3 d =
                        glm::normalize(forward + R * glm::dvec3(ndcX * tanH, 0.0, ndcY * tanV));
                    out[k] = Sky(float(d.z));
                    continue;
                }
                int mesh = 0;
                while (mesh + 1 < int(vis.primitiveBase.size()) &&
                       prim >= vis.primitiveBase[size_t(mesh) + 1])
                    ++mesh;
                const MeshRef& m = refs[size_t(mesh)];
                const uint32_t t = prim - vis.primitiveBase[size_t(mesh)];
                const uint32_t i0 = m.I[3 * t], i1 = m.I[3 * t + 1], i2 = m.I[3 * t + 2];
                const float b1 = vis.b1[idx], b2 = vis.b2[idx], b0 = 1.0f - b1 - b2;
                const glm::vec3 p = b0 * m.P[i0] + b1 * m.P[i1] + b2 * m.P[i2];
                glm::vec3 n = glm::normalize(b0 * m.N[i0] + b1 * m.N[i1] + b2 * m.N[i2]);
                const glm::vec3 toEye = eye - p;
                const float range = glm::length(toEye);
                const glm::vec3 v = toEye / range;
                if (mesh == 0) {
                    // Sea: emissivity at the local view angle (Masuda's wind average for the
                    // unresolved slopes), sky reflected about the resolved normal; a ray
                    // reflected into the sea meets the next wave's sky.
                    const float ndv = glm::dot(n, v);
                    const float eps = seaCurve_.Emissivity(std::max(ndv, 0.0f));
                    const float rz = std::abs(2.0f * ndv * n.z - v.z);
                    const float L = eps * seaB + (1.0f - eps) * Sky(rz);
                    const float tau = atmosphere_.TransmittanceLookUp(range);
                    out[k] = tau * L + (1.0f - tau) * airB;
                    continue;
                }
                if (glm::dot(n, v) < 0.0f) n = -n;
                modelK.push_back(k);
                modelP.push_back(p);
                modelN.push_back(n);
                modelMesh.push_back(mesh);
                if (shadows) {
                    const glm::vec3 o = ShadowRayOrigin(p, n);
                    if (occlusion.MayOcclude(o, sunDir, 1e30f)) {
                        origins.push_back(o);
                        originOwner.push_back(uint32_t(modelK.size() - 1));
                    }
                }
            }
        }
        std::vector<uint8_t> lit(modelK.size(), sunDir.z > 0.0f ? 1 : 0);
        if (!origins.empty()) {
            std::vector<uint8_t> visible(origins.size());
            occlusion.DirectionalVisibility(origins, sunDir, 0.0f, visible);
            for (size_t r = 0; r < origins.size(); ++r) lit[originOwner[r]] = visible[r];
            blockRays[size_t(block)] = origins.size();
        }
        for (size_t i = 0; i < modelK.size(); ++i) {
            const glm::vec3 p = modelP[i], n = modelN[i];
            const size_t entity = size_t(modelMesh[i]) - 1;
            // Orientation classes: up/down by n.z, horizontal azimuths linear in angle.
            const std::array<float, kC>& B = entityB[entity];
            const int base = lit[i] && glm::dot(n, sunDir) > 0.0f ? kO : 0;
            const float up = std::max(n.z, 0.0f), down = std::max(-n.z, 0.0f);
            const float side = 1.0f - up - down;
            float az = std::atan2(n.x, n.y) / float(M_PI / 4.0);
            if (az < 0.0f) az += 8.0f;
            const int a0 = std::min(int(az), 7), a1 = (a0 + 1) % 8;
            const float f = az - float(a0);
            const float Bs =
                up * B[size_t(base)] + down * B[size_t(base + kO - 1)] +
                side * ((1.0f - f) * B[size_t(base + 1 + a0)] + f * B[size_t(base + 1 + a1)]);
            const glm::vec3 toEye = eye - p;
            const float range = glm::length(toEye);
            const glm::vec3 v = toEye / range;
            // Reflected sky; rays reflected downward see the horizon (sea and air near B_air).
            const float rz = 2.0f * glm::dot(n, v) * n.z - v.z;
            const float eps = float(entities_[entity].emissivity);
            const float L = eps * Bs + (1.0f - eps) * Sky(std::max(rz, 0.0f));
            const float tau = atmosphere_.TransmittanceLookUp(range);
            out[modelK[i]] = tau * L + (1.0f - tau) * airB;
        }
    });
    for (uint64_t r : blockRays) stats_.shadowRays += r;
    stats_.shadeMs = Ms(t1, Clock::now());

    // Plumes (channels/plume) over the finished radiance.
    plumes_->CompositeFlir(state, cam, vis, *this, radiance);
}

}  // namespace seasense::channels
