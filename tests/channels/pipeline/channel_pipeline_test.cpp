// Channel pipeline: a pipeline that warmed up on one frame renders what a new one renders, for
// the stateful sensors (FLIR bolometer lag and AGC, NVG automatic brightness control) too.
#include "channels/pipeline/channel_pipeline.h"

#include <gtest/gtest.h>

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
        for (int64_t f = 3; f <= 5; ++f) {
            fresh.Render(world.Advance(f));
            warm.Render(world.Advance(f));
            EXPECT_TRUE(FrameBytes(fresh, name) == FrameBytes(warm, name)) << "frame " << f;
        }
    }
}

}  // namespace
}  // namespace seasense::channels
