// OCIO display transform: the project config, the Raw and ACES SDR views, agreement with
// ocioconvert.
#include "sensors/display/ocio_display.h"

#include <OpenColorIO/OpenColorIO.h>
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <tbb/task_arena.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "scene/core/error.h"
#include "scene/core/rng.h"
#include "sensors/output/image_writer.h"

namespace seasense::sensors {
namespace {

namespace fs = std::filesystem;
namespace OCIO = OCIO_NAMESPACE;

const fs::path kConfig = fs::path(SEASENSE_SOURCE_DIR) / "configs/ocio/config.ocio";
const std::string kDisplay = "sRGB";
const std::string kAces = "ACES 1.0 - SDR Video";
const std::string kRaw = "Raw";

// sRGB inverse EOTF (IEC 61966-2-1:1999, section 5.2): display-linear L ∈ [0, 1] → code value.
double SrgbEncode(double linear) {
    return linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}

Image Grey(const std::vector<float>& values) {
    Image image(int(values.size()), 1, 3);
    for (size_t i = 0; i < values.size(); ++i) {
        for (int c = 0; c < 3; ++c) image.At(int(i), 0)[c] = values[i];
    }
    return image;
}

bool CommandExists(const std::string& name) {
    return std::system(("command -v " + name + " > /dev/null 2>&1").c_str()) == 0;
}

// A fresh folder under the test temp dir, removed afterwards.
class TempFolder {
  public:
    TempFolder() {
        path_ = fs::path(::testing::TempDir()) /
                ("seasense_ocio_display_test_" + std::to_string(::getpid()));
        fs::remove_all(path_);
        fs::create_directories(path_);
    }
    ~TempFolder() {
        std::error_code ignored;
        fs::remove_all(path_, ignored);
    }
    const fs::path& Path() const { return path_; }

  private:
    fs::path path_;
};

TEST(OcioConfig, LoadsAndValidatesWithTheLibrary) {
    OCIO::ConstConfigRcPtr config = OCIO::Config::CreateFromFile(kConfig.c_str());
    EXPECT_NO_THROW(config->validate());
    EXPECT_STREQ(config->getColorSpace(OCIO::ROLE_SCENE_LINEAR)->getName(),
                 "Linear Rec.709 (sRGB)");
    EXPECT_STREQ(config->getColorSpace(OCIO::ROLE_REFERENCE)->getName(), "ACES2065-1");
    EXPECT_NE(config->getColorSpace("ACEScg"), nullptr);
    EXPECT_NE(config->getColorSpace("Raw"), nullptr);
    ASSERT_EQ(config->getNumViews(kDisplay.c_str()), 2);
    EXPECT_EQ(config->getView(kDisplay.c_str(), 0), kAces);
    EXPECT_EQ(config->getView(kDisplay.c_str(), 1), kRaw);
}

TEST(OcioConfig, PassesOciocheck) {
    if (!CommandExists("ociocheck")) GTEST_SKIP() << "ociocheck (opencolorio-tools) not installed";
    TempFolder folder;
    const fs::path log = folder.Path() / "ociocheck.log";
    const std::string command =
        "ociocheck --iconfig '" + kConfig.string() + "' > '" + log.string() + "' 2>&1";
    EXPECT_EQ(std::system(command.c_str()), 0);
    std::ifstream in(log);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("** Validation **\npassed"), std::string::npos) << text;
}

using Matrix3 = std::array<std::array<double, 3>, 3>;

Matrix3 Multiply(const Matrix3& a, const Matrix3& b) {
    Matrix3 m{};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            for (int k = 0; k < 3; ++k) m[i][j] += a[i][k] * b[k][j];
    return m;
}

Matrix3 Inverse(const Matrix3& a) {
    const double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
                       a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                       a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    Matrix3 m{};
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            // Cofactor of a[j][i] (transposed adjugate).
            const int r0 = (j + 1) % 3, r1 = (j + 2) % 3, c0 = (i + 1) % 3, c1 = (i + 2) % 3;
            m[i][j] = (a[r0][c0] * a[r1][c1] - a[r0][c1] * a[r1][c0]) / det;
        }
    }
    return m;
}

