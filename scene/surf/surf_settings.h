// Settings of the surf zone (environment.ocean.surf): shoreline frame, littoral slopes, tide,
// sandbar regions and an optional depth grid, in SI units and radians, with their reader.
#pragma once

#include <cstdint>
#include <filesystem>
#include <glm/glm.hpp>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "scene/config/config.h"

namespace seasense::scene {

class DepthGrid;

// The straight shoreline the surf zone is built along (seed 003, "Database considerations"):
// origin_m lies on the still-water line at tide 0 (mean sea level) and the shoreline runs
// toward azimuth_rad (from north, clockwise). Land is on the LEFT when facing along the
// shoreline, the sea on the right, so the seaward direction is azimuth_rad + 90°.
struct ShorelineSettings {
    glm::dvec2 origin_m{0.0};  // ENU (x east, y north), m
    double azimuth_rad = 0.0;
};

// One littoral zone of the automatic bathymetry: its seabed slope (rise over run, ≥ 0) across
// the shore and, for the supralittoral and sublittoral zones, its cross-shore extent (m). The
// intertidal zone's extent follows from the tidal range and its slope.
struct LittoralZoneSettings {
    double slope = 0.0;
    double width_m = 0.0;
};

// A sandbar (seed 003, "Sandbars", Figure 8), centred alongshore in its region: a flat crest
// width_m across the shore and length_m along it, its crest crestDepth_m below the tide level,
// its centre line distance_m seaward of the still-water line (s = distance_m); outside the crest
// it blends into the beach slope over sideSlope_m (a smoothstep in the distance from the crest
// rectangle), so waves feel it gradually.
struct SandbarSettings {
    double width_m = 20.0;
    double length_m = 200.0;
    double crestDepth_m = 1.0;
    double distance_m = 80.0;
    double sideSlope_m = 20.0;
};

// A stretch of shore width_m long (alongshore), with or without a sandbar. The list of regions
// repeats along the whole shoreline; region 0 starts at the shoreline origin.
struct SurfRegionSettings {
    double width_m = 300.0;
    std::optional<SandbarSettings> sandbar;
};

// What the values of a depth grid are: water depth below mean sea level (positive down) or
// seabed elevation above mean sea level (ENU z).
enum class DepthGridValues { Depth, Elevation };

struct DepthGridSettings {
    std::filesystem::path file;  // single-channel float image (OpenImageIO), resolved
    // ENU (x, y) of the centre of pixel (0, 0), the top-left pixel: columns run east, rows run
    // south (the image seen with north up), cells cell_m square.
    glm::dvec2 origin_m{0.0};
    double cell_m = 1.0;
    DepthGridValues values = DepthGridValues::Depth;
    std::shared_ptr<const DepthGrid> grid;  // read by the scenario reader
};

// environment.ocean.surf.foam: the white water the breakers leave (scene/surf/foam.h).
struct FoamSettings {
    // e-folding time (s) of the foam left behind the breaker line: bubble plumes and surface foam
    // of breaking waves decay in seconds to tens of seconds (Callaghan, Deane & Stokes 2013,
    // J. Phys. Oceanogr. 43: foam e-folding times ~ 1-10 s for individual whitecaps; surf-zone
    // foam lingers longer).
    double persistence_s = 8.0;
    // Size (m) of the streaks the foam breaks into, across the direction of travel, and their
    // elongation along it (length / width).
    double streakWidth_m = 3.0;
    double streakElongation = 4.0;
    uint64_t seed = 1;  // seeds the streak pattern
};

// environment.ocean.surf.spray: droplets thrown up where waves break (scene/surf/spray.h). Each
// particle stands for a clump of droplets of about 1 mm (whose linear-drag time dragTime_s gives
// their terminal fall speed g τ).
struct SpraySettings {
    bool enabled = true;
    // Breakers are looked for within this horizontal distance of the eyepoint (seed 003: "the
    // radius of the area of interest (from the observer) in which breaking waves are
    // simulated"), on a lattice of cells cell_m apart.
    double radius_m = 120.0;
    double cell_m = 3.0;
    // Emission slots: each cell gets one chance per interval_s (at a seeded instant within the
    // slot) to throw a burst, with this probability at full breaking intensity (the distribution
    // of breakers, seed 003), scaled by the intensity.
    double interval_s = 0.25;
    double probability = 0.6;
    int dropletsPerBurst = 10;
    double lifetime_s = 1.6;
    // Upward launch speed: uniform in [½, 1½] × this; horizontally the wave's group velocity.
    // Breaking-crest jets and splash-up rise at a few m/s (the crest moves at √(g h) ≈ 3–5 m/s
    // in 1–2 m of water).
    double launchSpeed_mps = 3.0;
    // Linear drag relaxation time τ of dv/dt = g + (w − v)/τ: terminal speed g τ. 1 mm drops fall
    // at 4.0 m/s (Gunn & Kinzer, J. Meteor. 6, 243 (1949)): τ ≈ 0.41 s.
    double dragTime_s = 0.41;
    double clumpRadius_m = 0.12;  // drawn radius of one particle (a clump of droplets)
    double opacity = 0.6;         // of a fresh clump's disc, fading linearly with age
    int maxParticles = 20000;     // the pool: nearest to the eyepoint kept
    uint64_t seed = 1;
};

// environment.ocean.surf.swash: the waterline running up and down the beach (SurfWaves::Swash).
struct SwashSettings {
    bool enabled = true;
    // Alongshore spacing of the beach cusps whose bays the swash runs farther into; 0: the
    // subharmonic edge-wave spacing λ = g T² tan β / π of the peak period T and the foreshore
    // slope β (Guza & Inman, J. Geophys. Res. 80, 2997 (1975)).
    double cuspSpacing_m = 0.0;
    // Relative alongshore modulation of the swash excursion by the cusps, in [0, 1].
    double cuspAmplitude = 0.5;
};

struct SurfSettings {
    ShorelineSettings shoreline;
    double tide_m = 0.0;  // water level above mean sea level
    // The tidal range: elevations (above mean sea level) of low and high water, which bound the
    // intertidal zone.
    double lowTide_m = -1.0;
    double highTide_m = 1.0;
    // Defaults: a sandy intermediate beach (foreshore tan β ≈ 0.05–0.1, nearshore ≈ 0.02;
    // Komar, Beach Processes and Sedimentation, 2nd ed. 1998, ch. 7) with a 40 m dry beach.
    LittoralZoneSettings supralittoral{0.08, 40.0};
    LittoralZoneSettings intertidal{0.05, 0.0};
    LittoralZoneSettings sublittoral{0.02, 200.0};
    // Seaward of the sublittoral zone the seabed keeps falling at this slope until it reaches
    // environment.ocean.depth_m, and stays there.
    double offshoreSlope = 0.05;
    std::vector<SurfRegionSettings> regions;  // empty: a plane beach without bars
    std::optional<DepthGridSettings> depthGrid;
    FoamSettings foam;
    SpraySettings spray;
    SwashSettings swash;
};

// Reads the environment.ocean.surf mapping (every key documented in docs/configuration.md);
// relative files are resolved against folder. oceanDepth_m is environment.ocean.depth_m.
// Throws ConfigError naming the key.
SurfSettings ParseSurfSettings(ConfigMap& map, const std::filesystem::path& folder,
                               double oceanDepth_m);

}  // namespace seasense::scene
