// Display transform of visible channels: scene-linear RGB → display RGB through an OCIO view.
#pragma once

#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "scene/core/image.h"

namespace seasense::sensors {

// Nearest n-bit code value of a display value v (1.0 = full scale), clamped to the code range;
// NaN maps to 0. The rule is OpenImageIO's float → unsigned conversion (v·max + 0.5,
// truncated), so our 8/16-bit output matches what `ocioconvert` writes for the same floats.
// Inline: the display LUT quantizes three values per pixel.
template <typename T>
inline T QuantizeUnorm(float v) {
    constexpr float kMax = float(std::numeric_limits<T>::max());
    if (!(v > 0.0f)) return 0;  // also NaN
    if (v >= 1.0f) return std::numeric_limits<T>::max();
    return T(v * kMax + 0.5f);
}
inline std::uint8_t QuantizeUnorm8(float v) { return QuantizeUnorm<std::uint8_t>(v); }
inline std::uint16_t QuantizeUnorm16(float v) { return QuantizeUnorm<std::uint16_t>(v); }

// One (display, view) pair of an OpenColorIO config, applied on the CPU. The input space is
// the config's scene_linear role (for configs/ocio/config.ocio: linear Rec.709 primaries,
// D65 white, which is what the renderer writes). Immutable after construction and safe to
// use from several threads at once.
class OcioDisplay {
  public:
    // Loads and validates the config. Throws InputError naming the config file if it is
    // missing, unreadable or invalid, has no scene_linear role, or lacks the display or view
    // (the message lists the available displays and views).
    OcioDisplay(const std::filesystem::path& configPath, std::string display, std::string view);
    ~OcioDisplay();
    OcioDisplay(OcioDisplay&&) noexcept;
    OcioDisplay& operator=(OcioDisplay&&) noexcept;

    // Display-encoded RGB (1.0 = display peak code value, not clamped) of sceneLinear ·
    // exposureScale. sceneLinear: 3 interleaved channels in the scene_linear space.
    // exposureScale: dimensionless factor ≥ 0 (2^EV). Parallel over row blocks; the result
    // does not depend on the thread count. Throws InputError for a bad exposure scale.
    Image ToDisplayFloat(const Image& sceneLinear, float exposureScale) const;

    // As ToDisplayFloat, quantized to 8 or 16 bits per channel with QuantizeUnorm8/16;
    // interleaved RGB, width×height×3 values, row 0 at the top.
    std::vector<std::uint8_t> ToDisplay8(const Image& sceneLinear, float exposureScale) const;
    std::vector<std::uint16_t> ToDisplay16(const Image& sceneLinear, float exposureScale) const;

    const std::string& Display() const;
    const std::string& View() const;
    // Name of the config's scene_linear colour space (the input space).
    const std::string& SceneLinearColorSpace() const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace seasense::sensors
