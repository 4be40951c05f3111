// End-to-end tests of `seasense capture`: outputs, metadata, OCIO agreement, determinism,
// exit statuses and atomic output.
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "tests/support/shell.h"

namespace fs = std::filesystem;

namespace {

const fs::path kSource = SEASENSE_SOURCE_DIR;
const fs::path kScenario = kSource / "tests/data/scenarios/capture-small.yaml";

using Result = seasense::testing::ShellResult;
using seasense::testing::Shell;

std::string Seasense() { return std::string(SEASENSE_BINARY); }

fs::path TempDir(const std::string& name) {
    fs::path d = fs::temp_directory_path() /
                 ("seasense_capture_test_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

std::string ReadBytes(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

Result Capture(const fs::path& out, const std::string& extra) {
    return Shell(Seasense() + " capture --config " + kScenario.string() +
                 " --channel small --out " + out.string() + " " + extra);
}

TEST(Capture, WritesImagesAndCaptureJson) {
    const fs::path out = TempDir("basic");
    const Result r = Capture(out, "--frames 3 --threads 2");
    ASSERT_EQ(r.status, 0) << r.output;
    for (int f = 0; f < 3; ++f) {
        char name[64];
        std::snprintf(name, sizeof name, "small_%06d", f);
        EXPECT_TRUE(fs::exists(out / "small" / (std::string(name) + ".exr")));
        EXPECT_TRUE(fs::exists(out / "small" / (std::string(name) + ".png")));
    }
    const auto doc = nlohmann::json::parse(ReadBytes(out / "small" / "capture.json"));
    ASSERT_EQ(doc["frames"].size(), 3u);
    EXPECT_EQ(doc["seed"], 7);
    EXPECT_EQ(doc["scenario_hash"].get<std::string>().size(), 16u);
    // Frame n is at n / frame_rate simulated seconds.
    EXPECT_NEAR(doc["frames"][2]["sim_time_s"].get<double>(), 2.0 / 30.0, 1e-12);
    EXPECT_EQ(doc["frames"][1]["time_utc"], "2026-06-21T20:00:00.033Z");
    for (const auto& entry : fs::directory_iterator(out / "small"))
        EXPECT_EQ(entry.path().string().find(".tmp"), std::string::npos) << entry.path();
}

TEST(Capture, MetadataIsVisibleToOiiotool) {
    const fs::path out = TempDir("meta");
    ASSERT_EQ(Capture(out, "--frames 1 --format exr").status, 0);
    const Result info = Shell("oiiotool --info -v " + (out / "small/small_000000.exr").string());
    ASSERT_EQ(info.status, 0) << info.output;
    for (const char* key :
         {"seasense:channel", "seasense:kind", "seasense:frame_index", "seasense:time_utc",
          "seasense:exposure_ev", "seasense:hfov_deg", "seasense:camera_position_m",
          "seasense:eyepoint_position_m", "seasense:units", "seasense:camera_from_world"})
        EXPECT_NE(info.output.find(key), std::string::npos) << key << "\n" << info.output;
    EXPECT_NE(info.output.find("2026-06-21T20:00:00.000Z"), std::string::npos);
    EXPECT_NE(info.output.find("cd/m^2"), std::string::npos);
}

TEST(Capture, PngEqualsOcioconvertOfTheExposedExr) {
    const fs::path out = TempDir("ocio");
    ASSERT_EQ(Capture(out, "--frames 1").status, 0);
    const fs::path exr = out / "small/small_000000.exr";
    OIIO::ImageBuf exrBuf(exr.string());
    ASSERT_TRUE(exrBuf.read());
    const float ev = exrBuf.spec().get_float_attribute("seasense:exposure_ev", 1e9f);
    ASSERT_LT(std::abs(ev), 100.0f);
    // Apply the recorded exposure with oiiotool, then the view with OCIO's own tool.
    const fs::path scaled = out / "scaled.exr", viaOcio = out / "ocioconvert.png";
    char mul[64];
    std::snprintf(mul, sizeof mul, "%.9g", std::exp2(double(ev)));
    Result r =
        Shell("oiiotool " + exr.string() + " --mulc " + mul + " -d float -o " + scaled.string());
    ASSERT_EQ(r.status, 0) << r.output;
    r = Shell("OCIO=" + (kSource / "configs/ocio/config.ocio").string() + " ocioconvert --view " +
              scaled.string() + " 'Linear Rec.709 (sRGB)' " + viaOcio.string() +
              " sRGB 'ACES 1.0 - SDR Video'");
    ASSERT_EQ(r.status, 0) << r.output;
    OIIO::ImageBuf ours((out / "small/small_000000.png").string()), theirs(viaOcio.string());
    ASSERT_TRUE(ours.read(0, 0, true, OIIO::TypeDesc::UINT8));
    ASSERT_TRUE(theirs.read(0, 0, true, OIIO::TypeDesc::UINT8));
    ASSERT_EQ(ours.spec().width, 160);
    ASSERT_EQ(theirs.spec().width, 160);
    const auto cmp = OIIO::ImageBufAlgo::compare(ours, theirs, 1.5f / 255.0f, 1.5f / 255.0f);
    EXPECT_EQ(cmp.nfail, 0u);
    EXPECT_LE(cmp.maxerror * 255.0, 1.0 + 1e-3);
}

TEST(Capture, OutputIsBitIdenticalForOneAndTwoThreads) {
    const fs::path a = TempDir("t1"), b = TempDir("t2");
    ASSERT_EQ(Capture(a, "--frames 2 --threads 1").status, 0);
    ASSERT_EQ(Capture(b, "--frames 2 --threads 2").status, 0);
    for (const char* f :
         {"small_000000.exr", "small_000000.png", "small_000001.exr", "small_000001.png"}) {
        const std::string x = ReadBytes(a / "small" / f), y = ReadBytes(b / "small" / f);
        EXPECT_FALSE(x.empty());
        EXPECT_TRUE(x == y) << f << " differs between 1 and 2 threads";
    }
    // Successive frames differ: the sea moves.
    EXPECT_NE(ReadBytes(a / "small/small_000000.exr"), ReadBytes(a / "small/small_000001.exr"));
}

TEST(Capture, BadInputExitsWithStatusTwoAndAReadableMessage) {
    const fs::path out = TempDir("bad");
    Result r = Shell(Seasense() + " capture --config " +
                     (kSource / "tests/data/configs/bad-nan.yaml").string() +
                     " --channel x --out " + out.string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("bad-nan.yaml:"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("terminate"), std::string::npos);

    r = Capture(out, "--channel nonexistent");
    EXPECT_EQ(r.status, 2);
    r = Shell(Seasense() + " capture --config " + kScenario.string() + " --channel nope --out " +
              out.string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find("small"), std::string::npos) << "lists the available channels";
    r = Capture(out, "--frames 0");
    EXPECT_EQ(r.status, 2) << r.output;
    r = Capture(out, "--start 2026-02-30T00:00:00Z");
    EXPECT_EQ(r.status, 2) << r.output;
    r = Capture(out, "--format jpeg");
    EXPECT_EQ(r.status, 2) << r.output;
    r = Shell(Seasense() + " capture --config /nonexistent/file.yaml --channel a");
    EXPECT_EQ(r.status, 2) << r.output;
    r = Shell(Seasense() + " frobnicate");
    EXPECT_EQ(r.status, 2) << r.output;
    r = Shell(Seasense() + " capture --help");
    EXPECT_EQ(r.status, 0);
    EXPECT_NE(r.output.find("--threads"), std::string::npos);
}

TEST(Capture, UnwritableOutputIsARuntimeFailureThatLeavesNothingBehind) {
    const fs::path dir = TempDir("unwritable");
    const fs::path blocker = dir / "file";
    std::ofstream(blocker) << "not a folder";
    const Result r = Capture(blocker / "sub", "--frames 1");
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("file"), std::string::npos) << r.output;
    EXPECT_EQ(ReadBytes(blocker), "not a folder");
    size_t entries = 0;
    for (const auto& e : fs::directory_iterator(dir)) (void)e, ++entries;
    EXPECT_EQ(entries, 1u);
}

}  // namespace
