// FLIR shading: sky from the atmosphere's band sky radiance, sea from its angle- and
// wind-dependent emissivity and reflected sky, models from material emissivity and temperature
// (heat balance per orientation class, sunlit or shaded by Embree), all through the path.
#include "channels/flir/flir_channel.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <map>

#include "channels/flir/cloud_infrared.h"
#include "channels/otw/spray_overlay.h"
#include "channels/plume/plume_composite.h"
#include "channels/view/surface_gather.h"
#include "scene/core/check.h"
#include "scene/core/error.h"
#include "scene/core/simd4.h"
#include "scene/core/simd_lanes.h"
#include "scene/sky/ephemeris.h"
#include "scene/sky/illuminance.h"

namespace seasense::channels {

namespace {

using namespace simd4;

// Luminous efficacy of direct-beam sunlight, lm/W: about 93 for a clear sky at moderate
// elevations (Littlefair, "The luminous efficacy of daylight: a review", Lighting Res.
// Technol. 17, 162 (1985)); converts the scene's sun illuminance to irradiance.
constexpr double kSunEfficacy_lm_W = 93.0;

// Shading tables. Sky over cos θ: 1025 nodes keep the linear interpolation within 1e-4
// relative of the exact spectral sum (the sky radiance is smooth in cos θ). Path over √range
// to 200 km (as Atmosphere's own table): 4097 nodes, steps of 0.11 √m, 2.2 m at 100 m range;
// the square root resolves short ranges, where the strongly absorbed parts of a band decay.
constexpr int kSkyNodes = 1025;
constexpr int kPathNodes = 4097;
constexpr double kMaxPathRange_m = 2.0e5;

// Sample rows per parallel task, and samples per shading chunk (a chunk's arrays stay in L1).
constexpr int kRowsPerBlock = 8;
constexpr size_t kChunk = 256;
// Sky samples in a row from which they are shaded as a run (ShadeSkyRun) rather than gathered.
constexpr int kMinSkyRun = 8;

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

double OrientationTemperatures::SunMemo::Irradiance_W_m2(double time_s, glm::dvec3& direction) {
    if (!valid_ || time_s != time_s_) {
        irradiance_W_m2_ = SunIrradiance_W_m2(scenario_, time_s, direction_);
        time_s_ = time_s;
        valid_ = true;
    }
    direction = direction_;
    return irradiance_W_m2_;
}

OrientationTemperatures::OrientationTemperatures(
    const radiometry::HeatBalanceParameters& parameters, const Environment& environment,
    const scene::Scenario& scenario, std::shared_ptr<SunMemo> sun)
    : parameters_(parameters),
      environment_(environment),
      scenario_(scenario),
      sun_(std::move(sun)) {
    CHECK(sun_);
}

glm::dvec3 OrientationTemperatures::ClassNormal(int o) {
    if (o == 0) return {0.0, 0.0, 1.0};
    if (o == kOrientations - 1) return {0.0, 0.0, -1.0};
    const double az = double(o - 1) * M_PI / 4.0;
    return {std::sin(az), std::cos(az), 0.0};
}

OrientationTemperatures::Drivers OrientationTemperatures::DriversAt(double time_s) {
    glm::dvec3 sunDir;
    const double E = sun_->Irradiance_W_m2(time_s, sunDir);
    Drivers all;
    for (int cls = 0; cls < kClasses; ++cls) {
        const int o = cls % kOrientations;
        const bool sunlit = cls >= kOrientations;
        const glm::dvec3 n = ClassNormal(o);
        radiometry::ThermalDrivers& d = all[size_t(cls)];
        d.time_s = time_s;
        d.solarIrradiance_W_m2 = sunlit ? E * std::max(glm::dot(n, sunDir), 0.0) : 0.0;
        d.longwaveIrradiance_W_m2 = radiometry::TiltedLongwaveIrradiance_W_m2(
            environment_.skyLongwave_W_m2, std::acos(std::clamp(n.z, -1.0, 1.0)),
            environment_.seaTemperature_K);
        d.airTemperature_K = environment_.airTemperature_K;
        d.windSpeed_mps = environment_.windSpeed_mps;
    }
    return all;
}

std::array<double, OrientationTemperatures::kClasses> OrientationTemperatures::Step(
    const std::array<double, kClasses>& from, const Drivers& a, const Drivers& b) const {
    std::array<double, kClasses> to;
    for (size_t c = 0; c < size_t(kClasses); ++c)
        to[c] = radiometry::IntegrateSurfaceTemperature(parameters_, {a[c], b[c]}, from[c]).back();
    return to;
}

std::array<double, OrientationTemperatures::kClasses> OrientationTemperatures::At(double time_s) {
    CHECK(time_s >= -kSpinUp_s);
    if (lastValid_ && time_s == lastTime_s_) return last_;
    last_ = Compute(time_s);
    lastTime_s_ = time_s;
    lastValid_ = true;
    return last_;
}

std::array<double, OrientationTemperatures::kClasses> OrientationTemperatures::Compute(
    double time_s) {
    const auto NodeTime = [](size_t k) { return -kSpinUp_s + double(k) * kGridStep_s; };
    const size_t k = size_t(std::floor((time_s + kSpinUp_s) / kGridStep_s));
    if (nodes_.empty()) {
        lastNodeDrivers_ = DriversAt(NodeTime(0));
        std::array<double, kClasses> first;
        for (size_t c = 0; c < size_t(kClasses); ++c)
            first[c] = radiometry::EquilibriumTemperature_K(parameters_, lastNodeDrivers_[c]);
        nodes_.push_back(first);
    }
    // Extend the grid node by node: each interval is integrated on its own, so a node's value
    // does not depend on how far earlier calls went.
    while (nodes_.size() <= k) {
        const Drivers next = DriversAt(NodeTime(nodes_.size()));
        nodes_.push_back(Step(nodes_.back(), lastNodeDrivers_, next));
        lastNodeDrivers_ = next;
    }
    if (!(time_s > NodeTime(k))) return nodes_[k];
    // The node's drivers again (k is usually the last node, whose drivers are kept).
    const Drivers atNode = k + 1 == nodes_.size() ? lastNodeDrivers_ : DriversAt(NodeTime(k));
    return Step(nodes_[k], atNode, DriversAt(time_s));
}

UniformTable::UniformTable(std::vector<float> nodes, float xMax)
    : nodes_(std::move(nodes)),
      scale_(float(nodes_.size() - 1) / xMax),
      last_(float(nodes_.size() - 1)) {
    CHECK(nodes_.size() >= 2 && xMax > 0.0f);
}

void UniformTable::operator()(size_t count, const float* x, float* out) const {
    const Lanes lookup(*this);
    // Whole lane groups, then the rest padded with zeros.
    size_t i = 0;
    for (; i + simd::kLanes <= count; i += simd::kLanes)
        simd::Store(out + i, lookup(simd::Load(x + i)));
    if (i < count) simd::Store(out + i, lookup(simd::Load(x + i, count - i, 0.0f)), count - i);
}

FlirChannel::FlirChannel(const scene::World& world, const scene::ChannelSettings& settings)
    : world_(world),
      setup_(ResolveFlirImager(settings, world.GetScenario().world.seed)),
      geometry_(world, setup_.channel),
      air_(world.GetScenario().environment.atmosphere
               ? radiometry::ParseAtmosphereSettings(*world.GetScenario().environment.atmosphere)
               : radiometry::AtmosphereSettings{}),
      sea_(world.GetScenario().environment.sea
               ? radiometry::ParseSeaSettings(*world.GetScenario().environment.sea)
               : radiometry::SeaSettings{}),
      table_(InfraredBandOf(settings.band)),
      atmosphere_(table_.GetBand(), air_, world.GetScenario().environment.visibility_m),
      seaCurve_(radiometry::SeaEmissivityTable::CurveForWind(
          radiometry::SeaSurfaceEmissivity(table_.GetBand()),
          world.GetScenario().environment.windSpeed_mps)),
      plumes_(std::make_unique<ChannelPlumes>(world)) {
    const scene::Scenario& sc = world.GetScenario();
    if (!sc.materialTable)
        throw InputError("scenario " + sc.file.string() +
                         ": the flir channel needs the material table's emissivities and "
                         "thermal models, but no material table was loaded");
    std::vector<float> nodes(kSkyNodes);
    for (int i = 0; i < kSkyNodes; ++i)
        nodes[size_t(i)] = float(atmosphere_.SkyRadiance(double(i) / (kSkyNodes - 1)));
    // 2∫₀¹ L(μ) μ dμ by the trapezoid rule over the table's nodes.
    double hemi = 0.0;
    for (int i = 0; i + 1 < kSkyNodes; ++i) {
        const double mu0 = double(i) / (kSkyNodes - 1), mu1 = double(i + 1) / (kSkyNodes - 1);
        hemi += (mu1 - mu0) * (nodes[size_t(i)] * mu0 + nodes[size_t(i) + 1] * mu1);
    }
    skyHemi_ = float(hemi);
    skyTable_ = UniformTable(std::move(nodes), 1.0f);
    seaEmissivity_ = UniformTable(seaCurve_.Nodes(), 1.0f);
    nodes.assign(kPathNodes, 0.0f);
    const double maxRoot = std::sqrt(kMaxPathRange_m);
    for (int i = 0; i < kPathNodes; ++i) {
        const double root = maxRoot * double(i) / (kPathNodes - 1);
        nodes[size_t(i)] = float(atmosphere_.Transmittance(root * root));
    }
    pathTau_ = UniformTable(std::move(nodes), float(maxRoot));

    const radiometry::MaterialTable materials = radiometry::ParseMaterialTable(*sc.materialTable);
    radiometry::ThermalEnvironment thermalEnv;
    thermalEnv.airTemperature_K = air_.airTemperature_K;
    thermalEnv.seaTemperature_K = sea_.temperature_K;
    OrientationTemperatures::Environment env;
    env.airTemperature_K = air_.airTemperature_K;
    env.seaTemperature_K = sea_.temperature_K;
    env.windSpeed_mps = sc.environment.windSpeed_mps;
    env.skyLongwave_W_m2 = atmosphere_.SkyLongwaveIrradiance_W_m2();
    // Entities of one heat-balance material share its temperatures (same drivers).
    std::map<std::string, int> heatBalanceOf;
    for (const scene::EntitySettings& e : sc.entities)
        entities_.push_back(
            ThermalOf(materials.Get(e.material), settings.band, env, thermalEnv, heatBalanceOf));

    // Surf zone. Foam is drawn wherever the sea mesh carries foam (deep-water whitecaps too):
    // the table's `foam` material, or without one the published emissivity of SurfInfrared at
    // the sea temperature. The beach needs the sand materials' thermal models.
    foam_.emissivity = surf_.foamEmissivity;
    foam_.staticT_K = sea_.temperature_K;
    if (const radiometry::Material* m = materials.Find("foam"))
        foam_ = ThermalOf(*m, settings.band, env, thermalEnv, heatBalanceOf);
    hasSurf_ = sc.environment.ocean.surf.has_value();
    if (hasSurf_) {
        for (const char* name : {"sand_dry", "sand_wet"})
            if (!materials.Find(name))
                throw InputError("scenario " + sc.file.string() +
                                 ": environment.ocean.surf: the flir channel draws the beach "
                                 "with the material table's sand_dry and sand_wet, but the table "
                                 "has no " +
                                 std::string(name));
        sandDry_ =
            ThermalOf(*materials.Find("sand_dry"), settings.band, env, thermalEnv, heatBalanceOf);
        sandWet_ =
            ThermalOf(*materials.Find("sand_wet"), settings.band, env, thermalEnv, heatBalanceOf);
    }
}

FlirChannel::EntityThermal FlirChannel::ThermalOf(const radiometry::Material& m,
                                                  scene::InfraredBand band,
                                                  const OrientationTemperatures::Environment& env,
                                                  const radiometry::ThermalEnvironment& thermalEnv,
                                                  std::map<std::string, int>& heatBalanceOf) {
    EntityThermal t;
    t.emissivity = band == scene::InfraredBand::Mwir ? m.emissivityMwir : m.emissivityLwir;
    if (m.thermal.kind == radiometry::ThermalModelKind::HeatBalance) {
        auto [it, added] = heatBalanceOf.emplace(m.name, int(heatBalance_.size()));
        if (added) {
            radiometry::HeatBalanceParameters p = m.thermal.heatBalance;
            p.emissivity = m.emissivityLwir;
            if (!sunMemo_)
                sunMemo_ = std::make_shared<OrientationTemperatures::SunMemo>(world_.GetScenario());
            heatBalance_.push_back(
                std::make_unique<OrientationTemperatures>(p, env, world_.GetScenario(), sunMemo_));
        }
        t.heatBalance = it->second;
    } else {
        t.staticT_K = m.StaticTemperature_K(thermalEnv);
    }
    return t;
}

FlirChannel::~FlirChannel() = default;

std::array<double, OrientationTemperatures::kClasses> FlirChannel::EntityTemperatures_K(
    size_t entity, double time_s) {
    CHECK(entity < entities_.size());
    return ClassTemperatures_K(entities_[entity], time_s);
}

std::array<double, OrientationTemperatures::kClasses> FlirChannel::ClassTemperatures_K(
    const EntityThermal& t, double time_s) {
    if (t.heatBalance >= 0) return heatBalance_[size_t(t.heatBalance)]->At(time_s);
    std::array<double, OrientationTemperatures::kClasses> out;
    out.fill(t.staticT_K);
    return out;
}

void FlirChannel::UpdateEntityRadiance(double time_s) {
    constexpr int kC = OrientationTemperatures::kClasses;
    entityB_.resize(entities_.size());
    for (size_t i = 0; i < entities_.size(); ++i) {
        const std::array<double, kC> T = EntityTemperatures_K(i, time_s);
        for (size_t c = 0; c < size_t(kC); ++c) entityB_[i][c] = float(table_.Radiance(T[c]));
    }
    // Foam and sand lie level: the upward class, sunlit (equal to shaded without sun).
    constexpr size_t kUpSunlit = size_t(OrientationTemperatures::kOrientations);
    surf_.foamEmissivity = float(foam_.emissivity);
    surf_.foamB = float(table_.Radiance(ClassTemperatures_K(foam_, time_s)[kUpSunlit]));
    if (!hasSurf_) return;
    const std::array<double, 2> T = SandTemperatures_K(time_s);
    const auto Leaving = [&](const EntityThermal& t, double T_K) {
        return float(t.emissivity * table_.Radiance(T_K) + (1.0 - t.emissivity) * skyHemi_);
    };
    surf_.sandDry = Leaving(sandDry_, T[0]);
    surf_.sandWet = Leaving(sandWet_, T[1]);
}

std::array<double, 2> FlirChannel::SandTemperatures_K(double time_s) {
    if (!hasSurf_) return {0.0, 0.0};
    constexpr size_t kUpSunlit = size_t(OrientationTemperatures::kOrientations);
    return {ClassTemperatures_K(sandDry_, time_s)[kUpSunlit],
            ClassTemperatures_K(sandWet_, time_s)[kUpSunlit]};
}

// The constants of one frame's shading.
struct FlirChannel::FrameShading {
    FrameShading(const VisibilityBuffer& v, const OcclusionScene& o) : vis(v), occlusion(o) {}

