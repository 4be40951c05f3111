// Thermal imager parameters (SI units, documented defaults) and their YAML reader.
#pragma once

#include <cstdint>

#include "scene/config/config.h"
#include "sensors/thermal/thermal_display.h"

namespace seasense::sensors {

// Defaults describe an uncooled LWIR microbolometer camera: 640×480, 17 µm pitch, 25 mm F/1.0
// lens, NETD 50 mK at 300 K, 10 ms thermal time constant (physics.md, "Typical sensors").
// A cooled MWIR camera is timeConstant_s = 0 (integrating detector, no lag) with a lower NETD.
struct ThermalImagerSettings {
    // Detector format. Set by the channel from its resolution; not read from the imager map.
    int width_px = 640;
    int height_px = 480;
    double pitch_m = 17e-6;
    // Active area / pitch²; the active area is a centred square of side √fillFactor·pitch.
    double fillFactor = 1.0;
    // Bolometer thermal time constant τ (s) of the first-order lag; 0 = integrating detector.
    double timeConstant_s = 0.010;

    double focalLength_m = 0.025;
    double fNumber = 1.0;
    double opticsTransmission = 0.9;  // τ_optics, scales the focal-plane irradiance
    double aberrationSigma_m = 0.0;   // Gaussian aberration blur σ on the focal plane
    // Minimum half-width of the optics+detector sampling kernel in pixels
    // (SamplingKernelRadius_px widens it for slow lenses and large aberration blur).
    int psfRadius_px = 4;

    // Temporal noise: NETD (K) at netdReference_K; 0 turns temporal noise off.
    double netd_K = 0.050;
    double netdReference_K = 300.0;
    // Fixed-pattern noise, drawn once from `seed`: per-pixel offset (K-equivalent at the NETD
    // reference), per-pixel relative gain (fraction), row and column offsets (K-equivalent).
    double offsetFpn_K = 0.0;
    double gainFpn = 0.0;
    double rowFpn_K = 0.0;
    double columnFpn_K = 0.0;
    // Seed of all noise; set by the channel from the scenario seed.
    uint64_t seed = 1;

    // Two-point non-uniformity correction from uniform blackbodies at nucLow_K and nucHigh_K,
    // each averaged over nucFrames noisy frames.
    bool nuc = false;
    double nucLow_K = 283.15;
    double nucHigh_K = 313.15;
    int nucFrames = 16;

    // 14-bit ADC: the focal-plane signal of blackbodies at adcMin_K … adcMax_K spans
    // counts 0 … 16383.
    double adcMin_K = 240.0;
    double adcMax_K = 340.0;

    AgcSettings agc;
};

// Reads the `imager:` mapping (all keys optional; units in the key names):
//   optics:   focal_length_mm, f_number, transmission, aberration_sigma_um or
//             aberration_sigma_px, psf_radius_px
//   detector: pitch_um, fill_factor, time_constant_ms
//   noise:    netd_mK, reference_K, offset_fpn_K, gain_fpn, row_fpn_K, column_fpn_K
//   nuc:      low_K, high_K, frames            (present = correction on)
//   adc:      min_K, max_K
//   agc:      mode (plateau | linear | manual), plateau, clip_low_percent,
//             clip_high_percent, time_constant_s, gain, level_counts
//   display:  polarity (white_hot | black_hot), palette (grayscale | ironbow | rainbow)
// Starts from `defaults` (width, height and seed come from there). Unknown keys, values out
// of range and inconsistent pairs throw scene::ConfigError naming the key path.
ThermalImagerSettings ReadThermalImagerSettings(const scene::ConfigValue& value,
                                                const ThermalImagerSettings& defaults = {});

}  // namespace seasense::sensors
