// Thermal frame files read back: raw counts, display and the radiometric EXR with its header.
#include "sensors/thermal/thermal_output.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "radiometry/planck/planck.h"

namespace seasense::sensors {
namespace {

namespace fs = std::filesystem;

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

TEST(ThermalOutput, WritesRawDisplayAndRadiometricFiles) {
    const fs::path folder =
        fs::path(::testing::TempDir()) / ("seasense_thermal_output_" + std::to_string(::getpid()));
    fs::remove_all(folder);
    const int w = 24, h = 16;
    ThermalImagerSettings s;
    s.width_px = w;
    s.height_px = h;
    s.opticsTransmission = 1.0;
    s.netd_K = 0.02;  // the gradient check below reads single pixels: 0.1 K is 5 σ
    s.agc.palette = Palette::Ironbow;
    ThermalImager imager(s, radiometry::Band::Lwir(), 1);
    Image scene(w, h, 1);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            scene.At(x, y)[0] =
                float(radiometry::BandRadiance(radiometry::Band::Lwir(), 280.0 + 2.0 * x));
    imager.Process(scene, 0.0);
    ThermalOutputPaths paths{folder / "raw.tif", folder / "display.png", folder / "flir.exr"};
    ImageMetadata extra;
    extra.Set("seasense:channel", std::string("flir"));
    WriteThermalFrame(imager, paths, extra);

    OIIO::ImageSpec spec;
    const std::vector<uint16_t> raw = ReadPixels<uint16_t>(paths.rawCounts, spec);
    ASSERT_EQ(raw.size(), size_t(w * h));
    EXPECT_EQ(spec.format, OIIO::TypeDesc::UINT16);
    for (size_t i = 0; i < raw.size(); ++i) ASSERT_EQ(raw[i], imager.Counts()[i]);

    const std::vector<uint8_t> display = ReadPixels<uint8_t>(paths.display, spec);
    EXPECT_EQ(spec.nchannels, 3);
    ASSERT_EQ(display.size(), imager.Display().size());
    for (size_t i = 0; i < display.size(); ++i) ASSERT_EQ(display[i], imager.Display()[i]);

    const std::vector<float> exr = ReadPixels<float>(paths.radiometricExr, spec);
    ASSERT_EQ(spec.nchannels, 2);
    EXPECT_EQ(spec.channelnames[0], "L");
    EXPECT_EQ(spec.channelnames[1], "T");
    EXPECT_EQ(spec.get_string_attribute("seasense:band"), imager.GetBand().Name());
    EXPECT_EQ(spec.get_string_attribute("seasense:channel"), "flir");
    EXPECT_FLOAT_EQ(spec.get_float_attribute("seasense:netd_K"), 0.02f);
    EXPECT_FLOAT_EQ(spec.get_float_attribute("seasense:f_number"), 1.0f);
    EXPECT_FLOAT_EQ(spec.get_float_attribute("seasense:focal_length_m"), 0.025f);
    EXPECT_FLOAT_EQ(spec.get_float_attribute("seasense:pitch_m"), 17e-6f);
    // L is the measured signal referred back through the camera equation E = τπL/(4F² + 1)
    // (Holst); T its blackbody temperature.
    const Image T = imager.ApparentTemperature();
    const radiometry::BandRadianceTable table(radiometry::Band::Lwir());
    for (int i = 0; i < w * h; ++i) {
        const double L = imager.Signal().pixels[size_t(i)] * 5.0 / (s.opticsTransmission * M_PI);
        ASSERT_NEAR(exr[size_t(2 * i)], L, 1e-6 * L);
        ASSERT_EQ(exr[size_t(2 * i + 1)], T.pixels[size_t(i)]);
        ASSERT_NEAR(T.pixels[size_t(i)], table.Temperature(exr[size_t(2 * i)]), 1e-3);
    }
    // Away from the image edges the gradient is linear in T to first order, so the blurred
    // pixels read close to their scene temperature (within the curvature of Planck's law).
    EXPECT_NEAR(T.At(12, 8)[0], 280.0 + 2.0 * 12, 0.1);
    fs::remove_all(folder);
}

}  // namespace
}  // namespace seasense::sensors
