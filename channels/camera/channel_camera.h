// A channel's pinhole camera: pose from the eyepoint and channel config, projection to the
// rasterizer's clip space, and per-sample view rays.
#pragma once

#include <glm/glm.hpp>

#include "channels/raster/rasterizer.h"
#include "scene/core/frames.h"
#include "scene/scenario/scenario.h"

namespace seasense::channels {

struct ChannelCamera {
    scene::Pose worldFromCamera;  // camera body frame: x right, y forward (optical axis), z up
    double hfov_rad = 1.0;
    int width = 0;  // pixels
    int height = 0;
    int supersampling = 1;
    double near_m = 0.25;

    int SampleWidth() const { return width * supersampling; }
    int SampleHeight() const { return height * supersampling; }
    // Tangent of half the horizontal / vertical field of view (square pixels).
    double TanHalfH() const;
    double TanHalfV() const;
    // clipFromWorld for the rasterizer (reversed infinite Z; see RasterCamera).
    glm::dmat4 ClipFromWorld() const;
    RasterCamera Raster() const;
    // Unit world direction through the centre of sample (sx, sy) of the supersampled grid.
    glm::dvec3 SampleDirection(double sx, double sy) const;
};

// The channel's camera for one frame: eyepoint pose composed with the channel's pose.
ChannelCamera MakeChannelCamera(const scene::Pose& eyepoint, const scene::ChannelSettings& ch);

}  // namespace seasense::channels
