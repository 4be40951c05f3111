// The preview display LUT against the exact OCIO transform it samples.
#include "sensors/display/display_lut.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <iterator>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <utility>

#include "scene/core/rng.h"

namespace seasense::sensors {
namespace {

const std::filesystem::path kConfig =
    std::filesystem::path(SEASENSE_SOURCE_DIR) / "configs/ocio/config.ocio";

TEST(DisplayLut, WithinAFewCodeValuesOfTheExactTransform) {
    const OcioDisplay exact(kConfig, "sRGB", "ACES 1.0 - SDR Video");
    const DisplayLut lut(exact);  // 65³ nodes over 2^-14 .. 2^6
    // Colours spread over 2^-12 .. 2^4 in log, plus greys, black and saturated primaries.
    Image img(4096, 1, 3);
    for (int i = 0; i < img.width; ++i) {
        float* p = img.At(i, 0);
        for (int c = 0; c < 3; ++c) {
            const double u = scene::Uniform01(5, uint64_t(c), uint64_t(i));
            p[c] = float(std::exp2(-12.0 + 16.0 * u));
        }
        if (i % 7 == 0) p[1] = p[2] = p[0];
        if (i % 11 == 0) p[1] = p[2] = 0.0f;
    }
    img.At(0, 0)[0] = img.At(0, 0)[1] = img.At(0, 0)[2] = 0.0f;
    const std::vector<uint8_t> a = exact.ToDisplay8(img, 1.0f), b = lut.ToDisplay8(img, 1.0f);
    int worst = 0;
    double sum = 0;
    for (size_t k = 0; k < a.size(); ++k) {
        const int d = std::abs(int(a[k]) - int(b[k]));
        worst = std::max(worst, d);
        sum += d;
    }
    // Measured: worst 4, mean 0.07 code values; the worst cases are saturated colours near
    // the RRT's gamut clamp, where the transform is least smooth.
    EXPECT_LE(worst, 6);
    EXPECT_LT(sum / double(a.size()), 0.15);
    // Exposure scales the input exactly as for the exact transform.
    const std::vector<uint8_t> a2 = exact.ToDisplay8(img, 0.25f), b2 = lut.ToDisplay8(img, 0.25f);
    for (size_t k = 0; k < a2.size(); ++k) EXPECT_LE(std::abs(int(a2[k]) - int(b2[k])), 6) << k;
}

// ToDisplay8 takes the grid coordinates eight (or four) pixels at a time with simd::Log2; it
// gives Apply's codes (libm log2 per value) within one code value, mostly the same, over 19
// decades and at the ends: zero, negative, NaN (the grid's lower end), tiny and huge values and
// +∞ (its top).
TEST(DisplayLut, ToDisplay8AgreesWithApplyPerPixel) {
    const OcioDisplay exact(kConfig, "sRGB", "ACES 1.0 - SDR Video");
    const DisplayLut lut(exact);
    Image img(3001, 1, 3);  // not a multiple of the lanes
    for (int i = 0; i < img.width; ++i)
        for (int c = 0; c < 3; ++c)
            img.At(i, 0)[c] =
                float(std::exp2(-40.0 + 63.0 * scene::Uniform01(6, uint64_t(c), uint64_t(i))));
    const float ends[] = {0.0f,
                          -1.0f,
                          1e-35f,
                          1e30f,
                          std::numeric_limits<float>::infinity(),
                          std::numeric_limits<float>::quiet_NaN()};
    for (size_t k = 0; k < std::size(ends); ++k) img.At(int(k), 0)[k % 3] = ends[k];
    const std::vector<uint8_t> codes = lut.ToDisplay8(img, 1.0f);
    const float lowest[3] = {0.0f, 0.0f, 0.0f};
    float low[3];
    lut.Apply(lowest, low);
    size_t same = 0;
    for (int i = 0; i < img.width; ++i) {
        float in[3], out[3];
        for (int c = 0; c < 3; ++c) {
            in[c] = img.At(i, 0)[c];
            if (std::isnan(in[c])) in[c] = 0.0f;  // NaN reads as the lower end
        }
        lut.Apply(in, out);
        for (int c = 0; c < 3; ++c) {
            const int d = std::abs(int(codes[size_t(3 * i + c)]) - int(QuantizeUnorm8(out[c])));
            ASSERT_LE(d, 1) << i << " " << c;
            same += d == 0;
        }
    }
    EXPECT_GT(same, size_t(3 * img.width) * 99 / 100);
}

// ToDisplay8 (eight pixels at a time where the build has AVX2) gives ToDisplay8Steps' codes byte
// for byte: colours over 63 octaves (below the grid's lower end to far above its top), grid
// nodes and the ends (±0, negatives, −∞, NaN, tiny and subnormal values, huge ones, +∞)
// in every lane, under several exposures, for sizes with every remainder of eight pixels.
TEST(DisplayLut, ToDisplay8EqualsItsStepsByteForByte) {
    const OcioDisplay exact(kConfig, "sRGB", "ACES 1.0 - SDR Video");
    const DisplayLut lut(exact);
    const float inf = std::numeric_limits<float>::infinity();
    const float ends[] = {0.0f,   -0.0f,   -1.0f,  -inf,  std::numeric_limits<float>::quiet_NaN(),
                          1e-30f, 1e-35f,  1e-40f, 1e30f, std::numeric_limits<float>::max(),
                          inf,    0.0625f, 64.0f,  65.0f, std::exp2(-14.0f)};
    size_t differ = 0, values = 0;
    // 307200 pixels, then 1, 18, 3, 20, 13, 6, 7 and 217: each remainder 0 .. 7 of eight.
    for (const auto& [w, h] :
         {std::pair{640, 480}, std::pair{1, 1}, std::pair{9, 2}, std::pair{3, 1}, std::pair{5, 4},
          std::pair{13, 1}, std::pair{3, 2}, std::pair{7, 1}, std::pair{31, 7}}) {
        Image img(w, h, 3);
        for (size_t k = 0; k < img.pixels.size(); ++k) {
            const uint64_t kind = uint64_t(w) * 1000003u + k;
            const double u = scene::Uniform01(7, kind, 0);
            float& v = img.pixels[k];
            if (k % 5 == 1) {  // an end, in every lane and component over the image
                v = ends[size_t(scene::Uniform01(7, kind, 1) * double(std::size(ends)))];
            } else if (k % 5 == 3) {  // a grid node, 0.3125 stop apart (64 cells over 20 stops)
                v = std::exp2(-14.0f + 0.3125f * float(int(u * 65.0)));
            } else {
                v = float(std::exp2(-40.0 + 63.0 * u));
            }
        }
        for (const float exposure : {1.0f, 0.25f, 3.7f, 1e-3f, 0.0f, -1.0f, inf}) {
            const std::vector<uint8_t> fast = lut.ToDisplay8(img, exposure);
            const std::vector<uint8_t> steps = lut.ToDisplay8Steps(img, exposure);
            ASSERT_EQ(fast.size(), steps.size());
            for (size_t k = 0; k < fast.size(); ++k) differ += fast[k] != steps[k];
            values += fast.size();
            EXPECT_EQ(std::memcmp(fast.data(), steps.data(), fast.size()), 0)
                << w << "x" << h << " exposure " << exposure;
        }
    }
    EXPECT_EQ(differ, 0u) << "of " << values;
}

// The preview's 2× downscale is OpenCV's INTER_AREA bit for bit (the preview was made with
// cv::resize before): random values over 40 octaves, the default preview size and an odd one.
TEST(DisplayLut, HalveRgbEqualsOpenCvAreaResize) {
    for (const auto& [w, h] : {std::pair{320, 240}, std::pair{17, 5}}) {
        Image src(2 * w, 2 * h, 3), ours(w, h, 3), theirs(w, h, 3);
        for (size_t i = 0; i < src.pixels.size(); ++i)
            src.pixels[i] = float(std::exp2(-20.0 + 40.0 * scene::Uniform01(3, 0, i)));
        HalveRgb(src, ours);
        const cv::Mat in(src.height, src.width, CV_32FC3, src.pixels.data());
        cv::Mat out(h, w, CV_32FC3, theirs.pixels.data());
        cv::resize(in, out, out.size(), 0, 0, cv::INTER_AREA);
        ASSERT_EQ(out.data, reinterpret_cast<uchar*>(theirs.pixels.data()));
        size_t differ = 0;
        for (size_t i = 0; i < ours.pixels.size(); ++i)
            differ += std::memcmp(&ours.pixels[i], &theirs.pixels[i], sizeof(float)) != 0;
        EXPECT_EQ(differ, 0u) << w << "x" << h;
    }
}

}  // namespace
}  // namespace seasense::sensors
