// Image and text output: EXR/PNG/TIFF round trips with metadata, atomic replacement, clear errors;
// ImageSink, direct and in the background.
#include "sensors/output/image_writer.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <unistd.h>
#include <zlib.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "scene/core/error.h"
#include "scene/core/rng.h"
#include "sensors/output/image_sink.h"

namespace seasense::sensors {
namespace {

namespace fs = std::filesystem;

std::string ReadBytes(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Names in `folder` that look like our temporary files.
std::vector<std::string> TempFilesIn(const fs::path& folder) {
    std::vector<std::string> found;
    for (const auto& entry : fs::recursive_directory_iterator(folder)) {
        const std::string name = entry.path().filename().string();
        if (name.find(".tmp.") != std::string::npos) found.push_back(name);
    }
    return found;
}

class ImageWriterTest : public ::testing::Test {
  protected:
    void SetUp() override {
        folder_ = fs::path(::testing::TempDir()) /
                  ("seasense_image_writer_test_" + std::to_string(::getpid()) + "_" +
                   ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(folder_);
        fs::create_directories(folder_);
    }
    void TearDown() override {
        EXPECT_TRUE(TempFilesIn(folder_).empty());
        std::error_code ignored;
        fs::remove_all(folder_, ignored);
    }
    fs::path folder_;
};

template <typename T>
std::vector<T> ReadPixels(const fs::path& path, OIIO::ImageSpec& spec) {
    auto in = OIIO::ImageInput::open(path.string());
    EXPECT_TRUE(in) << OIIO::geterror();
    if (!in) return {};
    spec = in->spec();
    std::vector<T> pixels(size_t(spec.width) * spec.height * spec.nchannels);
    EXPECT_TRUE(
        in->read_image(0, 0, 0, spec.nchannels, OIIO::BaseTypeFromC<T>::value, pixels.data()));
    return pixels;
}

// Noise over many binades, with signed zero, denormals and large values: any float that
// is not stored exactly would show.
Image NoiseImage(int width, int height, int channels, uint64_t seed) {
    Image image(width, height, channels);
    for (size_t i = 0; i < image.pixels.size(); ++i) {
        const double u = scene::Uniform01(seed, 0, i);
        image.pixels[i] =
            float((u - 0.3) * std::pow(2.0, 40.0 * scene::Uniform01(seed, 1, i) - 20.0));
    }
    image.pixels[0] = -0.0f;
    image.pixels[1] = std::numeric_limits<float>::denorm_min();
    image.pixels[2] = std::numeric_limits<float>::max();
    return image;
}

TEST_F(ImageWriterTest, ExrFloatRoundTripIsBitExactWithMetadata) {
    const Image image = NoiseImage(37, 23, 3, 1);
    ImageMetadata metadata;
    metadata.Set("seasense:channel", std::string("otw-center"));
    metadata.Set("seasense:frame_index", 42);
    metadata.Set("seasense:exposure_ev", -3.25f);
    metadata.Set("seasense:fov_deg", std::vector<float>{60.0f, 45.5f});
    const std::vector<float> spectrum = {0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f, 0.7f};
    metadata.Set("seasense:band_weights", spectrum);
    metadata.Set("seasense:eyepoint_m", Vector3f{{1.5f, -2.0f, 30.25f}});
    metadata.Set("seasense:intrinsics", Matrix33f{{1, 2, 3, 4, 5, 6, 7, 8, 9}});
    Matrix44f pose;
    for (int i = 0; i < 16; ++i) pose.m[size_t(i)] = 0.5f * float(i) - 3.0f;
    metadata.Set("seasense:worldFromCamera", pose);
    metadata.Set("seasense:frame_index", 43);  // replaces, does not duplicate

    const fs::path path = folder_ / "frame.exr";
    WriteExr(path, image, metadata);

    OIIO::ImageSpec spec;
    const std::vector<float> pixels = ReadPixels<float>(path, spec);
    EXPECT_EQ(spec.format, OIIO::TypeDesc::FLOAT);
    ASSERT_EQ(spec.width, 37);
    ASSERT_EQ(spec.height, 23);
    ASSERT_EQ(spec.nchannels, 3);
    EXPECT_EQ(spec.channelnames, (std::vector<std::string>{"R", "G", "B"}));
    ASSERT_EQ(pixels.size(), image.pixels.size());
    EXPECT_EQ(std::memcmp(pixels.data(), image.pixels.data(), pixels.size() * sizeof(float)), 0);

    EXPECT_EQ(spec.get_string_attribute("compression"), "zip");
    EXPECT_EQ(spec.get_string_attribute("seasense:channel"), "otw-center");
    EXPECT_EQ(spec.get_int_attribute("seasense:frame_index"), 43);
    EXPECT_EQ(spec.get_float_attribute("seasense:exposure_ev"), -3.25f);

    // OpenEXR has no 2-float array type: two floats come back as a v2f, longer arrays as
    // a floatvector; either way the same floats in the same order.
    for (const auto& [name, values] :
         {std::pair<std::string, std::vector<float>>{"seasense:fov_deg", {60.0f, 45.5f}},
          {"seasense:band_weights", spectrum}}) {
        const OIIO::ParamValue* array = spec.find_attribute(name);
        ASSERT_NE(array, nullptr) << name;
        ASSERT_EQ(array->type().basetype, OIIO::TypeDesc::FLOAT) << name;
        ASSERT_EQ(array->type().basevalues(), values.size()) << name;
        for (size_t k = 0; k < values.size(); ++k) {
            EXPECT_EQ(static_cast<const float*>(array->data())[k], values[k]) << name;
        }
    }

    const OIIO::ParamValue* eye = spec.find_attribute("seasense:eyepoint_m");
    ASSERT_NE(eye, nullptr);
    ASSERT_TRUE(eye->type().equivalent(OIIO::TypeVector));
    const float eyeExpected[3] = {1.5f, -2.0f, 30.25f};
    for (int i = 0; i < 3; ++i) EXPECT_EQ(eye->get<float>(i), eyeExpected[i]);

    const OIIO::ParamValue* intrinsics = spec.find_attribute("seasense:intrinsics");
    ASSERT_NE(intrinsics, nullptr);
    ASSERT_EQ(intrinsics->type(), OIIO::TypeMatrix33);
    for (int i = 0; i < 9; ++i) EXPECT_EQ(intrinsics->get<float>(i), float(i + 1));

    const OIIO::ParamValue* matrix = spec.find_attribute("seasense:worldFromCamera");
    ASSERT_NE(matrix, nullptr);
    ASSERT_EQ(matrix->type(), OIIO::TypeMatrix44);
    for (int i = 0; i < 16; ++i) EXPECT_EQ(matrix->get<float>(i), pose.m[size_t(i)]);
}

TEST_F(ImageWriterTest, ExrHalfStoresHalfExactlyRepresentableValues) {
    Image image(8, 4, 3);
    // Multiples of 1/64 below 32 and a few powers of two are exact in binary16 (IEEE 754-2008
    // binary16: 11-bit significand, exponents −14…15).
    for (size_t i = 0; i < image.pixels.size(); ++i) image.pixels[i] = float(i) / 64.0f - 0.25f;
    image.pixels[5] = 1024.0f;
    image.pixels[6] = 0.0009765625f;  // 2^-10
    ExrOptions options;
    options.pixelType = ExrPixelType::Half;
    const fs::path path = folder_ / "half.exr";
    WriteExr(path, image, {}, options);
    OIIO::ImageSpec spec;
    const std::vector<float> pixels = ReadPixels<float>(path, spec);
    EXPECT_EQ(spec.format, OIIO::TypeDesc::HALF);
    EXPECT_EQ(pixels, image.pixels);
}

TEST_F(ImageWriterTest, ExrSingleChannelAndCustomNames) {
    const Image image = NoiseImage(16, 9, 1, 2);
    const fs::path path = folder_ / "thermal.exr";
    WriteExr(path, image);
    OIIO::ImageSpec spec;
    EXPECT_EQ(ReadPixels<float>(path, spec), image.pixels);
    EXPECT_EQ(spec.channelnames, std::vector<std::string>{"Y"});

    ExrOptions named;
    named.channelNames = {"radiance"};
    WriteExr(path, image, {}, named);
    ReadPixels<float>(path, spec);
    EXPECT_EQ(spec.channelnames, std::vector<std::string>{"radiance"});

    named.channelNames = {"a", "b"};
    EXPECT_THROW(WriteExr(path, image, {}, named), InputError);
}

TEST_F(ImageWriterTest, PngAndTiffRoundTrip8And16Bit) {
    const int width = 13, height = 7, channels = 3;
    std::vector<std::uint8_t> codes8(size_t(width) * height * channels);
    std::vector<std::uint16_t> codes16(codes8.size());
    for (size_t i = 0; i < codes8.size(); ++i) {
        codes8[i] = std::uint8_t(scene::HashBits(3, 0, i));
        codes16[i] = std::uint16_t(scene::HashBits(3, 1, i));
    }
    for (const std::string extension : {".png", ".tif", ".TIFF"}) {
        const fs::path path8 = folder_ / ("display8" + extension);
        WriteDisplayImage8(path8, codes8, width, height, channels);
        OIIO::ImageSpec spec;
        EXPECT_EQ(ReadPixels<std::uint8_t>(path8, spec), codes8) << extension;
        EXPECT_EQ(spec.format, OIIO::TypeDesc::UINT8);

        const fs::path path16 = folder_ / ("display16" + extension);
        WriteDisplayImage16(path16, codes16, width, height, channels);
        EXPECT_EQ(ReadPixels<std::uint16_t>(path16, spec), codes16) << extension;
        EXPECT_EQ(spec.format, OIIO::TypeDesc::UINT16);
    }
    // Single channel (FLIR/NVG display) and string metadata in a PNG text chunk.
    ImageMetadata metadata;
    metadata.Set("ImageDescription", std::string("seasense nvg"));
    const std::vector<std::uint8_t> grey(size_t(width) * height, 77);
    const fs::path greyPath = folder_ / "grey.png";
    WriteDisplayImage8(greyPath, grey, width, height, 1, metadata);
    OIIO::ImageSpec spec;
    EXPECT_EQ(ReadPixels<std::uint8_t>(greyPath, spec), grey);
    EXPECT_EQ(spec.nchannels, 1);
    EXPECT_EQ(spec.get_string_attribute("ImageDescription"), "seasense nvg");
}

// The scanlines of a PNG as stored: the zlib stream of its IDAT chunks inflated, each row its
// filter-type byte followed by the filtered bytes (PNG specification, ISO/IEC 15948 §5.3 chunk
// layout, §7.3 and §9.2 filtering).
std::vector<std::uint8_t> StoredScanlines(const fs::path& path, size_t rowBytes, size_t rows) {
    const std::string bytes = ReadBytes(path);
    const auto be32 = [&](size_t at) {
        return (uint32_t(uint8_t(bytes[at])) << 24) | (uint32_t(uint8_t(bytes[at + 1])) << 16) |
               (uint32_t(uint8_t(bytes[at + 2])) << 8) | uint32_t(uint8_t(bytes[at + 3]));
    };
    std::string idat;
    for (size_t at = 8; at + 12 <= bytes.size();) {  // after the 8-byte signature
        const size_t length = be32(at);
        if (bytes.compare(at + 4, 4, "IDAT") == 0) idat.append(bytes, at + 8, length);
        at += 12 + length;  // length, type, data, CRC
    }
    std::vector<std::uint8_t> raw(rows * (1 + rowBytes));
    uLongf size = raw.size();
    EXPECT_EQ(uncompress(raw.data(), &size, reinterpret_cast<const Bytef*>(idat.data()),
                         uLong(idat.size())),
              Z_OK);
    EXPECT_EQ(size, raw.size());
    return raw;
}

TEST_F(ImageWriterTest, PngRowsAreStoredThroughTheSubFilter) {
    const int width = 29, height = 11;
    for (const int channels : {1, 3}) {
        std::vector<std::uint8_t> codes(size_t(width) * height * size_t(channels));
        for (size_t i = 0; i < codes.size(); ++i) codes[i] = std::uint8_t(scene::HashBits(4, 0, i));
        const fs::path path = folder_ / ("sub" + std::to_string(channels) + ".png");
        WriteDisplayImage8(path, codes, width, height, channels);
        const size_t rowBytes = size_t(width) * size_t(channels);
        const std::vector<std::uint8_t> stored = StoredScanlines(path, rowBytes, size_t(height));
        for (int y = 0; y < height; ++y) {
            const std::uint8_t* row = &stored[size_t(y) * (1 + rowBytes)];
            EXPECT_EQ(row[0], 1) << "row " << y << ": filter type 1 is Sub";
            // Undoing Sub: Raw(x) = Sub(x) + Raw(x − bpp) mod 256, Raw(x) = 0 left of the row.
            for (size_t x = 0; x < rowBytes; ++x) {
                const std::uint8_t left =
                    x >= size_t(channels) ? codes[size_t(y) * rowBytes + x - size_t(channels)] : 0;
                EXPECT_EQ(std::uint8_t(row[1 + x] + left), codes[size_t(y) * rowBytes + x])
                    << "row " << y << " byte " << x;
            }
        }
    }
}

TEST_F(ImageWriterTest, RejectsUnknownExtensionAndBadSizes) {
    const std::vector<std::uint8_t> pixels(12, 0);
    EXPECT_THROW(WriteDisplayImage8(folder_ / "frame.jpg", pixels, 2, 2, 3), InputError);
    EXPECT_THROW(WriteDisplayImage8(folder_ / "frame", pixels, 2, 2, 3), InputError);
    EXPECT_THROW(WriteDisplayImage8(folder_ / "frame.png", pixels, 0, 2, 3), InputError);
    EXPECT_THROW(WriteExr(folder_ / "empty.exr", Image()), InputError);
    EXPECT_TRUE(fs::is_empty(folder_));
}

TEST_F(ImageWriterTest, CreatesMissingFolders) {
    const fs::path path = folder_ / "a" / "b" / "c" / "frame.exr";
    WriteExr(path, NoiseImage(4, 4, 3, 4));
    EXPECT_TRUE(fs::is_regular_file(path));
    WriteTextFileAtomic(folder_ / "x" / "capture.json", "{}\n");
    EXPECT_EQ(ReadBytes(folder_ / "x" / "capture.json"), "{}\n");
}

TEST_F(ImageWriterTest, ParentThatIsAFileGivesAClearRuntimeError) {
    // chmod does not stop root, so make the folder impossible instead: its parent is a file.
    const fs::path blocker = folder_ / "not_a_folder";
    std::ofstream(blocker) << "x";
    const fs::path path = blocker / "out" / "frame.exr";
    try {
        WriteExr(path, NoiseImage(4, 4, 3, 5));
        FAIL() << "expected RuntimeError";
    } catch (const RuntimeError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find(path.string()), std::string::npos) << message;
        EXPECT_NE(message.find("output folder"), std::string::npos) << message;
    }
    EXPECT_THROW(WriteTextFileAtomic(blocker / "capture.json", "{}"), RuntimeError);
    EXPECT_EQ(ReadBytes(blocker), "x");
}

TEST_F(ImageWriterTest, FailedRenameLeavesTheTargetAndNoTempFile) {
    // The final name is a non-empty folder: the temporary file is written, the rename fails.
    const fs::path target = folder_ / "frame.png";
    fs::create_directories(target);
    std::ofstream(target / "keep.txt") << "keep";
    const std::vector<std::uint8_t> pixels(12, 9);
    try {
        WriteDisplayImage8(target, pixels, 2, 2, 3);
        FAIL() << "expected RuntimeError";
    } catch (const RuntimeError& e) {
        EXPECT_NE(std::string(e.what()).find(target.string()), std::string::npos) << e.what();
    }
    EXPECT_TRUE(fs::is_directory(target));
    EXPECT_EQ(ReadBytes(target / "keep.txt"), "keep");
}

// Runs `write` while this process may write files of at most 64 kB (RLIMIT_FSIZE, POSIX
// getrlimit), so that writing more fails mid-file with EFBIG; SIGXFSZ is ignored so the failure
// reaches the writer as an error instead of ending the process. Returns the RuntimeError's
// message, or nullopt if there was none.
template <typename WriteFn>
std::optional<std::string> RuntimeErrorUnderFileSizeLimit(WriteFn&& write) {
    rlimit saved{};
    EXPECT_EQ(::getrlimit(RLIMIT_FSIZE, &saved), 0);
    const auto previousHandler = ::signal(SIGXFSZ, SIG_IGN);
    rlimit limited = saved;
    limited.rlim_cur = 64 * 1024;
    EXPECT_EQ(::setrlimit(RLIMIT_FSIZE, &limited), 0);
    std::optional<std::string> message;
    try {
        write();
    } catch (const RuntimeError& e) {
        message = e.what();
    }
    ::setrlimit(RLIMIT_FSIZE, &saved);
    ::signal(SIGXFSZ, previousHandler);
    return message;
}

TEST_F(ImageWriterTest, FailedWriteLeavesTheExistingFileUnchanged) {
    const fs::path path = folder_ / "frame.exr";
    WriteExr(path, NoiseImage(4, 4, 3, 6));
    const std::string before = ReadBytes(path);
    // A 3 MB EXR.
    const auto message =
        RuntimeErrorUnderFileSizeLimit([&] { WriteExr(path, NoiseImage(512, 512, 3, 7)); });
    ASSERT_TRUE(message);
    EXPECT_NE(message->find(path.string()), std::string::npos) << *message;
    EXPECT_EQ(ReadBytes(path), before);

    // A PNG of noise, which does not compress: 192 kB.
    const fs::path png = folder_ / "frame.png";
    WriteDisplayImage8(png, std::vector<std::uint8_t>(12, 10), 2, 2, 3);
    const std::string pngBefore = ReadBytes(png);
    std::vector<std::uint8_t> noise(256 * 256 * 3);
    for (size_t i = 0; i < noise.size(); ++i) noise[i] = std::uint8_t(scene::HashBits(9, 0, i));
    const auto pngMessage =
        RuntimeErrorUnderFileSizeLimit([&] { WriteDisplayImage8(png, noise, 256, 256, 3); });
    ASSERT_TRUE(pngMessage);
    EXPECT_NE(pngMessage->find(png.string()), std::string::npos) << *pngMessage;
    EXPECT_NE(pngMessage->find("File too large"), std::string::npos) << *pngMessage;
    EXPECT_EQ(ReadBytes(png), pngBefore);
}

TEST_F(ImageWriterTest, SuccessfulOverwriteReplacesTheFile) {
    const fs::path path = folder_ / "frame.png";
    WriteDisplayImage8(path, std::vector<std::uint8_t>(12, 10), 2, 2, 3);
    WriteDisplayImage8(path, std::vector<std::uint8_t>(12, 200), 2, 2, 3);
    OIIO::ImageSpec spec;
    EXPECT_EQ(ReadPixels<std::uint8_t>(path, spec), std::vector<std::uint8_t>(12, 200));

    const fs::path text = folder_ / "capture.json";
    WriteTextFileAtomic(text, "{\"frames\": 1}\n");
    WriteTextFileAtomic(text, "{\"frames\": 2}\n");
    EXPECT_EQ(ReadBytes(text), "{\"frames\": 2}\n");
}

TEST_F(ImageWriterTest, SameInputGivesIdenticalBytesWithoutWallClockTime) {
    // Frames must be bit-identical across runs, but OIIO stamps EXR and TIFF headers with the
    // current time unless told otherwise: the writer stores the Unix epoch, or the capture
    // time the caller gives (in a PNG's tIME chunk).
    const Image image = NoiseImage(20, 10, 3, 8);
    const std::vector<std::uint8_t> codes(20 * 10 * 3, 5);
    ImageMetadata captured;
    captured.SetCaptureTime(*scene::ParseIso8601("2024-06-01T12:34:56.789Z"));
    for (const auto& [metadata, expected] :
         {std::pair<ImageMetadata, std::string>{{}, "1970:01:01 00:00:00"},
          {captured, "2024:06:01 12:34:56"}}) {
        WriteExr(folder_ / "a.exr", image, metadata);
        WriteDisplayImage8(folder_ / "a.tif", codes, 20, 10, 3, metadata);
        WriteDisplayImage8(folder_ / "a.png", codes, 20, 10, 3, metadata);
        WriteExr(folder_ / "b.exr", image, metadata);
        WriteDisplayImage8(folder_ / "b.png", codes, 20, 10, 3, metadata);
        EXPECT_EQ(ReadBytes(folder_ / "a.exr"), ReadBytes(folder_ / "b.exr"));
        EXPECT_EQ(ReadBytes(folder_ / "a.png"), ReadBytes(folder_ / "b.png"));
        for (const char* name : {"a.exr", "a.tif", "a.png"}) {
            auto in = OIIO::ImageInput::open((folder_ / name).string());
            ASSERT_TRUE(in) << OIIO::geterror();
            EXPECT_EQ(in->spec().get_string_attribute("DateTime"), expected) << name;
        }
    }
}

// The pixels of an image file, in the type T.
template <typename T>
std::vector<T> ReadPixelsOf(const fs::path& path) {
    OIIO::ImageSpec spec;
    return ReadPixels<T>(path, spec);
}

// ImageSink: a background sink writes the same files as a direct one from copies of the pixels
// taken at the call, and its write errors surface from Finish with the file named.
TEST_F(ImageWriterTest, SinkBackgroundFilesHoldThePixelsOfTheCallAndMatchDirectWrites) {
    // Large enough that encoding a file takes milliseconds: the caller overwrites its buffers
    // while the files of the call are still queued or being written.
    constexpr int w = 320, h = 241;
    std::vector<uint8_t> rgb(size_t(w) * h * 3);
    std::vector<uint16_t> gray16(size_t(w) * h);
    Image linear(w, h, 3);
    const auto fill = [&](int k) {
        for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = uint8_t((i * 7 + size_t(k) * 31) & 255);
        for (size_t i = 0; i < gray16.size(); ++i) gray16[i] = uint16_t(i * 977 + size_t(k));
        for (size_t i = 0; i < linear.pixels.size(); ++i) linear.pixels[i] = float(i) * 0.5f + k;
    };
    ImageMetadata md;
    md.Set("seasense:channel", std::string("test"));
    ImageSink background(2), direct;
    for (int k = 0; k < 4; ++k) {
        fill(k);
        const std::string n = std::to_string(k);
        background.Display8(folder_ / ("bg" + n + ".png"), rgb, w, h, 3, md);
        background.Display16(folder_ / ("bg" + n + "_raw.png"), gray16, w, h, 1, md);
        background.Exr(folder_ / ("bg" + n + ".exr"), linear, md);
        fill(100 + k);  // the caller reuses its buffers at once
    }
    background.Finish();
    for (int k = 0; k < 4; ++k) {
        fill(k);
        const std::string n = std::to_string(k);
        direct.Display8(folder_ / ("d" + n + ".png"), rgb, w, h, 3, md);
        direct.Display16(folder_ / ("d" + n + "_raw.png"), gray16, w, h, 1, md);
        direct.Exr(folder_ / ("d" + n + ".exr"), linear, md);
        EXPECT_EQ(ReadPixelsOf<uint8_t>(folder_ / ("bg" + n + ".png")), rgb) << k;
        EXPECT_EQ(ReadPixelsOf<uint16_t>(folder_ / ("bg" + n + "_raw.png")), gray16) << k;
        EXPECT_EQ(ReadPixelsOf<float>(folder_ / ("bg" + n + ".exr")), linear.pixels) << k;
        for (const char* suffix : {".png", "_raw.png", ".exr"})
            EXPECT_EQ(ReadBytes(folder_ / ("bg" + n + suffix)),
                      ReadBytes(folder_ / ("d" + n + suffix)))
                << k << suffix;
    }
}

TEST_F(ImageWriterTest, SinkBackgroundWriteErrorSurfacesFromFinishNamingTheFile) {
    // chmod does not stop root: make the folder impossible instead, its parent is a file.
    const fs::path blocker = folder_ / "not_a_folder";
    std::ofstream(blocker) << "x";
    const fs::path bad = blocker / "out" / "frame.png";
    const std::vector<uint8_t> gray(16, 128);
    ImageSink sink(4);
    sink.Display8(bad, gray, 4, 4, 1, {});
    try {
        sink.Finish();
        FAIL() << "expected RuntimeError";
    } catch (const RuntimeError& e) {
        EXPECT_NE(std::string(e.what()).find(bad.string()), std::string::npos) << e.what();
    }
    EXPECT_NO_THROW(sink.Finish());  // reported once
    sink.Display8(folder_ / "good.png", gray, 4, 4, 1, {});
    sink.Finish();
    EXPECT_EQ(ReadPixelsOf<uint8_t>(folder_ / "good.png"), gray);
}

// The chunk types and data of a PNG file, in order (ISO/IEC 15948 §5.3).
std::vector<std::pair<std::string, std::string>> PngChunks(const fs::path& path) {
    const std::string bytes = ReadBytes(path);
    std::vector<std::pair<std::string, std::string>> chunks;
    for (size_t at = 8; at + 12 <= bytes.size();) {
        const size_t length =
            (size_t(uint8_t(bytes[at])) << 24) | (size_t(uint8_t(bytes[at + 1])) << 16) |
            (size_t(uint8_t(bytes[at + 2])) << 8) | size_t(uint8_t(bytes[at + 3]));
        chunks.emplace_back(bytes.substr(at + 4, 4), bytes.substr(at + 8, length));
        at += 12 + length;
    }
    return chunks;
}

TEST_F(ImageWriterTest, PngStoresEveryAttributeAsTextAndDateTimeInTime) {
    ImageMetadata metadata;
    metadata.Set("seasense:channel", std::string("otw-center"));
    metadata.Set("seasense:frame_index", 43);
    metadata.Set("seasense:exposure_ev", -3.25f);
    metadata.Set("seasense:fov_deg", std::vector<float>{60.0f, 45.5f});
    metadata.Set("seasense:eyepoint_m", Vector3f{{1.5f, -2.0f, 30.25f}});
    metadata.Set("seasense:intrinsics", Matrix33f{{1, 2, 3, 4, 5, 6, 7, 8, 9}});
    Matrix44f pose;
    for (int i = 0; i < 16; ++i) pose.m[size_t(i)] = 0.5f * float(i) - 3.0f;
    metadata.Set("seasense:worldFromCamera", pose);
    // Floats whose shortest decimal form needs care: each must read back as the same float.
    const std::vector<float> hard = {0.1f,
                                     1.0f / 3.0f,
                                     16777216.0f,
                                     std::numeric_limits<float>::max(),
                                     std::numeric_limits<float>::denorm_min(),
                                     -0.0f};
    metadata.Set("seasense:hard", hard);
    metadata.Set("oiio:ColorSpace", std::string("Linear Rec.709 (sRGB)"));
    metadata.Set("ImageDescription", std::string("seasense otw"));
    metadata.SetCaptureTime(*scene::ParseIso8601("2024-06-01T12:34:56.789Z"));
    const fs::path path = folder_ / "frame.png";
    WriteDisplayImage8(path, std::vector<std::uint8_t>(5 * 4 * 3, 7), 5, 4, 3, metadata);

    auto in = OIIO::ImageInput::open(path.string());
    ASSERT_TRUE(in) << OIIO::geterror();
    const OIIO::ImageSpec& spec = in->spec();
    EXPECT_EQ(spec.get_string_attribute("seasense:channel"), "otw-center");
    EXPECT_EQ(spec.get_string_attribute("seasense:frame_index"), "43");
    EXPECT_EQ(spec.get_string_attribute("seasense:exposure_ev"), "-3.25");
    EXPECT_EQ(spec.get_string_attribute("seasense:fov_deg"), "60, 45.5");
    EXPECT_EQ(spec.get_string_attribute("seasense:eyepoint_m"), "1.5, -2, 30.25");
    EXPECT_EQ(spec.get_string_attribute("seasense:intrinsics"), "1, 2, 3, 4, 5, 6, 7, 8, 9");
    EXPECT_EQ(spec.get_string_attribute("seasense:worldFromCamera"),
              "-3, -2.5, -2, -1.5, -1, -0.5, 0, 0.5, 1, 1.5, 2, 2.5, 3, 3.5, 4, 4.5");
    const std::string hardText = spec.get_string_attribute("seasense:hard");
    const char* at = hardText.c_str();
    for (const float expected : hard) {
        char* end = nullptr;
        const float value = std::strtof(at, &end);
        ASSERT_NE(end, at) << hardText;
        EXPECT_EQ(std::memcmp(&value, &expected, sizeof(float)), 0) << hardText;
        at = end;
        if (*at == ',') at += 2;
    }
    EXPECT_EQ(*at, '\0') << hardText;
    EXPECT_EQ(spec.get_string_attribute("oiio:ColorSpace"), "Linear Rec.709 (sRGB)");
    EXPECT_EQ(spec.get_string_attribute("ImageDescription"), "seasense otw");
    EXPECT_EQ(spec.get_string_attribute("DateTime"), "2024:06:01 12:34:56");

    // As OIIO's PNG writer stored them: DateTime only in tIME, ImageDescription under PNG's own
    // keyword, every attribute in the order it was set.
    std::vector<std::string> keywords;
    for (const auto& [type, data] : PngChunks(path)) {
        if (type == "tIME") {
            EXPECT_EQ(data, std::string("\x07\xe8\x06\x01\x0c\x22\x38", 7));
        }
        if (type == "tEXt") keywords.push_back(data.substr(0, data.find('\0')));
    }
    EXPECT_EQ(keywords,
              (std::vector<std::string>{
                  "seasense:channel", "seasense:frame_index", "seasense:exposure_ev",
                  "seasense:fov_deg", "seasense:eyepoint_m", "seasense:intrinsics",
                  "seasense:worldFromCamera", "seasense:hard", "oiio:ColorSpace", "Description"}));
}

TEST_F(ImageWriterTest, PngKeepsADateTimeTimeCannotHoldAsText) {
    ImageMetadata metadata;
    metadata.Set("DateTime", std::string("2024:13:01 00:00:00"));  // month 13
    const fs::path path = folder_ / "frame.png";
    WriteDisplayImage8(path, std::vector<std::uint8_t>(3, 7), 1, 1, 3, metadata);
    for (const auto& [type, data] : PngChunks(path)) EXPECT_NE(type, "tIME");
    auto in = OIIO::ImageInput::open(path.string());
    ASSERT_TRUE(in) << OIIO::geterror();
    EXPECT_EQ(in->spec().get_string_attribute("DateTime"), "2024:13:01 00:00:00");
}

TEST_F(ImageWriterTest, PngRejectsAttributesItCannotStore) {
    const std::vector<std::uint8_t> pixels(12, 0);
    for (const auto& [name, value] : {std::pair<std::string, MetadataValue>{"two  spaces", 1},
                                      {std::string(80, 'k'), 1},
                                      {"tab\tkey", 1},
                                      {"nul", std::string("a\0b", 3)},
                                      {"empty", std::vector<float>{}},
                                      {"", 1}}) {
        ImageMetadata metadata;
        metadata.Set("seasense:channel", std::string("flir"));
        metadata.Set(name, value);
        const fs::path path = folder_ / "frame.png";
        try {
            WriteDisplayImage8(path, pixels, 2, 2, 3, metadata);
            ADD_FAILURE() << "expected InputError for '" << name << "'";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
        }
        EXPECT_TRUE(fs::is_empty(folder_)) << name;
    }
}

}  // namespace
}  // namespace seasense::sensors
