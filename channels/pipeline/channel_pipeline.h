// One channel end to end for a frame: render at-aperture radiance, apply the sensor model
// (visible: detector footprint and exposure; thermal: the thermal imager), display (OCIO for
// visible, the imager's AGC and palette for thermal) and write the frame's files.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "channels/flir/flir_channel.h"
#include "channels/nvg/nvg_channel.h"
#include "channels/otw/otw_channel.h"
#include "scene/world/world.h"
#include "sensors/display/display_lut.h"
#include "sensors/display/ocio_display.h"
#include "sensors/intensifier/intensifier.h"
#include "sensors/output/image_sink.h"
#include "sensors/thermal/thermal_imager.h"

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
    // outDir: files go to outDir/<channel>/. formats ⊂ {exr, png, tiff}, for flir channels
    // also raw_png and raw_tiff. ocioConfig: path of the OCIO config for visible channels.
    // Throws InputError for an unsupported channel kind or format.
    // Flir channels: the sensor is the channel's sensors::ThermalImager (FlirChannel::
    // ImagerSettings). Files per frame: exr, the radiometric EXR (L: band radiance at the
    // aperture as measured, W·m⁻²·sr⁻¹; T: its apparent temperature, K); png/tiff, the 8-bit
    // AGC display; raw_png/raw_tiff (<name>_raw.png/.tiff), the 16-bit raw ADC counts.
    // The imager is stateful (bolometer lag, AGC memory): its history starts, settled, at the
    // first frame this pipeline renders, and its temporal noise is keyed by the frame index;
    // so frames n0, n0 + 1, … rendered by any two pipelines from the same first frame n0 are
    // bit-identical.
    // Nvg channels: the sensor is the channel's sensors::Intensifier (stateful ABC, settled at
    // the first frame rendered, noise keyed by the frame index, as the thermal imager). Files
    // per frame: exr (L_p: photocathode-weighted photon radiance at the aperture, photons
    // s⁻¹ m⁻² sr⁻¹; B: screen brightness 0–1), png/tiff (8-bit P43 phosphor display).
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
    // From now on Write copies the frame's images and hands their files to a thread of this
    // pipeline (at most two frames' files waiting), so that the caller renders its next frame
    // while they are encoded, synced and renamed; record.writeMs is then the time of the
    // display transform and the copies. The files are the same bytes. A write error surfaces
    // from a later Write or from FinishWrites; on destruction the files handed over are
    // completed.
    void WriteInBackground();
    // Waits until every file handed over is written; rethrows the first write error.
    void FinishWrites();
    // Renders frame once and forgets it: the one-off work of a pipeline's first frame (buffers
    // allocated and first touched, tables and acceleration structures built on first use) done
    // ahead of time, so that a frame-locked run's first frame costs what the others do. The
    // sensor's history is restarted before and after, so frame may be any frame (also one
    // earlier than those already rendered) and the frames rendered next are bit for bit those
    // of a pipeline that never warmed up.
    void WarmUp(const scene::FrameState& frame);
    // The display image of the last rendered frame: 8-bit RGB, Width()×Height(), row 0 on top.
    // Otw: the channel's OCIO display transform, exact or through its 3-D LUT
    // (ChannelSettings::display).
    const std::vector<uint8_t>& DisplayRgb8();
    // The last frame at a reduced size for previews (the run's mosaic), 8-bit RGB. Visible:
    // the linear sensor image area-averaged to width×height, then displayed through a 3-D LUT
    // of the channel's display transform (sensors::DisplayLut, within a few code values of
    // it). Thermal: the imager's display frame, area-averaged.
    std::vector<uint8_t> PreviewRgb8(int width, int height);
    int Width() const { return channel_.width; }
    int Height() const { return channel_.height; }

    const std::filesystem::path& ChannelDir() const { return channelDir_; }
    // The channel renderer: Otw() for kind otw, Flir() for kind flir (CHECK-fails otherwise).
    const OtwChannel& Otw() const;
    const FlirChannel& Flir() const;
    const NvgChannel& Nvg() const;
    // Nvg channels: the image intensifier (its last frame).
    const sensors::Intensifier& GetIntensifier() const;
    // Flir channels: the thermal imager (its last frame's counts, display, measured radiance
    // and apparent temperature).
    const sensors::ThermalImager& Imager() const;

  private:
    const scene::World& world_;
    scene::ChannelSettings channel_;
    std::filesystem::path channelDir_;
    std::vector<std::string> formats_;
    const ChannelCamera& Camera() const;
    // Flir: the frame's files (Write for kind flir).
    void WriteThermal(const sensors::ImageMetadata& md, const std::string& base, FrameRecord& rec);

    std::unique_ptr<OtwChannel> otw_;
    std::unique_ptr<FlirChannel> flir_;
    std::unique_ptr<sensors::ThermalImager> imager_;  // flir
    std::unique_ptr<NvgChannel> nvg_;
    std::unique_ptr<sensors::Intensifier> intensifier_;  // nvg
    // Nvg: the frame's files (Write for kind nvg).
    void WriteNvg(const sensors::ImageMetadata& md, const std::string& base, FrameRecord& rec);
    std::unique_ptr<sensors::OcioDisplay> display_;
    Image samples_;
    Image pixels_;                   // otw: the last frame's sensor image (linear)
    scene::SceneState state_;        // the last frame's scene
    double ev_ = 0.0;                // the last frame's exposure
    std::vector<uint8_t> display8_;  // display transform of pixels_, when asked for
    bool displayValid_ = false;
    // Otw: the 3-D LUT of display_, built on first use (a preview, or display images with
    // ChannelSettings::Display::Lut).
    const sensors::DisplayLut& Lut();
    std::unique_ptr<sensors::DisplayLut> lut_;
    Image previewSmall_;       // otw: pixels_ scaled to the preview size (kept between frames)
    sensors::ImageSink sink_;  // direct, or background after WriteInBackground
};

// The project's OCIO config: $SEASENSE_OCIO if set, else configs/ocio/config.ocio found
// beside the executable's source tree (compiled-in path), else next to the scenario.
std::filesystem::path DefaultOcioConfig();

}  // namespace seasense::channels
