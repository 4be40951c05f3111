// View geometry shared by the channel renderers: the camera of a frame, the sea mesh for the
// view, entity meshes at the frame's poses (Embree refit), shadow-caster bounds and the
// rasterized visibility buffer.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include "channels/camera/channel_camera.h"
#include "channels/occlusion/occlusion.h"
#include "channels/raster/rasterizer.h"
#include "scene/core/image.h"
#include "scene/models/triangle_mesh.h"
#include "scene/ocean/ocean_mesh.h"
#include "scene/world/world.h"

namespace seasense::channels {

struct ViewFrameStats {
    uint64_t oceanTriangles = 0;
    uint64_t modelTriangles = 0;
    double oceanMs = 0.0;   // sea surface synthesis for the frame time (0 when already made)
    double meshMs = 0.0;    // sea mesh for the view, with its vertex attributes
    double rasterMs = 0.0;  // visibility buffer
    RasterStats raster;
};

class ViewGeometry {
  public:
    // Builds the occlusion scene from the world's models at frame 0 (committed once).
    ViewGeometry(const scene::World& world, const scene::ChannelSettings& settings);

    // Prepares frame `state`: the channel camera at the state's eyepoint, entity meshes moved
    // to their poses (refit only when a pose changed), the sea mesh for the view and the
    // visibility buffer. Runs in the caller's oneTBB arena; deterministic.
    void Update(const scene::SceneState& state);
    // Limits the sea mesh to the azimuths of the pixels in spans (one per pixel row; empty: the
    // whole frame), the only pixels the channel renders (NVG field stop). Pixels outside them
    // may then see no sea.
    void SetRenderSpans(std::vector<PixelSpan> spans);

    const ChannelCamera& Camera() const { return camera_; }
    // The last frame's visibility buffer (supersampled grid): mesh 0 is the sea, mesh i ≥ 1
    // the (i−1)-th entity.
    const VisibilityBuffer& Visibility() const { return vis_; }
    const scene::OceanMesh& Ocean() const { return ocean_; }
    // Per sea-mesh vertex (same indexing as Ocean().positions): x the water column above the
    // seabed (m, 0 where the sea lies on the beach; 1e4 without a surf zone), y the wetness of
    // the sand there (1 at or below high water, 0 on dry sand), z the foam coverage in [0, 1]
    // (surf-zone foam and deep-water whitecaps), w unused (0).
    const std::vector<glm::vec4>& OceanAttributes() const { return oceanAttributes_; }
    // The sea surface of the last frame (the mesh's source; DetailNormal for shading).
    const scene::OceanSurfaceFrame& OceanFrame() const { return *oceanFrame_; }
    // Entity meshes in the world frame (ENU metres) at the last frame's poses.
    const std::vector<scene::TriangleMesh>& EntityMeshes() const { return worldMeshes_; }
    const OcclusionScene& Occlusion() const { return occlusion_; }
    // Bounding box (world, m) of each shadow caster (entity), widened well beyond
    // OcclusionScene's own boxes of them (MeshBoxes): a cheap inline test for whole triangles
    // that leaves only candidates for MayOcclude.
    std::span<const AxisBox> CasterBoxes() const { return casterBoxes_; }
    const ViewFrameStats& Stats() const { return stats_; }

  private:
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
    std::vector<AxisBox> casterBoxes_;              // per entity (CasterBoxes)
    void UpdateOceanAttributes();

    scene::OceanMesh ocean_;
    std::vector<glm::vec4> oceanAttributes_;
    std::shared_ptr<const scene::OceanSurfaceFrame> oceanFrame_;
    VisibilityBuffer vis_;
    ViewFrameStats stats_;
    std::vector<PixelSpan> renderSpans_;  // empty: every pixel
};

// Azimuth sector [min, max] (radians, clockwise from north) that the camera's frustum covers,
// widened by margin_rad; max − min = 2π when it looks close to straight up or down.
void FrustumAzimuthSector(const ChannelCamera& camera, double margin_rad, double& min_rad,
                          double& max_rad);
// The same for the pixels of spans (one per pixel row of the camera), e.g. an NVG channel's
// field stop: no wider than FrustumAzimuthSector.
void SpansAzimuthSector(const ChannelCamera& camera, std::span<const PixelSpan> spans,
                        double& min_rad, double& max_rad);

// z of the unit view direction nearest the nadir among the camera's rays (its frustum's
// boundary and inside, exactly; not meaningful when the frustum holds the nadir).
double SteepestViewDirectionZ(const ChannelCamera& camera);
// Horizontal distance (m) inside which no sea can be seen by the camera: where the steepest
// downward view ray meets the plane of the highest crest, less the waves' horizontal reach.
// 0 when the eye is below the crests or looks straight down; +∞ when no view ray points down.
double NearestVisibleSeaRange_m(const ChannelCamera& camera, double crestHeight_m,
                                double horizontalReach_m);
// The same for the sea of a frame seen from eye_m: the crest and reach bounds taken over the
// disc of sea near the eye (OceanSurfaceFrame::LocalBoundsNear) rather than the whole surface.
// With the sea mesh's angular step, for the rings of that mesh (their footprints bounded by
// scene::OceanMeshFootprintBound_m), which bounds the Gerstner waves signed (their troughs).
double NearestVisibleSeaRange_m(
    const ChannelCamera& camera, const scene::OceanSurfaceFrame& sea, const glm::dvec3& eye_m,
    double meshAngularStep_rad = std::numeric_limits<double>::infinity());

// The sea mesh a channel asks for (ViewGeometry, and the mesh benchmarks): vertices 6 pixels
// apart on screen, the camera's own azimuth sector (that of renderSpans when given, one per
// pixel row: the pixels the channel renders) widened per band by the waves' reach
// (OceanMeshRequest::widenByReach), starting at the nearest visible range of this frame's sea.
scene::OceanMeshRequest SeaMeshRequest(const ChannelCamera& camera,
                                       const scene::OceanSurfaceFrame& sea,
                                       std::span<const PixelSpan> renderSpans = {});

}  // namespace seasense::channels
