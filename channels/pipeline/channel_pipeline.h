// One channel end to end for a frame: render at-aperture radiance, apply the sensor model
// (detector footprint, exposure), display through OCIO and write the frame's files.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "channels/otw/otw_channel.h"
#include "scene/world/world.h"
#include "sensors/display/display_lut.h"
#include "sensors/display/ocio_display.h"

namespace seasense::channels {

struct FrameRecord {
    int64_t frame = 0;
    scene::UtcTime utc;
    double time_s = 0.0;
    double renderMs = 0.0;  // rasterize + shade
    double sensorMs = 0.0;  // detector, exposure, display
    double writeMs = 0.0;
    double exposureEv = 0.0;
    std::vector<std::filesystem::path> files;
};

class ChannelPipeline {
  public:
    // outDir: files go to outDir/<channel>/. formats ⊂ {exr, png, tiff}. ocioConfig: path of
    // the OCIO config for visible channels. Throws InputError for an unsupported channel kind.
    ChannelPipeline(const scene::World& world, const scene::ChannelSettings& channel,
                    std::filesystem::path outDir, std::vector<std::string> formats,
                    const std::filesystem::path& ocioConfig);

    // Renders frame n and writes its files atomically. Runs in the caller's oneTBB arena.
    FrameRecord RenderAndWrite(int64_t frame);

    // The two halves of RenderAndWrite, for the frame-locked run: Render takes the published
    // dynamic state, renders and applies the sensor model (record.files stays empty); Write
    // then writes the frame's files (the display transform runs at most once per frame).
    FrameRecord Render(const scene::FrameState& frame);
    void Write(FrameRecord& record);
    // The display image of the last rendered frame: 8-bit RGB, Width()×Height(), row 0 on top.
    const std::vector<uint8_t>& DisplayRgb8();
    // The last frame at a reduced size for previews (the run's mosaic): the linear sensor
    // image area-averaged to width×height, then displayed through a 3-D LUT of the channel's
    // display transform (sensors::DisplayLut, within a few code values of it); 8-bit RGB.
    std::vector<uint8_t> PreviewRgb8(int width, int height);
    int Width() const { return channel_.width; }
    int Height() const { return channel_.height; }

    const std::filesystem::path& ChannelDir() const { return channelDir_; }
    const OtwChannel& Otw() const { return *otw_; }

  private:
    const scene::World& world_;
    scene::ChannelSettings channel_;
    std::filesystem::path channelDir_;
    std::vector<std::string> formats_;
    std::unique_ptr<OtwChannel> otw_;
    std::unique_ptr<sensors::OcioDisplay> display_;
    Image samples_;
    Image pixels_;                   // the last frame's sensor image (linear)
    scene::SceneState state_;        // the last frame's scene
    double ev_ = 0.0;                // the last frame's exposure
    std::vector<uint8_t> display8_;  // display transform of pixels_, when asked for
    bool displayValid_ = false;
    std::unique_ptr<sensors::DisplayLut> previewLut_;  // built on the first preview
};

// The project's OCIO config: $SEASENSE_OCIO if set, else configs/ocio/config.ocio found
// beside the executable's source tree (compiled-in path), else next to the scenario.
std::filesystem::path DefaultOcioConfig();

}  // namespace seasense::channels
