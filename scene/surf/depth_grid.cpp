// Reading and bilinear sampling of a user-supplied seabed grid.
#include "scene/surf/depth_grid.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "scene/core/check.h"
#include "scene/core/error.h"

namespace seasense::scene {

DepthGrid::DepthGrid(int width, int height, std::vector<float> values)
    : width_(width), height_(height), values_(std::move(values)) {
    CHECK(width_ >= 2 && height_ >= 2);
    CHECK(values_.size() == size_t(width_) * size_t(height_));
}

DepthGrid DepthGrid::Load(const std::filesystem::path& file) {
    const std::string name = file.string();
    auto in = OIIO::ImageInput::open(name);
    if (!in) {
        std::string why = OIIO::geterror();
        if (why.empty()) why = "cannot open";
        throw InputError(name + ": " + why);
    }
    const OIIO::ImageSpec& spec = in->spec();
    // Grids beyond 16384² (268 M cells, 1 GiB of floats) are refused rather than read.
    constexpr int kMaxSide = 16384;
    if (spec.nchannels != 1) {
        std::ostringstream out;
        out << name << ": a single-channel image is required, found " << spec.nchannels
            << " channels";
        throw InputError(out.str());
    }
    if (spec.width < 2 || spec.height < 2 || spec.width > kMaxSide || spec.height > kMaxSide ||
        spec.depth > 1) {
        std::ostringstream out;
        out << name << ": a 2-D image of 2 to " << kMaxSide
            << " pixels per side is required, found " << spec.width << " x " << spec.height;
        throw InputError(out.str());
    }
    std::vector<float> values(size_t(spec.width) * size_t(spec.height));
    if (!in->read_image(0, 0, 0, 1, OIIO::TypeDesc::FLOAT, values.data())) {
        std::string why = in->geterror();
        if (why.empty()) why = "cannot read the pixels";
        throw InputError(name + ": " + why);
    }
    for (size_t i = 0; i < values.size(); ++i) {
        if (!std::isfinite(values[i])) {
            std::ostringstream out;
            out << name << ": pixel (column " << i % size_t(spec.width) << ", row "
                << i / size_t(spec.width) << ") is not a finite number";
            throw InputError(out.str());
        }
    }
    return DepthGrid(spec.width, spec.height, std::move(values));
}

double DepthGrid::Sample(double column, double row) const {
    const double c = std::clamp(column, 0.0, double(width_ - 1));
    const double r = std::clamp(row, 0.0, double(height_ - 1));
    const int c0 = std::min(int(c), width_ - 2);
    const int r0 = std::min(int(r), height_ - 2);
    const double fc = c - c0, fr = r - r0;
    const double top = (1.0 - fc) * At(c0, r0) + fc * At(c0 + 1, r0);
    const double bottom = (1.0 - fc) * At(c0, r0 + 1) + fc * At(c0 + 1, r0 + 1);
    return (1.0 - fr) * top + fr * bottom;
}

}  // namespace seasense::scene
