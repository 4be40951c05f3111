// Per-kind plume defaults and the validating reader of the plumes configuration section.
#include "scene/plumes/plume_settings.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "scene/config/suggest.h"

namespace seasense::scene {
namespace {

constexpr double kRadPerDeg = std::numbers::pi / 180.0;

const std::vector<std::string> kKindNames = {"smoke", "flame", "dust", "exhaust", "steam"};
const std::vector<std::string> kSoilNames = {"none", "dry_clay", "light_sand"};
const std::vector<std::string> kRoadNames = {"paved", "clay", "sand"};
const std::vector<std::string> kStabilityNames = {"auto", "A", "B", "C", "D", "E", "F"};

// Upper limits that keep a plume's pool of puffs bounded (a few thousand per column).
constexpr double kMaxRate_hz = 100.0;
constexpr double kMaxLifetime_s = 3600.0;

// The entity named by attach_to, which must be one of names.
std::string ReadEntityName(const ConfigValue& value, const std::vector<std::string>& names) {
    std::string expected = "the name of an entity";
    if (names.empty()) expected += " (the scenario has none)";
    const std::string name = value.AsString();
    if (std::find(names.begin(), names.end(), name) == names.end()) {
        const std::optional<std::string> suggestion = SuggestClosest(name, names);
        value.Fail(expected,
                   value.Describe() + (suggestion ? " (did you mean '" + *suggestion + "'?)" : ""));
    }
    return name;
}

// Fails at key of m, when present, because attach_to sets what it would set.
void RejectWithAttachment(ConfigMap& m, std::string_view key, const char* why) {
    if (const std::optional<ConfigValue> v = m.Find(key))
        v->Fail(std::string("no ") + std::string(key) + " together with attach_to (" + why + ")",
                v->Describe());
}

PlumeSourceSettings ReadSource(const ConfigValue& value, const PlumeParseContext& context) {
    return ReadMap(value, [&](ConfigMap& m) {
        const auto kind = PlumeKind(m.GetEnum("kind", kKindNames));
        PlumeSourceSettings s = DefaultPlumeSource(kind);
        const std::optional<ConfigValue> attach = m.Find("attach_to");
        if (attach) {
            s.attachTo = ReadEntityName(*attach, context.entityNames);
            s.attachOffset_m = m.GetVec3("offset_m", NumberRange::Any("m"), s.attachOffset_m);
            RejectWithAttachment(m, "position_m", "the entity's pose and offset_m place it");
        } else {
            s.position_m = m.GetVec3("position_m", NumberRange::Any("m"));
        }
        // Negative: the source was already going when the scenario starts.
        s.start_s = m.GetDouble("start_s", NumberRange::Any("s"), s.start_s);
        s.duration_s = m.GetDouble("duration_s", NumberRange::Positive("s"), s.duration_s);
        s.rate_hz =
            m.GetDouble("rate_hz", NumberRange::OpenClosed(0, kMaxRate_hz, "Hz"), s.rate_hz);
        if (kind != PlumeKind::Flame)  // flame puffs live until they reach the flame height
            s.lifetime_s = m.GetDouble(
                "lifetime_s", NumberRange::OpenClosed(0, kMaxLifetime_s, "s"), s.lifetime_s);
        if (kind != PlumeKind::Dust)  // dust follows from speed and soil
            s.massRate_kgps =
                m.GetDouble("mass_rate_kgps", NumberRange::NonNegative("kg/s"), s.massRate_kgps);
        s.longTermFraction =
            m.GetDouble("long_term_fraction", NumberRange::Closed(0, 1), s.longTermFraction);
        s.decayRate_hz =
            m.GetDouble("decay_rate_hz", NumberRange::NonNegative("Hz"), s.decayRate_hz);
        s.albedo = m.GetDouble("albedo", NumberRange::Closed(0, 1), s.albedo);
        s.seed =
            uint64_t(m.GetInt("seed", 0, std::numeric_limits<int64_t>::max(), int64_t(s.seed)));
        switch (kind) {
            case PlumeKind::Smoke:
            case PlumeKind::Flame:
                s.heatRelease_W =
                    m.GetDouble("heat_release_W", NumberRange::Positive("W"), s.heatRelease_W);
                s.sourceRadius_m =
                    m.GetDouble("source_radius_m", NumberRange::Positive("m"), s.sourceRadius_m);
                if (kind == PlumeKind::Smoke)
                    s.exitTemperature_K = m.GetDouble(
                        "exit_temperature_K", NumberRange::Positive("K"), s.exitTemperature_K);
                else
                    s.flameTemperature_K = m.GetDouble(
                        "flame_temperature_K", NumberRange::Positive("K"), s.flameTemperature_K);
                break;
            case PlumeKind::Exhaust:
            case PlumeKind::Steam:
                s.sourceRadius_m =
                    m.GetDouble("source_radius_m", NumberRange::Positive("m"), s.sourceRadius_m);
                s.exitTemperature_K = m.GetDouble("exit_temperature_K", NumberRange::Positive("K"),
                                                  s.exitTemperature_K);
                s.exitVelocity_mps = m.GetDouble("exit_velocity_mps", NumberRange::Positive("m/s"),
                                                 s.exitVelocity_mps);
                break;
            case PlumeKind::Dust:
                if (attach) {
                    RejectWithAttachment(m, "speed_mps", "the vehicle is the entity");
                    RejectWithAttachment(m, "heading_deg", "the vehicle is the entity");
                } else {
                    s.speed_mps =
                        m.GetDouble("speed_mps", NumberRange::Closed(0, 100, "m/s"), s.speed_mps);
                    s.heading_rad =
                        m.GetDouble("heading_deg", NumberRange::Any("deg"), 0.0) * kRadPerDeg;
                }
                s.soil = SoilType(m.GetEnum("soil", kSoilNames, size_t(s.soil)));
                s.road = RoadType(m.GetEnum("road", kRoadNames, size_t(s.road)));
                s.siltPercent =
                    m.GetDouble("silt_percent", NumberRange::Closed(0, 100, "%"), s.siltPercent);
                s.moisturePercent = m.GetDouble(
                    "moisture_percent", NumberRange::OpenClosed(0, 100, "%"), s.moisturePercent);
                break;
        }
        return s;
    });
}

}  // namespace

std::string_view ToString(PlumeKind kind) { return kKindNames[size_t(kind)]; }

double SeedIndex(SoilType soil) {
    static constexpr double kIndex[] = {0.0, 0.5, 1.0};
    return kIndex[int(soil)];
}

double SeedIndex(RoadType road) {
    static constexpr double kIndex[] = {0.0, 0.5, 1.0};
    return kIndex[int(road)];
}

PlumeSourceSettings DefaultPlumeSource(PlumeKind kind) {
    PlumeSourceSettings s;
    s.kind = kind;
    switch (kind) {
        case PlumeKind::Smoke:
            // A 20 MW oil fire: soot is not scavenged within a puff's minutes (f_d = 1), dark
            // (fresh soot single-scattering albedo ≈ 0.2–0.3, Bond & Bergstrom, Aerosol Sci.
            // Technol. 40 (2006) 27).
            break;
        case PlumeKind::Flame:
            s.rate_hz = 8.0;
            s.massRate_kgps = 0.01;
            s.albedo = 0.2;
            break;
        case PlumeKind::Dust:
            // Coarse grains settle out within tens of seconds, a fine fraction stays; mineral
            // dust scatters far more than it absorbs in the visible.
            s.rate_hz = 4.0;
            s.lifetime_s = 90.0;
            s.longTermFraction = 0.3;
            s.decayRate_hz = 1.0 / 30.0;
            s.albedo = 0.9;
            break;
        case PlumeKind::Exhaust:
            // A ship's diesel funnel: hot, fast, little soot.
            s.rate_hz = 2.0;
            s.lifetime_s = 180.0;
            s.massRate_kgps = 0.002;
            s.albedo = 0.25;
            s.sourceRadius_m = 0.6;
            s.exitTemperature_K = 620.0;
            s.exitVelocity_mps = 15.0;
            break;
        case PlumeKind::Steam:
            // Condensed droplets evaporate as the plume mixes (f_d = 0); water scatters
            // without absorbing in the visible.
            s.rate_hz = 2.0;
            s.lifetime_s = 60.0;
            s.massRate_kgps = 0.5;
            s.longTermFraction = 0.0;
            s.decayRate_hz = 0.05;
            s.albedo = 0.999;
            s.sourceRadius_m = 1.0;
            s.exitTemperature_K = 373.15;
            s.exitVelocity_mps = 8.0;
            break;
    }
    return s;
}

PlumesSettings ParsePlumesSettings(ConfigMap& map, const PlumeParseContext& context) {
    PlumesSettings settings;
    settings.airTemperature_K = context.airTemperature_K;
    const size_t stability = map.GetEnum("stability", kStabilityNames, 0);
    if (stability > 0) settings.stability = StabilityClass(stability - 1);
    settings.inversionHeight_m =
        map.GetDouble("inversion_height_m", NumberRange::Positive("m"), settings.inversionHeight_m);
    settings.airTemperatureGiven = map.Find("air_temperature_K").has_value();
    settings.airTemperature_K = map.GetDouble(
        "air_temperature_K", NumberRange::Closed(180, 340, "K"), settings.airTemperature_K);
    for (const ConfigValue& source : map.GetList("sources", 0, kMaxPlumeSources, "plume sources"))
        settings.sources.push_back(ReadSource(source, context));
    map.Finish();
    return settings;
}

void PlaceAttachedSource(PlumeSourceSettings& source, const glm::dvec3& entityPosition_m,
                         const glm::dmat3& worldFromBody, const glm::dvec3& entityVelocity_mps) {
    const glm::dvec3 v{entityVelocity_mps.x, entityVelocity_mps.y, 0.0};
    source.position_m =
        entityPosition_m + v * source.start_s + worldFromBody * source.attachOffset_m;
    if (source.kind == PlumeKind::Dust) {
        source.speed_mps = glm::length(v);
        source.heading_rad = source.speed_mps > 0.0 ? std::atan2(v.x, v.y) : 0.0;
        source.velocity_mps = glm::dvec3(0.0);
    } else {
        source.velocity_mps = v;
    }
}

}  // namespace seasense::scene
