// The out-the-window (visible) channel: rasterized sea and models shaded in scene-linear
// Rec.709 luminance units (cd/m²) under an analytic sky and sun, with Embree shadows and fog.
#pragma once

#include <functional>
#include <memory>
#include <vector>

#include "channels/otw/shore_shading.h"
#include "channels/plume/plume_composite.h"
#include "channels/view/view_geometry.h"
#include "radiometry/sky/analytic_sky.h"
#include "scene/core/image.h"
#include "scene/sky/stars.h"
#include "scene/world/world.h"

namespace seasense::channels {

class BlackbodyGlowTable;
class ChannelPlumes;
class CloudSky;
class StarsNearView;

// --- Band basis (channels/nvg) ---
// Shading in another band's three-component basis instead of Rec.709 (NVG: three photocathode
// sub-bands, radiometry/nvg). Every light's photometric quantity (lx, cd/m²) is multiplied by
// its spectrum's components per lx; surfaces take per-component reflectances.
struct OtwBandBasis {
    radiometry::SkyConditions::BandBasis sky;
    glm::dvec3 sun{1.0}, moon{1.0}, stars{1.0}, lightning{1.0};  // components per lx
    std::vector<glm::dvec3> reflectance;                         // per entity, per component
    ShoreChannel shore[3];                                       // surf-zone optics per component
    // Radiance components of a blackbody at T_K (the glow of flames); empty: plumes do not glow.
    std::function<glm::dvec3(double T_K)> blackbody;
};
// --- end of band basis ---

struct OtwFrameStats {
    uint64_t oceanTriangles = 0;
    uint64_t modelTriangles = 0;
    uint64_t shadowRays = 0;   // rays actually traced (after the caster-bounds test)
    double meshMs = 0.0;       // sea mesh for the view
    double rasterMs = 0.0;     // visibility buffer
    double shadeMs = 0.0;      // shadow rays and shading
    double cloudMs = 0.0;      // cloud layers over the sky (channels/otw/cloud_layer)
    uint64_t cloudTraces = 0;  // cloud rays traced (grid nodes and exact sun/moon samples)
    RasterStats raster;
    PlumeCompositeStats plumes;  // plume compositing (zero without plumes)
};

class OtwChannel {
  public:
    // Builds the occlusion scene from the world's models (committed once; static).
    OtwChannel(const scene::World& world, const scene::ChannelSettings& settings);
    // In a band basis (channels/nvg): the components of Render's image are the basis's, in its
    // units; every light (sun, moon, stars, sky, lightning, the glow of flames) in its own
    // components, on the sky, sea, models, clouds, spray and plumes.
    // renderSpans (one per pixel row, or empty for all): only the pixels of each row's span
    // are rendered; every other sample of Render's image is 0 before the overlays (the NVG
    // channel's field stop passes no light there).
    OtwChannel(const scene::World& world, const scene::ChannelSettings& settings,
               const OtwBandBasis& basis, std::vector<PixelSpan> renderSpans = {});
    ~OtwChannel();

    // Renders the supersampled at-aperture radiance of frame `state` into radiance:
    // (width·N)×(height·N)×3, linear Rec.709, cd/m² (Y = luminance). Runs in the caller's
    // oneTBB arena; bit-identical for any thread count.
    void Render(const scene::SceneState& state, Image& radiance);

    // For tests: classify the shading pass's pixels one by one in the code for any N, which
    // the code for N = 2 (simd::kLanes pixels at a time, a pixel's samples on lanes) must
    // equal bit for bit.
    void SetClassifyPixelByPixel(bool on) { classifyPixelByPixel_ = on; }
    // For tests: the number of entries of the shading pass's triangle cache (a power of two;
    // default 2048). Whatever it holds, the images are the same bit for bit.
    void SetTriangleCacheEntries(uint32_t entries);

    const OtwFrameStats& Stats() const { return stats_; }
    const ChannelCamera& Camera() const { return geometry_.Camera(); }
    // The last frame's visibility buffer (supersampled grid): mesh 0 is the sea, mesh i ≥ 1
    // the (i−1)-th entity.
    const VisibilityBuffer& Visibility() const { return geometry_.Visibility(); }

  private:
    // Per-thread shading scratch, kept between frames so that a frame neither allocates nor
    // zero-fills its sample lists (fresh pages cost page faults on every frame).
    struct ShadeScratch;
    const scene::World& world_;
    scene::ChannelSettings settings_;
    ViewGeometry geometry_;
    std::vector<glm::dvec3> reflectance_;  // per entity
    ShoreChannel shore_[3];                // surf-zone optics per colour channel
    // The sky table depends only on the sun's and moon's directions and turbidity: rebuilt
    // when the quantized sun or moon direction changes.
    std::unique_ptr<radiometry::AnalyticSky> sky_;
    glm::dvec3 skySun_{0.0};
    glm::dvec3 skyMoon_{0.0};
    double skyMoonPhase_rad_ = 0.0, skyMoonDistance_m_ = 0.0;  // rounded, as the table has them
    std::unique_ptr<StarsNearView> stars_;  // the bright-star list (configs/stars)
    std::unique_ptr<ShadeScratch> scratch_;
    std::unique_ptr<ChannelPlumes> plumes_;  // scenario plumes (channels/plume)
    std::unique_ptr<CloudSky> clouds_;       // cloud pass scratch (environment.clouds)
    OtwFrameStats stats_;
    uint64_t frames_ = 0;  // frames rendered (empties the shading pass's triangle cache)
    std::unique_ptr<OtwBandBasis> basis_;            // null: Rec.709
    Image overlay_;                                  // band basis: grey overlays before conversion
    std::vector<uint8_t> overlayRows_;               // band basis: sample rows overlay_ drew on
    std::unique_ptr<BlackbodyGlowTable> basisGlow_;  // band basis: the flames' glow
    std::vector<PixelSpan> renderSpans_;             // per pixel row; empty: every pixel
    bool classifyPixelByPixel_ = false;              // SetClassifyPixelByPixel
    uint32_t triangleCacheEntries_ = 0;              // SetTriangleCacheEntries; 0: the default
};

}  // namespace seasense::channels
