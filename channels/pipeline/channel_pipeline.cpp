// Channel pipeline: the sensor owns the pixel, so radiance samples become pixels only here.
#include "channels/pipeline/channel_pipeline.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <opencv2/imgproc.hpp>

#include "scene/core/error.h"
#include "sensors/detector/detector.h"
#include "sensors/output/image_writer.h"

#ifndef SEASENSE_SOURCE_DIR
#define SEASENSE_SOURCE_DIR "."
#endif

namespace seasense::channels {

namespace {

double MsSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

const char* KindName(scene::ChannelKind k) {
    switch (k) {
        case scene::ChannelKind::Otw:
            return "otw";
        case scene::ChannelKind::Flir:
            return "flir";
        case scene::ChannelKind::Nvg:
            return "nvg";
    }
    return "?";
}

sensors::Matrix44f RowMajor(const glm::dmat4& m) {
    sensors::Matrix44f out;
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) out.m[size_t(r * 4 + c)] = float(m[c][r]);
    return out;
}

sensors::ImageMetadata FrameMetadata(const scene::World& world, const scene::ChannelSettings& ch,
                                     const scene::SceneState& state, const ChannelCamera& cam,
                                     double ev) {
    const scene::Scenario& sc = world.GetScenario();
    sensors::ImageMetadata md;
    md.SetCaptureTime(state.utc);
    md.Set("seasense:channel", ch.name);
    md.Set("seasense:kind", std::string(KindName(ch.kind)));
    md.Set("seasense:frame_index", int(state.frame));
    md.Set("seasense:time_utc", scene::FormatIso8601(state.utc));
    md.Set("seasense:sim_time_s", float(state.time_s));
    md.Set("seasense:scenario_hash", sc.hash);
    md.Set("seasense:seed", std::to_string(sc.world.seed));
    const glm::dvec3 eye = state.eyepoint.position_m;
    md.Set("seasense:eyepoint_position_m",
           sensors::Vector3f{{float(eye.x), float(eye.y), float(eye.z)}});
    const glm::dvec3 cp = cam.worldFromCamera.position_m;
    md.Set("seasense:camera_position_m",
           sensors::Vector3f{{float(cp.x), float(cp.y), float(cp.z)}});
    sensors::Matrix33f rot;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            rot.m[size_t(r * 3 + c)] = float(cam.worldFromCamera.worldFromBody[c][r]);
    md.Set("seasense:world_from_camera_rotation", rot);
    md.Set("seasense:frame", std::string("world ENU (x east, y north, z up), origin lat ") +
                                 std::to_string(sc.world.latitude_deg) + " lon " +
                                 std::to_string(sc.world.longitude_deg) +
                                 "; camera body x right, y forward, z up");
    md.Set("seasense:hfov_deg", float(cam.hfov_rad * 180.0 / M_PI));
    md.Set("seasense:vfov_deg", float(2.0 * std::atan(cam.TanHalfV()) * 180.0 / M_PI));
    md.Set("seasense:supersampling", cam.supersampling);
    if (ch.kind == scene::ChannelKind::Otw) {
        md.Set("seasense:units", std::string("cd/m^2 (linear Rec.709 D65 RGB; Y = luminance)"));
        md.Set("seasense:exposure_ev", float(ev));
        md.Set("seasense:exposure_mode",
               std::string(ch.exposure.mode == scene::ExposureMode::Auto ? "auto" : "manual"));
        md.Set("seasense:ocio_view", ch.ocioView);
        md.Set("oiio:ColorSpace", std::string("Linear Rec.709 (sRGB)"));
    }
    // Row-major, column-vector convention: p_camera = M · (p_world, 1).
    glm::dmat4 worldFromCamera(cam.worldFromCamera.worldFromBody);
    worldFromCamera[3] = glm::dvec4(cam.worldFromCamera.position_m, 1.0);
    md.Set("seasense:camera_from_world", RowMajor(glm::inverse(worldFromCamera)));
    return md;
}

}  // namespace

std::filesystem::path DefaultOcioConfig() {
    if (const char* env = std::getenv("SEASENSE_OCIO"); env && *env) return env;
    return std::filesystem::path(SEASENSE_SOURCE_DIR) / "configs" / "ocio" / "config.ocio";
}

