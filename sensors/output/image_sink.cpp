// Where a frame's image files go: written before the call returns, or on a background thread.
#include "sensors/output/image_sink.h"

#include <utility>
#include <vector>

namespace seasense::sensors {

ImageSink::ImageSink(size_t maxQueuedFiles)
    : queue_(std::make_unique<WriteQueue>(maxQueuedFiles)) {}

void ImageSink::Exr(const std::filesystem::path& path, const Image& image,
                    const ImageMetadata& metadata, const ExrOptions& options) {
    if (!queue_) return WriteExr(path, image, metadata, options);
    queue_->Push([path, image, metadata, options] { WriteExr(path, image, metadata, options); });
}

namespace {

// Writes now, or queues a copy of the pixels and the write (WriteDisplayImage8 or 16).
template <typename Sample, typename WriteFn>
void Display(WriteQueue* queue, WriteFn write, const std::filesystem::path& path,
             std::span<const Sample> pixels, int width, int height, int channels,
             const ImageMetadata& metadata) {
    if (!queue) return write(path, pixels, width, height, channels, metadata);
    queue->Push([write, path, copy = std::vector<Sample>(pixels.begin(), pixels.end()), width,
                 height, channels,
                 metadata] { write(path, copy, width, height, channels, metadata); });
}

}  // namespace

void ImageSink::Display8(const std::filesystem::path& path, std::span<const std::uint8_t> pixels,
                         int width, int height, int channels, const ImageMetadata& metadata) {
    Display(queue_.get(), WriteDisplayImage8, path, pixels, width, height, channels, metadata);
}

void ImageSink::Display16(const std::filesystem::path& path, std::span<const std::uint16_t> pixels,
                          int width, int height, int channels, const ImageMetadata& metadata) {
    Display(queue_.get(), WriteDisplayImage16, path, pixels, width, height, channels, metadata);
}

void ImageSink::Finish() {
    if (queue_) queue_->Finish();
}

}  // namespace seasense::sensors
