// Sky query: ephemeris (scene/sky/ephemeris) and illuminance (scene/sky/illuminance) at one
// place and instant, as text for people or JSON for scripts.
#include "channels/cli/query_sky.h"

#include <cmath>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "scene/core/error.h"
#include "scene/sky/ephemeris.h"
#include "scene/sky/illuminance.h"

namespace seasense::channels {

namespace {

constexpr double kDegPerRad = 180.0 / M_PI;
// Rise and set are searched this many days ahead (the moon can skip a day).
constexpr int kSearchDays = 3;

struct NextEvents {
    std::optional<scene::UtcTime> rise, set;
};

template <class EventsInDay>
NextEvents FindNext(scene::UtcTime from, EventsInDay&& eventsInDay) {
    NextEvents next;
    for (int day = 0; day < kSearchDays && !(next.rise && next.set); ++day) {
        const auto events = eventsInDay(from.PlusSeconds(86400.0 * day));
        if (!next.rise && events.rise) next.rise = events.rise;
        if (!next.set && events.set) next.set = events.set;
    }
    return next;
}

nlohmann::json TimeOrNull(const std::optional<scene::UtcTime>& t) {
    return t ? nlohmann::json(scene::FormatIso8601(*t)) : nlohmann::json(nullptr);
}

std::string TimeOrNone(const std::optional<scene::UtcTime>& t) {
    return t ? scene::FormatIso8601(*t) : std::string("none within 3 days");
}

}  // namespace

void RunQuerySky(const QuerySkyOptions& opt) {
    if (!std::isfinite(opt.latitude_deg) || std::abs(opt.latitude_deg) > 90.0)
        throw InputError("--lat: expected degrees in [-90, 90], found " +
                         std::to_string(opt.latitude_deg));
    if (!std::isfinite(opt.longitude_deg) || std::abs(opt.longitude_deg) > 180.0)
        throw InputError("--lon: expected degrees in [-180, 180], found " +
                         std::to_string(opt.longitude_deg));
    if (!std::isfinite(opt.height_m) || opt.height_m < -500.0 || opt.height_m > 1e5)
        throw InputError("--height-m: expected metres in [-500, 100000]");
    const auto t = scene::ParseIso8601(opt.time);
    if (!t)
        throw InputError("--time: expected ISO-8601 UTC time (e.g. 2026-06-21T18:30:00Z), found '" +
                         opt.time + "'");
    scene::Observer observer;
    observer.latitude_deg = opt.latitude_deg;
    observer.longitude_deg = opt.longitude_deg;
    observer.height_m = opt.height_m;

    const scene::CelestialPosition sun = scene::SunPosition(*t, observer);
    const scene::CelestialPosition moon = scene::MoonPosition(*t, observer);
    const scene::LunarPhase phase = scene::MoonPhase(*t, observer);
    const scene::Illuminance lux = scene::NaturalIlluminance(*t, observer, opt.skyDivisor);
    const NextEvents sunNext =
        FindNext(*t, [&](scene::UtcTime d) { return scene::SunEventsInDay(d, observer); });
    const NextEvents moonNext =
        FindNext(*t, [&](scene::UtcTime d) { return scene::MoonEventsInDay(d, observer); });

    if (opt.json) {
        nlohmann::json j;
        j["time_utc"] = scene::FormatIso8601(*t);
        j["latitude_deg"] = opt.latitude_deg;
        j["longitude_deg"] = opt.longitude_deg;
        j["sun"] = {{"altitude_deg", sun.altitude_rad * kDegPerRad},
                    {"azimuth_deg", sun.azimuth_rad * kDegPerRad},
                    {"distance_m", sun.distance_m}};
        j["moon"] = {{"altitude_deg", moon.altitude_rad * kDegPerRad},
                     {"azimuth_deg", moon.azimuth_rad * kDegPerRad},
                     {"distance_m", moon.distance_m},
                     {"illuminated_fraction", phase.illuminatedFraction},
                     {"phase_angle_deg", phase.phaseAngle_rad * kDegPerRad}};
        j["illuminance_lux"] = {{"sun", lux.sun_lux},
                                {"moon", lux.moon_lux},
                                {"sky", lux.sky_lux},
                                {"total", lux.total_lux}};
        j["twilight"] = std::string(scene::ToString(lux.twilight));
        j["events"] = {
            {"sun",
             {{"next_rise", TimeOrNull(sunNext.rise)}, {"next_set", TimeOrNull(sunNext.set)}}},
            {"moon",
             {{"next_rise", TimeOrNull(moonNext.rise)}, {"next_set", TimeOrNull(moonNext.set)}}}};
        std::cout << j.dump(2) << "\n";
        return;
    }
    std::printf("time            %s\n", scene::FormatIso8601(*t).c_str());
    std::printf("place           lat %.4f deg, lon %.4f deg, height %.0f m\n", opt.latitude_deg,
                opt.longitude_deg, opt.height_m);
    std::printf("sun             altitude %8.3f deg  azimuth %8.3f deg (apparent)\n",
                sun.altitude_rad * kDegPerRad, sun.azimuth_rad * kDegPerRad);
    std::printf("moon            altitude %8.3f deg  azimuth %8.3f deg (apparent)\n",
                moon.altitude_rad * kDegPerRad, moon.azimuth_rad * kDegPerRad);
    std::printf("moon phase      illuminated fraction %.4f, phase angle %.2f deg\n",
                phase.illuminatedFraction, phase.phaseAngle_rad * kDegPerRad);
    std::printf("illuminance     sun %.4g lx, moon %.4g lx, sky %.4g lx, total %.4g lx\n",
                lux.sun_lux, lux.moon_lux, lux.sky_lux, lux.total_lux);
    std::printf("twilight        %s\n", std::string(scene::ToString(lux.twilight)).c_str());
    std::printf("sun  next rise  %s\n     next set   %s\n", TimeOrNone(sunNext.rise).c_str(),
                TimeOrNone(sunNext.set).c_str());
    std::printf("moon next rise  %s\n     next set   %s\n", TimeOrNone(moonNext.rise).c_str(),
                TimeOrNone(moonNext.set).c_str());
}

}  // namespace seasense::channels
