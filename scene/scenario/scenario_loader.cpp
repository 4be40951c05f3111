// The scenario schema: YAML (degrees, files relative to the scenario) -> Scenario (SI, radians).
#include "scene/scenario/scenario_loader.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <string>

#include "scene/config/config.h"
#include "scene/config/digest.h"
#include "scene/config/suggest.h"
#include "scene/core/check.h"
#include "scene/core/error.h"
#include "scene/core/frames.h"
#include "scene/ocean/fft_ocean.h"
#include "scene/ocean/gerstner.h"

namespace seasense::scene {

namespace {

constexpr double kRadPerDeg = std::numbers::pi / 180.0;
// Largest image side in pixels, before and after supersampling (issue 2).
constexpr int64_t kMaxImageSide = 16384;
constexpr int64_t kMaxSupersampling = 8;
constexpr size_t kMaxChannels = 64;
constexpr size_t kMaxEntities = 100000;

const std::vector<std::string> kChannelKinds = {"otw", "flir", "nvg"};
// In the order of InfraredBand.
const std::vector<std::string> kInfraredBands = {"lwir", "mwir"};
const std::vector<std::string> kExposureModes = {"auto", "manual", "adapted"};
const std::vector<std::string> kOutputFormats = {"exr", "png", "tiff"};
// Flir channels also write the imager's 16-bit raw ADC counts.
const std::vector<std::string> kFlirOutputFormats = {"exr", "png", "tiff", "raw_png", "raw_tiff"};
// ChannelSettings::Display, in its order.
const std::vector<std::string> kDisplays = {"exact", "lut"};
const std::vector<std::string> kModelExtensions = {".obj", ".gltf", ".glb"};

// Names that end up in file names and command lines: [A-Za-z0-9_-]+.
bool IsSimpleName(const std::string& name) {
    if (name.empty()) return false;
    return std::all_of(name.begin(), name.end(), [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
    });
}

std::string ReadSimpleName(ConfigMap& map, std::string_view key) {
    constexpr const char* kExpected = "a name of letters, digits, '_' and '-'";
    const ConfigValue value = map.Require(key, kExpected);
    std::string name = value.AsString();
    if (!IsSimpleName(name)) value.Fail(kExpected);
    return name;
}

// A file path relative to the scenario's folder (absolute paths are taken as they are).
std::filesystem::path Resolve(const std::filesystem::path& folder, const std::string& relative) {
    return (folder / relative).lexically_normal();
}

double Degrees(ConfigMap& map, std::string_view key, const NumberRange& range, double fallback) {
    return map.GetDouble(key, range, fallback) * kRadPerDeg;
}

// heading_deg, pitch_deg, roll_deg, each optional (0): heading and roll any finite angle,
// pitch within [-90, 90] so that heading stays meaningful.
Attitude ReadAttitude(ConfigMap& map) {
    Attitude attitude;
    attitude.heading_rad = Degrees(map, "heading_deg", NumberRange::Any("deg"), 0.0);
    attitude.pitch_rad = Degrees(map, "pitch_deg", NumberRange::Closed(-90, 90, "deg"), 0.0);
    attitude.roll_rad = Degrees(map, "roll_deg", NumberRange::Any("deg"), 0.0);
    return attitude;
}

WorldSettings ReadWorld(ConfigMap& map) {
    WorldSettings world;
    ReadMap(map.Require("world", "a mapping"), [&](ConfigMap& w) {
        ReadMap(w.Require("origin", "a mapping"), [&](ConfigMap& origin) {
            world.latitude_deg =
                origin.GetDouble("latitude_deg", NumberRange::Closed(-90, 90, "deg"));
            world.longitude_deg =
                origin.GetDouble("longitude_deg", NumberRange::Closed(-180, 180, "deg"));
        });
        world.start = w.GetTime("start_utc");
        world.timeScale = w.GetDouble("time_scale", NumberRange::Positive(), world.timeScale);
        world.frameRate_hz = w.GetDouble("frame_rate_hz", NumberRange::OpenClosed(0, 1000, "Hz"),
                                         world.frameRate_hz);
        world.seed =
            uint64_t(w.GetInt("seed", 0, std::numeric_limits<int64_t>::max(), int64_t(world.seed)));
    });
    return world;
}

GerstnerWaveSettings ReadWave(const ConfigValue& value) {
    GerstnerWaveSettings wave;
    ReadMap(value, [&](ConfigMap& w) {
        wave.direction_rad = w.GetDouble("direction_deg", NumberRange::Any("deg")) * kRadPerDeg;
        wave.wavelength_m = w.GetDouble("wavelength_m", NumberRange::Positive("m"));
        wave.amplitude_m = w.GetDouble("amplitude_m", NumberRange::NonNegative("m"));
        // No steady wave is steeper than H/λ = 0.142 (Michell 1893; Stokes' limiting wave),
        // so A ≤ 0.071 λ; steeper input would also fold the Gerstner surface into loops.
        const double maxAmplitude = 0.071 * wave.wavelength_m;
        if (wave.amplitude_m > maxAmplitude)
            w.Require("amplitude_m", "")
                .Fail("a number (m) <= 0.071 × wavelength_m = " + FormatNumber(maxAmplitude) +
                          " (Stokes limiting steepness H/λ = 0.142)",
                      FormatNumber(wave.amplitude_m));
        wave.steepness = w.GetDouble("steepness", NumberRange::Closed(0, 1));
        wave.phase_rad = Degrees(w, "phase_deg", NumberRange::Any("deg"), 0.0);
    });
    return wave;
}

// environment.ocean.spectral: the sea keys and fft of ReadSpectralOceanSettings; the wind
// defaults to environment.wind, the seed to world.seed, the depth is environment.ocean.depth_m.
SpectralOceanSettings ReadSpectralOcean(const ConfigValue& value, const EnvironmentSettings& env,
                                        double depth_m, uint64_t seed) {
    SpectralOceanSettings defaults;
    defaults.sea.spectrum.windSpeed_mps = env.windSpeed_mps;
    defaults.sea.spectrum.windDirection_rad = env.windDirection_rad;
    defaults.sea.spectrum.depth_m = depth_m;
    defaults.fft.seed = seed;
    SpectralOceanSettings s = ReadMap(value, [&](ConfigMap& m) {
        if (const std::optional<ConfigValue> depth = m.Find("depth_m"))
            depth->Fail("no depth_m here (the water depth is environment.ocean.depth_m)");
        return ReadSpectralOceanSettings(m, defaults);
    });
    // The spectrum checks the combination of values (e.g. a height with no wind to shape it).
    try {
        const WaveSpectrum spectrum(ResolveSeaState(s.sea));
    } catch (const ConfigError&) {
        throw;
    } catch (const InputError& e) {
        value.Fail("a sea the spectrum model accepts", e.what());
    }
    return s;
}

EnvironmentSettings ReadEnvironment(ConfigMap& map, const WorldSettings& world,
                                    const std::filesystem::path& folder) {
    EnvironmentSettings env;
    ReadMap(map.Require("environment", "a mapping"), [&](ConfigMap& e) {
        const ConfigValue sunValue =
            e.Require("sun", "'ephemeris' or a mapping {azimuth_deg, elevation_deg}");
        if (sunValue.Node().IsScalar()) {
            if (sunValue.AsString() != "ephemeris")
                sunValue.Fail("'ephemeris' or a mapping {azimuth_deg, elevation_deg}");
            env.sun.fromEphemeris = true;
        } else {
            ReadMap(sunValue, [&](ConfigMap& sun) {
                env.sun.azimuth_rad =
                    sun.GetDouble("azimuth_deg", NumberRange::Any("deg")) * kRadPerDeg;
                env.sun.elevation_rad =
                    sun.GetDouble("elevation_deg", NumberRange::Closed(-90, 90, "deg")) *
                    kRadPerDeg;
                env.sun.illuminance_lux = sun.GetDouble(
                    "illuminance_lux", NumberRange::NonNegative("lux"), env.sun.illuminance_lux);
            });
        }
        if (std::optional<ConfigValue> sky = e.Find("sky")) {
            ReadMap(*sky, [&](ConfigMap& s) {
                // Preetham et al. (1999) fit their sky model for turbidity 1.7 .. 10.
                env.sky.turbidity =
                    s.GetDouble("turbidity", NumberRange::Closed(1.7, 10), env.sky.turbidity);
            });
        }
        env.visibility_m =
            e.GetDouble("visibility_m", NumberRange::Positive("m"), env.visibility_m);
        if (std::optional<ConfigValue> wind = e.Find("wind")) {
            ReadMap(*wind, [&](ConfigMap& w) {
                env.windSpeed_mps = w.GetDouble("speed_mps", NumberRange::NonNegative("m/s"));
                env.windDirection_rad =
                    w.GetDouble("direction_deg", NumberRange::Any("deg")) * kRadPerDeg;
            });
        }
        if (std::optional<ConfigValue> lightning = e.Find("lightning")) {
            env.lightning = ReadLightningSettings(*lightning);
            try {
                ValidateLightningSettings(*env.lightning);
            } catch (const InputError& error) {
                lightning->Fail(std::string("consistent lightning settings: ") + error.what());
            }
        }
        if (std::optional<ConfigValue> clouds = e.Find("clouds")) {
            env.clouds = ReadCloudLayers(*clouds);
            // The field checks what the single keys cannot (and calibrates its patterns).
            try {
                const CloudField field(env.clouds, world.seed);
            } catch (const ConfigError&) {
                throw;
            } catch (const InputError& error) {
                clouds->Fail(std::string("consistent cloud layers: ") + error.what());
            }
        }
        env.atmosphere = e.Find("atmosphere");
        env.sea = e.Find("sea");
        ReadMap(e.Require("ocean", "a mapping"), [&](ConfigMap& ocean) {
            env.ocean.depth_m =
                ocean.GetDouble("depth_m", NumberRange::Positive("m"), env.ocean.depth_m);
            // Spectral sea with optional Gerstner waves added, or Gerstner waves alone.
            if (const std::optional<ConfigValue> spectral = ocean.Find("spectral")) {
                env.ocean.spectral =
                    ReadSpectralOcean(*spectral, env, env.ocean.depth_m, world.seed);
                if (const std::optional<ConfigValue> waves = ocean.Find("waves"))
                    for (const ConfigValue& wave : waves->AsList(0, kMaxWaves, "waves"))
                        env.ocean.waves.push_back(ReadWave(wave));
            } else {
                for (const ConfigValue& wave : ocean.GetList("waves", 1, kMaxWaves, "waves"))
                    env.ocean.waves.push_back(ReadWave(wave));
            }
            env.ocean.foamThreshold = ocean.GetDouble("foam_threshold", NumberRange::Open(0.0, 1.0),
                                                      env.ocean.foamThreshold);
            if (const std::optional<ConfigValue> surf = ocean.Find("surf"))
                env.ocean.surf = ReadMap(*surf, [&](ConfigMap& m) {
                    return ParseSurfSettings(m, folder, env.ocean.depth_m);
                });
        });
    });
    return env;
}

std::string ListOrCount(const std::vector<std::string>& names) {
    constexpr size_t kMaxListed = 20;
    if (names.size() > kMaxListed) return std::to_string(names.size()) + " names";
    std::string out;
    for (size_t i = 0; i < names.size(); ++i) out += (i ? ", " : "") + names[i];
    return out;
}

EntitySettings ReadEntity(const ConfigValue& value, const std::filesystem::path& folder,
                          const std::vector<std::string>& materialNames,
                          const std::string& materialFile) {
    EntitySettings entity;
    ReadMap(value, [&](ConfigMap& e) {
        const ConfigValue name = e.Require("name", "a non-empty string");
        entity.name = name.AsString();
        if (entity.name.empty()) name.Fail("a non-empty string");

        constexpr const char* kModelExpected =
            "a readable model file (.obj, .gltf or .glb) relative to the scenario's folder";
        const ConfigValue model = e.Require("model", kModelExpected);
        const std::string modelText = model.AsString();
        std::string extension = std::filesystem::path(modelText).extension().string();
        for (char& c : extension) c = char(std::tolower(static_cast<unsigned char>(c)));
        if (std::find(kModelExtensions.begin(), kModelExtensions.end(), extension) ==
            kModelExtensions.end())
            model.Fail(kModelExpected);
        entity.model = Resolve(folder, modelText);
        if (std::optional<std::string> problem = FileReadProblem(entity.model))
            model.Fail(kModelExpected,
                       model.Describe() + " (" + entity.model.string() + ": " + *problem + ")");

        entity.position_m = e.GetVec3("position_m", NumberRange::Any("m"));
        entity.attitude = ReadAttitude(e);
        entity.scale = e.GetDouble("scale", NumberRange::Positive(), entity.scale);
        entity.speed_mps = e.GetDouble("speed_mps", NumberRange::Closed(-100, 100, "m/s"), 0.0);
        entity.rideWaves = e.GetBool("ride_waves", false);

        const std::string expectedMaterial =
            "a material of " + materialFile + " (" + ListOrCount(materialNames) + ")";
        const ConfigValue material = e.Require("material", expectedMaterial);
        entity.material = material.AsString();
        if (std::find(materialNames.begin(), materialNames.end(), entity.material) ==
            materialNames.end()) {
            const std::optional<std::string> suggestion =
                SuggestClosest(entity.material, materialNames);
            material.Fail(
                expectedMaterial,
                material.Describe() + (suggestion ? " (did you mean '" + *suggestion + "'?)" : ""));
        }
    });
    return entity;
}

ExposureSettings ReadExposure(const ConfigValue& value) {
    ExposureSettings exposure;
    ReadMap(value, [&](ConfigMap& x) {
        const size_t mode = x.GetEnum("mode", kExposureModes);
        if (kExposureModes[mode] == "auto") {
            exposure.mode = ExposureMode::Auto;
            exposure.keyValue = x.GetDouble("key", NumberRange::Open(0, 1), exposure.keyValue);
        } else if (kExposureModes[mode] == "manual") {
            exposure.mode = ExposureMode::Manual;
            exposure.ev = x.GetDouble("ev", NumberRange::Any("EV"));
        } else {
            exposure.mode = ExposureMode::Adapted;
        }
    });
    return exposure;
}

ChannelSettings ReadChannel(const ConfigValue& value) {
    ChannelSettings channel;
    ReadMap(value, [&](ConfigMap& c) {
        channel.name = ReadSimpleName(c, "name");
        channel.kind = ChannelKind(c.GetEnum("kind", kChannelKinds));

        const ConfigValue resolution = c.Require("resolution", "a sequence of 2 integers");
        const std::vector<ConfigValue> size = resolution.AsList(2, 2, "integers");
        channel.width = int(size[0].AsInt(1, kMaxImageSide));
        channel.height = int(size[1].AsInt(1, kMaxImageSide));

        // A flir channel with an imager may take its field of view from the imager's focal
        // length and pitch instead (checked where the channel is built).
        const NumberRange fov = NumberRange::Open(0, 180, "deg");
        if (channel.kind == ChannelKind::Flir) channel.imager = c.Find("imager");
        if (channel.imager) {
            const std::optional<ConfigValue> hfov = c.Find("hfov_deg");
            channel.hfovGiven = hfov.has_value();
            if (hfov) channel.hfov_rad = hfov->AsDouble(fov) * kRadPerDeg;
        } else {
            channel.hfov_rad = c.GetDouble("hfov_deg", fov) * kRadPerDeg;
        }
        if (std::optional<ConfigValue> pose = c.Find("pose")) {
            ReadMap(*pose, [&](ConfigMap& p) {
                channel.offset_m = p.GetVec3("offset_m", NumberRange::Any("m"), channel.offset_m);
                channel.attitude = ReadAttitude(p);
            });
        }

        // The supersampled image obeys the same side limit as the output image.
        const std::optional<ConfigValue> supersampling = c.Find("supersampling");
        if (supersampling) channel.supersampling = int(supersampling->AsInt(1, kMaxSupersampling));
        const int64_t longest = std::max(channel.width, channel.height);
        if (longest * channel.supersampling > kMaxImageSide) {
            const int64_t limit = std::min(kMaxImageSide / longest, kMaxSupersampling);
            const std::string sizeText =
                std::to_string(channel.width) + "x" + std::to_string(channel.height);
            if (supersampling) {
                supersampling->Fail("an integer in [1, " + std::to_string(limit) +
                                    "] for resolution " + sizeText +
                                    " (resolution x supersampling <= 16384 per axis)");
            }
            std::string found = "[";
            found += std::to_string(channel.width) + ", " + std::to_string(channel.height) + "]";
            resolution.Fail("at most " + std::to_string(kMaxImageSide / channel.supersampling) +
                                " pixels per axis with the default supersampling " +
                                std::to_string(channel.supersampling) +
                                " (resolution x supersampling <= 16384 per axis)",
                            found);
        }

        channel.near_m = c.GetDouble("near_m", NumberRange::Positive("m"), channel.near_m);
        channel.shadows = c.GetBool("shadows", channel.shadows);
        if (std::optional<ConfigValue> output = c.Find("output")) {
            ReadMap(*output, [&](ConfigMap& o) {
                channel.formats.clear();
                const bool flir = channel.kind == ChannelKind::Flir;
                const std::vector<std::string>& names = flir ? kFlirOutputFormats : kOutputFormats;
                for (const ConfigValue& format :
                     o.GetList("formats", 1, names.size(),
                               flir ? "formats (exr, png, tiff, raw_png, raw_tiff)"
                                    : "formats (exr, png, tiff)")) {
                    const std::string& name = names[format.AsEnum(names)];
                    if (std::find(channel.formats.begin(), channel.formats.end(), name) !=
                        channel.formats.end())
                        format.Fail("each format at most once", "'" + name + "' again");
                    channel.formats.push_back(name);
                }
                if (std::optional<ConfigValue> display = o.Find("display")) {
                    if (channel.kind != ChannelKind::Otw)
                        display->Fail(
                            "no display key: only otw channels display through "
                            "OpenColorIO (flir and nvg have their own display chains)",
                            "display on a " + kChannelKinds[size_t(channel.kind)] + " channel");
                    channel.display = ChannelSettings::Display(display->AsEnum(kDisplays));
                }
            });
        }
        if (std::optional<ConfigValue> exposure = c.Find("exposure"))
            channel.exposure = ReadExposure(*exposure);
        if (channel.kind == ChannelKind::Flir)
            channel.band = InfraredBand(c.GetEnum("band", kInfraredBands, 0));
        if (channel.kind == ChannelKind::Nvg) channel.intensifier = c.Find("intensifier");
        if (std::optional<ConfigValue> view = c.Find("ocio_view")) {
            channel.ocioView = view->AsString();
            if (channel.ocioView.empty()) view->Fail("a non-empty OpenColorIO view name");
        }
    });
    return channel;
}

// The material table named by materials_file, or materials.yaml beside the scenario.
std::filesystem::path FindMaterialFile(ConfigMap& root, const std::filesystem::path& folder,
                                       const ConfigLocation& rootLocation) {
    if (std::optional<ConfigValue> value = root.Find("materials_file")) {
        constexpr const char* kExpected =
            "a readable material table file relative to the scenario's folder";
        const std::filesystem::path file = Resolve(folder, value->AsString());
        if (std::optional<std::string> problem = FileReadProblem(file))
            value->Fail(kExpected,
                        value->Describe() + " (" + file.string() + ": " + *problem + ")");
        return file;
    }
    const std::filesystem::path file = Resolve(folder, "materials.yaml");
    if (std::optional<std::string> problem = FileReadProblem(file)) {
        throw ConfigError(rootLocation, "materials_file",
                          "a material table: the key materials_file, or a readable "
                          "materials.yaml next to the scenario",
                          "neither (" + file.string() + ": " + *problem + ")");
    }
    return file;
}

}  // namespace

std::vector<MaterialSettings> LoadMaterialTable(const std::filesystem::path& file,
                                                std::optional<ConfigValue>* tableNode) {
    const ConfigDocument document = LoadConfigFile(file);
    std::vector<MaterialSettings> materials;
    ReadMap(document.root, [&](ConfigMap& root) {
        ConfigMap table = root.GetMap("materials");
        if (tableNode) *tableNode = table.Value();
        for (const auto& [name, value] : table.Entries()) {
            if (!IsSimpleName(name))
                value.Fail("a material named with letters, digits, '_' and '-'",
                           "the name '" + name + "'");
            MaterialSettings material;
            material.name = name;
            ReadMap(value, [&](ConfigMap& m) {
                material.reflectanceRgb = m.GetVec3("reflectance_rgb", NumberRange::Closed(0, 1));
                // The infrared and thermal keys belong to radiometry::ParseMaterialTable,
                // which validates them (Scenario::materialTable).
                m.Entries();
            });
            materials.push_back(material);
        }
        if (materials.empty()) table.Value().Fail("at least one material", "an empty mapping");
        table.Finish();
    });
    return materials;
}

Scenario LoadScenario(const std::filesystem::path& file) {
    const ConfigDocument document = LoadConfigFile(file);
    Scenario scenario;
    scenario.file = file;
    scenario.hash = Fnv1a64Hex(document.bytes);
    std::filesystem::path folder = file.parent_path();
    if (folder.empty()) folder = ".";

    ReadMap(document.root, [&](ConfigMap& root) {
        scenario.world = ReadWorld(root);
        scenario.environment = ReadEnvironment(root, scenario.world, folder);

        const std::filesystem::path materialFile =
            FindMaterialFile(root, folder, document.root.Location());
        scenario.materials = LoadMaterialTable(materialFile, &scenario.materialTable);
        std::vector<std::string> materialNames;
        for (const MaterialSettings& m : scenario.materials) materialNames.push_back(m.name);

        if (std::optional<ConfigValue> entities = root.Find("entities")) {
            for (const ConfigValue& item : entities->AsList(0, kMaxEntities, "entities")) {
                EntitySettings entity =
                    ReadEntity(item, folder, materialNames, materialFile.filename().string());
                for (size_t i = 0; i < scenario.entities.size(); ++i) {
                    if (scenario.entities[i].name == entity.name) {
                        const ConfigValue name = item.AsMap().Require("name", "");
                        name.Fail("an entity name not used before (entities[" + std::to_string(i) +
                                  "] has it)");
                    }
                }
                scenario.entities.push_back(std::move(entity));
            }
        }

        if (std::optional<ConfigValue> plumes = root.Find("plumes")) {
            PlumeParseContext context;
            for (const EntitySettings& e : scenario.entities) context.entityNames.push_back(e.name);
            ReadMap(*plumes,
                    [&](ConfigMap& m) { scenario.plumes = ParsePlumesSettings(m, context); });
            // An attached source follows its entity's planned track (World's MovingPose:
            // position_m + speed_mps · t along the heading).
            for (PlumeSourceSettings& source : scenario.plumes.sources) {
                if (source.attachTo.empty()) continue;
                const auto entity = std::find_if(
                    scenario.entities.begin(), scenario.entities.end(),
                    [&](const EntitySettings& e) { return e.name == source.attachTo; });
                CHECK(entity != scenario.entities.end());
                const double h = entity->attitude.heading_rad;
                const glm::dvec3 velocity =
                    entity->speed_mps * glm::dvec3{std::sin(h), std::cos(h), 0.0};
                PlaceAttachedSource(source, entity->position_m,
                                    WorldFromBodyRotation(entity->attitude), velocity);
            }
        }

        ReadMap(root.Require("eyepoint", "a mapping"), [&](ConfigMap& eye) {
            scenario.eyepoint.position_m = eye.GetVec3("position_m", NumberRange::Any("m"));
            scenario.eyepoint.attitude = ReadAttitude(eye);
            scenario.eyepoint.speed_mps =
                eye.GetDouble("speed_mps", NumberRange::Closed(-300, 300, "m/s"), 0.0);
        });

        const std::vector<ConfigValue> channels =
            root.GetList("channels", 1, kMaxChannels, "channels");
        for (const ConfigValue& item : channels) {
            ChannelSettings channel = ReadChannel(item);
            for (size_t i = 0; i < scenario.channels.size(); ++i) {
                if (scenario.channels[i].name == channel.name) {
                    const ConfigValue name = item.AsMap().Require("name", "");
                    name.Fail("a channel name not used before (channels[" + std::to_string(i) +
                              "] has it)");
                }
            }
            scenario.channels.push_back(std::move(channel));
        }
    });
    return scenario;
}

}  // namespace seasense::scene
