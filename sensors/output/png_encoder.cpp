// PNG encoder (PNG specification, ISO/IEC 15948:2004 = W3C PNG 2nd edition): the chunks by hand
// (§5), the image data through the Sub filter and libdeflate's zlib compressor.
#include "sensors/output/png_encoder.h"

#include <libdeflate.h>

#include <algorithm>
#include <cstring>
#include <memory>
#include <new>

#include "scene/core/error.h"

namespace seasense::sensors {

namespace {

// §5.2: the first eight bytes of every PNG file.
constexpr std::uint8_t kSignature[8] = {137, 80, 78, 71, 13, 10, 26, 10};

// §11.2.2 colour types by channel count: greyscale, greyscale with alpha, truecolour,
// truecolour with alpha.
constexpr std::uint8_t kColourType[4] = {0, 4, 2, 6};

// §9.2 filter type 1.
constexpr std::uint8_t kFilterSub = 1;

// libdeflate's fastest level: see the comment on PNG compression in image_writer.cpp.
constexpr int kCompressionLevel = 1;

void AppendBe16(std::vector<std::uint8_t>& out, std::uint32_t value) {
    out.push_back(std::uint8_t(value >> 8));
    out.push_back(std::uint8_t(value));
}

// §7.1: PNG integers are big-endian.
void AppendBe32(std::vector<std::uint8_t>& out, std::uint32_t value) {
    AppendBe16(out, value >> 16);
    AppendBe16(out, value);
}

// §5.3: length of the data, chunk type, data, and the CRC-32 of type and data (§5.5: the
// CRC of ISO 3309 / ITU-T V.42, which is the one libdeflate_crc32 computes).
void AppendChunk(std::vector<std::uint8_t>& out, const char (&type)[5],
                 std::span<const std::uint8_t> data) {
    AppendBe32(out, std::uint32_t(data.size()));
    const std::size_t typeAt = out.size();
    out.insert(out.end(), type, type + 4);
    out.insert(out.end(), data.begin(), data.end());
    AppendBe32(out, libdeflate_crc32(0, out.data() + typeAt, 4 + data.size()));
}

// Sub (§9.2): each byte minus the byte one pixel to its left, modulo 256, the bytes left of
// the row counting as 0. A pixel is `channels` bytes at 8 bits a sample.
void SubFilterRow(const std::uint8_t* row, std::uint8_t* out, std::size_t samples,
                  std::size_t channels) {
    for (std::size_t i = 0; i < channels; ++i) out[i] = row[i];
    for (std::size_t i = channels; i < samples; ++i)
        out[i] = std::uint8_t(row[i] - row[i - channels]);
}

// As above at 16 bits a sample: each sample is two bytes, most significant first (§7.1), and
// each byte is filtered against the same byte of the sample one pixel to the left.
void SubFilterRow(const std::uint16_t* row, std::uint8_t* out, std::size_t samples,
                  std::size_t channels) {
    for (std::size_t i = 0; i < channels; ++i) {
        out[2 * i] = std::uint8_t(row[i] >> 8);
        out[2 * i + 1] = std::uint8_t(row[i]);
    }
    for (std::size_t i = channels; i < samples; ++i) {
        const unsigned sample = row[i], left = row[i - channels];
        out[2 * i] = std::uint8_t((sample >> 8) - (left >> 8));
        out[2 * i + 1] = std::uint8_t(sample - left);
    }
}

struct CompressorDeleter {
    void operator()(libdeflate_compressor* compressor) const {
        libdeflate_free_compressor(compressor);
    }
};

void CheckTime(const PngTime& t) {
    if (!PngTimeIsValid(t)) {
        throw InputError("PNG time " + std::to_string(t.year) + "-" + std::to_string(t.month) +
                         "-" + std::to_string(t.day) + " " + std::to_string(t.hour) + ":" +
                         std::to_string(t.minute) + ":" + std::to_string(t.second) +
                         " is out of range");
    }
}

template <typename Sample>
std::vector<std::uint8_t> Encode(std::span<const Sample> pixels, int width, int height,
                                 int channels, const PngInfo& info, std::size_t maxIdatLength) {
    if (width <= 0 || height <= 0 || channels < 1 || channels > 4) {
        throw InputError("PNG image size " + std::to_string(width) + "x" + std::to_string(height) +
                         "x" + std::to_string(channels) +
                         " is invalid, expected positive width and height and 1..4 channels");
    }
    const std::size_t samplesPerRow = std::size_t(width) * std::size_t(channels);
    if (pixels.size() != samplesPerRow * std::size_t(height)) {
        throw InputError("PNG pixel buffer holds " + std::to_string(pixels.size()) +
                         " samples for " + std::to_string(width) + "x" + std::to_string(height) +
                         "x" + std::to_string(channels));
    }
    if (maxIdatLength == 0 || maxIdatLength > kPngMaxChunkLength) {
        throw InputError("PNG IDAT chunk length limit " + std::to_string(maxIdatLength) +
                         " is outside 1.." + std::to_string(kPngMaxChunkLength));
    }
    CheckPngInfo(info);
    try {
        // §7.3: every row is its filter-type byte followed by the filtered bytes, and all the
        // rows form one zlib stream (§10), so they are filtered into one buffer and compressed
        // in one call.
        const std::size_t rowBytes = samplesPerRow * sizeof(Sample);
        const std::size_t filteredSize = std::size_t(height) * (1 + rowBytes);
        const auto filtered = std::make_unique_for_overwrite<std::uint8_t[]>(filteredSize);
        for (std::size_t y = 0; y < std::size_t(height); ++y) {
            std::uint8_t* out = filtered.get() + y * (1 + rowBytes);
            out[0] = kFilterSub;
            SubFilterRow(pixels.data() + y * samplesPerRow, out + 1, samplesPerRow,
                         std::size_t(channels));
        }

        // §10.1: compression method 0 is a zlib stream with a window of at most 32768 bytes,
        // the window libdeflate always uses.
        const std::unique_ptr<libdeflate_compressor, CompressorDeleter> compressor(
            libdeflate_alloc_compressor(kCompressionLevel));
        if (!compressor) throw std::bad_alloc();
        const std::size_t bound = libdeflate_zlib_compress_bound(compressor.get(), filteredSize);
        const auto stream = std::make_unique_for_overwrite<std::uint8_t[]>(bound);
        const std::size_t streamSize = libdeflate_zlib_compress(compressor.get(), filtered.get(),
                                                                filteredSize, stream.get(), bound);
        if (streamSize == 0) {
            throw RuntimeError("PNG image data of " + std::to_string(filteredSize) +
                               " bytes did not compress into libdeflate's bound of " +
                               std::to_string(bound) + " bytes");
        }

        std::vector<std::uint8_t> file;
        std::size_t textBytes = 0;
        for (const PngText& entry : info.text)
            textBytes += 13 + entry.keyword.size() + entry.text.size();
        const std::size_t idatChunks = (streamSize + maxIdatLength - 1) / maxIdatLength;
        file.reserve(8 + 25 + 19 + textBytes + streamSize + 12 * idatChunks + 12);
        file.insert(file.end(), std::begin(kSignature), std::end(kSignature));

        // §11.2.2: bit depth, colour type, compression method 0, filter method 0 (adaptive
        // filtering with the five basic types), interlace method 0 (none).
        std::vector<std::uint8_t> data;
        AppendBe32(data, std::uint32_t(width));
        AppendBe32(data, std::uint32_t(height));
        data.push_back(std::uint8_t(8 * sizeof(Sample)));
        data.push_back(kColourType[channels - 1]);
        data.push_back(0);
        data.push_back(0);
        data.push_back(0);
        AppendChunk(file, "IHDR", data);

        if (info.time) {
            data.clear();
            AppendBe16(data, std::uint32_t(info.time->year));
            for (const int field : {info.time->month, info.time->day, info.time->hour,
                                    info.time->minute, info.time->second}) {
                data.push_back(std::uint8_t(field));
            }
            AppendChunk(file, "tIME", data);
        }
        // §11.3.4.3: keyword, a NUL separator, the text (no terminating NUL).
        for (const PngText& entry : info.text) {
            data.assign(entry.keyword.begin(), entry.keyword.end());
            data.push_back(0);
            data.insert(data.end(), entry.text.begin(), entry.text.end());
            AppendChunk(file, "tEXt", data);
        }
        // §11.2.4: the zlib stream is the concatenation of consecutive IDAT chunks' data, split
        // anywhere.
        for (std::size_t at = 0; at < streamSize; at += maxIdatLength) {
            AppendChunk(file, "IDAT",
                        {stream.get() + at, std::min(maxIdatLength, streamSize - at)});
        }
        AppendChunk(file, "IEND", {});
        return file;
    } catch (const std::bad_alloc&) {
        throw RuntimeError("out of memory encoding a " + std::to_string(width) + "x" +
                           std::to_string(height) + "x" + std::to_string(channels) + " PNG");
    }
}

}  // namespace

bool PngTimeIsValid(const PngTime& t) {
    // §11.3.6.1 (second 60 is a leap second).
    return t.year >= 0 && t.year <= 65535 && t.month >= 1 && t.month <= 12 && t.day >= 1 &&
           t.day <= 31 && t.hour >= 0 && t.hour <= 23 && t.minute >= 0 && t.minute <= 59 &&
           t.second >= 0 && t.second <= 60;
}

std::string PngKeywordProblem(std::string_view keyword) {
    if (keyword.empty()) return "it is empty";
    if (keyword.size() > 79) return "it is longer than 79 bytes";
    for (const char c : keyword) {
        const unsigned byte = static_cast<unsigned char>(c);
        if (!((byte >= 32 && byte <= 126) || byte >= 161)) {
            return "it holds byte " + std::to_string(byte) +
                   ", outside the printable Latin-1 characters (32-126, 161-255)";
        }
    }
    if (keyword.front() == ' ' || keyword.back() == ' ') return "it starts or ends with a space";
    if (keyword.find("  ") != std::string_view::npos) return "it holds consecutive spaces";
    return {};
}

void CheckPngInfo(const PngInfo& info) {
    if (info.time) CheckTime(*info.time);
    for (const PngText& entry : info.text) {
        const std::string problem = PngKeywordProblem(entry.keyword);
        if (!problem.empty()) {
            throw InputError("'" + entry.keyword + "' cannot be a PNG text keyword: " + problem);
        }
        if (entry.text.find('\0') != std::string::npos) {
            throw InputError("PNG text '" + entry.keyword + "' holds a NUL byte");
        }
    }
}

std::vector<std::uint8_t> EncodePng(std::span<const std::uint8_t> pixels, int width, int height,
                                    int channels, const PngInfo& info, std::size_t maxIdatLength) {
    return Encode(pixels, width, height, channels, info, maxIdatLength);
}

std::vector<std::uint8_t> EncodePng(std::span<const std::uint16_t> pixels, int width, int height,
                                    int channels, const PngInfo& info, std::size_t maxIdatLength) {
    return Encode(pixels, width, height, channels, info, maxIdatLength);
}

}  // namespace seasense::sensors
