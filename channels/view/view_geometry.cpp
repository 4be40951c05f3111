// View geometry: frustum-limited sea mesh, entity refit and rasterization shared by the
// channel renderers (moved unchanged out of the OTW channel).
#include "channels/view/view_geometry.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "scene/core/check.h"
#include "scene/surf/foam.h"

namespace seasense::channels {

namespace {

// Sea mesh vertex spacing on screen: waves are smooth at this scale and their normals are
// interpolated per sample.
constexpr double kOceanVertexSpacing_px = 6.0;

// Calls fn(d) for unit world directions along the boundary of the camera's frustum (33 per
// edge); fn returns false to stop early.
template <class Fn>
void ForEachFrustumBoundaryDirection(const ChannelCamera& cam, Fn&& fn) {
    constexpr int kSteps = 32;
    for (int e = 0; e < 4; ++e) {
        for (int i = 0; i <= kSteps; ++i) {
            const double s = double(i) / kSteps;
            const double u = e == 0 ? s : e == 1 ? 1.0 : e == 2 ? 1.0 - s : 0.0;
            const double v = e == 0 ? 0.0 : e == 1 ? s : e == 2 ? 1.0 : 1.0 - s;
            if (!fn(cam.SampleDirection(u * cam.SampleWidth() - 0.5, v * cam.SampleHeight() - 0.5)))
                return;
        }
    }
}

// Whether the world direction dir lies inside the frustum.
bool FrustumContains(const ChannelCamera& cam, const glm::dvec3& dir) {
    const glm::dvec3 c = glm::transpose(cam.worldFromCamera.worldFromBody) * dir;
    if (c.y <= 0.0) return false;  // behind the camera
    return std::abs(c.x / c.y) <= cam.TanHalfH() && std::abs(c.z / c.y) <= cam.TanHalfV();
}

// Whether the straight-down direction lies inside the frustum (its boundary winds around it).
bool FrustumContainsNadir(const ChannelCamera& cam) {
    return FrustumContains(cam, glm::dvec3(0, 0, -1));
}

}  // namespace

namespace {

// The azimuth sector of the directions forEach(fn) passes to fn (their boundary suffices: see
// the callers), relative to the camera's axis, widened by margin; [0, 2π] when one lies close
// to the zenith or nadir.
template <class ForEach>
void AzimuthSector(const ChannelCamera& cam, double margin, double& lo, double& hi,
                   ForEach&& forEach) {
    const glm::dvec3 axis = cam.worldFromCamera.worldFromBody * glm::dvec3(0, 1, 0);
    const double centre = std::atan2(axis.x, axis.y);
    double minRel = 0.0, maxRel = 0.0;
    bool full = false;
    forEach([&](const glm::dvec3& d) {
        if (std::hypot(d.x, d.y) < 0.05) {
            full = true;  // within ~3° of the zenith or nadir: all azimuths are near
            return false;
        }
        const double rel = std::remainder(std::atan2(d.x, d.y) - centre, 2.0 * M_PI);
        minRel = std::min(minRel, rel);
        maxRel = std::max(maxRel, rel);
        return true;
    });
    if (full || maxRel - minRel + 2.0 * margin >= 2.0 * M_PI) {
        lo = 0.0;
        hi = 2.0 * M_PI;
        return;
    }
    lo = centre + minRel - margin;
    hi = centre + maxRel + margin;
}

}  // namespace

void FrustumAzimuthSector(const ChannelCamera& cam, double margin, double& lo, double& hi) {
    // A frustum holding the nadir or the zenith sees every azimuth (its boundary winds around
    // the pole, which the extremes of its sampled azimuths need not show).
    if (FrustumContainsNadir(cam) || FrustumContains(cam, glm::dvec3(0, 0, 1))) {
        lo = 0.0;
        hi = 2.0 * M_PI;
        return;
    }
    // The azimuth extremes of a convex cone of directions lie on its boundary.
    AzimuthSector(cam, margin, lo, hi,
                  [&](const auto& fn) { ForEachFrustumBoundaryDirection(cam, fn); });
}

void SpansAzimuthSector(const ChannelCamera& cam, std::span<const PixelSpan> spans, double& lo,
                        double& hi) {
    CHECK(spans.size() == size_t(cam.height));
    // Where the frustum's sector is all azimuths (a pole in it or near it), so is the spans'.
    // Else no pole lies on any image row, so along a row the azimuth of the view direction changes
    // monotonically and a row's span reaches its extremes at its end corners: the pixels'
    // outer edges, at sample coordinate px·N − ½ (as the frustum's boundary), on the row's top
    // and bottom edges; and the frustum's sector, which holds them all, spans less than 2π
    // about the axis, so their azimuths relative to it do not wrap.
    FrustumAzimuthSector(cam, 0.0, lo, hi);
    if (hi - lo >= 2.0 * M_PI) return;
    const double n = cam.supersampling;
    AzimuthSector(cam, 0.0, lo, hi, [&](const auto& fn) {
        for (int py = 0; py < cam.height; ++py) {
            const PixelSpan& span = spans[size_t(py)];
            if (span.begin >= span.end) continue;
            for (const double sy : {py * n - 0.5, (py + 1) * n - 0.5})
                for (const double sx : {span.begin * n - 0.5, span.end * n - 0.5})
                    if (!fn(cam.SampleDirection(sx, sy))) return;
        }
    });
}

double SteepestViewDirectionZ(const ChannelCamera& cam) {
    // Outside the nadir, the view direction nearest it lies on the frustum's boundary, four
    // great-circle arcs between the corner rays (the image edges). On an arc from a to b, −d_z
    // is largest at an end or where the arc passes nearest the nadir: at the nadir's projection
    // onto the arc's plane, when that lies between a and b.
    const double sw = cam.SampleWidth(), sh = cam.SampleHeight();
    const glm::dvec3 corner[4] = {
        cam.SampleDirection(-0.5, -0.5), cam.SampleDirection(sw - 0.5, -0.5),
        cam.SampleDirection(sw - 0.5, sh - 0.5), cam.SampleDirection(-0.5, sh - 0.5)};
    double z = 1.0;
    for (int e = 0; e < 4; ++e) {
        const glm::dvec3 &a = corner[e], &b = corner[(e + 1) % 4];
        z = std::min(z, a.z);
        const glm::dvec3 n = glm::normalize(glm::cross(a, b));
        const glm::dvec3 p = glm::dvec3(0.0, 0.0, -1.0) + n.z * n;  // nadir minus its normal part
        const double length = glm::length(p);
        if (!(length > 1e-12)) continue;  // the arc's plane is horizontal: the ends suffice
        const glm::dvec3 q = p / length;
        if (glm::dot(glm::cross(a, q), n) >= 0.0 && glm::dot(glm::cross(q, b), n) >= 0.0)
            z = std::min(z, q.z);
    }
    return z;
}

namespace {
// tan of the depression below the horizontal of a unit direction whose z is z < 0.
double DepressionTan(double z) { return -z / std::sqrt(std::max(1.0 - z * z, 1e-18)); }
}  // namespace

double NearestVisibleSeaRange_m(const ChannelCamera& cam, double crestHeight_m,
                                double horizontalReach_m) {
    const double h = cam.worldFromCamera.position_m.z - crestHeight_m;
    if (h <= 0.0 || FrustumContainsNadir(cam)) return 0.0;
    // The steepest downward view ray meets the crest plane nearest: range = h / slope, with
    // slope = tan(depression) = −d_z / |d_xy| for unit d.
    const double z = SteepestViewDirectionZ(cam);
    if (z >= 0.0) return std::numeric_limits<double>::infinity();  // no ray looks down
    const double slope = DepressionTan(z);
    // A margin of 1e-6 for the rounding of the above; then allow for vertices that the waves
    // carry horizontally toward the eye. (Sampling the boundary at 33 directions per edge, as
    // this did before with a 20 % margin, missed the steepest ray near the nadir: a view 80°
    // down with the nadir just outside it got a range up to 100 times too far.)
    return std::max(0.0, (1.0 - 1e-6) * h / slope - horizontalReach_m);
}

double NearestVisibleSeaRange_m(const ChannelCamera& cam, const scene::OceanSurfaceFrame& sea,
                                const glm::dvec3& eye_m, double meshAngularStep_rad) {
    // A radius r is a safe nearest range when the range found from the bounds over the disc of
    // radius r is at least r (every rest position within r is then drawn below the view), and so
    // is that range when it is at most r (the disc holds it). The range from the bounds over a
    // disc never grows with its radius, so the largest safe r lies between the range r1 from the
    // disc of the under-eye range r0 (safe: r1 ≤ r0) and r0; bisection narrows it, each step
    // keeping a safe lower end. The bounds near the eye (LocalBoundsNear) follow the waves
    // there, which puts the range of a 2 m eye several metres further out than the whole sea's
    // highest crest does (configs/five-channel.yaml's flir: 1.3 m → 5–7 m).
    const auto rangeFrom = [&](double radius_m) {
        const double maxFootprint_m =
            std::isfinite(meshAngularStep_rad)
                ? scene::OceanMeshFootprintBound_m(radius_m, eye_m.z, sea.SignificantHeight_m(),
                                                   meshAngularStep_rad)
                : std::numeric_limits<double>::infinity();
        const scene::SurfaceBounds b =
            sea.LocalBoundsNear(eye_m.x, eye_m.y, radius_m, maxFootprint_m);
        return NearestVisibleSeaRange_m(cam, b.height_m, b.horizontal_m);
    };
    const double r0 = rangeFrom(0.0);
    if (!(r0 > 0.0) || !std::isfinite(r0)) return r0;
    double lo = rangeFrom(r0), hi = r0;
    constexpr int kBisections = 6;
    for (int i = 0; i < kBisections && hi - lo > 0.01 * hi; ++i) {
        const double mid = 0.5 * (lo + hi);
        if (rangeFrom(mid) >= mid)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

scene::OceanMeshRequest SeaMeshRequest(const ChannelCamera& cam,
                                       const scene::OceanSurfaceFrame& sea,
                                       std::span<const PixelSpan> renderSpans) {
    scene::OceanMeshRequest req;
    req.eye_m = cam.worldFromCamera.position_m;
    req.angularStep_rad = kOceanVertexSpacing_px * cam.hfov_rad / double(cam.width);
    // The view's own sector (of the rendered pixels only, where the channel renders a part of
    // the frame); the mesh widens each band by what the waves can carry sideways.
    if (renderSpans.empty())
        FrustumAzimuthSector(cam, 0.0, req.azimuthMin_rad, req.azimuthMax_rad);
    else
        SpansAzimuthSector(cam, renderSpans, req.azimuthMin_rad, req.azimuthMax_rad);
    req.widenByReach = true;
    req.minRange_m = NearestVisibleSeaRange_m(cam, sea, req.eye_m, req.angularStep_rad);
    // The rings near the eye are seen no steeper than the lowest view ray: its depression's
    // tangent rounded up to a step of 2^(1/8) (9 %), so that a view that pitches and rolls a
    // little (an eyepoint on a ship) keeps the same near rings, which would otherwise move.
    const double z = SteepestViewDirectionZ(cam);
    if (z < 0.0)
        req.maxDepressionTan = std::exp2(std::ceil(8.0 * std::log2(DepressionTan(z))) / 8.0);
    return req;
}

ViewGeometry::ViewGeometry(const scene::World& world, const scene::ChannelSettings& settings)
    : world_(world), settings_(settings) {
    const scene::SceneState s0 = world.State(0);
    for (const scene::EntityState& e : s0.entities) {
        worldMeshes_.push_back(scene::TransformMesh(*e.bodyMesh, e.pose));
        entityPoses_.push_back(e.pose);
        occlusionIds_.push_back(
            occlusion_.AddMesh(worldMeshes_.back().positions, worldMeshes_.back().indices));
    }
    occlusion_.Commit();
    UpdateCasterBounds();
}

void ViewGeometry::SetRenderSpans(std::vector<PixelSpan> spans) {
    CHECK(spans.empty() || spans.size() == size_t(settings_.height));
    renderSpans_ = std::move(spans);
}

void ViewGeometry::UpdateEntities(const scene::SceneState& state) {
    CHECK(state.entities.size() == worldMeshes_.size());
    bool moved = false;
    for (size_t i = 0; i < state.entities.size(); ++i) {
        const scene::Pose& pose = state.entities[i].pose;
        if (pose.position_m == entityPoses_[i].position_m &&
            pose.worldFromBody == entityPoses_[i].worldFromBody)
            continue;
        worldMeshes_[i] = scene::TransformMesh(*state.entities[i].bodyMesh, pose);
        entityPoses_[i] = pose;
        occlusion_.UpdateMesh(occlusionIds_[i], worldMeshes_[i].positions);
        moved = true;
    }
    if (!moved) return;
    occlusion_.Commit();
    UpdateCasterBounds();
}

void ViewGeometry::UpdateCasterBounds() {
    // The occlusion scene's box of each entity (its vertices' bounds, already enlarged a little)
    // enlarged again, far more than OcclusionScene's 1e-5 relative + 0.1 mm: each caster's box
    // holds the scene's box of it, so that passing MayOcclude implies passing this test, caster
    // by caster, despite float rounding. (The scene's boxes spare a second pass over the
    // vertices.)
    const std::span<const AxisBox> sceneBoxes = occlusion_.MeshBoxes();
    casterBoxes_.clear();
    float largest_m = 0.0f;
    for (uint32_t id : occlusionIds_) {
        const AxisBox& box = casterBoxes_.emplace_back(sceneBoxes[id]);
        const glm::vec3 magnitude = glm::max(glm::abs(box.min), glm::abs(box.max));
        largest_m = std::max({largest_m, magnitude.x, magnitude.y, magnitude.z});
    }
    const float margin_m = 1e-3f * largest_m + 0.1f;
    for (AxisBox& box : casterBoxes_) box.min -= margin_m, box.max += margin_m;
}

void ViewGeometry::UpdateOceanAttributes() {
    const scene::OceanSurfaceFrame& sea = *oceanFrame_;
    const scene::SurfWaves* surf = sea.Surf();
    const double threshold = world_.GetScenario().environment.ocean.foamThreshold;
    oceanAttributes_.resize(ocean_.positions.size());
    const int rings = ocean_.rings;
    if (rings == 0) return;
    CHECK(ocean_.ringStart.size() == size_t(rings) + 1 &&
          ocean_.ringStart.back() == ocean_.positions.size());
    tbb::parallel_for(0, rings, [&](int j) {
        const double radius = ocean_.radii_m[size_t(j)];
        const double drop = scene::CurvatureDrop_m(radius);
        for (size_t v = ocean_.ringStart[size_t(j)]; v < ocean_.ringStart[size_t(j) + 1]; ++v) {
            // Without a surf zone the column is optically deep: 1e4 m, where the seabed's share
            // e^(−K·depth) is 0 in float for any water. Finite, because the rasterizer
            // interpolates attributes with barycentric weights that can be exactly 0, and
            // 0 · ∞ is NaN.
            glm::vec4 a(1.0e4f, 0.0f, float(scene::WhitecapCoverage(ocean_.jacobian[v], threshold)),
                        0.0f);
            if (surf) {
                const scene::Bathymetry& bathy = surf->Bathy();
                const glm::vec3& p = ocean_.positions[v];
                // The seabed under the drawn (displaced) point, dropped by the same curvature.
                const double bed = bathy.SeabedZ_m(p.x, p.y);
                a.x = float(std::max(0.0, double(p.z) + drop - bed));
                if (a.x <= 0.0f) a.z = 0.0f;  // no whitecaps on the sand
                // Sand at or below high water has been wet by the last tide; above it dries over
                // the swash's run-up (taken as 0.3 m of elevation).
                a.y = float(std::clamp(1.0 - (bed - bathy.Settings().highTide_m) / 0.3, 0.0, 1.0));
                // Surf foam (computed with the vertex, OceanMesh::surfFoam) only where there is
                // water above the seabed (none on the dry beach).
                if (a.x > 0.0f) a.z = std::max(a.z, ocean_.surfFoam[v]);
            }
            oceanAttributes_[v] = a;
        }
    });
}

void ViewGeometry::Update(const scene::SceneState& state) {
    camera_ = MakeChannelCamera(state.eyepoint, settings_);
    const ChannelCamera& cam = camera_;
    UpdateEntities(state);

    using Clock = std::chrono::steady_clock;
    const auto Ms = [](Clock::time_point a, Clock::time_point b) {
        return std::chrono::duration<double, std::milli>(b - a).count();
    };
    const Clock::time_point t0 = Clock::now();
    // The sea surface at the frame time (shared with every other user of this time), then its
    // mesh for this view: vertices kOceanVertexSpacing_px apart on screen.
    oceanFrame_ = world_.Ocean().At(state.time_s);
    const scene::OceanSurfaceFrame& sea = *oceanFrame_;
    const Clock::time_point tSea = Clock::now();
    scene::BuildOceanMesh(sea, SeaMeshRequest(cam, sea, renderSpans_), ocean_);
    UpdateOceanAttributes();

    std::vector<RasterMesh> meshes;
    // The sea is seen from both sides only when a camera dips below it; cull back faces.
    meshes.push_back({ocean_.positions, ocean_.indices, true});
    for (const scene::TriangleMesh& m : worldMeshes_)
        meshes.push_back({m.positions, m.indices, true});
    const Clock::time_point t1 = Clock::now();
    rasterizer_.Render(meshes, cam.Raster(), vis_);
    const Clock::time_point t2 = Clock::now();

    stats_ = {};
    stats_.raster = rasterizer_.Stats();
    stats_.oceanMs = Ms(t0, tSea);
    stats_.meshMs = Ms(tSea, t1);
    stats_.rasterMs = Ms(t1, t2);
    stats_.oceanTriangles = ocean_.indices.size() / 3;
    for (const scene::TriangleMesh& m : worldMeshes_) stats_.modelTriangles += m.TriangleCount();
}

}  // namespace seasense::channels