ChannelPipeline::ChannelPipeline(const scene::World& world, const scene::ChannelSettings& channel,
                                 std::filesystem::path outDir, std::vector<std::string> formats,
                                 const std::filesystem::path& ocioConfig)
    : world_(world),
      channel_(channel),
      channelDir_(std::move(outDir) / channel.name),
      formats_(std::move(formats)) {
    if (channel_.kind == scene::ChannelKind::Flir) {
        flir_ = std::make_unique<FlirChannel>(world_, channel_);
        return;
    }
    if (channel_.kind != scene::ChannelKind::Otw)
        throw InputError("channel '" + channel_.name + "': kind '" + KindName(channel_.kind) +
                         "' is not available yet; this build renders kinds 'otw' and 'flir'");
    otw_ = std::make_unique<OtwChannel>(world_, channel_);
    display_ = std::make_unique<sensors::OcioDisplay>(ocioConfig, "sRGB", channel_.ocioView);
}

const OtwChannel& ChannelPipeline::Otw() const {
    CHECK(otw_);
    return *otw_;
}

const FlirChannel& ChannelPipeline::Flir() const {
    CHECK(flir_);
    return *flir_;
}

const ChannelCamera& ChannelPipeline::Camera() const {
    return flir_ ? flir_->Camera() : otw_->Camera();
}

std::vector<uint8_t> ChannelPipeline::WhiteHot8(const Image& temperature, double lo_K,
                                                double hi_K) {
    const size_t n = size_t(temperature.width) * size_t(temperature.height);
    std::vector<uint8_t> rgb(3 * n);
    // A uniform frame has no contrast to stretch: show it mid-grey.
    const double scale = hi_K > lo_K ? 255.0 / (hi_K - lo_K) : 0.0;
    for (size_t i = 0; i < n; ++i) {
        const double v = scale > 0.0 ? (double(temperature.pixels[i]) - lo_K) * scale : 127.5;
        const uint8_t q = uint8_t(std::lround(std::clamp(v, 0.0, 255.0)));
        rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] = q;
    }
    return rgb;
}

FrameRecord ChannelPipeline::RenderAndWrite(int64_t frame) {
    FrameRecord rec = Render(world_.Advance(frame));
    Write(rec);
    return rec;
}

FrameRecord ChannelPipeline::Render(const scene::FrameState& frame) {
    FrameRecord rec;
    state_ = world_.Compose(frame);
    rec.frame = state_.frame;
    rec.utc = state_.utc;
    rec.time_s = state_.time_s;

    auto t0 = std::chrono::steady_clock::now();
    if (flir_) {
        flir_->Render(state_, samples_);
        rec.renderMs = MsSince(t0);
        t0 = std::chrono::steady_clock::now();
        sensors::IntegrateFootprint(samples_, channel_.supersampling, pixels_);
        if (temperature_.width != pixels_.width || temperature_.height != pixels_.height)
            temperature_ = Image(pixels_.width, pixels_.height, 1);
        const radiometry::BandRadianceTable& table = flir_->RadianceTable();
        const int w = pixels_.width;
        tbb::parallel_for(0, pixels_.height, [&](int y) {
            const float* L = pixels_.At(0, y);
            float* T = temperature_.At(0, y);
            for (int x = 0; x < w; ++x) T[x] = float(table.Temperature(double(L[x])));
        });
        const auto [lo, hi] =
            std::minmax_element(temperature_.pixels.begin(), temperature_.pixels.end());
        minT_K_ = *lo;
        maxT_K_ = *hi;
        displayValid_ = false;
        rec.sensorMs = MsSince(t0);
        return rec;
    }
    otw_->Render(state_, samples_);
    rec.renderMs = MsSince(t0);

    t0 = std::chrono::steady_clock::now();
    sensors::IntegrateFootprint(samples_, channel_.supersampling, pixels_);
    ev_ = channel_.exposure.mode == scene::ExposureMode::Auto
              ? sensors::AutoExposureEv(pixels_, channel_.exposure.keyValue)
              : channel_.exposure.ev;
    rec.exposureEv = ev_;
    displayValid_ = false;
    rec.sensorMs = MsSince(t0);
    return rec;
}

