// Reader of the thermal imager settings from a scenario's `imager:` mapping.
#include "sensors/thermal/thermal_settings.h"

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace seasense::sensors {

namespace {

using scene::ConfigMap;
using scene::ConfigValue;
using scene::NumberRange;

// An optional number whose key carries a non-SI unit: value·toSi, or the SI fallback.
double GetScaled(ConfigMap& map, std::string_view key, const NumberRange& range, double toSi,
                 double fallbackSi) {
    return map.GetDouble(key, range, fallbackSi / toSi) * toSi;
}

// Reads the optional pair lowKey < highKey (K) into lo and hi (which hold the defaults). An
// inverted pair is reported at the upper key when it was given, else at the lower one.
void ReadOrderedPair(ConfigMap& m, std::string_view lowKey, std::string_view highKey, double& lo,
                     double& hi) {
    const NumberRange kelvin = NumberRange::Closed(150.0, 2500.0, "K");
    const std::optional<ConfigValue> low = m.Find(lowKey);
    const std::optional<ConfigValue> high = m.Find(highKey);
    if (low) lo = low->AsDouble(kelvin);
    if (high) hi = high->AsDouble(kelvin);
    if (hi > lo) return;
    if (high)
        high->Fail("a number (K) above " + std::string(lowKey) + " = " + scene::FormatNumber(lo));
    low->Fail("a number (K) below " + std::string(highKey) + " = " + scene::FormatNumber(hi) +
              " (the default)");
}

void ReadOptics(ConfigMap& m, ThermalImagerSettings& s) {
    s.focalLength_m =
        GetScaled(m, "focal_length_mm", NumberRange::Positive("mm"), 1e-3, s.focalLength_m);
    s.fNumber = m.GetDouble("f_number", NumberRange::Closed(0.5, 64.0), s.fNumber);
    s.opticsTransmission =
        m.GetDouble("transmission", NumberRange::OpenClosed(0.0, 1.0), s.opticsTransmission);
    const std::optional<ConfigValue> um = m.Find("aberration_sigma_um");
    const std::optional<ConfigValue> px = m.Find("aberration_sigma_px");
    if (um && px)
        px->Fail("only one of aberration_sigma_um and aberration_sigma_px",
                 "both keys in " + m.Path());
    // σ in pixels is converted with the pitch, so the detector block is read first.
    if (um) s.aberrationSigma_m = um->AsDouble(NumberRange::Closed(0.0, 1000.0, "um")) * 1e-6;
    if (px) s.aberrationSigma_m = px->AsDouble(NumberRange::Closed(0.0, 20.0, "px")) * s.pitch_m;
    s.psfRadius_px = int(m.GetInt("psf_radius_px", 1, 32, s.psfRadius_px));
}

void ReadDetector(ConfigMap& m, ThermalImagerSettings& s) {
    s.pitch_m = GetScaled(m, "pitch_um", NumberRange::Closed(1.0, 100.0, "um"), 1e-6, s.pitch_m);
    s.fillFactor = m.GetDouble("fill_factor", NumberRange::OpenClosed(0.0, 1.0), s.fillFactor);
    s.timeConstant_s = GetScaled(m, "time_constant_ms", NumberRange::Closed(0.0, 1000.0, "ms"),
                                 1e-3, s.timeConstant_s);
}

void ReadNoise(ConfigMap& m, ThermalImagerSettings& s) {
    s.netd_K = GetScaled(m, "netd_mK", NumberRange::Closed(0.0, 10000.0, "mK"), 1e-3, s.netd_K);
    s.netdReference_K =
        m.GetDouble("reference_K", NumberRange::Closed(150.0, 2500.0, "K"), s.netdReference_K);
    s.offsetFpn_K =
        m.GetDouble("offset_fpn_K", NumberRange::Closed(0.0, 100.0, "K"), s.offsetFpn_K);
    s.gainFpn = m.GetDouble("gain_fpn", NumberRange::Closed(0.0, 0.5), s.gainFpn);
    s.rowFpn_K = m.GetDouble("row_fpn_K", NumberRange::Closed(0.0, 100.0, "K"), s.rowFpn_K);
    s.columnFpn_K =
        m.GetDouble("column_fpn_K", NumberRange::Closed(0.0, 100.0, "K"), s.columnFpn_K);
}

void ReadNuc(ConfigMap& m, ThermalImagerSettings& s) {
    s.nuc = true;
    ReadOrderedPair(m, "low_K", "high_K", s.nucLow_K, s.nucHigh_K);
    s.nucFrames = int(m.GetInt("frames", 1, 1024, s.nucFrames));
}

void ReadAdc(ConfigMap& m, ThermalImagerSettings& s) {
    ReadOrderedPair(m, "min_K", "max_K", s.adcMin_K, s.adcMax_K);
}

void ReadAgc(ConfigMap& m, AgcSettings& a) {
    static const std::vector<std::string> kModes = {"plateau", "linear", "manual"};
    a.mode = AgcMode(m.GetEnum("mode", kModes, size_t(a.mode)));
    a.plateau = m.GetDouble("plateau", NumberRange::Closed(1.0, 1e9), a.plateau);
    a.clipLow =
        GetScaled(m, "clip_low_percent", NumberRange::Closed(0.0, 49.0, "%"), 0.01, a.clipLow);
    a.clipHigh =
        GetScaled(m, "clip_high_percent", NumberRange::Closed(0.0, 49.0, "%"), 0.01, a.clipHigh);
    a.timeConstant_s =
        m.GetDouble("time_constant_s", NumberRange::Closed(0.0, 3600.0, "s"), a.timeConstant_s);
    a.manualGain = m.GetDouble("gain", NumberRange::Closed(1e-3, 1e4), a.manualGain);
    a.manualLevel_counts =
        m.GetDouble("level_counts", NumberRange::Closed(0.0, kAdcMaxCount), a.manualLevel_counts);
}

void ReadDisplay(ConfigMap& m, AgcSettings& a) {
    static const std::vector<std::string> kPolarities = {"white_hot", "black_hot"};
    static const std::vector<std::string> kPalettes = {"grayscale", "ironbow", "rainbow"};
    a.polarity = Polarity(m.GetEnum("polarity", kPolarities, size_t(a.polarity)));
    a.palette = Palette(m.GetEnum("palette", kPalettes, size_t(a.palette)));
}

}  // namespace

ThermalImagerSettings ReadThermalImagerSettings(const ConfigValue& value,
                                                const ThermalImagerSettings& defaults) {
    return scene::ReadMap(value, [&](ConfigMap& root) {
        ThermalImagerSettings s = defaults;
        // Fixed order: the detector (pitch) before the optics (σ in pixels).
        if (std::optional<ConfigMap> m = root.FindMap("detector")) {
            ReadDetector(*m, s);
            m->Finish();
        }
        if (std::optional<ConfigMap> m = root.FindMap("optics")) {
            ReadOptics(*m, s);
            m->Finish();
        }
        if (std::optional<ConfigMap> m = root.FindMap("noise")) {
            ReadNoise(*m, s);
            m->Finish();
        }
        if (std::optional<ConfigMap> m = root.FindMap("nuc")) {
            ReadNuc(*m, s);
            m->Finish();
        }
        if (std::optional<ConfigMap> m = root.FindMap("adc")) {
            ReadAdc(*m, s);
            m->Finish();
        }
        if (std::optional<ConfigMap> m = root.FindMap("agc")) {
            ReadAgc(*m, s.agc);
            m->Finish();
        }
        if (std::optional<ConfigMap> m = root.FindMap("display")) {
            ReadDisplay(*m, s.agc);
            m->Finish();
        }
        return s;
    });
}

}  // namespace seasense::sensors
