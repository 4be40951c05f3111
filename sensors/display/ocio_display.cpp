// Display transform of visible channels: scene-linear RGB → display RGB through an OCIO view.
#include "sensors/display/ocio_display.h"

#include <OpenColorIO/OpenColorIO.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

#include "scene/core/check.h"
#include "scene/core/error.h"

namespace OCIO = OCIO_NAMESPACE;

namespace seasense::sensors {

namespace {

// Pixels per parallel work item: large enough to amortise the per-block OCIO call, small
// enough to give both cores work on a 640×480 frame.
constexpr int kPixelsPerBlock = 16384;

std::string Quoted(const std::filesystem::path& path) { return "'" + path.string() + "'"; }

// "sRGB: [ACES 1.0 - SDR Video, Raw]; ..." for error messages.
std::string DisplaysAndViews(const OCIO::Config& config) {
    std::ostringstream out;
    for (int d = 0; d < config.getNumDisplays(); ++d) {
        const char* display = config.getDisplay(d);
        if (d > 0) out << "; ";
        out << "'" << display << "': [";
        for (int v = 0; v < config.getNumViews(display); ++v) {
            out << (v > 0 ? ", '" : "'") << config.getView(display, v) << "'";
        }
        out << "]";
    }
    if (config.getNumDisplays() == 0) out << "(none)";
    return out.str();
}

bool HasDisplay(const OCIO::Config& config, const std::string& display) {
    for (int d = 0; d < config.getNumDisplays(); ++d) {
        if (display == config.getDisplay(d)) return true;
    }
    return false;
}

bool HasView(const OCIO::Config& config, const std::string& display, const std::string& view) {
    for (int v = 0; v < config.getNumViews(display.c_str()); ++v) {
        if (view == config.getView(display.c_str(), v)) return true;
    }
    return false;
}

}  // namespace

struct OcioDisplay::Impl {
    std::string display;
    std::string view;
    std::string sceneLinear;
    OCIO::ConstCPUProcessorRcPtr cpu;
};

OcioDisplay::OcioDisplay(const std::filesystem::path& configPath, std::string display,
                         std::string view)
    : impl_(std::make_unique<Impl>()) {
    impl_->display = std::move(display);
    impl_->view = std::move(view);
    std::error_code error;
    if (!std::filesystem::is_regular_file(configPath, error)) {
        throw InputError("OCIO config " + Quoted(configPath) +
                         " does not exist or is not a regular file");
    }
    OCIO::ConstConfigRcPtr config;
    try {
        config = OCIO::Config::CreateFromFile(configPath.c_str());
        config->validate();
    } catch (const OCIO::Exception& e) {
        throw InputError("OCIO config " + Quoted(configPath) + " cannot be used: " + e.what());
    }
    const OCIO::ConstColorSpaceRcPtr sceneLinear = config->getColorSpace(OCIO::ROLE_SCENE_LINEAR);
    if (!sceneLinear) {
        throw InputError("OCIO config " + Quoted(configPath) +
                         " has no 'scene_linear' role; expected the colour space the renderer "
                         "writes");
    }
    impl_->sceneLinear = sceneLinear->getName();
    if (!HasDisplay(*config, impl_->display)) {
        throw InputError("OCIO config " + Quoted(configPath) + " has no display '" +
                         impl_->display +
                         "'; available displays and views: " + DisplaysAndViews(*config));
    }
    if (!HasView(*config, impl_->display, impl_->view)) {
        throw InputError("OCIO config " + Quoted(configPath) + " has no view '" + impl_->view +
                         "' for display '" + impl_->display +
                         "'; available displays and views: " + DisplaysAndViews(*config));
    }
    try {
        OCIO::DisplayViewTransformRcPtr transform = OCIO::DisplayViewTransform::Create();
        transform->setSrc(impl_->sceneLinear.c_str());
        transform->setDisplay(impl_->display.c_str());
        transform->setView(impl_->view.c_str());
        const OCIO::ConstProcessorRcPtr processor = config->getProcessor(transform);
        // The same bit depths and optimisation level as `ocioconvert` uses for float images
        // (OCIO 2.1 src/apps/ocioconvert/main.cpp), so our floats equal the reference tool's
        // bit for bit (tested); OPTIMIZATION_NONE would be slower and no closer to the tool.
        impl_->cpu = processor->getOptimizedCPUProcessor(OCIO::BIT_DEPTH_F32, OCIO::BIT_DEPTH_F32,
                                                         OCIO::OPTIMIZATION_DEFAULT);
    } catch (const OCIO::Exception& e) {
        throw InputError("OCIO config " + Quoted(configPath) + ": cannot build the '" +
                         impl_->display + "' / '" + impl_->view + "' transform: " + e.what());
    }
}

OcioDisplay::~OcioDisplay() = default;
OcioDisplay::OcioDisplay(OcioDisplay&&) noexcept = default;
OcioDisplay& OcioDisplay::operator=(OcioDisplay&&) noexcept = default;

Image OcioDisplay::ToDisplayFloat(const Image& sceneLinear, float exposureScale) const {
    CHECK_MSG(sceneLinear.channels == 3,
              "OcioDisplay needs an RGB image, got " << sceneLinear.channels << " channels");
    CHECK(sceneLinear.pixels.size() == size_t(sceneLinear.width) * size_t(sceneLinear.height) * 3);
    if (!std::isfinite(exposureScale) || exposureScale < 0.0f) {
        std::ostringstream message;
        message << "exposure scale must be a finite factor >= 0, found " << exposureScale;
        throw InputError(message.str());
    }
    Image display(sceneLinear.width, sceneLinear.height, 3);
    const int width = sceneLinear.width;
    if (width == 0 || sceneLinear.height == 0) return display;
    const int rowsPerBlock = std::max(1, kPixelsPerBlock / width);
    // Each pixel is transformed on its own, so the block partition cannot change any value:
    // the result is the same for every thread count.
    try {
        tbb::parallel_for(tbb::blocked_range<int>(0, sceneLinear.height, rowsPerBlock),
                          [&](const tbb::blocked_range<int>& rows) {
                              const float* in = sceneLinear.At(0, rows.begin());
                              float* out = display.At(0, rows.begin());
                              const size_t count = size_t(rows.size()) * size_t(width) * 3;
                              for (size_t i = 0; i < count; ++i) out[i] = in[i] * exposureScale;
                              OCIO::PackedImageDesc block(out, width, long(rows.size()), 3);
                              impl_->cpu->apply(block);
                          });
    } catch (const OCIO::Exception& e) {
        throw RuntimeError("OCIO display transform '" + impl_->display + "' / '" + impl_->view +
                           "' failed: " + e.what());
    }
    return display;
}

std::vector<std::uint8_t> OcioDisplay::ToDisplay8(const Image& sceneLinear,
                                                  float exposureScale) const {
    const Image display = ToDisplayFloat(sceneLinear, exposureScale);
    std::vector<std::uint8_t> codes(display.pixels.size());
    std::transform(display.pixels.begin(), display.pixels.end(), codes.begin(), QuantizeUnorm8);
    return codes;
}

std::vector<std::uint16_t> OcioDisplay::ToDisplay16(const Image& sceneLinear,
                                                    float exposureScale) const {
    const Image display = ToDisplayFloat(sceneLinear, exposureScale);
    std::vector<std::uint16_t> codes(display.pixels.size());
    std::transform(display.pixels.begin(), display.pixels.end(), codes.begin(), QuantizeUnorm16);
    return codes;
}

const std::string& OcioDisplay::Display() const { return impl_->display; }
const std::string& OcioDisplay::View() const { return impl_->view; }
const std::string& OcioDisplay::SceneLinearColorSpace() const { return impl_->sceneLinear; }

}  // namespace seasense::sensors
