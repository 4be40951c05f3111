// The thermal imager: at-aperture band radiance in, 14-bit counts and display frames out.
#pragma once

#include <tbb/enumerable_thread_specific.h>

#include <cstdint>
#include <span>
#include <vector>

#include "radiometry/bands/band.h"
#include "radiometry/planck/planck.h"
#include "scene/core/image.h"
#include "sensors/output/image_writer.h"
#include "sensors/thermal/optics_kernel.h"
#include "sensors/thermal/thermal_display.h"
#include "sensors/thermal/thermal_settings.h"

namespace seasense::sensors {

// Temperature (K) of a target seen through a path of transmission tauPath (0 < τ ≤ 1) filled
// with air at airT_K: inverts L = τ·B(T) + (1 − τ)·B(T_air) (issue 5; physics.md, at-sensor
// radiance with ε = 1) for the measured band radiance L (W·m⁻²·sr⁻¹), with `table`'s band.
// Throws InputError for τ outside (0, 1], non-finite input or a path-corrected radiance ≤ 0
// (the path alone is brighter than the measurement).
double ApparentTemperature(const radiometry::BandRadianceTable& table, double radiance_W_m2_sr,
                           double tauPath, double airT_K);

// Focal-plane irradiance E = τ π L / (4 F#² + 1) (W·m⁻²) from scene radiance L (W·m⁻²·sr⁻¹)
// through optics of transmission tau (Holst, "Electro-Optical Imaging System Performance",
// camera equation for an on-axis point of an aplanatic lens).
double FocalPlaneIrradiance(double radiance_W_m2_sr, double tau, double fNumber);

// Stateful: the bolometer lag, the AGC memory and the noise frame counter carry over from one
// Process() call to the next; the fixed pattern and the NUC are drawn once on construction.
// Every stage is parallel over rows with oneTBB and bit-identical for any thread count.
class ThermalImager {
  public:
    // supersamples: N, the input holds N×N samples per pixel. Throws InputError for invalid
    // settings (non-positive sizes, transmission outside (0, 1], ADC range not increasing, ...).
    ThermalImager(const ThermalImagerSettings& settings, radiometry::Band band, int supersamples);

    // Images one frame: samples is the at-aperture band radiance (W·m⁻²·sr⁻¹, 1 channel,
    // (width·N)×(height·N), row 0 at the top) at simulation time time_s (s), which must
    // increase from call to call. The first frame sets the lag and AGC state directly. The
    // temporal noise is a pure function of (seed, noiseFrame, pixel), so a frame's noise does
    // not depend on which frames were imaged before it.
    void Process(const Image& samples, double time_s, int64_t noiseFrame);
    // Process with noiseFrame = FramesProcessed().
    void Process(const Image& samples, double time_s) { Process(samples, time_s, frame_); }
    // Forgets the frames processed (bolometer lag, AGC memory, frame count): the next Process
    // is a first frame again, bit for bit what a newly made imager gives, with the working
    // memory kept.
    void Restart();

    const ThermalImagerSettings& Settings() const { return settings_; }
    const radiometry::Band& GetBand() const { return table_.GetBand(); }
    const radiometry::BandRadianceTable& Table() const { return table_; }
    const SamplingKernel& Kernel() const { return kernel_; }
    const ThermalDisplay& Agc() const { return display_; }
    int Supersamples() const { return kernel_.supersamples; }
    int64_t FramesProcessed() const { return frame_; }
    // Horizontal field of view 2·atan(width·pitch / (2 f)) (rad).
    double HorizontalFov_rad() const;

    // Last frame, width×height, row 0 at the top:
    // band radiance at the detector, τ_optics·L after optics blur and lag, before noise
    // (W·m⁻²·sr⁻¹);
    const Image& Radiance() const { return radiance_; }
    // the detector signal as focal-plane irradiance (W·m⁻²) after fixed pattern, temporal
    // noise and NUC, the ADC input;
    const Image& Signal() const { return signal_; }
    // 14-bit ADC counts;
    std::span<const uint16_t> Counts() const { return counts_; }
    // the AGC display, DisplayChannels() bytes per pixel (gray, or RGB for a colour palette);
    std::span<const uint8_t> Display() const { return display8_; }
    int DisplayChannels() const { return display_.Channels(); }
    // the band radiance at the aperture (W·m⁻²·sr⁻¹) that the detector signal stands for:
    // Signal() / (τ π / (4F#² + 1)), with the temporal noise and any fixed pattern the NUC
    // left, what a radiometric camera reports (before the ADC, so neither quantised nor
    // clipped). Computed on request;
    Image MeasuredRadiance() const;
    // apparent blackbody temperature (K) per pixel: BandRadianceTable::Temperature of
    // MeasuredRadiance(), 0 K where it is not positive. Computed on request.
    Image ApparentTemperature() const;

    // Focal-plane irradiance (W·m⁻²) of a blackbody at T_K filling the field.
    double BlackbodyIrradiance(double T_K) const;
    // ADC transfer: counts = clamp(round(AdcGain()·E + AdcOffset()), 0, 16383), E in W·m⁻²;
    // gain in counts per W·m⁻².
    double AdcGain() const { return adcGain_; }
    double AdcOffset() const { return adcOffset_; }
    // Temporal noise std of the signal (W·m⁻²): NETD·τ π/(4F#² + 1)·dL_B/dT at the NETD
    // reference temperature.
    double NoiseSigma() const { return noiseSigma_; }

    // Header attributes for the outputs: band, NETD, optics, pitch, ADC range, and the last
    // frame's noiseFrame as its frame index.
    ImageMetadata Metadata() const;

  private:
    void BuildFixedPattern();
    void CalibrateNuc();
    // Signal of pixel i for focal-plane irradiance E before NUC, with noise normal z.
    double RawSignal(size_t i, double E, double z) const;

    ThermalImagerSettings settings_;
    radiometry::BandRadianceTable table_;
    SamplingKernel kernel_;
    ThermalDisplay display_;
    double irradiancePerRadiance_;  // τ π / (4F#² + 1), sr
    double noiseSigma_;             // W·m⁻²
    double adcGain_, adcOffset_;
    // Per-pixel response s = gain·E + offset + noiseScale·σ·z after FPN and NUC; empty when
    // the response is ideal (no FPN, no NUC).
    std::vector<float> rawGain_, rawOffset_;         // fixed pattern before NUC
    std::vector<float> gain_, offset_, noiseScale_;  // with the NUC folded in
    Image radiance_, signal_;
    std::vector<uint16_t> counts_;
    std::vector<uint8_t> display8_;
    // Per-thread working memory of Process, kept between frames: the sampling kernel's rows
    // and one row of noise deviates.
    struct RowScratch {
        std::vector<float> kernel, noise;
    };
    tbb::enumerable_thread_specific<RowScratch> scratch_;
    int64_t frame_ = 0;           // frames processed
    int64_t lastNoiseFrame_ = 0;  // noiseFrame of the last frame (its frame index)
    double lastTime_s_ = 0.0;
};

}  // namespace seasense::sensors
