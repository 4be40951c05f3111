// WMO Beaufort and sea state tables as data, their resolution into spectrum parameters, and the
// reader of the sea settings.
#include "scene/ocean/sea_state.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <sstream>

#include "scene/core/check.h"
#include "scene/core/error.h"
#include "scene/ocean/gerstner.h"

namespace seasense::scene {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kRadPerDeg = std::numbers::pi / 180.0;

// WMO Beaufort scale of wind force: 10 m wind limits in m/s and probable / probable maximum
// wave heights of well-developed open-sea wind waves (WMO-No. 558, Manual on Marine
// Meteorological Services; reproduced by the Met Office, "National Meteorological Library
// Fact sheet 6: The Beaufort Scale"), limits to 0.1 m/s as published.
constexpr std::array<BeaufortForce, 13> kBeaufort = {{
    {0, "Calm", 0.0, 0.2, 0.0, 0.0},
    {1, "Light air", 0.3, 1.5, 0.1, 0.1},
    {2, "Light breeze", 1.6, 3.3, 0.2, 0.3},
    {3, "Gentle breeze", 3.4, 5.4, 0.6, 1.0},
    {4, "Moderate breeze", 5.5, 7.9, 1.0, 1.5},
    {5, "Fresh breeze", 8.0, 10.7, 2.0, 2.5},
    {6, "Strong breeze", 10.8, 13.8, 3.0, 4.0},
    {7, "Near gale", 13.9, 17.1, 4.0, 5.5},
    {8, "Gale", 17.2, 20.7, 5.5, 7.5},
    {9, "Strong gale", 20.8, 24.4, 7.0, 10.0},
    {10, "Storm", 24.5, 28.4, 9.0, 12.5},
    {11, "Violent storm", 28.5, 32.6, 11.5, 16.0},
    {12, "Hurricane", 32.7, kInf, 14.0, kNaN},
}};

// WMO Manual on Codes (WMO-No. 306), Vol. I.1, code table 3700 "State of the sea", also the
// Douglas sea scale; heights are significant wave heights (physics.md).
constexpr std::array<WmoSeaState, 10> kSeaStates = {{
    {0, "Calm (glassy)", 0.0, 0.0},
    {1, "Calm (rippled)", 0.0, 0.1},
    {2, "Smooth (wavelets)", 0.1, 0.5},
    {3, "Slight", 0.5, 1.25},
    {4, "Moderate", 1.25, 2.5},
    {5, "Rough", 2.5, 4.0},
    {6, "Very rough", 4.0, 6.0},
    {7, "High", 6.0, 9.0},
    {8, "Very high", 9.0, 14.0},
    {9, "Phenomenal", 14.0, kInf},
}};

const std::vector<std::string> kSpectrumNames = {"phillips", "pierson_moskowitz", "jonswap", "tma"};
const std::vector<std::string> kSpreadingNames = {"mitsuyasu", "hasselmann", "donelan_banner"};

std::string Fixed(double x, int digits) {
    if (std::isnan(x)) return "–";
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.*f", digits, x);
    return buf;
}

std::string Band(double lo, double hi, int digits) {
    if (std::isinf(hi)) return "≥ " + Fixed(lo, digits);
    if (lo == hi) return Fixed(lo, digits);
    return Fixed(lo, digits) + "–" + Fixed(hi, digits);
}

}  // namespace

std::span<const BeaufortForce> BeaufortScale() { return kBeaufort; }
std::span<const WmoSeaState> WmoSeaStates() { return kSeaStates; }

double BeaufortWindSpeed_mps(int force) {
    CHECK(force >= 0 && force <= 12);
    if (force == 0) return 0.0;
    const BeaufortForce& b = kBeaufort[force];
    if (std::isinf(b.windMax_mps))
        return b.windMin_mps + 0.5 * (kBeaufort[11].windMax_mps - kBeaufort[11].windMin_mps);
    return 0.5 * (b.windMin_mps + b.windMax_mps);
}

double SeaStateSignificantHeight_m(int code) {
    CHECK(code >= 0 && code <= 9);
    const WmoSeaState& s = kSeaStates[code];
    if (std::isinf(s.heightMax_m))
        return s.heightMin_m + 0.5 * (kSeaStates[8].heightMax_m - kSeaStates[8].heightMin_m);
    return 0.5 * (s.heightMin_m + s.heightMax_m);
}

