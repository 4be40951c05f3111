// The validating reader of environment.ocean.surf.
#include "scene/surf/surf_settings.h"

#include <limits>
#include <numbers>
#include <string>

#include "scene/core/error.h"
#include "scene/surf/depth_grid.h"

namespace seasense::scene {
namespace {

constexpr double kRadPerDeg = std::numbers::pi / 180.0;
constexpr size_t kMaxRegions = 256;
// Slopes up to rise/run 1 (45°); seed 003's steepest training beach is 0.5.
const NumberRange kSlope = NumberRange::Closed(0.0, 1.0);
const std::vector<std::string> kGridValues = {"depth", "elevation"};

glm::dvec2 ReadVec2(ConfigMap& map, std::string_view key) {
    const std::vector<ConfigValue> items =
        map.Require(key, "a sequence of 2 numbers (m)").AsList(2, 2, "numbers (m)");
    const NumberRange any = NumberRange::Any("m");
    return {items[0].AsDouble(any), items[1].AsDouble(any)};
}

LittoralZoneSettings ReadZone(const ConfigValue& value, LittoralZoneSettings zone) {
    ReadMap(value, [&](ConfigMap& m) {
        zone.slope = m.GetDouble("slope", kSlope, zone.slope);
        zone.width_m = m.GetDouble("width_m", NumberRange::NonNegative("m"), zone.width_m);
    });
    return zone;
}

SandbarSettings ReadSandbar(const ConfigValue& value, double regionWidth_m) {
    SandbarSettings bar;
    ReadMap(value, [&](ConfigMap& m) {
        bar.width_m = m.GetDouble("width_m", NumberRange::Positive("m"), bar.width_m);
        bar.length_m = m.GetDouble("length_m", NumberRange::Positive("m"), bar.length_m);
        // Negative: the crest stands above the water at this tide.
        bar.crestDepth_m =
            m.GetDouble("crest_depth_m", NumberRange::Closed(-10.0, 100.0, "m"), bar.crestDepth_m);
        bar.distance_m = m.GetDouble("distance_m", NumberRange::Any("m"), bar.distance_m);
        bar.sideSlope_m = m.GetDouble("side_slope_m", NumberRange::Positive("m"), bar.sideSlope_m);
        // The bar and its flanks stay inside the region, so that regions never cut a bar.
        if (bar.length_m + 2.0 * bar.sideSlope_m > regionWidth_m) {
            std::optional<ConfigValue> where = m.Find("length_m");
            if (!where) where = m.Find("side_slope_m");
            const ConfigValue& v = where ? *where : m.Value();
            v.Fail("length_m + 2 side_slope_m <= the region's width_m = " +
                       FormatNumber(regionWidth_m) + " (a bar stays inside its region)",
                   FormatNumber(bar.length_m) + " + 2 × " + FormatNumber(bar.sideSlope_m));
        }
    });
    return bar;
}

SurfRegionSettings ReadRegion(const ConfigValue& value) {
    SurfRegionSettings region;
    ReadMap(value, [&](ConfigMap& m) {
        region.width_m = m.GetDouble("width_m", NumberRange::Positive("m"));
        if (const std::optional<ConfigValue> bar = m.Find("sandbar"))
            region.sandbar = ReadSandbar(*bar, region.width_m);
    });
    return region;
}

DepthGridSettings ReadDepthGrid(const ConfigValue& value, const std::filesystem::path& folder) {
    DepthGridSettings g;
    ReadMap(value, [&](ConfigMap& m) {
        constexpr const char* kExpected =
            "a single-channel float image (OpenImageIO: TIFF, EXR, ...) relative to the "
            "scenario's folder";
        const ConfigValue file = m.Require("file", kExpected);
        g.file = (folder / file.AsString()).lexically_normal();
        try {
            g.grid = std::make_shared<const DepthGrid>(DepthGrid::Load(g.file));
        } catch (const InputError& e) {
            file.Fail(kExpected, file.Describe() + " (" + e.what() + ")");
        }
        g.origin_m = ReadVec2(m, "origin_m");
        g.cell_m = m.GetDouble("cell_m", NumberRange::Positive("m"));
        g.values = DepthGridValues(m.GetEnum("values", kGridValues));
    });
    return g;
}

void ReadSpray(const ConfigValue& value, SpraySettings& p) {
    ReadMap(value, [&](ConfigMap& m) {
        p.enabled = m.GetBool("enabled", p.enabled);
        p.radius_m = m.GetDouble("radius_m", NumberRange::Closed(1.0, 5000.0, "m"), p.radius_m);
        p.cell_m = m.GetDouble("cell_m", NumberRange::Closed(0.25, 100.0, "m"), p.cell_m);
        p.interval_s =
            m.GetDouble("interval_s", NumberRange::Closed(0.01, 60.0, "s"), p.interval_s);
        p.probability = m.GetDouble("probability", NumberRange::Closed(0.0, 1.0), p.probability);
        p.dropletsPerBurst = int(m.GetInt("droplets_per_burst", 1, 1000, p.dropletsPerBurst));
        p.lifetime_s =
            m.GetDouble("lifetime_s", NumberRange::Closed(0.05, 60.0, "s"), p.lifetime_s);
        p.launchSpeed_mps = m.GetDouble("launch_speed_mps", NumberRange::Closed(0.0, 50.0, "m/s"),
                                        p.launchSpeed_mps);
        p.dragTime_s =
            m.GetDouble("drag_time_s", NumberRange::Closed(0.01, 100.0, "s"), p.dragTime_s);
        p.clumpRadius_m =
            m.GetDouble("clump_radius_m", NumberRange::Closed(0.001, 10.0, "m"), p.clumpRadius_m);
        p.opacity = m.GetDouble("opacity", NumberRange::Closed(0.0, 1.0), p.opacity);
        p.maxParticles = int(m.GetInt("max_particles", 0, 10'000'000, p.maxParticles));
        p.seed =
            uint64_t(m.GetInt("seed", 0, std::numeric_limits<int64_t>::max(), int64_t(p.seed)));
    });
}

}  // namespace

SurfSettings ParseSurfSettings(ConfigMap& map, const std::filesystem::path& folder,
                               double oceanDepth_m) {
    SurfSettings s;
    ReadMap(map.Require("shoreline", "a mapping {origin_m, azimuth_deg}"), [&](ConfigMap& m) {
        s.shoreline.origin_m = ReadVec2(m, "origin_m");
        s.shoreline.azimuth_rad = m.GetDouble("azimuth_deg", NumberRange::Any("deg")) * kRadPerDeg;
    });
    // Largest tidal ranges on Earth are about 16 m (Bay of Fundy).
    if (const std::optional<ConfigValue> tide = map.Find("tide_m")) {
        s.tide_m = tide->AsDouble(NumberRange::Closed(-20.0, 20.0, "m"));
        if (s.tide_m <= -oceanDepth_m)
            tide->Fail("a tide above the ocean floor (> -environment.ocean.depth_m = " +
                       FormatNumber(-oceanDepth_m) + ")");
    }

    if (const std::optional<ConfigValue> foam = map.Find("foam")) {
        ReadMap(*foam, [&](ConfigMap& m) {
            FoamSettings& f = s.foam;
            f.persistence_s =
                m.GetDouble("persistence_s", NumberRange::Positive("s"), f.persistence_s);
            f.streakWidth_m =
                m.GetDouble("streak_width_m", NumberRange::Positive("m"), f.streakWidth_m);
            f.streakElongation = m.GetDouble("streak_elongation", NumberRange::Closed(1.0, 100.0),
                                             f.streakElongation);
            f.seed =
                uint64_t(m.GetInt("seed", 0, std::numeric_limits<int64_t>::max(), int64_t(f.seed)));
        });
    }

    if (const std::optional<ConfigValue> spray = map.Find("spray")) ReadSpray(*spray, s.spray);
    if (const std::optional<ConfigValue> swash = map.Find("swash")) {
        ReadMap(*swash, [&](ConfigMap& m) {
            s.swash.enabled = m.GetBool("enabled", s.swash.enabled);
            s.swash.cuspSpacing_m = m.GetDouble(
                "cusp_spacing_m", NumberRange::Closed(0.0, 1000.0, "m"), s.swash.cuspSpacing_m);
            s.swash.cuspAmplitude =
                m.GetDouble("cusp_amplitude", NumberRange::Closed(0.0, 1.0), s.swash.cuspAmplitude);
        });
    }

    if (const std::optional<ConfigValue> grid = map.Find("depth_grid")) {
        s.depthGrid = ReadDepthGrid(*grid, folder);
        // The grid replaces the automatic bathymetry: its keys would do nothing.
        for (const char* key :
             {"supralittoral", "intertidal", "sublittoral", "offshore_slope", "regions"}) {
            if (const std::optional<ConfigValue> v = map.Find(key))
                v->Fail(std::string("no ") + key +
                            " with depth_grid (the grid replaces the slopes and sandbars)",
                        v->Describe());
        }
        return s;
    }

    if (const std::optional<ConfigValue> v = map.Find("supralittoral"))
        s.supralittoral = ReadZone(*v, s.supralittoral);
    if (const std::optional<ConfigValue> v = map.Find("intertidal")) {
        ReadMap(*v, [&](ConfigMap& m) {
            s.intertidal.slope =
                m.GetDouble("slope", NumberRange::OpenClosed(0.0, 1.0), s.intertidal.slope);
            s.lowTide_m =
                m.GetDouble("low_water_m", NumberRange::Closed(-20.0, 0.0, "m"), s.lowTide_m);
            s.highTide_m =
                m.GetDouble("high_water_m", NumberRange::Closed(0.0, 20.0, "m"), s.highTide_m);
        });
    }
    if (const std::optional<ConfigValue> v = map.Find("sublittoral"))
        s.sublittoral = ReadZone(*v, s.sublittoral);
    s.offshoreSlope = map.GetDouble("offshore_slope", kSlope, s.offshoreSlope);
    if (const std::optional<ConfigValue> regions = map.Find("regions"))
        for (const ConfigValue& r : regions->AsList(1, kMaxRegions, "regions"))
            s.regions.push_back(ReadRegion(r));
    return s;
}

}  // namespace seasense::scene