std::array<double, 3> Xyz(double x, double y) { return {x / y, 1.0, (1.0 - x - y) / y}; }

// XYZ-from-RGB for primaries and white given as xy chromaticities (SMPTE RP 177-1993, 3.3).
Matrix3 XyzFromRgb(const double primaries[3][2], const double white[2]) {
    Matrix3 p{};
    for (int c = 0; c < 3; ++c) {
        const std::array<double, 3> xyz = Xyz(primaries[c][0], primaries[c][1]);
        for (int r = 0; r < 3; ++r) p[r][c] = xyz[r];
    }
    const Matrix3 inverse = Inverse(p);
    const std::array<double, 3> w = Xyz(white[0], white[1]);
    for (int c = 0; c < 3; ++c) {
        const double s = inverse[c][0] * w[0] + inverse[c][1] * w[1] + inverse[c][2] * w[2];
        for (int r = 0; r < 3; ++r) p[r][c] *= s;
    }
    return p;
}

// Von Kries adaptation in the Bradford cone space (Lam 1985; matrix as in CIECAM97s).
Matrix3 BradfordAdaptation(const double from[2], const double to[2]) {
    const Matrix3 bradford = {
        {{0.8951, 0.2664, -0.1614}, {-0.7502, 1.7135, 0.0367}, {0.0389, -0.0685, 1.0296}}};
    const std::array<double, 3> src = Xyz(from[0], from[1]), dst = Xyz(to[0], to[1]);
    Matrix3 scale{};
    for (int i = 0; i < 3; ++i) {
        const double coneSrc =
            bradford[i][0] * src[0] + bradford[i][1] * src[1] + bradford[i][2] * src[2];
        const double coneDst =
            bradford[i][0] * dst[0] + bradford[i][1] * dst[1] + bradford[i][2] * dst[2];
        scale[i][i] = coneDst / coneSrc;
    }
    return Multiply(Inverse(bradford), Multiply(scale, bradford));
}

TEST(OcioConfig, LinearRec709ToAces2065IsTheBradfordAdaptedPrimaryConversion) {
    // Rec.709 primaries and D65 white: ITU-R BT.709-6, items 1.3 and 1.4. AP0 primaries and
    // the ACES white point: SMPTE ST 2065-1:2012, section 4.
    const double rec709[3][2] = {{0.640, 0.330}, {0.300, 0.600}, {0.150, 0.060}};
    const double d65[2] = {0.3127, 0.3290};
    const double ap0[3][2] = {{0.7347, 0.2653}, {0.0, 1.0}, {0.0001, -0.0770}};
    const double acesWhite[2] = {0.32168, 0.33767};
    const Matrix3 expected =
        Multiply(Inverse(XyzFromRgb(ap0, acesWhite)),
                 Multiply(BradfordAdaptation(d65, acesWhite), XyzFromRgb(rec709, d65)));

    OCIO::ConstConfigRcPtr config = OCIO::Config::CreateFromFile(kConfig.c_str());
    OCIO::ConstCPUProcessorRcPtr cpu =
        config->getProcessor("Linear Rec.709 (sRGB)", "ACES2065-1")->getDefaultCPUProcessor();
    for (int column = 0; column < 3; ++column) {
        float rgb[3] = {0.0f, 0.0f, 0.0f};
        rgb[column] = 1.0f;
        cpu->applyRGB(rgb);
        // Float processing of double matrices: a few float ulps.
        for (int row = 0; row < 3; ++row) EXPECT_NEAR(rgb[row], expected[row][column], 1e-6);
    }
}

TEST(OcioDisplay, MissingConfigNamesTheFile) {
    try {
        OcioDisplay display("/nonexistent/seasense.ocio", kDisplay, kAces);
        FAIL() << "expected InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("/nonexistent/seasense.ocio"), std::string::npos);
    }
}

