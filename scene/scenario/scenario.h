// The typed, validated scenario: what a configs/*.yaml file describes, in SI units and radians.
#pragma once

#include <cstdint>
#include <filesystem>
#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <vector>

#include "scene/config/config.h"
#include "scene/core/time.h"
#include "scene/ocean/ocean_settings.h"
#include "scene/plumes/plume_settings.h"
#include "scene/sky/clouds.h"
#include "scene/sky/lightning.h"
#include "scene/surf/surf_settings.h"

namespace seasense::scene {

// Orientation as yaw (heading, clockwise from north), pitch (nose up) and roll (right side
// down), applied in that order (intrinsic z-y'-x''), all radians.
struct Attitude {
    double heading_rad = 0.0;
    double pitch_rad = 0.0;
    double roll_rad = 0.0;
};

struct WorldSettings {
    double latitude_deg = 0.0;  // origin of the local ENU frame
    double longitude_deg = 0.0;
    UtcTime start;               // simulation time of frame 0
    double timeScale = 1.0;      // simulated seconds per real second
    double frameRate_hz = 30.0;  // simulated frames per (scaled) second
    uint64_t seed = 1;
};

// The sun: fixed by the user, or (`sun: ephemeris`) placed by the ephemeris at the frame's UTC
// time with a direct-normal illuminance from the air mass and turbidity.
struct SunSettings {
    bool fromEphemeris = false;
    double azimuth_rad = 0.0;        // from true north, clockwise (fixed sun)
    double elevation_rad = 0.5;      // above the horizon (fixed sun)
    double illuminance_lux = 1.0e5;  // on a surface normal to the sun, at the ground (fixed sun)
};

struct SkySettings {
    double turbidity = 3.0;  // Linke-style turbidity of Preetham et al. (1999), 1.7 .. 10
};

struct GerstnerWaveSettings {
    double direction_rad = 0.0;  // direction of travel, azimuth from north clockwise
    double wavelength_m = 10.0;
    double amplitude_m = 0.1;
    double steepness = 0.5;  // Q in [0, 1]: horizontal orbit / linear theory (1: trochoid)
    double phase_rad = 0.0;
};

// The sea surface: Gerstner waves alone, or the spectral (FFT) sea with the Gerstner waves (a few
// long swells, say) added to it.
struct OceanSettings {
    std::vector<GerstnerWaveSettings> waves;
    double depth_m = 1.0e4;  // water depth for dispersion ω² = g k tanh(k h)
    // Set: the spectral model (its depth is depth_m, its seed world.seed unless fft.seed).
    std::optional<SpectralOceanSettings> spectral;
    // Foam coverage reported by queries rises from 0 where the Jacobian's smaller eigenvalue is
    // this value to 1 where the surface folds (eigenvalue 0); in (0, 1).
    double foamThreshold = 0.3;
    // environment.ocean.surf: the surf zone (shoreline, bathymetry, sandbars). Absent: open water
    // of depth_m everywhere. It lives in the ocean section because it reshapes the same sea
    // surface (OceanSurface is built from these settings) and falls offshore to depth_m.
    std::optional<SurfSettings> surf;
};

struct EnvironmentSettings {
    SunSettings sun;
    SkySettings sky;
    double visibility_m = 20000.0;   // meteorological optical range (Koschmieder, 2 % contrast)
    double windSpeed_mps = 5.0;      // at 10 m
    double windDirection_rad = 0.0;  // direction the wind blows toward, from north clockwise
    OceanSettings ocean;
    // environment.atmosphere and environment.sea as written: parsed and validated by
    // radiometry::ParseAtmosphereSettings / ParseSeaSettings where the infrared channels are
    // built (scene does not depend on radiometry). Absent: the parsers' defaults.
    std::optional<ConfigValue> atmosphere;
    std::optional<ConfigValue> sea;
    // environment.lightning: thunderstorm cells and bolt/stroke parameters (ReadLightningSettings).
    std::optional<LightningSettings> lightning;
    // environment.clouds: cloud layers (ReadCloudLayers); empty: a cloudless sky.
    std::vector<CloudLayerSettings> clouds;
};

// A static mesh placed in the world. Positions are ENU metres at the model origin.
struct EntitySettings {
    std::string name;
    std::filesystem::path model;  // resolved against the scenario file's folder
    glm::dvec3 position_m{0.0};
    Attitude attitude;
    double scale = 1.0;
    std::string material;    // a name from the material table
    double speed_mps = 0.0;  // along the heading, horizontal; position_m is at frame 0
    // Heave, pitch and roll follow the sea surface under the hull (quasi-static: the height at
    // the origin, pitch and roll from the heights at bow/stern and the beam ends).
    bool rideWaves = false;
};

struct EyepointSettings {
    glm::dvec3 position_m{0.0, 0.0, 2.0};  // at frame 0
    Attitude attitude;
    double speed_mps = 0.0;  // along the heading, horizontal
};

enum class ChannelKind { Otw, Flir, Nvg };

// Spectral band of an infrared (flir) channel.
enum class InfraredBand { Lwir, Mwir };

enum class ExposureMode { Manual, Auto, Adapted };
inline const char* ToString(ExposureMode mode) {
    return mode == ExposureMode::Manual ? "manual"
           : mode == ExposureMode::Auto ? "auto"
                                        : "adapted";
}

struct ExposureSettings {
    ExposureMode mode = ExposureMode::Auto;
    // Manual: display value = scene-linear × 2^ev. Auto: ev chosen so that the frame's
    // log-average luminance maps to keyValue (Reinhard et al. 2002 key). Adapted: the key
    // follows the log-average luminance (sensors::AdaptedKey), so dim scenes display dim.
    double ev = 0.0;
    double keyValue = 0.18;
};

struct ChannelSettings {
    std::string name;
    ChannelKind kind = ChannelKind::Otw;
    int width = 640;
    int height = 480;
    double hfov_rad = 1.0471975511965976;  // 60°
    glm::dvec3 offset_m{0.0};              // position relative to the eyepoint, eyepoint frame
    Attitude attitude;                     // relative to the eyepoint
    int supersampling = 2;                 // N: N×N samples per pixel
    double near_m = 0.25;
    bool shadows = true;
    std::vector<std::string> formats{"exr", "png"};
    // Otw channels: how the display images (png, tiff) are made from the linear image. Exact:
    // the OCIO display transform of every pixel (~1800 instructions a pixel with the ACES
    // output transform). Lut: a 65³ table of that transform, interpolated in log2 of each
    // component (sensors::DisplayLut, the run's mosaic preview), ~1/34 of the instructions, within
    // one code value of the exact transform on the five-channel demo's frames (README,
    // Configuration).
    enum class Display { Exact, Lut } display = Display::Exact;
    ExposureSettings exposure;
    std::string ocioView = "ACES 1.0 - SDR Video";  // display view of configs/ocio/config.ocio
    InfraredBand band = InfraredBand::Lwir;         // flir channels only
    // Flir channels: the `imager:` mapping as written, parsed and checked against the channel
    // where the channel is built (channels/flir; scene does not depend on sensors). Absent: the
    // default imager. A flir channel with an imager may leave out hfov_deg (hfovGiven false)
    // and take its field of view from the imager's focal length and pixel pitch.
    std::optional<ConfigValue> imager;
    bool hfovGiven = true;
    // Nvg channels: the `intensifier:` mapping as written, parsed where the channel is built
    // (channels/nvg, sensors/intensifier). Absent: the default Gen III goggle.
    std::optional<ConfigValue> intensifier;
};

struct MaterialSettings {
    std::string name;
    glm::dvec3 reflectanceRgb{0.5};  // linear Rec.709 diffuse reflectance (hemispherical)
};

struct Scenario {
    std::filesystem::path file;  // the file it was read from
    std::string hash;            // hex digest of the file's bytes, for capture.json
    WorldSettings world;
    EnvironmentSettings environment;
    std::vector<EntitySettings> entities;
    EyepointSettings eyepoint;
    std::vector<ChannelSettings> channels;
    // The `plumes:` section (no sources when absent). Sources attached to an entity already
    // carry its planned track (PlaceAttachedSource).
    PlumesSettings plumes;
    std::vector<MaterialSettings> materials;  // from the material table file
    // The `materials:` mapping of the material table file, for radiometry::ParseMaterialTable
    // (emissivities and thermal models); set by LoadScenario.
    std::optional<ConfigValue> materialTable;

    const ChannelSettings* FindChannel(const std::string& name) const;
    const MaterialSettings* FindMaterial(const std::string& name) const;
};

}  // namespace seasense::scene
