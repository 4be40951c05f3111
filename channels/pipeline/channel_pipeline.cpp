// Channel pipeline: the sensor owns the pixel, so radiance samples become pixels only here.
#include "channels/pipeline/channel_pipeline.h"

#include <immintrin.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <opencv2/imgproc.hpp>

#include "scene/core/error.h"
#include "sensors/detector/detector.h"
#include "sensors/display/display_lut.h"
#include "sensors/output/image_writer.h"
#include "sensors/thermal/thermal_output.h"

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
        md.Set("seasense:exposure_mode", std::string(ToString(ch.exposure.mode)));
        md.Set("seasense:ocio_view", ch.ocioView);
        // How the display images (png, tiff) applied that view.
        md.Set("seasense:display",
               std::string(ch.display == scene::ChannelSettings::Display::Lut ? "lut" : "exact"));
        md.Set("oiio:ColorSpace", std::string("Linear Rec.709 (sRGB)"));
    }
    if (ch.kind == scene::ChannelKind::Nvg)
        md.Set("seasense:units",
               std::string("L_p: photocathode-weighted photon radiance (relative QE, peak 1), "
                           "photons s^-1 m^-2 sr^-1; B: screen brightness (1 = saturation)"));
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
    const bool thermal = channel_.kind == scene::ChannelKind::Flir;
    for (const std::string& f : formats_) {
        const bool raw = f == "raw_png" || f == "raw_tiff";
        if (f == "exr" || f == "png" || f == "tiff" || (raw && thermal)) continue;
        std::string msg = "channel '";
        msg += channel_.name + "': output format '" + f + "'; expected exr, png, tiff";
        msg += thermal ? ", raw_png or raw_tiff" : " (raw_png and raw_tiff are for flir channels)";
        throw InputError(msg);
    }
    if (channel_.kind == scene::ChannelKind::Nvg) {
        nvg_ = std::make_unique<NvgChannel>(world_, channel_);
        intensifier_ = std::make_unique<sensors::Intensifier>(nvg_->IntensifierSettings(),
                                                              channel_.supersampling);
        return;
    }
    if (thermal) {
        flir_ = std::make_unique<FlirChannel>(world_, channel_);
        channel_ = flir_->Settings();  // the field of view resolved with the imager
        imager_ = std::make_unique<sensors::ThermalImager>(
            flir_->ImagerSettings(), flir_->GetBand(), channel_.supersampling);
        return;
    }
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

const NvgChannel& ChannelPipeline::Nvg() const {
    CHECK(nvg_);
    return *nvg_;
}

const sensors::Intensifier& ChannelPipeline::GetIntensifier() const {
    CHECK(intensifier_);
    return *intensifier_;
}

const sensors::ThermalImager& ChannelPipeline::Imager() const {
    CHECK(imager_);
    return *imager_;
}

const ChannelCamera& ChannelPipeline::Camera() const {
    if (nvg_) return nvg_->Camera();
    return flir_ ? flir_->Camera() : otw_->Camera();
}

FrameRecord ChannelPipeline::RenderAndWrite(int64_t frame) {
    FrameRecord rec = Render(world_.Advance(frame));
    Write(rec);
    return rec;
}

void ChannelPipeline::WarmUp(const scene::FrameState& frame) {
    if (imager_) imager_->Restart();
    if (intensifier_) intensifier_->Restart();
    Render(frame);
    if (imager_) imager_->Restart();
    if (intensifier_) intensifier_->Restart();
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
        imager_->Process(samples_, state_.time_s, state_.frame);
        displayValid_ = false;
        rec.sensorMs = MsSince(t0);
        return rec;
    }
    if (nvg_) {
        nvg_->Render(state_, samples_);
        rec.renderMs = MsSince(t0);
        t0 = std::chrono::steady_clock::now();
        intensifier_->Process(samples_, state_.time_s, state_.frame);
        displayValid_ = false;
        rec.sensorMs = MsSince(t0);
        return rec;
    }
    otw_->Render(state_, samples_);
    rec.renderMs = MsSince(t0);

    t0 = std::chrono::steady_clock::now();
    if (channel_.exposure.mode == scene::ExposureMode::Manual) {
        sensors::IntegrateFootprint(samples_, channel_.supersampling, pixels_);
        ev_ = channel_.exposure.ev;
    } else {
        // The log-average luminance taken in the footprint pass (AutoExposureEv and
        // AdaptedExposureEv of pixels_, without reading the image back).
        const double Lavg =
            sensors::IntegrateFootprintLogAverage(samples_, channel_.supersampling, pixels_);
        ev_ = channel_.exposure.mode == scene::ExposureMode::Auto
                  ? sensors::ExposureEv(Lavg, channel_.exposure.keyValue)
                  : sensors::ExposureEv(Lavg, sensors::AdaptedKey(Lavg));
    }
    rec.exposureEv = ev_;
    displayValid_ = false;
    rec.sensorMs = MsSince(t0);
    return rec;
}