TEST(OcioDisplay, BrokenConfigNamesTheFile) {
    TempFolder folder;
    const fs::path bad = folder.Path() / "broken.ocio";
    std::ofstream(bad) << "ocio_profile_version: 2.1\nroles: [this is not a map\n";
    try {
        OcioDisplay display(bad, kDisplay, kAces);
        FAIL() << "expected InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(bad.string()), std::string::npos) << e.what();
    }
}

TEST(OcioDisplay, MissingViewOrDisplayListsWhatIsAvailable) {
    for (const auto& [display, view] :
         {std::pair<std::string, std::string>{kDisplay, "Filmic"}, {"Rec.2020", kAces}}) {
        try {
            OcioDisplay ocio(kConfig, display, view);
            FAIL() << "expected InputError for " << display << " / " << view;
        } catch (const InputError& e) {
            const std::string message = e.what();
            EXPECT_NE(message.find(kConfig.string()), std::string::npos) << message;
            EXPECT_NE(message.find("'sRGB'"), std::string::npos) << message;
            EXPECT_NE(message.find("'" + kAces + "'"), std::string::npos) << message;
            EXPECT_NE(message.find("'Raw'"), std::string::npos) << message;
        }
    }
}

TEST(OcioDisplay, RawViewIsIdentity) {
    const OcioDisplay raw(kConfig, kDisplay, kRaw);
    EXPECT_EQ(raw.SceneLinearColorSpace(), "Linear Rec.709 (sRGB)");
    const std::vector<float> values = {-1.0f, 0.0f, 0.1f, 0.25f, 0.5f, 1.0f, 3.5f};
    const Image out = raw.ToDisplayFloat(Grey(values), 1.0f);
    for (size_t i = 0; i < values.size(); ++i) {
        for (int c = 0; c < 3; ++c) EXPECT_EQ(out.At(int(i), 0)[c], values[i]);
    }
    // 0.5 · 255 = 127.5 rounds to 128; the exposure factor multiplies before the view.
    EXPECT_EQ(raw.ToDisplay8(Grey({0.5f}), 1.0f)[0], 128);
    EXPECT_EQ(raw.ToDisplay8(Grey({0.25f}), 2.0f)[0], 128);
    EXPECT_EQ(raw.ToDisplay16(Grey({0.5f}), 1.0f)[0], 32768);  // 32767.5 rounds up
    EXPECT_EQ(raw.ToDisplay8(Grey({-0.2f}), 1.0f)[0], 0);
    EXPECT_EQ(raw.ToDisplay8(Grey({7.0f}), 1.0f)[0], 255);
}

TEST(OcioDisplay, QuantizationRoundsToNearestAndClamps) {
    EXPECT_EQ(QuantizeUnorm8(0.0f), 0);
    EXPECT_EQ(QuantizeUnorm8(1.0f), 255);
    EXPECT_EQ(QuantizeUnorm8(0.4f / 255.0f), 0);
    EXPECT_EQ(QuantizeUnorm8(0.6f / 255.0f), 1);
    EXPECT_EQ(QuantizeUnorm8(std::nanf("")), 0);
    EXPECT_EQ(QuantizeUnorm8(-INFINITY), 0);
    EXPECT_EQ(QuantizeUnorm8(INFINITY), 255);
    EXPECT_EQ(QuantizeUnorm16(1.0f), 65535);
    EXPECT_EQ(QuantizeUnorm16(1000.4f / 65535.0f), 1000);
}

