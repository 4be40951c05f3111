// Test support: a level camera looking north and a visibility buffer that sees only sky, for
// tests that composite onto a channel's samples without rendering a scene.
#pragma once

#include <numbers>

#include "channels/camera/channel_camera.h"
#include "channels/raster/rasterizer.h"

namespace seasense::channels {

// A level camera at eye looking north (y) with a 30° horizontal field; odd sizes put the centre
// pixel's ray on the optical axis.
inline ChannelCamera NorthCamera(const glm::dvec3& eye, int width, int height, int supersampling) {
    ChannelCamera cam;
    cam.worldFromCamera = scene::Pose{eye, glm::dmat3(1.0)};
    cam.hfov_rad = 30.0 * std::numbers::pi / 180.0;
    cam.width = width;
    cam.height = height;
    cam.supersampling = supersampling;
    cam.near_m = 0.25;
    return cam;
}

// A visibility buffer that sees only sky.
inline VisibilityBuffer SkyOnly(const ChannelCamera& cam) {
    VisibilityBuffer vis;
    vis.width = cam.SampleWidth();
    vis.height = cam.SampleHeight();
    const size_t n = size_t(vis.width) * size_t(vis.height);
    vis.depth.assign(n, 0.0f);
    vis.primitive.assign(n, kNoPrimitive);
    vis.b1.assign(n, 0.0f);
    vis.b2.assign(n, 0.0f);
    vis.primitiveBase = {0};
    return vis;
}

}  // namespace seasense::channels
