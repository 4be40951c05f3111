// A user-supplied seabed grid: a single-channel float image (read with OpenImageIO) placed on
// the ENU plane, sampled bilinearly.
#pragma once

#include <filesystem>
#include <vector>

#include "scene/surf/surf_settings.h"

namespace seasense::scene {

class DepthGrid {
  public:
    // Reads a single-channel image of finite values (any pixel type OpenImageIO converts to
    // float; TIFF, EXR, ...). Throws InputError when the file cannot be read, has more than one
    // channel, fewer than 2 × 2 pixels, or a non-finite value.
    static DepthGrid Load(const std::filesystem::path& file);
    // A grid from values in row-major order (row 0 first), width × height.
    DepthGrid(int width, int height, std::vector<float> values);

    int Width() const { return width_; }
    int Height() const { return height_; }
    float At(int column, int row) const { return values_[size_t(row) * width_ + column]; }

    // Bilinear value at continuous pixel coordinates (column, row), pixel centres on integers;
    // outside the image the border pixels extend outward.
    double Sample(double column, double row) const;

  private:
    int width_ = 0;
    int height_ = 0;
    std::vector<float> values_;
};

}  // namespace seasense::scene