TEST(OcioDisplay, AcesSdrMapsMidGreyToTenPercentOfPeak) {
    // ACES 1.0 output transform, aces-dev CTL (ACESlib.Tonescales.ctl, ODT.Academy.
    // RGBmonitor_100nits_dim.ctl, ACESlib.ODT_Common.ctl): the RRT + 48 nit ODT tone scale
    // maps scene 0.18 to its mid point 4.8 cd/m²; the video ODT normalises with
    // CINEMA_WHITE = 48 and CINEMA_BLACK = 0.02 cd/m², then applies the dark-to-dim surround
    // gamma 0.9811 to Y; neutrals stay neutral (glow and red modifier scale with saturation,
    // the saturation matrices preserve grey). Then sRGB encoding.
    const double relativeY = std::pow((4.8 - 0.02) / (48.0 - 0.02), 0.9811);
    const double expected = SrgbEncode(relativeY);  // ≈ 0.3560
    const OcioDisplay aces(kConfig, kDisplay, kAces);
    const Image out = aces.ToDisplayFloat(Grey({0.18f}), 1.0f);
    // OCIO evaluates the tone scale with its own fixed-function and LUT ops and fast
    // pow/log approximations: allow a quarter of an 8-bit code value.
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(out.pixels[c], expected, 0.25 / 255.0);
    // The same grey through an exposure factor: 0.09 · 2 = 0.18.
    const Image exposed = aces.ToDisplayFloat(Grey({0.09f}), 2.0f);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(exposed.pixels[c], expected, 0.25 / 255.0);
}

TEST(OcioDisplay, AcesSdrIsMonotonicBlackAtZeroAndSaturatesWhite) {
    const OcioDisplay aces(kConfig, kDisplay, kAces);
    // Neutral ramp from 0 through 1e-4 … 1e4 (8 decades, 64 steps per decade).
    std::vector<float> values = {0.0f};
    for (int i = 0; i <= 8 * 64; ++i) values.push_back(float(1e-4 * std::pow(10.0, i / 64.0)));
    const Image out = aces.ToDisplayFloat(Grey(values), 1.0f);
    for (size_t i = 1; i < values.size(); ++i) {
        for (int c = 0; c < 3; ++c) {
            EXPECT_GE(out.At(int(i), 0)[c], out.At(int(i - 1), 0)[c]) << "at " << values[i];
            // Strictly increasing through the tone scale's toe, mid and shoulder.
            if (values[i] > 0.01f && values[i] < 5.0f) {
                EXPECT_GT(out.At(int(i), 0)[c], out.At(int(i - 1), 0)[c]) << "at " << values[i];
            }
        }
    }
    // Black: the ODT subtracts CINEMA_BLACK, so scene 0 is display 0.
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(out.At(0, 0)[c], 0.0f, 1e-3f);
    const std::vector<std::uint8_t> codes = aces.ToDisplay8(Grey({0.0f, 100.0f, 1e4f}), 1.0f);
    for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(codes[c], 0);
        // The tone scale reaches the 48 cd/m² peak at 0.18 · 2^6.5 ≈ 16.3 (ODT max point):
        // anything brighter is display white.
        EXPECT_EQ(codes[3 + c], 255);
        EXPECT_EQ(codes[6 + c], 255);
    }
}

TEST(OcioDisplay, RejectsABadExposureScale) {
    const OcioDisplay aces(kConfig, kDisplay, kAces);
    for (float scale : {-1.0f, std::nanf(""), INFINITY}) {
        EXPECT_THROW(aces.ToDisplayFloat(Grey({0.18f}), scale), InputError);
    }
}

// Colour test chart: hue and exposure sweeps with out-of-gamut (negative) and > 1 values.
Image TestChart(int width, int height) {
    Image image(width, height, 3);
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            float* p = image.At(x, y);
            const double hue = 2.0 * M_PI * x / width;
            const double stops = -8.0 + 14.0 * y / (height - 1);  // 2^-8 … 2^6
            const double level = std::pow(2.0, stops);
            for (int c = 0; c < 3; ++c) {
                // Saturation above 1 makes components negative: outside the Rec.709 gamut.
                const double saturation = 1.3 * x / (width - 1);
                const double chroma = std::cos(hue - 2.0 * M_PI * c / 3.0);
                p[c] = float(level * (1.0 + saturation * chroma));
            }
        }
    }
    // A few random pixels over the full range, and pure primaries.
    for (int i = 0; i < width; ++i) {
        float* p = image.At(i, height / 2);
        for (int c = 0; c < 3; ++c) {
            p[c] = float(-0.5 + 20.0 * scene::Uniform01(7, uint64_t(c), uint64_t(i)));
        }
    }
    for (int c = 0; c < 3; ++c) {
        float* p = image.At(c, 0);
        p[0] = p[1] = p[2] = 0.0f;
        p[c] = 1.0f;
    }
    return image;
}

