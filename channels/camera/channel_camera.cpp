// Pinhole projection with square pixels, derived from the horizontal field of view.
#include "channels/camera/channel_camera.h"

#include <cmath>

namespace seasense::channels {

double ChannelCamera::TanHalfH() const { return std::tan(0.5 * hfov_rad); }
double ChannelCamera::TanHalfV() const { return TanHalfH() * double(height) / double(width); }

glm::dmat4 ChannelCamera::ClipFromWorld() const {
    // cameraFromWorld: p_cam = Rᵀ (p − c), camera axes (right, forward, up).
    const glm::dmat3 camFromWorldRot = glm::transpose(worldFromCamera.worldFromBody);
    const glm::dvec3 t = -(camFromWorldRot * worldFromCamera.position_m);
    glm::dmat4 cameraFromWorld(camFromWorldRot);
    cameraFromWorld[3] = glm::dvec4(t, 1.0);
    // clip = (x/tanH, z/tanV, near, y): w is the distance along the optical axis (forward),
    // x right, y (clip) up; glm is column-major, so set columns.
    glm::dmat4 clipFromCamera(0.0);
    clipFromCamera[0][0] = 1.0 / TanHalfH();  // camera x → clip x
    clipFromCamera[2][1] = 1.0 / TanHalfV();  // camera z (up) → clip y
    clipFromCamera[1][3] = 1.0;               // camera y (forward) → clip w
    clipFromCamera[3][2] = near_m;            // constant clip z = near → depth near/w
    return clipFromCamera * cameraFromWorld;
}

RasterCamera ChannelCamera::Raster() const {
    RasterCamera rc;
    rc.clipFromWorld = glm::mat4(ClipFromWorld());
    rc.near_m = float(near_m);
    rc.width = SampleWidth();
    rc.height = SampleHeight();
    return rc;
}

glm::dvec3 ChannelCamera::SampleDirection(double sx, double sy) const {
    const double ndcX = 2.0 * (sx + 0.5) / SampleWidth() - 1.0;
    const double ndcY = 1.0 - 2.0 * (sy + 0.5) / SampleHeight();
    const glm::dvec3 body{ndcX * TanHalfH(), 1.0, ndcY * TanHalfV()};
    return glm::normalize(worldFromCamera.worldFromBody * body);
}

ChannelCamera MakeChannelCamera(const scene::Pose& eyepoint, const scene::ChannelSettings& ch) {
    ChannelCamera cam;
    cam.worldFromCamera = scene::Compose(eyepoint, scene::PoseFrom(ch.offset_m, ch.attitude));
    cam.hfov_rad = ch.hfov_rad;
    cam.width = ch.width;
    cam.height = ch.height;
    cam.supersampling = ch.supersampling;
    cam.near_m = ch.near_m;
    return cam;
}

}  // namespace seasense::channels
