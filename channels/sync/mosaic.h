// The run's mosaic video: every channel's display image tiled with its name, the frame number
// and the simulation time, written as MP4 through OpenCV (FFmpeg backend).
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace seasense::channels::sync {

struct MosaicTile {
    std::string name;
    int width = 0, height = 0;  // channel display image size
};

// Width of one channel's tile in the mosaic, pixels.
inline constexpr int kMosaicTileWidth = 320;

// Size of a channel's preview image for the mosaic: kMosaicTileWidth wide (or the channel's
// own width if smaller), the channel's aspect ratio kept.
void MosaicPreviewSize(int channelWidth, int channelHeight, int& width, int& height);

class MosaicVideo {
  public:
    // Tiles in reading order: one row for up to three channels, else ⌈√n⌉ columns (3 for
    // five, so that the three contiguous out-the-window channels of the default run form the
    // top row). Each
    // tile is tileWidth_px wide, images scaled to fit. Writes to a hidden temporary file in
    // the folder of path; Finish() renames it to path. RuntimeError when no MP4 encoder opens.
    MosaicVideo(const std::filesystem::path& path, const std::vector<MosaicTile>& tiles, double fps,
                int tileWidth_px = 320);
    ~MosaicVideo();  // without Finish(): the temporary file is removed
    // Adds one frame. images[i]: tile i's 8-bit RGB pixels (width·height·3), row 0 on top.
    void AddFrame(const std::vector<const uint8_t*>& images, const std::string& caption);
    // Closes the stream and renames it into place (only if at least one frame was written).
    void Finish();
    int Width() const { return width_; }
    int Height() const { return height_; }
    int64_t Frames() const { return frames_; }

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
    std::filesystem::path path_, temp_;
    std::vector<MosaicTile> tiles_;
    int columns_ = 1, tileW_ = 0, tileH_ = 0, captionH_ = 0, width_ = 0, height_ = 0;
    int64_t frames_ = 0;
};

}  // namespace seasense::channels::sync