TEST(OcioDisplay, MatchesOcioconvertWithinOneCodeValue) {
    if (!CommandExists("ocioconvert"))
        GTEST_SKIP() << "ocioconvert (opencolorio-tools) not installed";
    TempFolder folder;
    const Image chart = TestChart(96, 64);
    const fs::path input = folder.Path() / "chart.exr";
    WriteExr(input, chart);
    const OcioDisplay aces(kConfig, kDisplay, kAces);

    // ocioconvert reads $OCIO, processes the float pixels and lets OIIO convert to the
    // output file's type: uint8 for PNG (v·255 + 0.5, truncated), float for EXR.
    for (const std::string extension : {".png", ".exr"}) {
        const fs::path output = folder.Path() / ("reference" + extension);
        const std::string command = "OCIO='" + kConfig.string() + "' ocioconvert --view '" +
                                    input.string() + "' 'Linear Rec.709 (sRGB)' '" +
                                    output.string() + "' sRGB '" + kAces + "' > '" +
                                    (folder.Path() / "ocioconvert.log").string() + "' 2>&1";
        ASSERT_EQ(std::system(command.c_str()), 0) << command;
        auto in = OIIO::ImageInput::open(output.string());
        ASSERT_TRUE(in) << OIIO::geterror();
        const OIIO::ImageSpec& spec = in->spec();
        ASSERT_EQ(spec.width, chart.width);
        ASSERT_EQ(spec.height, chart.height);
        ASSERT_EQ(spec.nchannels, 3);
        if (extension == ".png") {
            ASSERT_EQ(spec.format, OIIO::TypeDesc::UINT8);
            std::vector<std::uint8_t> reference(chart.pixels.size());
            ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, reference.data()));
            const std::vector<std::uint8_t> ours = aces.ToDisplay8(chart, 1.0f);
            int maxDifference = 0;
            for (size_t i = 0; i < ours.size(); ++i) {
                maxDifference = std::max(maxDifference, std::abs(int(ours[i]) - reference[i]));
            }
            EXPECT_LE(maxDifference, 1);
        } else {
            std::vector<float> reference(chart.pixels.size());
            ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, reference.data()));
            const Image ours = aces.ToDisplayFloat(chart, 1.0f);
            double maxDifference = 0.0;
            for (size_t i = 0; i < reference.size(); ++i) {
                maxDifference =
                    std::max(maxDifference, double(std::abs(ours.pixels[i] - reference[i])));
            }
            // Within one 16-bit code value, so 16-bit output agrees with the tool too.
            EXPECT_LE(maxDifference, 1.0 / 65535.0);
        }
    }
}

TEST(OcioDisplay, ResultDoesNotDependOnThreadCount) {
    const Image chart = TestChart(300, 200);  // several row blocks
    const OcioDisplay aces(kConfig, kDisplay, kAces);
    Image one, two;
    tbb::task_arena(1).execute([&] { one = aces.ToDisplayFloat(chart, 1.5f); });
    tbb::task_arena(2).execute([&] { two = aces.ToDisplayFloat(chart, 1.5f); });
    ASSERT_EQ(one.pixels.size(), two.pixels.size());
    EXPECT_EQ(std::memcmp(one.pixels.data(), two.pixels.data(), one.pixels.size() * sizeof(float)),
              0);
}

}  // namespace
}  // namespace seasense::sensors
