// Reader of the image-intensifier settings from a scenario's `intensifier:` mapping.
#include "sensors/intensifier/intensifier_settings.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

namespace seasense::sensors {

namespace {

using scene::ConfigMap;
using scene::NumberRange;

constexpr double kRadPerDeg = std::numbers::pi / 180.0;

}  // namespace

double IntensifierSettings::FocalLength_m() const {
    return 0.5 * photocathodeDiameter_m / std::tan(0.5 * fieldStop_rad);
}

std::vector<PixelSpan> FieldStopSpans(const IntensifierSettings& s) {
    const int w = s.width_px, h = s.height_px;
    const double tanHalfH = std::tan(0.5 * s.hfov_rad), tanHalfV = tanHalfH * h / w;
    const double tanStop = std::tan(0.5 * s.fieldStop_rad);
    std::vector<PixelSpan> spans(size_t(std::max(h, 0)));
    for (int y = 0; y < h; ++y) {
        const double v = ((y + 0.5) / h * 2.0 - 1.0) * tanHalfV;
        PixelSpan& span = spans[size_t(y)];
        for (int x = 0; x < w; ++x) {
            const double u = ((x + 0.5) / w * 2.0 - 1.0) * tanHalfH;
            if (u * u + v * v > tanStop * tanStop) continue;
            if (span.begin == span.end) span.begin = x;
            span.end = x + 1;
        }
    }
    return spans;
}

double IntensifierSettings::PixelPitch_m() const {
    return FocalLength_m() * 2.0 * std::tan(0.5 * hfov_rad) / width_px;
}

double IntensifierSettings::PixelFramePe(double rate_pe_s_mm2) const {
    const double pitch_mm = PixelPitch_m() * 1e3;
    return rate_pe_s_mm2 * pitch_mm * pitch_mm * frameTime_s;
}

IntensifierSettings ReadIntensifierSettings(const scene::ConfigValue& value,
                                            const IntensifierSettings& defaults) {
    return scene::ReadMap(value, [&](ConfigMap& root) {
        IntensifierSettings s = defaults;
        if (std::optional<ConfigMap> m = root.FindMap("optics")) {
            s.fNumber = m->GetDouble("f_number", NumberRange::Closed(0.5, 64.0), s.fNumber);
            s.opticsTransmission = m->GetDouble("transmission", NumberRange::OpenClosed(0.0, 1.0),
                                                s.opticsTransmission);
            s.fieldStop_rad = m->GetDouble("field_stop_deg", NumberRange::Open(0.0, 170.0, "deg"),
                                           s.fieldStop_rad / kRadPerDeg) *
                              kRadPerDeg;
            s.photocathodeDiameter_m =
                m->GetDouble("photocathode_diameter_mm", NumberRange::Closed(1.0, 100.0, "mm"),
                             s.photocathodeDiameter_m * 1e3) *
                1e-3;
            m->Finish();
        }
        if (std::optional<ConfigMap> m = root.FindMap("photocathode")) {
            static const std::vector<std::string> kGenerations = {"gen2", "gen3"};
            static const std::vector<std::string> kFilters = {"none", "a", "b"};
            s.cathode = Photocathode(m->GetEnum("generation", kGenerations, size_t(s.cathode)));
            s.filter = MinusBlue(m->GetEnum("minus_blue", kFilters, size_t(s.filter)));
            s.qePeak = m->GetDouble("qe_peak", NumberRange::OpenClosed(0.0, 1.0), s.qePeak);
            m->Finish();
        }
        if (std::optional<ConfigMap> m = root.FindMap("tube")) {
            s.resolution_lp_mm = m->GetDouble(
                "resolution_lp_mm", NumberRange::Closed(5.0, 500.0, "lp/mm"), s.resolution_lp_mm);
            s.noiseFactor =
                m->GetDouble("noise_factor", NumberRange::Closed(1.0, 10.0), s.noiseFactor);
            s.halo_rad = m->GetDouble("halo_deg", NumberRange::Closed(0.0, 20.0, "deg"),
                                      s.halo_rad / kRadPerDeg) *
                         kRadPerDeg;
            s.haloFraction =
                m->GetDouble("halo_fraction", NumberRange::Closed(0.0, 0.5), s.haloFraction);
            m->Finish();
        }
        if (std::optional<ConfigMap> m = root.FindMap("abc")) {
            s.abcLevel = m->GetDouble("level", NumberRange::OpenClosed(0.0, 1.0), s.abcLevel);
            s.abcThreshold_pe_s_mm2 = m->GetDouble(
                "threshold_pe_s_mm2", NumberRange::Positive("pe/(s mm2)"), s.abcThreshold_pe_s_mm2);
            s.abcTimeConstant_s = m->GetDouble(
                "time_constant_s", NumberRange::Closed(0.0, 60.0, "s"), s.abcTimeConstant_s);
            m->Finish();
        }
        if (std::optional<ConfigMap> m = root.FindMap("bsp")) {
            s.bspThreshold_pe_s_mm2 = m->GetDouble(
                "threshold_pe_s_mm2", NumberRange::Positive("pe/(s mm2)"), s.bspThreshold_pe_s_mm2);
            m->Finish();
        }
        return s;
    });
}

}  // namespace seasense::sensors
