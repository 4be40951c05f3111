// Channel pipeline: a pipeline that warmed up on one frame renders what a new one renders, for
// the stateful sensors (FLIR bolometer lag and AGC, NVG automatic brightness control) too; the
// rendered scene of a frame does not depend on the frame a pipeline started at.
#include "channels/pipeline/channel_pipeline.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "scene/scenario/scenario_loader.h"

namespace seasense::channels {
namespace {

// Everything a frame leaves behind that the run and capture write or show: the display image,
// and the sensor's radiometric images (lagged radiance and ADC counts for a FLIR, photon
// radiance and screen brightness for an NVG).
std::vector<uint8_t> FrameBytes(ChannelPipeline& p, const std::string& kind) {
    std::vector<uint8_t> bytes = p.DisplayRgb8();
    const auto Append = [&](const void* data, size_t n) {
        const size_t at = bytes.size();
        bytes.resize(at + n);
        std::memcpy(bytes.data() + at, data, n);
    };
    const auto AppendImage = [&](const Image& im) {
        Append(im.pixels.data(), im.pixels.size() * sizeof(float));
    };
    if (kind == "flir") {
        AppendImage(p.Imager().Radiance());
        Append(p.Imager().Counts().data(), p.Imager().Counts().size_bytes());
    } else if (kind == "nvg") {
        AppendImage(p.GetIntensifier().PhotonRadiance());
        AppendImage(p.GetIntensifier().Brightness());
    }
    return bytes;
}

TEST(ChannelPipeline, WarmedUpPipelineRendersWhatANewOneRenders) {
    const scene::Scenario sc = scene::LoadScenario(std::filesystem::path(SEASENSE_SOURCE_DIR) /
                                                   "tests/data/scenarios/run-nvg.yaml");
    const scene::World world(sc);
    const auto out = std::filesystem::temp_directory_path();
    for (const std::string name : {"otw", "nvg", "flir"}) {
        SCOPED_TRACE(name);
        const scene::ChannelSettings& ch = *sc.FindChannel(name);
        ASSERT_EQ(ch.kind == scene::ChannelKind::Flir  ? "flir"
                  : ch.kind == scene::ChannelKind::Nvg ? "nvg"
                                                       : "otw",
                  name);
        ChannelPipeline fresh(world, ch, out, {"png"}, DefaultOcioConfig());
        ChannelPipeline warm(world, ch, out, {"png"}, DefaultOcioConfig());
        // Warmed up on the first frame it then renders, as a run's renderer is (the caches a
        // first frame fills, such as the sky table rebuilt at a quantized sun step from the
        // frame that crossed it, then hold what a new pipeline's first frame puts there).
        warm.WarmUp(world.Advance(3));
        std::vector<std::vector<uint8_t>> freshFrames;
        for (int64_t f = 3; f <= 5; ++f) {
            fresh.Render(world.Advance(f));
            warm.Render(world.Advance(f));
            freshFrames.push_back(FrameBytes(fresh, name));
            EXPECT_TRUE(freshFrames.back() == FrameBytes(warm, name)) << "frame " << f;
        }
        // Warmed up again on an earlier frame than it last rendered (a benchmark starting its
        // window over): the sensors start over as a new pipeline's, so the frames repeat.
        warm.WarmUp(world.Advance(3));
        for (int64_t f = 3; f <= 5; ++f) {
            warm.Render(world.Advance(f));
            EXPECT_TRUE(freshFrames[size_t(f - 3)] == FrameBytes(warm, name)) << "again " << f;
        }
    }
}

// The at-aperture image of frame f, whatever frame the pipeline started at: the OTW display (its
// sensor keeps no history) and the NVG's photon radiance before the intensifier's ABC. Caches
// kept between frames (the sky table, rebuilt at quantized steps of the sun's and moon's
// paths; plume fields; the occlusion BVH, refitted) must give every frame the same bits. Over
// the first frames of run-nvg.yaml the moon's sky crosses a step, and of five-channel.yaml the
// setting sun's (every ~7 frames) with the burning hulk's plume lit by it.
TEST(ChannelPipeline, FramesDoNotDependOnTheFirstFrameRendered) {
    const std::filesystem::path root(SEASENSE_SOURCE_DIR);
    struct Case {
        std::filesystem::path scenario;
        std::string channel;
        int64_t starts[3], last;
    };
    for (const Case& c : {Case{root / "tests/data/scenarios/run-nvg.yaml", "otw", {0, 2, 3}, 8},
                          Case{root / "tests/data/scenarios/run-nvg.yaml", "nvg", {0, 2, 3}, 8},
                          Case{root / "configs/five-channel.yaml", "otw-center", {0, 4, 9}, 16}}) {
        SCOPED_TRACE(c.scenario.filename().string() + " " + c.channel);
        const scene::Scenario sc = scene::LoadScenario(c.scenario);
        scene::ChannelSettings ch = *sc.FindChannel(c.channel);
        ch.width = std::min(ch.width, 160);
        ch.height = std::min(ch.height, 120);
        const scene::World world(sc);
        // Frame f's image per start, for f from the latest start on.
        std::vector<std::vector<std::vector<uint8_t>>> images;
        for (const int64_t start : c.starts) {
            ChannelPipeline p(world, ch, std::filesystem::temp_directory_path(), {"png"},
                              DefaultOcioConfig());
            images.emplace_back();
            for (int64_t f = start; f <= c.last; ++f) {
                p.Render(world.Advance(f));
                if (f < c.starts[2]) continue;
                if (ch.kind == scene::ChannelKind::Nvg) {
                    const Image& L = p.GetIntensifier().PhotonRadiance();
                    std::vector<uint8_t> bytes(L.pixels.size() * sizeof(float));
                    std::memcpy(bytes.data(), L.pixels.data(), bytes.size());
                    images.back().push_back(std::move(bytes));
                } else {
                    images.back().push_back(p.DisplayRgb8());
                }
            }
        }
        for (size_t k = 0; k < images[0].size(); ++k)
            for (size_t s = 1; s < images.size(); ++s)
                EXPECT_TRUE(images[s][k] == images[0][k])
                    << "frame " << c.starts[2] + int64_t(k) << " from start " << c.starts[s];
    }
}

// An otw channel asking for `display: lut` makes its display images through the 65³ LUT of its
// OCIO display transform: within one code value of the exact transform (OCIO's own CPU
// processor, the reference) on a frame of the five-channel demo at dusk, sky, sea, surf, the
// burning hulk's flame and smoke, but not equal to it everywhere (the option takes effect), and
// the files say which transform made them.
TEST(ChannelPipeline, OtwDisplayThroughTheLutIsWithinOneCodeOfTheExactTransform) {
    const scene::Scenario sc = scene::LoadScenario(std::filesystem::path(SEASENSE_SOURCE_DIR) /
                                                   "configs/five-channel.yaml");
    scene::ChannelSettings ch = *sc.FindChannel("otw-center");
    ch.width = 320;
    ch.height = 240;
    const scene::World world(sc);
    const std::filesystem::path out = std::filesystem::temp_directory_path() /
                                      ("seasense_pipeline_lut_" + std::to_string(getpid()));
    ch.display = scene::ChannelSettings::Display::Exact;
    ChannelPipeline exact(world, ch, out / "exact", {"png"}, DefaultOcioConfig());
    ch.display = scene::ChannelSettings::Display::Lut;
    ChannelPipeline lut(world, ch, out / "lut", {"png"}, DefaultOcioConfig());
    const scene::FrameState frame = world.Advance(120);
    exact.Render(frame);
    FrameRecord rec = lut.Render(frame);
    const std::vector<uint8_t>& a = exact.DisplayRgb8();
    const std::vector<uint8_t>& b = lut.DisplayRgb8();
    ASSERT_EQ(a.size(), b.size());
    int worst = 0;
    size_t differing = 0;
    for (size_t k = 0; k < a.size(); ++k) {
        const int d = std::abs(int(a[k]) - int(b[k]));
        worst = std::max(worst, d);
        differing += d != 0;
    }
    EXPECT_LE(worst, 1);
    // Measured at 640×480: 9 % of the values one code off (the LUT's error, ~0.05 code values
    // on average, moves values across a rounding boundary).
    EXPECT_GT(differing, 0u);
    EXPECT_LT(double(differing), 0.15 * double(a.size()));

    lut.Write(rec);
    ASSERT_EQ(rec.files.size(), 1u);
    auto in = OIIO::ImageInput::open(rec.files[0].string());
    ASSERT_TRUE(in);
    EXPECT_EQ(in->spec().get_string_attribute("seasense:display"), "lut");
    std::vector<uint8_t> written(b.size());
    ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, written.data()));
    EXPECT_TRUE(written == b);
    in->close();
    std::filesystem::remove_all(out);
}

}  // namespace
}  // namespace seasense::channels