    const VisibilityBuffer& vis;
    const OcclusionScene& occlusion;
    std::vector<MeshArrays> meshes;  // mesh 0 the sea
    // SeaGather::DeepVertices' flags of the sea's vertices at kSurfDeepColumn_m.
    const uint8_t* deepVertices = nullptr;
    int sampleWidth = 0, sampleHeight = 0;
    glm::vec3 eye{0.0f}, sunDir{0.0f};
    bool shadows = false;
    // occlusion.MayOcclude along sunDir (to 1e30 m), prepared once for the frame's model samples.
    OccluderBoundsTest occluders;
    float seaB = 0.0f, airB = 0.0f;
    SurfInfrared surf;
    // View rays: direction ∝ forward + up·ndcY − right + (x + ½)·colStep (the camera axes
    // scaled by the pinhole geometry), so sky samples need no trigonometry.
    glm::vec3 colStep{0.0f};
    glm::dvec3 forward{0.0}, right{0.0}, up{0.0};
};

// Per-thread scratch of the shading pass, kept between frames. Samples are sorted into sky, sea
// and model lists as they are gathered; sky and sea are shaded four lanes at a time whenever
// kChunk of them have gathered, so their arrays stay in L1 between gathering and shading. The few
// model samples of a row block go one by one at its end.
struct FlirChannel::ShadeBlock {
    // Sky: sample index within the block, view direction's z and squared length.
    alignas(16) uint32_t skyK[kChunk];
    alignas(16) float skyZ[kChunk], skyLength[kChunk];
    // Sea: per sample position, (unnormalized) normal and sea-mesh attributes as SeaGather
    // writes them; and the runs of consecutive samples they came from (first sample index and
    // length; a row's sea samples come in long runs, so they are written back a run at a time).
    SeaSamples<kChunk> sea;
    uint32_t seaRunK[kChunk], seaRunLength[kChunk];
    size_t seaRuns = 0;
    std::vector<uint32_t> modelK;
    std::vector<glm::vec3> modelP, modelN;
    std::vector<int> modelMesh;
    std::vector<glm::vec3> origins;
    std::vector<uint32_t> originOwner;
    std::vector<uint8_t> lit, visible;
    alignas(16) float a[kChunk], b[kChunk], c[kChunk], d[kChunk], e[kChunk];
};
struct FlirChannel::ShadeScratch {
    tbb::enumerable_thread_specific<ShadeBlock> perThread;
    std::vector<uint8_t> deepVertices;  // FrameShading::deepVertices
};

namespace {

// The end of the run of sky samples (kNoPrimitive) in prims[x, sw) that starts at x.
int SkyRunEnd(const uint32_t* prims, int x, int sw) {
    int end = x + 1;
    const __m128i none = _mm_set1_epi32(int32_t(kNoPrimitive));
    for (; end + 4 <= sw; end += 4) {
        const __m128i p = _mm_loadu_si128(reinterpret_cast<const __m128i*>(prims + end));
        const int sky = _mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(p, none)));
        if (sky != 0xf) return end + __builtin_ctz(unsigned(~sky));
    }
    while (end < sw && prims[end] == kNoPrimitive) ++end;
    return end;
}

// |v|: the sign bit cleared.
simd::VF Abs(simd::VF v) { return simd::VF(simd::VI(v) & 0x7fffffff); }

}  // namespace

