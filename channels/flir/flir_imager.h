// The thermal imager of a flir channel: its settings from the channel's `imager:` mapping, made
// consistent with the channel's resolution, field of view and the scenario's seed.
#pragma once

#include <cstdint>

#include "scene/scenario/scenario.h"
#include "sensors/thermal/thermal_settings.h"

namespace seasense::channels {

// Largest relative difference between the channel's hfov_deg and the imager's
// 2·atan(width·pitch / (2·focal length)) when both are given.
inline constexpr double kFovTolerance = 1e-3;

struct FlirImagerSetup {
    scene::ChannelSettings channel;         // hfov_rad resolved from the imager if not given
    sensors::ThermalImagerSettings imager;  // detector format = the channel's resolution
};

// Reads channel.imager (the default imager, sensors::ThermalImagerSettings, when absent) for
// the channel's resolution. Field of view and focal length f, with W the width in pixels and p
// the pitch: hfov = 2·atan(W·p / (2 f)).
//   - hfov_deg given, optics.focal_length_mm not: f = W·p / (2·tan(hfov/2));
//   - focal_length_mm given, hfov_deg not: hfov from f;
//   - both: they must agree within kFovTolerance (relative, on the hfov).
// The noise seed is scene::HashBits(scenarioSeed, FNV-1a of the channel name, stream), so every
// channel of a scenario has its own fixed pattern and noise, the same in every process.
// Throws scene::ConfigError naming the imager key (file:line:column, key path).
FlirImagerSetup ResolveFlirImager(const scene::ChannelSettings& channel, uint64_t scenarioSeed);

}  // namespace seasense::channels
