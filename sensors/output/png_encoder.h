// PNG encoder (PNG specification, ISO/IEC 15948:2004 = W3C PNG 2nd edition): 8- and 16-bit
// gray, gray+alpha, RGB and RGBA, with tIME and tEXt metadata, every row through the Sub filter,
// compressed with libdeflate at level 1.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace seasense::sensors {

// tIME chunk (§11.3.6.1): when the image was last modified, in UTC.
struct PngTime {
    int year = 1970;
    int month = 1;
    int day = 1;
    int hour = 0;
    int minute = 0;
    int second = 0;
};

// One tEXt chunk (§11.3.4.3). The text is stored byte for byte (PNG reads it as Latin-1).
struct PngText {
    std::string keyword;
    std::string text;
};

// Everything stored besides the pixels; the text chunks in this order.
struct PngInfo {
    std::optional<PngTime> time;
    std::vector<PngText> text;
};

// Largest data length of one chunk (§5.3, 2^31 − 1 bytes); longer image data is split over
// several IDAT chunks.
inline constexpr std::size_t kPngMaxChunkLength = 0x7fffffff;

// Whether every field of `t` is in its range (§11.3.6.1).
bool PngTimeIsValid(const PngTime& t);

// Why `keyword` cannot be a tEXt keyword (§11.3.4.2: 1–79 Latin-1 printable characters, no
// leading, trailing or consecutive spaces), or an empty string if it can.
std::string PngKeywordProblem(std::string_view keyword);

// Throws InputError (a message without a file name) if `info` cannot be stored: a bad keyword,
// a NUL inside a text, a time field out of range.
void CheckPngInfo(const PngInfo& info);

// The complete PNG file of width×height pixels of `channels` interleaved samples (1 gray,
// 2 gray+alpha, 3 RGB, 4 RGBA), row 0 at the top. `maxIdatLength` is the most data one IDAT
// chunk holds (tests lower it to see the data split). Throws InputError for invalid sizes or
// info (CheckPngInfo), RuntimeError if memory or compression fail.
std::vector<std::uint8_t> EncodePng(std::span<const std::uint8_t> pixels, int width, int height,
                                    int channels, const PngInfo& info,
                                    std::size_t maxIdatLength = kPngMaxChunkLength);
// As above with 16-bit samples (stored big-endian, §7.1).
std::vector<std::uint8_t> EncodePng(std::span<const std::uint16_t> pixels, int width, int height,
                                    int channels, const PngInfo& info,
                                    std::size_t maxIdatLength = kPngMaxChunkLength);

}  // namespace seasense::sensors