void FlirChannel::ShadeSky(ShadeBlock& sc, size_t count, float* out) const {
    // L_sky(cos θ) with cos θ = d_z / |d|.
    for (size_t i = 0; i < count; i += simd::kLanes) {
        const size_t lanes = std::min(simd::kLanes, count - i);
        const simd::VF z = simd::Load(&sc.skyZ[i], lanes, 1.0f);
        const simd::VF len2 = simd::Load(&sc.skyLength[i], lanes, 1.0f);
        simd::Store(sc.a + i, z / simd::Sqrt(len2));
    }
    skyTable_(count, sc.a, sc.b);
    for (size_t i = 0; i < count; ++i) out[sc.skyK[i]] = sc.b[i];
}

void FlirChannel::ShadeSkyRun(const FrameShading& f, const glm::vec3& rowBase, int x0, int x1,
                              ShadeBlock& sc, float* rowOut) const {
    // The view directions of the run a lane group at a time, with glm's operations of the
    // sample-by-sample path in the same order (d = rowBase + (x + ½) colStep,
    // |d|² = (x² + y²) + z²), so the same bits; then L_sky(d_z / |d|) as ShadeSky.
    simd::VI iota;
    for (size_t l = 0; l < simd::kLanes; ++l) iota[l] = int32_t(l);
    for (int start = x0; start < x1; start += int(kChunk)) {
        const size_t count = size_t(std::min(x1 - start, int(kChunk)));
        for (size_t i = 0; i < count; i += simd::kLanes) {
            const simd::VF t = __builtin_convertvector(iota + (start + int(i)), simd::VF) + 0.5f;
            const simd::VF dx = rowBase.x + t * f.colStep.x;
            const simd::VF dy = rowBase.y + t * f.colStep.y;
            const simd::VF dz = rowBase.z + t * f.colStep.z;
            const simd::VF len2 = (dx * dx + dy * dy) + dz * dz;
            simd::Store(sc.a + i, dz / simd::Sqrt(len2));
        }
        skyTable_(count, sc.a, rowOut + start);
    }
}

