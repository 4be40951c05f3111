// Image-intensifier (NVG) parameters (SI units, documented defaults) and their YAML reader.
#pragma once

#include <cstdint>
#include <vector>

#include "scene/config/config.h"
#include "scene/core/image.h"

namespace seasense::sensors {

enum class Photocathode { Gen2, Gen3 };
enum class MinusBlue { None, ClassA, ClassB };

// Defaults describe an aviation Gen III goggle (physics.md, "Night vision"): 40° circular field,
// f/1.2 objective (ANVIS-class goggles use ≈ 25–27 mm f/1.2 objectives), GaAs photocathode,
// 64 lp/mm tube, MCP noise factor 2 (physics.md: 1.5–2.5), 1.8° halo, P43 phosphor.
struct IntensifierSettings {
    // Image format. Set by the channel from its resolution and field of view.
    int width_px = 640;
    int height_px = 480;
    double hfov_rad = 0.6981317007977318;  // 40°
    double frameTime_s = 1.0 / 30.0;       // photocathode integration per frame (the frame period)
    uint64_t seed = 1;                     // noise; set by the channel from the scenario seed

    // Objective and field stop: the circular field of fieldStop_rad across fills the photocathode
    // diameter, which fixes the focal length (FocalLength_m).
    double fNumber = 1.2;
    double opticsTransmission = 0.8;
    double fieldStop_rad = 0.6981317007977318;  // 40°: the circular mask
    // 18 mm: the standard photocathode/screen format of aviation and hand-held tubes (the
    // "18 mm" MX-10160 / MX-11769 tubes of ANVIS and PVS-14).
    double photocathodeDiameter_m = 18e-3;

    Photocathode cathode = Photocathode::Gen3;
    MinusBlue filter = MinusBlue::None;
    // Peak quantum efficiency (electrons per photon): Gen III GaAs ≈ 0.3 at 600–800 nm; Gen II
    // S-25 ≈ 0.1–0.15 (Csorba, "Image Tubes", Sams 1985, ch. 4).
    double qePeak = 0.30;

    double resolution_lp_mm = 64.0;          // limiting resolution (MTF 3 %) at the photocathode
    double noiseFactor = 2.0;                // MCP excess noise factor F: SNR = √(N/F)
    double halo_rad = 0.031415926535897934;  // 1.8°: halo diameter (constant angle)
    double haloFraction = 0.03;              // share of each pixel's signal spread into its halo

    // Automatic brightness control: while the field's mean photocathode current density is
    // below abcThreshold (photoelectrons s⁻¹ mm⁻²; 1e6 ≈ 1.6e-7 A/m², a starlit scene) the gain
    // is at its maximum; above, it holds the mean screen brightness at `level` (fraction of the
    // screen's saturation), following changes with a first-order lag. The ABC senses the screen
    // current, which a saturated MCP channel cannot raise: each pixel counts at most the
    // photoelectrons that saturated it at the previous frame's gain.
    double abcLevel = 0.35;
    double abcThreshold_pe_s_mm2 = 1.0e6;
    double abcTimeConstant_s = 0.25;
    // Bright-source protection: above this mean photocathode current density (photoelectrons
    // s⁻¹ mm⁻²; 4e8 ≈ 6.4e-5 A/m², about ten times a full-moon scene) the photocathode's duty
    // cycle falls as threshold / mean, holding the cathode current.
    double bspThreshold_pe_s_mm2 = 4.0e8;

    // Focal length (m) from the field stop and the photocathode diameter.
    double FocalLength_m() const;
    // Pixel pitch on the photocathode (m): the channel's hfov over width_px.
    double PixelPitch_m() const;
    // Photoelectrons per pixel per frame of a photocathode current density (pe s⁻¹ mm⁻²).
    double PixelFramePe(double rate_pe_s_mm2) const;
};

// The pixels inside the circular field stop, row by row: [begin, end) of the pixels of row y
// (0 = top) whose centre ray is within fieldStop_rad/2 of the optical axis (begin = end when
// none). The stop is convex, so each row's pixels are one run. Light outside it never reaches
// the photocathode: the intensifier reads and the NVG channel renders only these pixels.
std::vector<PixelSpan> FieldStopSpans(const IntensifierSettings& settings);

// Reads the `intensifier:` mapping (all keys optional; units in the key names):
//   optics:       f_number, transmission, field_stop_deg, photocathode_diameter_mm
//   photocathode: generation (gen2 | gen3), minus_blue (none | a | b), qe_peak
//   tube:         resolution_lp_mm, noise_factor, halo_deg, halo_fraction
//   abc:          level, threshold_pe_s_mm2, time_constant_s
//   bsp:          threshold_pe_s_mm2
// Starts from `defaults` (format, field of view, frame time and seed come from there). Unknown
// keys and values out of range throw scene::ConfigError naming the key path (file:line:column).
IntensifierSettings ReadIntensifierSettings(const scene::ConfigValue& value,
                                            const IntensifierSettings& defaults = {});

}  // namespace seasense::sensors