const std::vector<uint8_t>& ChannelPipeline::DisplayRgb8() {
    if (!displayValid_) {
        display8_ = flir_ ? WhiteHot8(temperature_, minT_K_, maxT_K_)
                          : display_->ToDisplay8(pixels_, float(std::exp2(ev_)));
        displayValid_ = true;
    }
    return display8_;
}

std::vector<uint8_t> ChannelPipeline::PreviewRgb8(int width, int height) {
    CHECK(width > 0 && height > 0);
    if (flir_) {
        // The frame's own display range, so the preview matches the full-size display.
        if (width == temperature_.width && height == temperature_.height)
            return WhiteHot8(temperature_, minT_K_, maxT_K_);
        Image small(width, height, 1);
        const cv::Mat src(temperature_.height, temperature_.width, CV_32FC1,
                          const_cast<float*>(temperature_.pixels.data()));
        cv::Mat dst(height, width, CV_32FC1, small.pixels.data());
        cv::resize(src, dst, dst.size(), 0, 0, cv::INTER_AREA);
        return WhiteHot8(small, minT_K_, maxT_K_);
    }
    if (!previewLut_) previewLut_ = std::make_unique<sensors::DisplayLut>(*display_);
    if (width == pixels_.width && height == pixels_.height)
        return previewLut_->ToDisplay8(pixels_, float(std::exp2(ev_)));
    Image small(width, height, 3);
    const cv::Mat src(pixels_.height, pixels_.width, CV_32FC3,
                      const_cast<float*>(pixels_.pixels.data()));
    cv::Mat dst(height, width, CV_32FC3, small.pixels.data());
    cv::resize(src, dst, dst.size(), 0, 0, cv::INTER_AREA);
    return previewLut_->ToDisplay8(small, float(std::exp2(ev_)));
}

void ChannelPipeline::Write(FrameRecord& rec) {
    const auto t0 = std::chrono::steady_clock::now();
    sensors::ImageMetadata md = FrameMetadata(world_, channel_, state_, Camera(), ev_);
    Image exr;
    sensors::ExrOptions exrOptions;
    if (flir_) {
        const radiometry::Band& band = flir_->GetBand();
        md.Set("seasense:band", band.Name());
        md.Set("seasense:band_min_wavelength_um", float(band.MinWavelength_m() * 1e6));
        md.Set("seasense:band_max_wavelength_um", float(band.MaxWavelength_m() * 1e6));
        md.Set("seasense:units",
               std::string("L: band radiance at the aperture, W/(m^2 sr); T: apparent "
                           "(blackbody-equivalent) temperature, K"));
        md.Set("seasense:display", std::string("white-hot, linear between the frame's minimum "
                                               "and maximum apparent temperature"));
        md.Set("seasense:display_min_K", float(minT_K_));
        md.Set("seasense:display_max_K", float(maxT_K_));
        md.Set("seasense:sensor", std::string("detector footprint (100 % fill), no noise"));
        exr = Image(pixels_.width, pixels_.height, 2);
        for (size_t i = 0; i < temperature_.pixels.size(); ++i) {
            exr.pixels[2 * i] = pixels_.pixels[i];
            exr.pixels[2 * i + 1] = temperature_.pixels[i];
        }
        exrOptions.channelNames = {"L", "T"};
    }
    char stem[64];
    std::snprintf(stem, sizeof stem, "_%06lld", (long long)rec.frame);
    const std::string base = channel_.name + stem;
    for (const std::string& fmt : formats_) {
        const std::filesystem::path path = channelDir_ / (base + "." + fmt);
        if (fmt == "exr")
            sensors::WriteExr(path, flir_ ? exr : pixels_, md, exrOptions);
        else
            sensors::WriteDisplayImage8(path, DisplayRgb8(), pixels_.width, pixels_.height, 3, md);
        rec.files.push_back(path);
    }
    rec.writeMs = MsSince(t0);
}

}  // namespace seasense::channels
