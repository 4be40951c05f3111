// Files of one thermal frame: 16-bit raw counts, the 8-bit AGC display and a radiometric EXR.
#pragma once

#include <filesystem>

#include "sensors/output/image_sink.h"
#include "sensors/output/image_writer.h"
#include "sensors/thermal/thermal_imager.h"

namespace seasense::sensors {

// Where to write each product; an empty path skips it.
struct ThermalOutputPaths {
    // 16-bit PNG or TIFF of the 14-bit ADC counts as they are (0 … 16383, not rescaled).
    std::filesystem::path rawCounts;
    // 8-bit PNG or TIFF of the AGC display (gray, or RGB for a colour palette).
    std::filesystem::path display;
    // Float OpenEXR with channels "L" (ThermalImager::MeasuredRadiance, band radiance at the
    // aperture as measured, W·m⁻²·sr⁻¹) and "T" (its apparent blackbody temperature, K).
    std::filesystem::path radiometricExr;
};

// Writes the imager's last frame. `metadata` (capture time, channel name, ...) is extended
// with the imager's own attributes (ThermalImager::Metadata) and the units of each file.
// Atomic per file (image_writer.h). Throws RuntimeError if a file cannot be written.
void WriteThermalFrame(const ThermalImager& imager, const ThermalOutputPaths& paths,
                       ImageMetadata metadata = {});
// As above, the files handed to `sink` (written now, or copied and written in the background).
void WriteThermalFrame(const ThermalImager& imager, const ThermalOutputPaths& paths,
                       ImageMetadata metadata, ImageSink& sink);

}  // namespace seasense::sensors
