// Spectral ocean by inverse FFT (Tessendorf 2001) in cascades of non-commensurate periodic
// patches: height, choppy displacement, slopes, Jacobian and velocity, with truthful queries.
#pragma once

#include <array>
#include <complex>
#include <cstdint>
#include <functional>
#include <glm/glm.hpp>
#include <opencv2/core.hpp>
#include <span>
#include <vector>

#include "scene/config/config.h"
#include "scene/ocean/ocean_settings.h"
#include "scene/ocean/sea_state.h"
#include "scene/ocean/spectrum.h"
#include "scene/ocean/surface_terms.h"

namespace seasense::scene {

// Reads a mapping with the sea keys of ReadSeaStateSettings and an optional
// fft: {grid_size, patch_sizes_m, cascades, choppiness, seed}; unknown keys are errors.
SpectralOceanSettings ReadSpectralOceanSettings(const ConfigValue& value,
                                                const SpectralOceanSettings& defaults = {});
// The same keys from a mapping being read (the caller may read more keys and calls Finish).
SpectralOceanSettings ReadSpectralOceanSettings(ConfigMap& map,
                                                const SpectralOceanSettings& defaults = {});

// Patch sizes for a spectrum (m): the largest max(250 m, 10 peak wavelengths) so the peak is
// sampled by ≥ 10 wavenumber rings, each next one 37/250 of the previous (a ratio of coprime
// integers: the sum of two patches repeats only after 37 largest patches).
std::vector<double> DefaultPatchSizes(const WaveSpectrum& spectrum, int cascadeCount);

// Fields synthesized per cascade grid node, before the choppiness factor λ is applied. Dx, Dy
// are the horizontal displacement, derivatives are with respect to the rest position, and the
// rates are time derivatives at a fixed rest position.
enum class OceanField : int {
    Height,      // η, m
    DispX,       // Dx (east), m
    DispY,       // Dy (north), m
    SlopeX,      // ∂η/∂x
    SlopeY,      // ∂η/∂y
    DispXX,      // ∂Dx/∂x
    DispYY,      // ∂Dy/∂y
    DispXY,      // ∂Dx/∂y = ∂Dy/∂x
    HeightRate,  // ∂η/∂t, m/s
    DispXRate,   // ∂Dx/∂t, m/s
    DispYRate,   // ∂Dy/∂t, m/s
};
inline constexpr int kOceanFieldCount = 11;

// The synthesized fields of all cascades at one instant (an immutable snapshot once filled).
// The surface is the sum over cascades of each periodic field, sampled bilinearly.
class FftOceanFrame {
  public:
    double Time_s() const { return t_s_; }
    size_t CascadeCount() const { return cascades_.size(); }
    double PatchSize_m(size_t cascade) const { return cascades_[cascade].patch_m; }
    int GridSize() const { return n_; }
    double Choppiness() const { return choppiness_; }
    // Whether the rate fields (HeightRate, DispXRate, DispYRate) were synthesized.
    bool HasRates() const { return hasRates_; }

    // Field value at grid node (ix, iy) of a cascade, which lies at rest position
    // (ix, iy) · L / N (periodic).
    float Field(size_t cascade, OceanField field, int ix, int iy) const;
    // Plane p of a cascade: N × N CV_32FC2, transposed (row ix, column iy), field 2p in the
    // real and field 2p + 1 in the imaginary part (before the choppiness factor).
    const cv::Mat& FieldPlane(size_t cascade, int plane) const;

    // Displacement and derivatives at rest position (x0, y0) (world metres), choppiness applied,
    // cascades sampled bilinearly. The velocity is NaN when the rates were not synthesized.
    // With cascadeWeights (one per cascade) each cascade's fields are scaled by its weight.
    SurfaceTerms Terms(double x0, double y0, const double* cascadeWeights = nullptr) const;
    // Surface at rest position (x0, y0) (world metres).
    OceanSample Evaluate(double x0, double y0) const {
        return MakeOceanSample(x0, y0, Terms(x0, y0));
    }

    // Surface drawn above the world point (x, y): the rest position whose displaced horizontal
    // position is (x, y) is found by fixed-point iteration, so HeightAt answers with the
    // height of the surface a mesh of Evaluate's points shows there.
    OceanSample SampleAt(double x, double y) const;
    double HeightAt(double x, double y) const { return SampleAt(x, y).position.z; }