const std::vector<uint8_t>& ChannelPipeline::DisplayRgb8() {
    if (!displayValid_) {
        if (intensifier_) {
            const std::span<const uint8_t> d = intensifier_->Display();
            display8_.assign(d.begin(), d.end());
        } else if (imager_) {
            // The imager's display: gray (one byte per pixel) or already RGB.
            const std::span<const uint8_t> d = imager_->Display();
            if (imager_->DisplayChannels() == 3) {
                display8_.assign(d.begin(), d.end());
            } else {
                display8_.resize(3 * d.size());
                size_t i = 0;
#if defined(__SSSE3__)
                // Sixteen gray bytes to 48 RGB bytes by three byte shuffles.
                const __m128i spread[3] = {
                    _mm_setr_epi8(0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3, 4, 4, 4, 5),
                    _mm_setr_epi8(5, 5, 6, 6, 6, 7, 7, 7, 8, 8, 8, 9, 9, 9, 10, 10),
                    _mm_setr_epi8(10, 11, 11, 11, 12, 12, 12, 13, 13, 13, 14, 14, 14, 15, 15, 15)};
                for (; i + 16 <= d.size(); i += 16) {
                    const __m128i g = _mm_loadu_si128(reinterpret_cast<const __m128i*>(&d[i]));
                    for (int k = 0; k < 3; ++k)
                        _mm_storeu_si128(
                            reinterpret_cast<__m128i*>(&display8_[3 * i + 16 * size_t(k)]),
                            _mm_shuffle_epi8(g, spread[k]));
                }
#endif
                for (; i < d.size(); ++i)
                    display8_[3 * i] = display8_[3 * i + 1] = display8_[3 * i + 2] = d[i];
            }
        } else if (channel_.display == scene::ChannelSettings::Display::Lut) {
            display8_ = Lut().ToDisplay8(pixels_, float(std::exp2(ev_)));
        } else {
            display8_ = display_->ToDisplay8(pixels_, float(std::exp2(ev_)));
        }
        displayValid_ = true;
    }
    return display8_;
}

std::vector<uint8_t> ChannelPipeline::PreviewRgb8(int width, int height) {
    CHECK(width > 0 && height > 0);
    if (imager_ || intensifier_) {
        const std::vector<uint8_t>& rgb = DisplayRgb8();
        if (width == channel_.width && height == channel_.height) return rgb;
        std::vector<uint8_t> small(size_t(width) * size_t(height) * 3);
        const cv::Mat src(channel_.height, channel_.width, CV_8UC3,
                          const_cast<uint8_t*>(rgb.data()));
        cv::Mat dst(height, width, CV_8UC3, small.data());
        cv::resize(src, dst, dst.size(), 0, 0, cv::INTER_AREA);
        return small;
    }
    if (width == pixels_.width && height == pixels_.height)
        return Lut().ToDisplay8(pixels_, float(std::exp2(ev_)));
    // Kept between frames: a fresh 0.9 MB image each frame is zero-filled (and page-faulted)
    // only to be overwritten by the resize.
    Image& small = previewSmall_;
    if (small.width != width || small.height != height || small.channels != 3)
        small = Image(width, height, 3);
    if (pixels_.width == 2 * width && pixels_.height == 2 * height) {
        sensors::HalveRgb(pixels_, small);  // the five-channel run's 640×480 → 320×240
    } else {
        const cv::Mat src(pixels_.height, pixels_.width, CV_32FC3,
                          const_cast<float*>(pixels_.pixels.data()));
        cv::Mat dst(height, width, CV_32FC3, small.pixels.data());
        cv::resize(src, dst, dst.size(), 0, 0, cv::INTER_AREA);
        CHECK(dst.data == reinterpret_cast<uchar*>(small.pixels.data()));  // written in place
    }
    return Lut().ToDisplay8(small, float(std::exp2(ev_)));
}

