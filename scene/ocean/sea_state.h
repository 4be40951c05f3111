// Sea state presets (WMO Beaufort force, WMO sea state code 3700) and their resolution into the
// parameters of a directional wave spectrum; configuration reader for the sea settings.
#pragma once

#include <optional>
#include <span>
#include <string>

#include "scene/config/config.h"
#include "scene/ocean/spectrum.h"

namespace seasense::scene {

// One force of the WMO Beaufort scale: 10 m wind speed limits (m/s) and the probable and
// probable maximum heights of well-developed open-sea wind waves (m), as tabulated by WMO
// (Manual on Marine Meteorological Services, WMO-No. 558; the Met Office reproduces it).
struct BeaufortForce {
    int force;
    const char* description;
    double windMin_mps;
    double windMax_mps;  // +∞ for force 12
    double probableHeight_m;
    double probableMaxHeight_m;  // NaN where WMO gives none
};
std::span<const BeaufortForce> BeaufortScale();

// One code of WMO code table 3700 "State of the sea" (Manual on Codes, WMO-No. 306, Vol. I.1):
// significant wave height limits (m), the upper limit belonging to the code.
struct WmoSeaState {
    int code;
    const char* description;
    double heightMin_m;
    double heightMax_m;  // +∞ for code 9
};
std::span<const WmoSeaState> WmoSeaStates();

// Representative 10 m wind of a Beaufort force (m/s): the middle of its band; 0 for calm, and
// for the open band of force 12 its lower limit plus half the width of force 11's band.
double BeaufortWindSpeed_mps(int force);

// Representative significant wave height of a WMO sea state code (m): the middle of its band,
// and for the open band of code 9 its lower limit plus half the width of code 8's band.
double SeaStateSignificantHeight_m(int code);

// The 10 m wind speed whose fully developed Pierson–Moskowitz sea has significant height Hs:
// Hs = 2 √(α/β) U19.5² / g ≈ 0.21 U19.5²/g (physics.md), U10 = U19.5 / 1.026.
double FullyDevelopedWindSpeed_mps(double significantHeight_m);

// Sea conditions as a scenario states them. A Beaufort force or an explicit wind speed sets the
// wind; a sea state code or an explicit Hs sets the height. Without a wind, it follows from Hs
// by full development; without a height, from the wind (and fetch) through the spectrum.
struct SeaStateSettings {
    std::optional<int> beaufort;          // 0–12
    std::optional<int> seaState;          // 0–9
    std::optional<double> windSpeed_mps;  // at 10 m
    SpectrumSettings spectrum;            // model, spreading, direction, fetch, depth, swell ...
};

// Fills in wind speed and significant height from the presets. Throws InputError when a
// height is asked for without any wind or peak period to give it a shape.
SpectrumSettings ResolveSeaState(const SeaStateSettings& settings);

// Reads the sea keys from map (the caller checks for unknown keys with Finish):
//   beaufort, sea_state, wind_speed_mps, wind_direction_deg (toward, from north clockwise),
//   fetch_m, depth_m, significant_height_m, peak_period_s,
//   spectrum: phillips | pierson_moskowitz | jonswap | tma,
//   spreading: mitsuyasu | hasselmann | donelan_banner, gamma, sigma_a, sigma_b,
//   phillips: {alpha, exponent, alignment_exponent, against_wind_factor, small_wave_cutoff_m},
//   swell: {significant_height_m, peak_period_s, direction_deg, gamma, spreading_exponent}.
// defaults supplies every value the file leaves out (e.g. the scenario's wind).
SeaStateSettings ReadSeaStateSettings(ConfigMap& map, const SeaStateSettings& defaults = {});

// Markdown tables of both preset scales with the wind, Hs and peak period each preset gives
// (fully developed Pierson–Moskowitz sea), for the README.
std::string SeaStatePresetsMarkdown();

}  // namespace seasense::scene