double FullyDevelopedWindSpeed_mps(double hs) {
    CHECK(hs >= 0.0);
    // Pierson–Moskowitz (1964): m0 = α U19.5⁴ / (4 β g²), α = 8.1e-3, β = 0.74.
    const double ratio = 2.0 * std::sqrt(8.1e-3 / 0.74);
    return std::sqrt(hs * kGravity_mps2 / ratio) / WindSpeed19_5(1.0);
}

SpectrumSettings ResolveSeaState(const SeaStateSettings& s) {
    SpectrumSettings out = s.spectrum;
    if (s.seaState) out.significantHeight_m = SeaStateSignificantHeight_m(*s.seaState);
    if (s.beaufort)
        out.windSpeed_mps = BeaufortWindSpeed_mps(*s.beaufort);
    else if (s.windSpeed_mps)
        out.windSpeed_mps = *s.windSpeed_mps;
    else if (out.significantHeight_m)
        out.windSpeed_mps = FullyDevelopedWindSpeed_mps(*out.significantHeight_m);
    if (out.significantHeight_m && *out.significantHeight_m > 0.0 && out.windSpeed_mps <= 0.0)
        throw InputError("sea state: a significant wave height of " +
                         FormatNumber(*out.significantHeight_m) +
                         " m needs a wind to shape its spectrum; give a wind speed above 0 or "
                         "leave the wind out so that it follows from full development");
    return out;
}

SeaStateSettings ReadSeaStateSettings(ConfigMap& map, const SeaStateSettings& defaults) {
    SeaStateSettings s = defaults;
    SpectrumSettings& sp = s.spectrum;
    const std::optional<ConfigValue> beaufort = map.Find("beaufort");
    const std::optional<ConfigValue> seaState = map.Find("sea_state");
    const std::optional<ConfigValue> wind = map.Find("wind_speed_mps");
    const std::optional<ConfigValue> height = map.Find("significant_height_m");
    if (beaufort && wind) wind->Fail("no wind_speed_mps next to beaufort (give one of the two)");
    if (seaState && height)
        height->Fail("no significant_height_m next to sea_state (give one of the two)");
    if (beaufort) {
        s.beaufort = int(beaufort->AsInt(0, 12));
        s.windSpeed_mps.reset();
    }
    if (wind) {
        s.windSpeed_mps = wind->AsDouble(NumberRange::Closed(0.0, 100.0, "m/s"));
        s.beaufort.reset();
    }
    if (seaState) {
        s.seaState = int(seaState->AsInt(0, 9));
        sp.significantHeight_m.reset();
    }
    if (height) {
        sp.significantHeight_m = height->AsDouble(NumberRange::Closed(0.0, 30.0, "m"));
        s.seaState.reset();
    }
    sp.windDirection_rad = map.GetDouble("wind_direction_deg", NumberRange::Any("deg"),
                                         sp.windDirection_rad / kRadPerDeg) *
                           kRadPerDeg;
    sp.fetch_m = map.GetDouble("fetch_m", NumberRange::OpenClosed(0.0, kInf, "m"), sp.fetch_m);
    sp.depth_m = map.GetDouble("depth_m", NumberRange::OpenClosed(0.0, 1.0e5, "m"), sp.depth_m);
    if (const std::optional<ConfigValue> period = map.Find("peak_period_s"))
        sp.peakPeriod_s = period->AsDouble(NumberRange::OpenClosed(0.0, 60.0, "s"));
    sp.model = SpectrumModel(map.GetEnum("spectrum", kSpectrumNames, size_t(sp.model)));
    sp.spreading = SpreadingModel(map.GetEnum("spreading", kSpreadingNames, size_t(sp.spreading)));
    sp.gamma = map.GetDouble("gamma", NumberRange::Closed(1.0, 20.0), sp.gamma);
    sp.sigmaA = map.GetDouble("sigma_a", NumberRange::Open(0.0, 1.0), sp.sigmaA);
    sp.sigmaB = map.GetDouble("sigma_b", NumberRange::Open(0.0, 1.0), sp.sigmaB);
    if (sp.model == SpectrumModel::Phillips && sp.peakPeriod_s) {
        const std::optional<ConfigValue> period = map.Find("peak_period_s");
        if (period)
            period->Fail("no peak_period_s with spectrum: phillips (its peak follows the wind)");
        sp.peakPeriod_s.reset();
    }
    if (std::optional<ConfigMap> ph = map.FindMap("phillips")) {
        PhillipsSettings& p = sp.phillips;
        p.alpha = ph->GetDouble("alpha", NumberRange::OpenClosed(0.0, 1.0), p.alpha);
        p.exponent = ph->GetDouble("exponent", NumberRange::OpenClosed(2.0, 10.0), p.exponent);
        p.alignmentExponent = ph->GetDouble("alignment_exponent", NumberRange::Closed(0.0, 64.0),
                                            p.alignmentExponent);
        p.againstWindFactor = ph->GetDouble("against_wind_factor", NumberRange::Closed(0.0, 1.0),
                                            p.againstWindFactor);
        p.smallWaveCutoff_m = ph->GetDouble(
            "small_wave_cutoff_m", NumberRange::Closed(0.0, 10.0, "m"), p.smallWaveCutoff_m);
        ph->Finish();
    }
    if (std::optional<ConfigMap> sw = map.FindMap("swell")) {
        SwellSettings w = sp.swell.value_or(SwellSettings{});
        w.significantHeight_m =
            sw->GetDouble("significant_height_m", NumberRange::Closed(0.0, 30.0, "m"));
        w.peakPeriod_s = sw->GetDouble("peak_period_s", NumberRange::OpenClosed(0.0, 60.0, "s"));
        w.direction_rad = sw->GetDouble("direction_deg", NumberRange::Any("deg")) * kRadPerDeg;
        w.gamma = sw->GetDouble("gamma", NumberRange::Closed(1.0, 20.0), w.gamma);
        w.spreadingPeak =
            sw->GetDouble("spreading_exponent", NumberRange::Closed(0.0, 1000.0), w.spreadingPeak);
        sw->Finish();
        sp.swell = w;
    }
    // A height with an explicit zero wind cannot be given a shape (ResolveSeaState explains).
    const bool heightAsked = (s.seaState && *s.seaState > 0) ||
                             (sp.significantHeight_m && *sp.significantHeight_m > 0.0);
    if (heightAsked && wind && s.windSpeed_mps && *s.windSpeed_mps == 0.0)
        wind->Fail("a wind speed above 0 m/s when a wave height is given (or no wind_speed_mps)");
    if (heightAsked && beaufort && s.beaufort && *s.beaufort == 0)
        beaufort->Fail("a Beaufort force above 0 when a wave height is given (or no beaufort)");
    return s;
}

