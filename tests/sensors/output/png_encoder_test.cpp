// PNG encoder: files that libpng (through OIIO) decodes to the same pixels, and whose chunks,
// CRCs, header fields and filtered rows are as the PNG specification says, checked with zlib.
#include "sensors/output/png_encoder.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <unistd.h>
#include <zlib.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "scene/core/error.h"
#include "scene/core/rng.h"

namespace seasense::sensors {
namespace {

namespace fs = std::filesystem;

struct Chunk {
    std::string type;
    std::vector<std::uint8_t> data;
};

std::uint32_t Be32(const std::uint8_t* at) {
    return (std::uint32_t(at[0]) << 24) | (std::uint32_t(at[1]) << 16) |
           (std::uint32_t(at[2]) << 8) | std::uint32_t(at[3]);
}

// The chunks of a PNG file (ISO/IEC 15948 §5.2 signature, §5.3 chunk layout), each CRC checked
// with zlib's crc32 (the CRC of §5.5).
std::vector<Chunk> ChunksOf(const std::vector<std::uint8_t>& file) {
    const std::uint8_t signature[8] = {137, 80, 78, 71, 13, 10, 26, 10};
    EXPECT_GE(file.size(), 8u);
    EXPECT_EQ(std::memcmp(file.data(), signature, 8), 0);
    std::vector<Chunk> chunks;
    std::size_t at = 8;
    while (at + 12 <= file.size()) {
        const std::size_t length = Be32(&file[at]);
        if (at + 12 + length > file.size()) {
            ADD_FAILURE() << "chunk at " << at << " runs past the end of the file";
            break;
        }
        Chunk chunk;
        chunk.type.assign(reinterpret_cast<const char*>(&file[at + 4]), 4);
        chunk.data.assign(file.begin() + std::ptrdiff_t(at + 8),
                          file.begin() + std::ptrdiff_t(at + 8 + length));
        const uLong crc = crc32(0L, &file[at + 4], uInt(4 + length));
        EXPECT_EQ(Be32(&file[at + 8 + length]), crc) << "CRC of " << chunk.type;
        chunks.push_back(std::move(chunk));
        at += 12 + length;
    }
    EXPECT_EQ(at, file.size()) << "bytes after the last chunk";
    return chunks;
}

// The image as OIIO (libpng underneath) reads it back from a file.
template <typename Sample>
std::vector<Sample> DecodeWithOiio(const std::vector<std::uint8_t>& file, OIIO::ImageSpec& spec) {
    const fs::path path =
        fs::path(::testing::TempDir()) /
        ("seasense_png_encoder_test_" + std::to_string(::getpid()) + "_" +
         ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".png");
    {
        std::ofstream out(path, std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(file.data()), std::streamsize(file.size()));
    }
    // PNG alpha is unassociated; by default OIIO would multiply the colour by it on reading.
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = OIIO::ImageInput::open(path.string(), &config);
    EXPECT_TRUE(in) << OIIO::geterror();
    if (!in) return {};
    spec = in->spec();
    std::vector<Sample> pixels(std::size_t(spec.width) * spec.height * spec.nchannels);
    EXPECT_TRUE(
        in->read_image(0, 0, 0, spec.nchannels, OIIO::BaseTypeFromC<Sample>::value, pixels.data()))
        << in->geterror();
    in->close();
    fs::remove(path);
    return pixels;
}

// Noise with runs of repeated pixels, so that the compressor both copies matches and stores
// literals; 16-bit samples have different high and low bytes.
template <typename Sample>
std::vector<Sample> TestPixels(int width, int height, int channels, std::uint64_t seed) {
    std::vector<Sample> pixels(std::size_t(width) * height * channels);
    for (std::size_t i = 0; i < pixels.size(); ++i) {
        const std::size_t pixel = i / std::size_t(channels);
        const bool repeat = (pixel / 5) % 3 == 0 && pixel >= 1;
        pixels[i] = repeat ? pixels[i - std::size_t(channels)]
                           : Sample(scene::HashBits(seed, std::uint64_t(channels), i));
    }
    return pixels;
}

// Checks the file's structure against its input: chunk order, IHDR fields, and the inflated
// image data row by row (filter type 1, and undoing Sub gives the input's bytes).
template <typename Sample>
void CheckStructure(const std::vector<std::uint8_t>& file, const std::vector<Sample>& pixels,
                    int width, int height, int channels) {
    const std::vector<Chunk> chunks = ChunksOf(file);
    ASSERT_GE(chunks.size(), 3u);
    EXPECT_EQ(chunks.front().type, "IHDR");
    EXPECT_EQ(chunks.back().type, "IEND");
    EXPECT_TRUE(chunks.back().data.empty());

    // §11.2.2 IHDR.
    const std::vector<std::uint8_t>& ihdr = chunks.front().data;
    ASSERT_EQ(ihdr.size(), 13u);
    EXPECT_EQ(Be32(&ihdr[0]), std::uint32_t(width));
    EXPECT_EQ(Be32(&ihdr[4]), std::uint32_t(height));
    EXPECT_EQ(ihdr[8], 8 * sizeof(Sample)) << "bit depth";
    const std::uint8_t colourTypes[4] = {0, 4, 2, 6};
    EXPECT_EQ(ihdr[9], colourTypes[channels - 1]) << "colour type";
    EXPECT_EQ(ihdr[10], 0) << "compression method";
    EXPECT_EQ(ihdr[11], 0) << "filter method";
    EXPECT_EQ(ihdr[12], 0) << "interlace method";

    // §11.2.4: the IDAT chunks are consecutive and their data concatenated is one zlib stream.
    std::vector<std::uint8_t> stream;
    int idatRuns = 0;
    for (std::size_t k = 0; k < chunks.size(); ++k) {
        if (chunks[k].type != "IDAT") continue;
        if (k == 0 || chunks[k - 1].type != "IDAT") ++idatRuns;
        stream.insert(stream.end(), chunks[k].data.begin(), chunks[k].data.end());
    }
    EXPECT_EQ(idatRuns, 1);

    const std::size_t bytesPerPixel = std::size_t(channels) * sizeof(Sample);
    const std::size_t rowBytes = std::size_t(width) * bytesPerPixel;
    // The input's bytes as PNG stores them: 16-bit samples most significant byte first (§7.1).
    std::vector<std::uint8_t> expected;
    for (const Sample s : pixels) {
        if (sizeof(Sample) == 2) expected.push_back(std::uint8_t(s >> 8));
        expected.push_back(std::uint8_t(s));
    }
    std::vector<std::uint8_t> raw(std::size_t(height) * (1 + rowBytes) + 1);
    uLongf size = raw.size();
    ASSERT_EQ(uncompress(raw.data(), &size, stream.data(), uLong(stream.size())), Z_OK);
    ASSERT_EQ(size, raw.size() - 1) << "inflated size";
    for (std::size_t y = 0; y < std::size_t(height); ++y) {
        const std::uint8_t* row = &raw[y * (1 + rowBytes)];
        EXPECT_EQ(row[0], 1) << "row " << y << ": filter type 1 is Sub";
        // §9.2: Raw(x) = Sub(x) + Raw(x − bpp) mod 256, Raw(x) = 0 left of the row.
        std::vector<std::uint8_t> unfiltered(rowBytes);
        for (std::size_t x = 0; x < rowBytes; ++x) {
            const std::uint8_t left = x >= bytesPerPixel ? unfiltered[x - bytesPerPixel] : 0;
            unfiltered[x] = std::uint8_t(row[1 + x] + left);
        }
        ASSERT_EQ(unfiltered,
                  std::vector<std::uint8_t>(expected.begin() + std::ptrdiff_t(y * rowBytes),
                                            expected.begin() + std::ptrdiff_t((y + 1) * rowBytes)))
            << "row " << y;
    }
}

struct Size {
    int width;
    int height;
};

constexpr Size kSizes[] = {{1, 1}, {1, 6}, {7, 1}, {2, 2}, {13, 5}, {31, 9}, {257, 4}};

TEST(PngEncoder, EightBitImagesDecodeToTheSamePixelsAndFollowTheFormat) {
    for (const Size size : kSizes) {
        for (int channels = 1; channels <= 4; ++channels) {
            SCOPED_TRACE(std::to_string(size.width) + "x" + std::to_string(size.height) + "x" +
                         std::to_string(channels));
            const auto pixels = TestPixels<std::uint8_t>(size.width, size.height, channels, 11);
            const std::vector<std::uint8_t> file =
                EncodePng(pixels, size.width, size.height, channels, {});
            CheckStructure(file, pixels, size.width, size.height, channels);
            OIIO::ImageSpec spec;
            EXPECT_EQ(DecodeWithOiio<std::uint8_t>(file, spec), pixels);
            EXPECT_EQ(spec.width, size.width);
            EXPECT_EQ(spec.height, size.height);
            EXPECT_EQ(spec.nchannels, channels);
            EXPECT_EQ(spec.format, OIIO::TypeDesc::UINT8);
        }
    }
}

TEST(PngEncoder, SixteenBitImagesDecodeToTheSamePixelsAndFollowTheFormat) {
    for (const Size size : kSizes) {
        for (int channels = 1; channels <= 4; ++channels) {
            SCOPED_TRACE(std::to_string(size.width) + "x" + std::to_string(size.height) + "x" +
                         std::to_string(channels));
            const auto pixels = TestPixels<std::uint16_t>(size.width, size.height, channels, 12);
            const std::vector<std::uint8_t> file =
                EncodePng(pixels, size.width, size.height, channels, {});
            CheckStructure(file, pixels, size.width, size.height, channels);
            OIIO::ImageSpec spec;
            EXPECT_EQ(DecodeWithOiio<std::uint16_t>(file, spec), pixels);
            EXPECT_EQ(spec.format, OIIO::TypeDesc::UINT16);
        }
    }
}

TEST(PngEncoder, ImageDataLongerThanTheChunkLimitIsSplitOverConsecutiveIdatChunks) {
    const int width = 40, height = 30, channels = 3;
    const auto pixels = TestPixels<std::uint8_t>(width, height, channels, 13);
    const std::vector<std::uint8_t> file = EncodePng(pixels, width, height, channels, {}, 100);
    CheckStructure(file, pixels, width, height, channels);
    int idats = 0;
    for (const Chunk& chunk : ChunksOf(file)) {
        if (chunk.type != "IDAT") continue;
        ++idats;
        EXPECT_LE(chunk.data.size(), 100u);
        EXPECT_FALSE(chunk.data.empty());
    }
    EXPECT_GT(idats, 10);
    OIIO::ImageSpec spec;
    EXPECT_EQ(DecodeWithOiio<std::uint8_t>(file, spec), pixels);
}

TEST(PngEncoder, StoresTimeAndTextChunksInOrder) {
    PngInfo info;
    info.time = PngTime{2024, 6, 1, 12, 34, 56};
    info.text = {{"seasense:channel", "otw-center"},
                 {"Description", "two\nlines"},
                 {"empty", ""},
                 {std::string(79, 'k'), "longest keyword"},
                 {"caf\xe9", "Latin-1 keyword"}};
    const std::vector<std::uint8_t> pixels(6, 9);
    const std::vector<Chunk> chunks = ChunksOf(EncodePng(pixels, 2, 1, 3, info));
    std::vector<std::string> types;
    for (const Chunk& chunk : chunks) types.push_back(chunk.type);
    EXPECT_EQ(types, (std::vector<std::string>{"IHDR", "tIME", "tEXt", "tEXt", "tEXt", "tEXt",
                                               "tEXt", "IDAT", "IEND"}));
    // §11.3.6.1: year (2 bytes), month, day, hour, minute, second.
    EXPECT_EQ(chunks[1].data, (std::vector<std::uint8_t>{0x07, 0xe8, 6, 1, 12, 34, 56}));
    // §11.3.4.3: keyword, NUL, text.
    for (std::size_t k = 0; k < info.text.size(); ++k) {
        const std::string expected = info.text[k].keyword + '\0' + info.text[k].text;
        EXPECT_EQ(std::string(chunks[2 + k].data.begin(), chunks[2 + k].data.end()), expected);
    }
    // And no tIME without a time.
    for (const Chunk& chunk : ChunksOf(EncodePng(pixels, 2, 1, 3, {}))) {
        EXPECT_NE(chunk.type, "tIME");
    }
}

TEST(PngEncoder, RejectsKeywordsTextsAndTimesPngCannotHold) {
    EXPECT_EQ(PngKeywordProblem("seasense:frame_index"), "");
    EXPECT_EQ(PngKeywordProblem("Creation Time"), "");
    EXPECT_EQ(PngKeywordProblem(std::string(79, 'a')), "");
    for (const std::string& bad :
         {std::string(), std::string(80, 'a'), std::string("a\0b", 3), std::string(" lead"),
          std::string("trail "), std::string("two  spaces"), std::string("tab\there"),
          std::string("del\x7f"), std::string("nbsp\xa0")}) {
        EXPECT_NE(PngKeywordProblem(bad), "") << bad;
        PngInfo info;
        info.text = {{bad, "x"}};
        EXPECT_THROW(CheckPngInfo(info), InputError) << bad;
        EXPECT_THROW(EncodePng(std::vector<std::uint8_t>(1, 0), 1, 1, 1, info), InputError);
    }
    PngInfo nul;
    nul.text = {{"key", std::string("a\0b", 3)}};
    EXPECT_THROW(EncodePng(std::vector<std::uint8_t>(1, 0), 1, 1, 1, nul), InputError);
    for (const PngTime t : {PngTime{2024, 0, 1, 0, 0, 0}, PngTime{2024, 13, 1, 0, 0, 0},
                            PngTime{2024, 1, 32, 0, 0, 0}, PngTime{2024, 1, 1, 24, 0, 0},
                            PngTime{2024, 1, 1, 0, 60, 0}, PngTime{2024, 1, 1, 0, 0, 61},
                            PngTime{-1, 1, 1, 0, 0, 0}, PngTime{65536, 1, 1, 0, 0, 0}}) {
        EXPECT_FALSE(PngTimeIsValid(t));
        PngInfo info;
        info.time = t;
        EXPECT_THROW(CheckPngInfo(info), InputError);
    }
    EXPECT_TRUE(PngTimeIsValid(PngTime{2016, 12, 31, 23, 59, 60}));
}

TEST(PngEncoder, RejectsBadSizes) {
    const std::vector<std::uint8_t> pixels(12, 0);
    EXPECT_THROW(EncodePng(pixels, 0, 4, 3, {}), InputError);
    EXPECT_THROW(EncodePng(pixels, 4, -1, 3, {}), InputError);
    EXPECT_THROW(EncodePng(pixels, 4, 1, 5, {}), InputError);
    EXPECT_THROW(EncodePng(pixels, 2, 2, 2, {}), InputError);  // 8 samples, not 12
    EXPECT_THROW(EncodePng(pixels, 2, 2, 3, {}, 0), InputError);
}

}  // namespace
}  // namespace seasense::sensors