void FlirChannel::ShadeSea(const FrameShading& f, ShadeBlock& sc, size_t count, float* out) const {
    // Emissivity at the local view angle (Masuda's wind average for the unresolved slopes), sky
    // reflected about the resolved normal (a ray reflected into the sea meets the next wave's
    // sky); sand where the sea lies on the beach and foam over both (SurfInfraredRadiance);
    // through the path. The entries past count (the last lane group's unused lanes) repeat the
    // last sample, so that those lanes compute finite values that are never stored.
    using simd::VF;
    const auto Lanes = [&](SeaComponent k, size_t i) { return simd::Load(sc.sea.c[k] + i); };
    for (float(&component)[kChunk + simd::kLanes] : sc.sea.c)
        std::fill(component + count,
                  component + (count + simd::kLanes - 1) / simd::kLanes * simd::kLanes,
                  component[count - 1]);
    // The frame's constants in locals: the stores to sc could alias f's members, which would
    // be read again for every lane group.
    const VF eyeX = simd::Splat(f.eye.x), eyeY = simd::Splat(f.eye.y), eyeZ = simd::Splat(f.eye.z);
    const SurfInfrared surf = f.surf;
    const VF airB = simd::Splat(f.airB), seaB = simd::Splat(f.seaB);
    const UniformTable::Lanes emissivity(seaEmissivity_), sky(skyTable_), path(pathTau_);
    // Deep records alone (SeaGather, kSurfDeepColumn_m; sums false): their surf radiance is the
    // water term's bits.
    const bool sums = sc.sea.sums;
    for (size_t i = 0; i < count; i += simd::kLanes) {
        VF nx = Lanes(kSeaNx, i), ny = Lanes(kSeaNy, i), nz = Lanes(kSeaNz, i);
        const VF px = Lanes(kSeaPx, i), py = Lanes(kSeaPy, i), pz = Lanes(kSeaPz, i);
        const VF invN = 1.0f / simd::Sqrt(simd::Dot(nx, ny, nz, nx, ny, nz));
        nx = nx * invN, ny = ny * invN, nz = nz * invN;
        const VF tx = eyeX - px, ty = eyeY - py, tz = eyeZ - pz;
        const VF range = simd::Sqrt(simd::Dot(tx, ty, tz, tx, ty, tz));
        const VF invRange = 1.0f / range;
        const VF ndv = simd::Dot(nx, ny, nz, tx, ty, tz) * invRange;
        const VF rz = (2.0f * ndv) * nz - tz * invRange;
        const VF epsWater = emissivity(simd::Max(ndv, VF{}));  // at cos θ_view
        const VF skyR = sky(Abs(rz));                          // at the reflected cos θ_zenith
        const VF tau = path(simd::Sqrt(range));
        const VF L = sums ? SurfInfraredRadiance(surf, epsWater, seaB, skyR, Lanes(kSeaDepth, i),
                                                 Lanes(kSeaWet, i), Lanes(kSeaFoam, i))
                          : SurfWaterRadiance(epsWater, seaB, skyR);
        simd::Store(sc.b + i, tau * L + (1.0f - tau) * airB);
    }
    sc.sea.sums = false;
    const float* L = sc.b;
    for (size_t r = 0; r < sc.seaRuns; L += sc.seaRunLength[r], ++r)
        std::copy_n(L, sc.seaRunLength[r], out + sc.seaRunK[r]);
    sc.seaRuns = 0;
}

