// Where a frame's image files go: written before the call returns, or on a background thread.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>

#include "scene/core/image.h"
#include "sensors/output/image_writer.h"
#include "sensors/output/write_queue.h"

namespace seasense::sensors {

// The image writers (WriteExr, WriteDisplayImage8/16) behind one object. A direct sink writes
// each file before returning; a background sink copies the pixels and metadata, so the caller
// may overwrite its buffers at once, and writes the file (encode, sync, rename: atomic as the
// writers are) on a WriteQueue thread, in call order. The files are the same bytes either way.
// A background sink's write errors surface as the writers' exceptions from a later call or
// from Finish.
class ImageSink {
  public:
    // Direct.
    ImageSink() = default;
    // Background, at most maxQueuedFiles files waiting (a call waits while that many do).
    explicit ImageSink(size_t maxQueuedFiles);

    bool Background() const { return queue_ != nullptr; }
    void Exr(const std::filesystem::path& path, const Image& image, const ImageMetadata& metadata,
             const ExrOptions& options = {});
    void Display8(const std::filesystem::path& path, std::span<const std::uint8_t> pixels,
                  int width, int height, int channels, const ImageMetadata& metadata);
    void Display16(const std::filesystem::path& path, std::span<const std::uint16_t> pixels,
                   int width, int height, int channels, const ImageMetadata& metadata);
    // Waits until every file handed over is written; rethrows the first write error not yet
    // reported. Nothing to do for a direct sink.
    void Finish();

  private:
    std::unique_ptr<WriteQueue> queue_;
};

}  // namespace seasense::sensors
