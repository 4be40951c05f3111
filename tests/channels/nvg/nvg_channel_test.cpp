// NVG channel: shipped scenarios' intensifiers resolve; a lightning flash washes the goggle out
// through the ABC's lag and the image recovers; the moonless night sky is NIR-bright.
#include "channels/nvg/nvg_channel.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "channels/pipeline/channel_pipeline.h"
#include "radiometry/bands/builtin_bands.h"
#include "scene/scenario/scenario_loader.h"

namespace seasense::channels {
namespace {

const std::filesystem::path kConfigs = std::filesystem::path(SEASENSE_SOURCE_DIR) / "configs";

TEST(NvgChannel, EveryShippedNvgChannelResolvesItsIntensifier) {
    int nvg = 0;
    for (const auto& entry : std::filesystem::directory_iterator(kConfigs)) {
        if (entry.path().extension() != ".yaml" || entry.path().filename() == "materials.yaml")
            continue;
        SCOPED_TRACE(entry.path().string());
        const scene::Scenario sc = scene::LoadScenario(entry.path());
        for (const scene::ChannelSettings& ch : sc.channels) {
            if (ch.kind != scene::ChannelKind::Nvg) continue;
            const sensors::IntensifierSettings s = ResolveIntensifier(ch, sc);
            EXPECT_EQ(s.width_px, ch.width);
            EXPECT_GT(s.FocalLength_m(), 0.0);
            ++nvg;
        }
    }
    EXPECT_GE(nvg, 2);  // nvg.yaml and five-channel.yaml
}

// Mean screen brightness over the field stop.
double FieldBrightness(const sensors::Intensifier& t) {
    const Image& b = t.Brightness();
    double sum = 0.0;
    int n = 0;
    for (int y = 0; y < b.height; ++y)
        for (int x = 0; x < b.width; ++x)
            if (t.InField(x, y)) {
                sum += *b.At(x, y);
                ++n;
            }
    return sum / n;
}

// A flash in the field of view (the storm 9 km out, bolts below the frame's top): the
// photocathode's photon flux jumps for the flash's frames, the screen brightens while the
// ABC lags, and the image returns to its level once the flash has decayed.
TEST(NvgChannel, LightningFlashRaisesThePhotonFluxThenTheImageRecovers) {
    const scene::Scenario sc = scene::LoadScenario(kConfigs / "nvg.yaml");
    scene::ChannelSettings ch = *sc.FindChannel("nvg");
    ch.width = 160;
    ch.height = 120;
    const scene::World world(sc);
    const scene::Lightning* lightning = world.GetLightning();
    ASSERT_NE(lightning, nullptr);
    const double frame_s = sc.world.timeScale / sc.world.frameRate_hz;
    const std::vector<scene::Flash> flashes = lightning->FlashesBetween(10 * frame_s, 600.0);
    ASSERT_FALSE(flashes.empty());
    const int64_t flashFrame = int64_t(std::ceil(flashes[0].start_s / frame_s));
    // Frames without any flash light: the last one before, and one well after the flash.
    int64_t after = int64_t(std::ceil(flashes[0].end_s / frame_s)) + 30;
    ASSERT_TRUE(lightning->FlashesBetween((after - 1) * frame_s, after * frame_s).empty());
    ChannelPipeline p(world, ch, std::filesystem::temp_directory_path(), {"png"},
                      DefaultOcioConfig());
    const int64_t first = flashFrame - 5;
    double peBefore = 0.0, levelBefore = 0.0, peFlash = 0.0, levelFlash = 0.0;
    for (int64_t f = first; f <= after; ++f) {
        p.Render(world.Advance(f));
        const sensors::Intensifier& t = p.GetIntensifier();
        if (f == flashFrame - 1) {
            peBefore = t.MeanPhotoelectrons();
            levelBefore = FieldBrightness(t);
        }
        if (f == flashFrame) {
            peFlash = t.MeanPhotoelectrons();
            levelFlash = FieldBrightness(t);
        }
    }
    EXPECT_GT(peFlash, 1.2 * peBefore);
    EXPECT_GT(levelFlash, levelBefore);
    EXPECT_NEAR(FieldBrightness(p.GetIntensifier()) / levelBefore, 1.0, 0.05);
}

// Published night-sky colours through the photocathode: the moonless sky (airglow) gives a
// Gen III tube more photons per lux than moonlight does (Benn & Ellison 1998 vs Kieffer &
// Stone 2005), and moonlight more than sunlight.
TEST(NvgChannel, BandBasisFollowsSourceColours) {
    const scene::Scenario sc = scene::LoadScenario(kConfigs / "nvg.yaml");
    const scene::World world(sc);
    const radiometry::PhotonResponse r(radiometry::NvgGen3());
    const OtwBandBasis b = NvgBandBasis(world, r);
    const auto total = [](const glm::dvec3& v) { return v.x + v.y + v.z; };
    EXPECT_GT(total(b.sky.night), total(b.moon));
    EXPECT_GT(total(b.moon), total(b.sun));
    ASSERT_EQ(b.reflectance.size(), world.State(0).entities.size());
}

}  // namespace
}  // namespace seasense::channels
