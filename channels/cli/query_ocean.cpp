// Ocean query: the scenario's sea surface (scene/ocean/ocean_surface) at one world point and
// instant — the surface the renderers draw there — as text for people or JSON for scripts.
#include "channels/cli/query_ocean.h"

#include <cmath>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "scene/core/error.h"
#include "scene/ocean/ocean_surface.h"
#include "scene/scenario/scenario_loader.h"

namespace seasense::channels {

namespace {

constexpr double kDegPerRad = 180.0 / M_PI;
// Query points are ENU metres on the tangent plane at the scenario's origin; beyond 1000 km
// that plane is no longer the sea.
constexpr double kMaxOffset_m = 1.0e6;

double CheckedCoordinate(const char* option, double v) {
    if (!std::isfinite(v) || std::abs(v) > kMaxOffset_m) {
        std::ostringstream msg;
        msg << option << ": expected metres in [-1000000, 1000000], found " << v;
        throw InputError(msg.str());
    }
    return v;
}

// Degrees in [0, 360), or NaN.
double AzimuthDeg(double rad) {
    if (std::isnan(rad)) return rad;
    const double d = std::fmod(rad * kDegPerRad, 360.0);
    return d < 0.0 ? d + 360.0 : d;
}

nlohmann::json Number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nullptr; }

nlohmann::json Vector(const glm::dvec3& v) { return {v.x, v.y, v.z}; }

}  // namespace

void RunQueryOcean(const QueryOceanOptions& opt) {
    const double x = CheckedCoordinate("--x", opt.x_m);
    const double y = CheckedCoordinate("--y", opt.y_m);
    const scene::Scenario scenario = scene::LoadScenario(opt.config);
    scene::UtcTime when = scenario.world.start;
    if (!opt.time.empty()) {
        const auto t = scene::ParseIso8601(opt.time);
        if (!t)
            throw InputError(
                "--time: expected ISO-8601 UTC time (e.g. 2026-06-21T18:30:00Z), found '" +
                opt.time + "'");
        when = *t;
    }
    // Frame times count from world.start_utc (World::Advance: utc = start + time_s).
    const double t_s = double(when.unixNs - scenario.world.start.unixNs) / 1e9;

    const scene::OceanSurface sea(scenario.environment.ocean);
    const scene::OceanPointQuery q = sea.Query(x, y, t_s);
    const scene::SeaSummary& s = sea.Summary();
    const scene::OceanSample& p = q.surface;

    if (opt.json) {
        nlohmann::json j;
        j["time_utc"] = scene::FormatIso8601(when);
        j["time_s"] = t_s;
        j["x_m"] = x;
        j["y_m"] = y;
        j["model"] = s.spectral ? "spectral" : "gerstner";
        j["surface"] = {{"height_m", p.position.z},
                        {"normal", Vector(p.normal)},
                        {"orbital_velocity_mps", Vector(p.velocity_mps)},
                        {"jacobian", p.jacobian},
                        {"min_eigenvalue", p.minEigenvalue},
                        {"foam_coverage", q.foamCoverage},
                        {"rest_position_m", {q.rest_m.x, q.rest_m.y}}};
        j["water_depth_m"] = q.waterDepth_m;
        j["sea"] = {{"significant_height_m", s.significantHeight_m},
                    {"peak_period_s", Number(s.peakPeriod_s)},
                    {"peak_wavelength_m", Number(s.peakWavelength_m)},
                    {"dominant_direction_deg", Number(AzimuthDeg(s.dominantDirection_rad))},
                    {"phase_speed_mps", Number(s.phaseSpeed_mps)},
                    {"group_speed_mps", Number(s.groupSpeed_mps)},
                    {"wind_speed_mps", Number(s.windSpeed_mps)},
                    {"wind_direction_deg", Number(AzimuthDeg(s.windDirection_rad))}};
        if (q.hasSurf) {
            const scene::SurfPointInfo& f = q.surf;
            j["surf"] = {{"seabed_z_m", f.seabedZ_m},
                         {"surf_weight", f.surfWeight},
                         {"wave_height_m", 2.0 * f.envelope_m},
                         {"breaking_intensity", f.breaking.intensity},
                         {"broken", f.breaking.broken},
                         {"time_since_breaking_s", f.breaking.timeSinceBreaking_s},
                         {"direction_deg", AzimuthDeg(f.direction_rad)},
                         {"phase_deg", f.phase_rad * 180.0 / M_PI},
                         {"phase_speed_mps", f.phaseSpeed_mps},
                         {"group_speed_mps", f.groupSpeed_mps}};
        }
        std::cout << j.dump(2) << "\n";
        return;
    }
    std::printf("time              %s (t = %.3f s)\n", scene::FormatIso8601(when).c_str(), t_s);
    std::printf("point             x %.3f m, y %.3f m (ENU)\n", x, y);
    std::printf("model             %s\n", s.spectral ? "spectral (FFT) + Gerstner" : "Gerstner");
    std::printf("height            %.4f m\n", p.position.z);
    std::printf("normal            %.5f %.5f %.5f\n", p.normal.x, p.normal.y, p.normal.z);
    std::printf("orbital velocity  %.4f %.4f %.4f m/s\n", p.velocity_mps.x, p.velocity_mps.y,
                p.velocity_mps.z);
    std::printf("jacobian          %.4f (smaller eigenvalue %.4f)\n", p.jacobian, p.minEigenvalue);
    std::printf("foam coverage     %.3f\n", q.foamCoverage);
    std::printf("water depth       %.2f m\n", q.waterDepth_m);
    std::printf("significant Hs    %.3f m\n", s.significantHeight_m);
    std::printf("dominant wave     period %.2f s, wavelength %.1f m, toward %.1f deg\n",
                s.peakPeriod_s, s.peakWavelength_m, AzimuthDeg(s.dominantDirection_rad));
    std::printf("speeds            phase %.3f m/s, group %.3f m/s\n", s.phaseSpeed_mps,
                s.groupSpeed_mps);
    if (q.hasSurf) {
        const scene::SurfPointInfo& f = q.surf;
        std::printf("surf              seabed z %.2f m, surf weight %.2f, group height %.3f m\n",
                    f.seabedZ_m, f.surfWeight, 2.0 * f.envelope_m);
        std::printf("breaking          intensity %.3f, %s, %.1f s since the breaker line\n",
                    f.breaking.intensity, f.breaking.broken ? "broken" : "unbroken",
                    f.breaking.timeSinceBreaking_s);
        std::printf("local wave        toward %.1f deg, phase %.1f deg, c %.3f m/s, cg %.3f m/s\n",
                    AzimuthDeg(f.direction_rad), f.phase_rad * 180.0 / M_PI, f.phaseSpeed_mps,
                    f.groupSpeed_mps);
    }
    if (s.spectral)
        std::printf("wind              %.2f m/s toward %.1f deg\n", s.windSpeed_mps,
                    AzimuthDeg(s.windDirection_rad));
}

}  // namespace seasense::channels
