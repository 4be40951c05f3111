// A 3-D lookup table of an OCIO display transform over log2-encoded scene-linear RGB: a fast
// approximation for previews (the run's mosaic), and for the display images of channels that
// ask for it (output.display: lut).
#pragma once

#include <cstdint>
#include <vector>

#include "scene/core/image.h"
#include "sensors/display/ocio_display.h"

namespace seasense::sensors {

class DisplayLut {
  public:
    // Samples display.ToDisplayFloat on an edge³ grid uniform in log2 of each linear
    // component over [2^minLog2, 2^maxLog2] (inputs outside clamp to the ends; 0 and
    // negatives map to the lower end). The ACES output transforms are smooth in log
    // exposure, so trilinear interpolation there stays close to the exact transform: with
    // the defaults (65³ nodes, 0.31 stop apart) within 6 code values, mean 0.07 (tested), at
    // a few ns per pixel instead of ~110 ns. Building it costs one exact transform of 65³
    // colours (~30 ms).
    explicit DisplayLut(const OcioDisplay& display, int edge = 65, float minLog2 = -14.0f,
                        float maxLog2 = 6.0f);

    // 8-bit display RGB of linear · exposureScale (QuantizeUnorm8 of the interpolated value).
    // linear: 3 interleaved channels. Parallel; the result does not depend on thread count.
    std::vector<std::uint8_t> ToDisplay8(const Image& linear, float exposureScale) const;
    // ToDisplay8 with one Trilinear call per pixel (what it does without AVX2, and the
    // reference its eight-pixel AVX2 form is tested against byte for byte).
    std::vector<std::uint8_t> ToDisplay8Steps(const Image& linear, float exposureScale) const;
    // One colour, display-encoded float (1.0 = peak).
    void Apply(const float rgb[3], float out[3]) const;

  private:
    // The interpolated display value of grid cell i0 at fractions f (each in [0, 1]).
    void Trilinear(const int i0[3], const float f[3], float out[3]) const;
    int edge_;
    float minLog2_, scale_;     // grid coordinate = (log2 x − minLog2) · scale
    std::vector<float> table_;  // edge³ × 3, red fastest, and one float of padding
};

// dst = src (3 channels) halved in each direction, for previews: each value is ((a + b) + c) + d
// times ¼ over its 2×2 source values, row by row — the sums, in their order, of OpenCV's
// cv::resize INTER_AREA for an exact factor 2 (tested equal bit for bit), without OpenCV's
// thread pool. Runs in the caller's oneTBB arena.
void HalveRgb(const Image& src, Image& dst);

}  // namespace seasense::sensors
