// Writers of the thermal imager's raw, display and radiometric frames.
#include "sensors/thermal/thermal_output.h"

#include <tbb/parallel_for.h>

#include <utility>

namespace seasense::sensors {

void WriteThermalFrame(const ThermalImager& imager, const ThermalOutputPaths& paths,
                       ImageMetadata metadata) {
    ImageSink direct;
    WriteThermalFrame(imager, paths, std::move(metadata), direct);
}

void WriteThermalFrame(const ThermalImager& imager, const ThermalOutputPaths& paths,
                       ImageMetadata metadata, ImageSink& sink) {
    for (MetadataAttribute& a : imager.Metadata().attributes)
        metadata.Set(std::move(a.name), std::move(a.value));
    const int w = imager.Radiance().width, h = imager.Radiance().height;
    if (!paths.rawCounts.empty()) {
        ImageMetadata m = metadata;
        m.Set("seasense:pixel_unit", std::string("ADC counts (14 bit)"));
        sink.Display16(paths.rawCounts, imager.Counts(), w, h, 1, m);
    }
    if (!paths.display.empty()) {
        ImageMetadata m = metadata;
        m.Set("seasense:pixel_unit", std::string("display level (AGC)"));
        sink.Display8(paths.display, imager.Display(), w, h, imager.DisplayChannels(), m);
    }
    if (!paths.radiometricExr.empty()) {
        const Image T = imager.ApparentTemperature();
        const Image L = imager.MeasuredRadiance();
        Image both(w, h, 2);
        tbb::parallel_for(0, h, [&](int y) {
            for (int x = 0; x < w; ++x) {
                both.At(x, y)[0] = L.At(x, y)[0];
                both.At(x, y)[1] = T.At(x, y)[0];
            }
        });
        ImageMetadata m = metadata;
        m.Set("seasense:L_unit",
              std::string("W m-2 sr-1 (band radiance at the aperture as measured: the detector "
                          "signal before the ADC / (optics transmission pi / (4 F^2 + 1)))"));
        m.Set("seasense:T_unit", std::string("K (apparent blackbody temperature of L)"));
        ExrOptions options;
        options.channelNames = {"L", "T"};
        sink.Exr(paths.radiometricExr, both, m, options);
    }
}

}  // namespace seasense::sensors