std::string SeaStatePresetsMarkdown() {
    std::ostringstream out;
    const auto pmHeight = [](double u10) {
        if (u10 <= 0.0) return 0.0;
        SpectrumSettings s;
        s.model = SpectrumModel::PiersonMoskowitz;
        s.windSpeed_mps = u10;
        return WaveSpectrum(s).SignificantHeight_m();
    };
    const auto pmPeriod = [](double u10) {
        return u10 > 0.0 ? 2.0 * std::numbers::pi / PiersonMoskowitzPeakOmega(u10) : kNaN;
    };
    out << "Beaufort scale (WMO; wind at 10 m). Preset: the middle of the wind band; the sea is\n"
           "computed from the spectrum (Hs and Tp below: fully developed Pierson–Moskowitz).\n\n"
           "| Force | Description | U10 (m/s) | Preset U10 (m/s) | WMO probable wave height (m) | "
           "WMO probable max (m) | PM Hs (m) | PM Tp (s) |\n"
           "|---:|---|---|---:|---:|---:|---:|---:|\n";
    for (const BeaufortForce& b : kBeaufort) {
        const double u = BeaufortWindSpeed_mps(b.force);
        out << "| " << b.force << " | " << b.description << " | "
            << Band(b.windMin_mps, b.windMax_mps, 1) << " | " << Fixed(u, 2) << " | "
            << Fixed(b.probableHeight_m, 1) << " | " << Fixed(b.probableMaxHeight_m, 1) << " | "
            << Fixed(pmHeight(u), 2) << " | " << Fixed(pmPeriod(u), 1) << " |\n";
    }
    out << "\nWMO sea state (code table 3700, WMO-No. 306). Preset: the middle of the Hs band;\n"
           "without a wind setting the wind follows from full development (Pierson–Moskowitz).\n\n"
           "| Code | Description | Hs (m) | Preset Hs (m) | Fully developed U10 (m/s) | "
           "PM Tp (s) |\n"
           "|---:|---|---|---:|---:|---:|\n";
    for (const WmoSeaState& s : kSeaStates) {
        const double hs = SeaStateSignificantHeight_m(s.code);
        const double u = FullyDevelopedWindSpeed_mps(hs);
        out << "| " << s.code << " | " << s.description << " | "
            << Band(s.heightMin_m, s.heightMax_m, 2) << " | " << Fixed(hs, 3) << " | "
            << Fixed(u, 2) << " | " << Fixed(pmPeriod(u), 1) << " |\n";
    }
    return out.str();
}

}  // namespace seasense::scene
