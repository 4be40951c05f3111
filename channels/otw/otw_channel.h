// The out-the-window (visible) channel: rasterized sea and models shaded in scene-linear
// Rec.709 luminance units (cd/m²) under an analytic sky and sun, with Embree shadows and fog.
#pragma once

#include <memory>
#include <vector>

#include "channels/camera/channel_camera.h"
#include "channels/occlusion/occlusion.h"
#include "channels/raster/rasterizer.h"
#include "radiometry/sky/analytic_sky.h"
#include "scene/core/image.h"
#include "scene/models/triangle_mesh.h"
#include "scene/ocean/ocean_mesh.h"
#include "scene/world/world.h"

namespace seasense::channels {

struct OtwFrameStats {
    uint64_t oceanTriangles = 0;
    uint64_t modelTriangles = 0;
    uint64_t shadowRays = 0;  // rays actually traced (after the caster-bounds test)
    double meshMs = 0.0;      // sea mesh for the view
    double rasterMs = 0.0;    // visibility buffer
    double shadeMs = 0.0;     // shadow rays and shading
    RasterStats raster;
};

class OtwChannel {
  public:
    // Builds the occlusion scene from the world's models (committed once; static).
    OtwChannel(const scene::World& world, const scene::ChannelSettings& settings);
    ~OtwChannel();

    // Renders the supersampled at-aperture radiance of frame `state` into radiance:
    // (width·N)×(height·N)×3, linear Rec.709, cd/m² (Y = luminance). Runs in the caller's
    // oneTBB arena; bit-identical for any thread count.
    void Render(const scene::SceneState& state, Image& radiance);

    const OtwFrameStats& Stats() const { return stats_; }
    const ChannelCamera& Camera() const { return camera_; }
    // The last frame's visibility buffer (supersampled grid): mesh 0 is the sea, mesh i ≥ 1
    // the (i−1)-th entity.
    const VisibilityBuffer& Visibility() const { return vis_; }

  private:
    // Per-thread shading scratch, kept between frames so that a frame neither allocates nor
    // zero-fills its sample lists (fresh pages cost page faults on every frame).
    struct ShadeScratch;
    // Moves entity meshes to the frame's poses (transform, Embree refit) when they changed.
    void UpdateEntities(const scene::SceneState& state);
    void UpdateCasterBounds();

    const scene::World& world_;
    scene::ChannelSettings settings_;
    ChannelCamera camera_;
    Rasterizer rasterizer_;
    OcclusionScene occlusion_;
    std::vector<scene::TriangleMesh> worldMeshes_;  // entity meshes in the world frame
    std::vector<scene::Pose> entityPoses_;          // the poses worldMeshes_ were built at
    std::vector<uint32_t> occlusionIds_;            // Embree geometry of each entity
    std::vector<glm::dvec3> reflectance_;           // per entity
    // Bounding box of all shadow casters, widened well beyond OcclusionScene's own caster
    // bounds: a cheap inline test that leaves only candidates for MayOcclude.
    glm::vec3 casterMin_{0.0f}, casterMax_{0.0f};
    scene::OceanMesh ocean_;
    VisibilityBuffer vis_;
    // The sky depends only on the sun and turbidity: rebuilt when they change.
    std::unique_ptr<radiometry::AnalyticSky> sky_;
    glm::dvec3 skySun_{0.0};
    double skySunLux_ = -1.0;
    std::unique_ptr<ShadeScratch> scratch_;
    OtwFrameStats stats_;
};

// Azimuth sector [min, max] (radians, clockwise from north) that the camera's frustum covers,
// widened by margin_rad; max − min = 2π when it looks close to straight up or down.
void FrustumAzimuthSector(const ChannelCamera& camera, double margin_rad, double& min_rad,
                          double& max_rad);

// Horizontal distance (m) inside which no sea can be seen by the camera: the steepest
// downward view ray meets the plane of the highest crest, less a 20 % margin and the waves'
// horizontal reach. 0 when the eye is below the crests or looks straight down; +∞ when no
// view ray points down.
double NearestVisibleSeaRange_m(const ChannelCamera& camera, double crestHeight_m,
                                double horizontalReach_m);

}  // namespace seasense::channels