const sensors::DisplayLut& ChannelPipeline::Lut() {
    CHECK(display_);
    if (!lut_) lut_ = std::make_unique<sensors::DisplayLut>(*display_);
    return *lut_;
}

void ChannelPipeline::WriteThermal(const sensors::ImageMetadata& md, const std::string& base,
                                   FrameRecord& rec) {
    for (const std::string& fmt : formats_) {
        sensors::ThermalOutputPaths paths;
        std::filesystem::path path;
        if (fmt == "exr") {
            path = paths.radiometricExr = channelDir_ / (base + ".exr");
        } else if (fmt == "png" || fmt == "tiff") {
            path = paths.display = channelDir_ / (base + "." + fmt);
        } else {  // raw_png, raw_tiff
            path = paths.rawCounts = channelDir_ / (base + "_raw." + fmt.substr(4));
        }
        sensors::WriteThermalFrame(*imager_, paths, md, sink_);
        rec.files.push_back(path);
    }
}

void ChannelPipeline::WriteNvg(const sensors::ImageMetadata& frameMd, const std::string& base,
                               FrameRecord& rec) {
    const sensors::Intensifier& t = *intensifier_;
    sensors::ImageMetadata md = frameMd;
    md.Set("seasense:abc_gain_per_pe", float(t.Gain()));
    md.Set("seasense:bsp_duty", float(t.Duty()));
    md.Set("seasense:mean_photoelectrons_per_pixel", float(t.MeanPhotoelectrons()));
    md.Set("seasense:pe_per_photon_radiance", float(t.PhotoelectronsPerRadiance()));
    for (const std::string& fmt : formats_) {
        const std::filesystem::path path = channelDir_ / (base + "." + fmt);
        if (fmt == "exr") {
            const Image& L = t.PhotonRadiance();
            const Image& B = t.Brightness();
            Image both(L.width, L.height, 2);
            for (size_t i = 0; i < L.pixels.size(); ++i) {
                both.pixels[2 * i] = L.pixels[i];
                both.pixels[2 * i + 1] = B.pixels[i];
            }
            sensors::ExrOptions options;
            options.channelNames = {"L_p", "B"};
            sink_.Exr(path, both, md, options);
        } else {
            sink_.Display8(path, t.Display(), t.Brightness().width, t.Brightness().height, 3, md);
        }
        rec.files.push_back(path);
    }
}

void ChannelPipeline::Write(FrameRecord& rec) {
    const auto t0 = std::chrono::steady_clock::now();
    sensors::ImageMetadata md = FrameMetadata(world_, channel_, state_, Camera(), ev_);
    char stem[64];
    std::snprintf(stem, sizeof stem, "_%06lld", (long long)rec.frame);
    const std::string base = channel_.name + stem;
    if (intensifier_) {
        WriteNvg(md, base, rec);
        rec.writeMs = MsSince(t0);
        return;
    }
    if (imager_) {
        WriteThermal(md, base, rec);
        rec.writeMs = MsSince(t0);
        return;
    }
    for (const std::string& fmt : formats_) {
        const std::filesystem::path path = channelDir_ / (base + "." + fmt);
        if (fmt == "exr")
            sink_.Exr(path, pixels_, md);
        else
            sink_.Display8(path, DisplayRgb8(), pixels_.width, pixels_.height, 3, md);
        rec.files.push_back(path);
    }
    rec.writeMs = MsSince(t0);
}

void ChannelPipeline::WriteInBackground() {
    // Two frames' files may wait: the renderer is a frame ahead of its writer at most.
    sink_ = sensors::ImageSink(2 * formats_.size());
}

void ChannelPipeline::FinishWrites() { sink_.Finish(); }

}  // namespace seasense::channels
