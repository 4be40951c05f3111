// Mosaic video: area-averaged downscaling of each channel into its tile, Hershey-font labels.
#include "channels/sync/mosaic.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "scene/core/check.h"
#include "scene/core/error.h"

namespace seasense::channels::sync {

struct MosaicVideo::Impl {
    cv::VideoWriter writer;
    cv::Mat canvas;
};

namespace {

void Label(cv::Mat& img, const std::string& text, cv::Point at, double scale) {
    // Dark outline under white text: readable over sky and sea alike.
    cv::putText(img, text, at, cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(0, 0, 0), 3,
                cv::LINE_AA);
    cv::putText(img, text, at, cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(255, 255, 255), 1,
                cv::LINE_AA);
}

}  // namespace

void MosaicPreviewSize(int channelWidth, int channelHeight, int& width, int& height) {
    width = std::min(channelWidth, kMosaicTileWidth);
    height = std::max(1, int(std::lround(double(width) * channelHeight / channelWidth)));
}

MosaicVideo::MosaicVideo(const std::filesystem::path& path, const std::vector<MosaicTile>& tiles,
                         double fps, int tileWidth_px)
    : impl_(std::make_unique<Impl>()), path_(path), tiles_(tiles) {
    CHECK(!tiles.empty() && tileWidth_px >= 16 && fps > 0.0);
    columns_ = tiles.size() <= 3 ? int(tiles.size())
                                 : int(std::ceil(std::sqrt(double(tiles.size()) - 1e-9)));
    const int rows = int((tiles.size() + size_t(columns_) - 1) / size_t(columns_));
    tileW_ = tileWidth_px & ~1;
    double maxAspect = 0.0;
    for (const MosaicTile& t : tiles) maxAspect = std::max(maxAspect, double(t.height) / t.width);
    tileH_ = (int(std::ceil(tileW_ * maxAspect)) + 1) & ~1;
    captionH_ = 24;
    width_ = columns_ * tileW_;
    height_ = rows * tileH_ + captionH_;
    std::string tempName = ".";
    tempName += path.stem().string();
    tempName += '.';
    tempName += std::to_string(::getpid());
    tempName += ".tmp";
    tempName += path.extension().string();
    temp_ = path.parent_path() / tempName;
    // MPEG-4 Part 2 ("mp4v"): the encoder Debian's FFmpeg build always has.
    impl_->writer.open(temp_.string(), cv::VideoWriter::fourcc('m', 'p', '4', 'v'), fps,
                       cv::Size(width_, height_), true);
    if (!impl_->writer.isOpened())
        throw RuntimeError("cannot open an MP4 encoder for " + temp_.string() +
                           " (OpenCV videoio with FFmpeg is needed)");
    impl_->canvas = cv::Mat(height_, width_, CV_8UC3);
}

MosaicVideo::~MosaicVideo() {
    if (impl_ && impl_->writer.isOpened()) {
        impl_->writer.release();
        std::error_code ec;
        std::filesystem::remove(temp_, ec);
    }
}

void MosaicVideo::AddFrame(const std::vector<const uint8_t*>& images, const std::string& caption) {
    CHECK(images.size() == tiles_.size());
    cv::Mat& canvas = impl_->canvas;
    canvas.setTo(cv::Scalar(0, 0, 0));
    for (size_t i = 0; i < tiles_.size(); ++i) {
        const MosaicTile& t = tiles_[i];
        const int x0 = int(i % size_t(columns_)) * tileW_, y0 = int(i / size_t(columns_)) * tileH_;
        const int h = std::max(1, int(std::lround(double(tileW_) * t.height / t.width)));
        if (images[i]) {
            // OpenCV wants BGR; the channels deliver RGB.
            const cv::Mat rgb(t.height, t.width, CV_8UC3, const_cast<uint8_t*>(images[i]));
            cv::Mat scaled, bgr;
            cv::resize(rgb, scaled, cv::Size(tileW_, std::min(h, tileH_)), 0, 0, cv::INTER_AREA);
            cv::cvtColor(scaled, bgr, cv::COLOR_RGB2BGR);
            bgr.copyTo(canvas(cv::Rect(x0, y0, bgr.cols, bgr.rows)));
        }
        Label(canvas, t.name, cv::Point(x0 + 6, y0 + 18), 0.5);
    }
    Label(canvas, caption, cv::Point(6, height_ - 7), 0.5);
    impl_->writer.write(canvas);
    ++frames_;
}

void MosaicVideo::Finish() {
    if (!impl_->writer.isOpened()) return;
    impl_->writer.release();
    std::error_code ec;
    if (frames_ == 0) {
        std::filesystem::remove(temp_, ec);
        return;
    }
    std::filesystem::rename(temp_, path_, ec);
    if (ec) {
        std::filesystem::remove(temp_, ec);
        throw RuntimeError("cannot move the mosaic video into place at " + path_.string() + ": " +
                           ec.message());
    }
}

}  // namespace seasense::channels::sync