    static constexpr int kPlanes = 6;      // two real fields per complex transform
    static constexpr int kRatePlanes = 2;  // the last two planes hold the rates

    // The frame as bytes, to hand fields synthesized in one process to another on the same
    // machine (channels/sync): grid size, choppiness, time, whether the rates were made, and
    // each cascade's patch size and field planes, bit for bit (native representation).
    // EncodedBytes is what Encode writes.
    size_t EncodedBytes() const;
    void Encode(uint8_t* out) const;
    // EncodedBytes of a frame with n × n grids, the given cascades and with or without rates.
    static size_t EncodedBytesFor(int n, size_t cascades, bool withRates);
    // Makes this frame the one Encode wrote (reusing its buffers): every field bit for bit.
    // RuntimeError when the bytes are not such a frame (wrong tag, length or grid).
    void Decode(const uint8_t* in, size_t bytes);

  private:
    friend class FftOcean;
    struct Cascade {
        double patch_m = 0.0;
        std::array<cv::Mat, kPlanes> spectrum, scratch;  // CV_32FC2 work space
        // CV_32FC2, transposed (row ix, column iy): field 2p in re, 2p+1 in im.
        std::array<cv::Mat, kPlanes> field;
    };
    std::vector<Cascade> cascades_;
    int n_ = 0;
    double choppiness_ = 0.0;
    double t_s_ = 0.0;
    bool hasRates_ = true;
};

// The wavenumber band a cascade synthesizes: modes with kMin ≤ |k| < kMax (rad/m).
struct CascadeBand {
    double patch_m = 0.0;
    double kMin_radpm = 0.0;
    double kMax_radpm = 0.0;
    double variance_m2 = 0.0;  // Σ F Δk² over the cascade's modes
    // Median wavenumber of the cascade's slope variance (Σ k² F Δk²): the waves that carry the
    // slopes, and so the shading, this cascade draws (rad/m; 0 for an empty cascade).
    double slopeMedian_radpm = 0.0;
};

class FftOcean {
  public:
    // Directional variance density F(kx, ky) in m⁴ over the wavevector along the direction of
    // travel, as WaveSpectrum::DensityK.
    using Density = std::function<double(double kx_radpm, double ky_radpm)>;

    // Throws InputError for invalid settings.
    FftOcean(const WaveSpectrum& spectrum, const FftOceanSettings& settings);
    // For a density of one's own; settings.patchSizes_m must be given.
    FftOcean(const Density& density, double depth_m, const FftOceanSettings& settings);

    // Fields at time t_s (seconds) into frame, reusing its buffers. Thread-parallel (oneTBB);
    // the result is bit-identical for any thread count. Without rates the three time-derivative
    // fields are skipped (a third less work: rendering needs only the geometry).
    void Synthesize(double t_s, FftOceanFrame& frame, bool withRates = true) const;
    FftOceanFrame Synthesize(double t_s) const;

    std::span<const CascadeBand> Cascades() const { return bands_; }
    int GridSize() const { return n_; }
    double Depth_m() const { return depth_m_; }
    double Choppiness() const { return choppiness_; }

    // Σ F(k) Δk² over the synthesized modes: the expected variance of the height field (m²).
    double ModeVariance_m2() const { return modeVariance_m2_; }

    // Complex amplitude h(k, t) (m) of height mode k = (mx, my) · 2π/L of a cascade, with
    // mx, my in [−N/2, N/2): h0(k) e^{−iωt} + conj(h0(−k)) e^{iωt}, so the mode of h0(k)
    // travels along +k.
    std::complex<double> HeightMode(size_t cascade, int mx, int my, double t_s) const;

  private:
    struct Modes {
        std::vector<std::complex<float>> h0;           // h0(k), index iy·N + ix
        std::vector<std::complex<float>> h0MinusConj;  // conj(h0(−k))
        std::vector<double> omega;                     // rad/s
        std::vector<float> kx, ky;                     // rad/m
        std::vector<float> chop;                       // coth(k h) / k: displacement per height
    };

    void Build(const Density& density, const FftOceanSettings& settings);
    size_t Index(int mx, int my) const;

    int n_ = 0;
    double depth_m_ = 0.0;
    double choppiness_ = 0.0;
    double modeVariance_m2_ = 0.0;
    std::vector<CascadeBand> bands_;
    std::vector<Modes> modes_;
    std::vector<int> maxRow_;  // per cascade: largest |my| of a mode in its band
};

}  // namespace seasense::scene