uint64_t FlirChannel::ShadeRows(const FrameShading& f, int y0, int y1, float* out) {
    constexpr int kC = OrientationTemperatures::kClasses,
                  kO = OrientationTemperatures::kOrientations;
    ShadeBlock& sc = scratch_->perThread.local();
    const int sw = f.sampleWidth;
    sc.modelK.clear(), sc.modelP.clear(), sc.modelN.clear(), sc.modelMesh.clear();
    sc.origins.clear(), sc.originOwner.clear();

    // Sort the samples by kind: sky view directions, sea surface records (shaded a chunk at a
    // time), model positions and normals.
    size_t skyCount = 0, seaCount = 0;
    TriangleCache tri;
    // Mesh 0's primitives (all of them when there are no models); deep water from
    // kSurfDeepColumn_m, where ShadeSea's SurfInfraredRadiance needs no attribute sums.
    const std::vector<uint32_t>& bases = f.vis.primitiveBase;
    SeaGather sea(f.meshes[0], bases[0], (bases.size() > 1 ? bases[1] : kNoPrimitive) - bases[0],
                  kSurfDeepColumn_m, f.deepVertices);
    for (int y = y0; y < y1; ++y) {
        const double ndcY = 1.0 - 2.0 * (y + 0.5) / f.sampleHeight;
        const glm::vec3 rowBase(f.forward + f.up * ndcY - f.right);
        const size_t row = f.vis.Index(0, y);
        const uint32_t* prims = f.vis.primitive.data() + row;
        const float* b1 = f.vis.b1.data() + row;
        const float* b2 = f.vis.b2.data() + row;
        const uint32_t kRow = uint32_t(size_t(y - y0) * size_t(sw));
        for (int x = 0; x < sw;) {
            const uint32_t k = kRow + uint32_t(x), prim = prims[x];
            if (sea.IsSea(prim)) {
                const int x0 = x;
                x = sea.Gather(prims, b1, b2, x, sw, sc.sea, seaCount);
                sc.seaRunK[sc.seaRuns] = k;
                sc.seaRunLength[sc.seaRuns++] = uint32_t(x - x0);
                if (seaCount == kChunk) ShadeSea(f, sc, seaCount, out), seaCount = 0;
                continue;
            }
            if (prim == kNoPrimitive) {
                // A run of sky (most rows above the horizon): shaded straight into out; a short
                // one gathered with the block's other short runs.
                const int end = SkyRunEnd(prims, x, sw);
                if (end - x >= kMinSkyRun) {
                    ShadeSkyRun(f, rowBase, x, end, sc, out + kRow);
                    x = end;
                    continue;
                }
                for (; x < end; ++x) {
                    const glm::vec3 d = rowBase + (float(x) + 0.5f) * f.colStep;
                    sc.skyK[skyCount] = kRow + uint32_t(x);
                    sc.skyZ[skyCount] = d.z;
                    sc.skyLength[skyCount] = glm::dot(d, d);
                    if (++skyCount == kChunk) ShadeSky(sc, skyCount, out), skyCount = 0;
                }
                continue;
            }
            alignas(16) float p[4], n[4];
            int mesh = 0;
            tri.Surface(f.vis.primitiveBase, f.meshes, prim, b1[x], b2[x], p, n, mesh);
            ++x;
            const glm::vec3 position(p[0], p[1], p[2]);
            glm::vec3 normal = glm::normalize(glm::vec3(n[0], n[1], n[2]));
            if (glm::dot(normal, f.eye - position) < 0.0f) normal = -normal;
            sc.modelK.push_back(k);
            sc.modelP.push_back(position);
            sc.modelN.push_back(normal);
            sc.modelMesh.push_back(mesh);
            if (f.shadows) {
                const glm::vec3 o = ShadowRayOrigin(position, normal);
                if (f.occluders.MayOcclude(o)) {
                    sc.origins.push_back(o);
                    sc.originOwner.push_back(uint32_t(sc.modelK.size() - 1));
                }
            }
        }
    }
    if (skyCount > 0) ShadeSky(sc, skyCount, out);
    if (seaCount > 0) ShadeSea(f, sc, seaCount, out);

    // Pass 4: models (a small fraction of the frame): sunlit or shaded by the shadow rays.
    sc.lit.assign(sc.modelK.size(), f.sunDir.z > 0.0f ? 1 : 0);
    if (!sc.origins.empty()) {
        sc.visible.resize(sc.origins.size());
        // Every origin passed f.occluders above: not tested again.
        f.occlusion.DirectionalVisibility(sc.origins, f.sunDir, 0.0f, sc.visible, true);
        for (size_t r = 0; r < sc.origins.size(); ++r) sc.lit[sc.originOwner[r]] = sc.visible[r];
    }
    for (size_t i = 0; i < sc.modelK.size(); ++i) {
        const glm::vec3 p = sc.modelP[i], n = sc.modelN[i];
        const size_t entity = size_t(sc.modelMesh[i]) - 1;
        // Orientation classes: up/down by n.z, horizontal azimuths linear in angle.
        const std::array<float, kC>& B = entityB_[entity];
        const int base = sc.lit[i] && glm::dot(n, f.sunDir) > 0.0f ? kO : 0;
        const float up = std::max(n.z, 0.0f), down = std::max(-n.z, 0.0f);
        const float side = 1.0f - up - down;
        float az = std::atan2(n.x, n.y) / float(M_PI / 4.0);
        if (az < 0.0f) az += 8.0f;
        const int a0 = std::min(int(az), 7), a1 = (a0 + 1) % 8;
        const float w = az - float(a0);
        const float Bs =
            up * B[size_t(base)] + down * B[size_t(base + kO - 1)] +
            side * ((1.0f - w) * B[size_t(base + 1 + a0)] + w * B[size_t(base + 1 + a1)]);
        const glm::vec3 toEye = f.eye - p;
        const float range = glm::length(toEye);
        const glm::vec3 v = toEye / range;
        // Reflected sky; rays reflected downward see the horizon (sea and air near B_air).
        const float rz = 2.0f * glm::dot(n, v) * n.z - v.z;
        const float eps = float(entities_[entity].emissivity);
        const float L = eps * Bs + (1.0f - eps) * skyTable_(std::max(rz, 0.0f));
        const float tau = pathTau_(std::sqrt(range));
        out[sc.modelK[i]] = tau * L + (1.0f - tau) * f.airB;
    }
    return sc.origins.size();
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
    UpdateEntityRadiance(state.time_s);
    const Clock::time_point t1 = Clock::now();
    stats_.thermalMs = Ms(t0, t1);

    const ChannelCamera& cam = geometry_.Camera();
    const VisibilityBuffer& vis = geometry_.Visibility();
    const OcclusionScene& occlusion = geometry_.Occlusion();
    const int sw = cam.SampleWidth(), sh = cam.SampleHeight();
    if (radiance.width != sw || radiance.height != sh || radiance.channels != 1)
        radiance = Image(sw, sh, 1);

    const glm::dmat3& R = cam.worldFromCamera.worldFromBody;
    const double tanH = cam.TanHalfH(), tanV = cam.TanHalfV();
    FrameShading frame(vis, occlusion);
    const scene::OceanMesh& ocean = geometry_.Ocean();
    CHECK(geometry_.OceanAttributes().size() == ocean.positions.size());
    frame.meshes.push_back({ocean.positions.data(), ocean.normals.data(), ocean.indices.data(),
                            geometry_.OceanAttributes().data()});
    for (const scene::TriangleMesh& m : geometry_.EntityMeshes())
        frame.meshes.push_back({m.positions.data(), m.normals.data(), m.indices.data()});
    frame.sampleWidth = sw;
    frame.sampleHeight = sh;
    frame.eye = glm::vec3(cam.worldFromCamera.position_m);
    frame.sunDir = glm::vec3(state.sun.direction);
    frame.shadows = setup_.channel.shadows && !occlusion.Empty() && frame.sunDir.z > 0.0f;
    frame.occluders = occlusion.BoundsTest(frame.sunDir, 1e30f);
    frame.seaB = float(table_.Radiance(sea_.temperature_K));
    frame.airB = float(atmosphere_.AirRadiance());
    frame.surf = surf_;
    frame.colStep = glm::vec3(R * glm::dvec3(2.0 * tanH / sw, 0.0, 0.0));
    frame.forward = R * glm::dvec3(0.0, 1.0, 0.0);
    frame.right = R * glm::dvec3(tanH, 0.0, 0.0);
    frame.up = R * glm::dvec3(0.0, 0.0, tanV);

    if (!scratch_) scratch_ = std::make_unique<ShadeScratch>();
    // The sea's deep vertices once for the frame, rather than each triangle's test in every
    // row block and sample row that meets it.
    scratch_->deepVertices.resize(ocean.positions.size());
    SeaGather::DeepVertices(geometry_.OceanAttributes().data(), ocean.positions.size(),
                            kSurfDeepColumn_m, scratch_->deepVertices.data());
    frame.deepVertices = scratch_->deepVertices.data();
    const int blocks = (sh + kRowsPerBlock - 1) / kRowsPerBlock;
    std::vector<uint64_t> blockRays(size_t(blocks), 0);
    tbb::parallel_for(0, blocks, [&](int block) {
        const int y0 = block * kRowsPerBlock, y1 = std::min(sh, y0 + kRowsPerBlock);
        blockRays[size_t(block)] = ShadeRows(frame, y0, y1, radiance.At(0, y0));
    });
    for (uint64_t r : blockRays) stats_.shadowRays += r;
    stats_.shadeMs = Ms(t1, Clock::now());

    // --- Cloud layers (channels/flir/cloud_infrared) over the sky. ---
    if (const scene::CloudField* clouds = world_.Clouds()) {
        if (!clouds_) clouds_ = std::make_unique<CloudSky>();
        FlirCloudOptics optics;
        optics.table = &table_;
        optics.surfaceAir_K = air_.airTemperature_K;
        optics.airRadiance = atmosphere_.AirRadiance();
        optics.transmittance = [this](double range_m) {
            return double(pathTau_(float(std::sqrt(std::min(range_m, kMaxPathRange_m)))));
        };
        const glm::dvec3 eye = cam.worldFromCamera.position_m;
        const CloudSkyStats cloud = clouds_->Composite(
            *clouds, state.time_s, cam, vis,
            [&](const glm::dvec3& d, const scene::CloudHit& hit) {
                return FlirCloudCover(optics, eye, d, hit);
            },
            {}, radiance);
        stats_.cloudMs = cloud.ms;
        stats_.cloudTraces = cloud.gridTraces;
    }
    // --- end of cloud layers ---

    // --- Surf spray (channels/otw/spray_overlay): foam-emissivity water at the sea temperature
    // (the reflected (1 − ε_f) part from the zenith sky), through the path. ---
    DrawSprayInfrared(
        world_, state, cam, vis,
        surf_.foamEmissivity * frame.seaB + (1.0f - surf_.foamEmissivity) * skyTable_(1.0f),
        [&](double range_m, float L) {
            const float tau = pathTau_(float(std::sqrt(std::min(range_m, kMaxPathRange_m))));
            return tau * L + (1.0f - tau) * frame.airB;
        },
        radiance);
    // Plumes (channels/plume) over the finished radiance.
    plumes_->CompositeFlir(state, cam, vis, *this, radiance);
    stats_.plumes = plumes_->Stats();
}

}  // namespace seasense::channels
