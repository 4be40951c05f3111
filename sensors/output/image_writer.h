// Atomic image and text file output: EXR (scene-linear float) and TIFF (display) with OpenImageIO,
// PNG (display) with our own encoder (png_encoder.h).
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "scene/core/image.h"
#include "scene/core/time.h"

namespace seasense::sensors {

// Three floats, written to EXR as a v3f attribute.
struct Vector3f {
    std::array<float, 3> v{};
};
// 3×3 matrix, element [r * 3 + c] is row r, column c (EXR m33f x[r][c]).
struct Matrix33f {
    std::array<float, 9> m{};
};
// 4×4 matrix, element [r * 4 + c] is row r, column c (EXR m44f x[r][c]).
struct Matrix44f {
    std::array<float, 16> m{};
};

// One metadata value. std::vector<float> is a float array (EXR floatvector).
using MetadataValue =
    std::variant<std::string, int, float, std::vector<float>, Vector3f, Matrix33f, Matrix44f>;

struct MetadataAttribute {
    std::string name;
    MetadataValue value;
};

// Named attributes stored in the image header, in insertion order. Names follow OIIO/EXR
// conventions ("seasense:frame_index"); a name used twice keeps the last value.
struct ImageMetadata {
    std::vector<MetadataAttribute> attributes;

    // Adds the attribute, or replaces the value of an attribute with the same name.
    void Set(std::string name, MetadataValue value);
    // The value stored under `name`, or nullptr.
    const MetadataValue* Find(std::string_view name) const;
    // Sets "DateTime" (EXR capDate, TIFF DateTime, PNG tIME) to `t`, to the second, in the
    // "YYYY:MM:DD hh:mm:ss" form OIIO and EXIF use. For a simulator this is the simulation
    // time of the frame. Without it the writers store the Unix epoch: OIIO would otherwise
    // stamp EXR and TIFF files with the wall clock and identical frames would differ.
    void SetCaptureTime(scene::UtcTime t);
};

enum class ExrPixelType { Half, Float };

struct ExrOptions {
    ExrPixelType pixelType = ExrPixelType::Float;
    // Channel names; empty means the defaults for the channel count: Y, (Y, A), (R, G, B),
    // (R, G, B, A). Required for other channel counts.
    std::vector<std::string> channelNames;
};

// Writes `image` (any channel count, row 0 at the top) as a zip-compressed OpenEXR file with
// `metadata` as header attributes. Pixel values are stored as given (scene-linear, whatever
// units the caller states in the metadata). Atomic: readers see the old file or the complete
// new one, never a partial file. Creates the parent folder if missing.
// Throws InputError for an empty image or bad channel names, RuntimeError if writing fails.
void WriteExr(const std::filesystem::path& path, const Image& image,
              const ImageMetadata& metadata = {}, const ExrOptions& options = {});

// Writes display-referred 8-bit pixels (interleaved, width×height×channels, 1..4 channels,
// row 0 at the top) as PNG or TIFF, chosen by the extension (.png, .tif, .tiff, any case).
// TIFF stores what OIIO's TIFF writer supports of the metadata; PNG stores DateTime in its tIME
// chunk and every other attribute as a tEXt chunk (keyword = name, numbers as text; see PngInfoFor
// in the .cpp), and throws InputError for a name that cannot be a PNG keyword. Atomic as WriteExr.
void WriteDisplayImage8(const std::filesystem::path& path, std::span<const std::uint8_t> pixels,
                        int width, int height, int channels, const ImageMetadata& metadata = {});

// As WriteDisplayImage8, with 16-bit pixels (0..65535 spans the display range).
void WriteDisplayImage16(const std::filesystem::path& path, std::span<const std::uint16_t> pixels,
                         int width, int height, int channels, const ImageMetadata& metadata = {});

// Writes `text` (JSON, CSV) to `path` atomically, creating the parent folder if missing.
// Throws RuntimeError naming the path if it cannot.
void WriteTextFileAtomic(const std::filesystem::path& path, std::string_view text);

}  // namespace seasense::sensors
