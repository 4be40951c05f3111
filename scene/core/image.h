// A plain float image (interleaved channels, row 0 at the top) passed between pipeline stages.
#pragma once

#include <cstddef>
#include <vector>

#include "scene/core/check.h"

namespace seasense {

struct Image {
    int width = 0;
    int height = 0;
    int channels = 0;
    std::vector<float> pixels;

    Image() = default;
    Image(int w, int h, int c) : width(w), height(h), channels(c) {
        CHECK(w >= 0 && h >= 0 && c > 0);
        pixels.assign(size_t(w) * size_t(h) * size_t(c), 0.0f);
    }
    float* At(int x, int y) {
        return pixels.data() + (size_t(y) * size_t(width) + size_t(x)) * size_t(channels);
    }
    const float* At(int x, int y) const {
        return pixels.data() + (size_t(y) * size_t(width) + size_t(x)) * size_t(channels);
    }
};

// A run of pixels [begin, end) in one image row (empty when begin = end).
struct PixelSpan {
    int begin = 0, end = 0;
};

}  // namespace seasense
