// The image intensifier of an NVG channel: photocathode photoelectrons from at-aperture photon
// radiance, MCP scintillation noise, halo, tube MTF, automatic brightness control with lag,
// bright-source protection, circular field stop and P43 phosphor display.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "scene/core/image.h"
#include "sensors/intensifier/intensifier_settings.h"

namespace seasense::sensors {

class Intensifier {
  public:
    // supersampling: N of the N×N samples per pixel of the radiance given to Process.
    Intensifier(const IntensifierSettings& settings, int supersampling);

    // One frame at scene time time_s (s): samples is (width·N)×(height·N)×C photon radiance
    // (photons s⁻¹ m⁻² sr⁻¹, photocathode-QE-weighted relative to the peak), summed over its C
    // components (the sub-bands of radiometry/nvg). The ABC state follows time_s from the
    // previous call (settled on the first call, or when time does not advance); noise is a pure
    // function of (seed, frame, pixel), so any thread count gives the same frame.
    void Process(const Image& samples, double time_s, int64_t frame);
    // Forgets the frames processed (the ABC's gain history): the next Process starts settled,
    // bit for bit what a newly made intensifier gives, with the working memory kept.
    void Restart();

    // Mean photoelectrons per pixel per frame for photon radiance 1 photon s⁻¹ m⁻² sr⁻¹ at the
    // optical axis: QE_peak · τ_optics · A_pixel · π/(4F²) · t_frame (étendue of a pixel behind
    // an f/F objective, small-angle).
    double PhotoelectronsPerRadiance() const { return pePerRadiance_; }

    // Last frame: per pixel photon radiance at the aperture inside the field stop (0 outside:
    // the stop passes no light; 1 channel), the noisy photoelectron count after the
    // photocathode (1 channel), screen brightness (1 channel, 0 … 1 = saturation), and the
    // 8-bit sRGB P43 display (width×height×3, row 0 on top).
    const Image& PhotonRadiance() const { return radiance_; }
    const Image& Photoelectrons() const { return electrons_; }
    const Image& Brightness() const { return brightness_; }
    std::span<const uint8_t> Display() const { return display_; }

    // ABC gain (screen brightness per photoelectron), BSP duty cycle, and the field's mean
    // photoelectrons per pixel per frame before BSP, of the last frame.
    double Gain() const { return gain_; }
    double Duty() const { return duty_; }
    double MeanPhotoelectrons() const { return meanPe_; }
    // Whether pixel (x, y) lies inside the circular field stop.
    bool InField(int x, int y) const { return mask_[size_t(y) * size_t(s_.width_px) + size_t(x)]; }
    // Halo radius and tube-MTF Gaussian σ in pixels.
    double HaloRadius_px() const { return haloRadius_px_; }
    double MtfSigma_px() const { return mtfSigma_px_; }
    const IntensifierSettings& Settings() const { return s_; }

  private:
    IntensifierSettings s_;
    int n_;
    double pePerRadiance_ = 0.0;
    double haloRadius_px_ = 0.0, mtfSigma_px_ = 0.0;
    std::vector<float> mtfKernel_;
    std::vector<PixelSpan> spans_;  // FieldStopSpans of the settings
    std::vector<uint8_t> mask_;
    size_t fieldCount_ = 0;  // pixels inside the field stop
    Image radiance_, electrons_, halo_, brightness_;
    std::vector<uint8_t> display_;
    std::vector<double> prefix_;        // halo: row prefix sums, kept between frames
    std::vector<double> rowSum_;        // per-row sums over the field stop
    std::vector<uint8_t> phosphorLut_;  // kLutSize × 4: brightness → sRGB P43 colour, 0
    bool started_ = false;
    double lastTime_s_ = 0.0;
    double gain_ = 0.0, duty_ = 1.0, meanPe_ = 0.0;
};

// A Poisson deviate of the given mean from 64 random bits (e.g. scene::HashBits): exact for
// mean ≤ 30 (inversion of the CDF by sequential search from the 53 high bits, Devroye,
// "Non-Uniform Random Variate Generation", 1986, §X.3.3), else the normal approximation
// (sensors/thermal NormalFromBits of the low 32 bits) rounded to an integer ≥ 0.
double PoissonDeviate(double mean, uint64_t bits);

}  // namespace seasense::sensors
