// Embree 3 occlusion scene: triangle meshes, refit of moving meshes, shadow-ray packets.
#include "channels/occlusion/occlusion.h"

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "scene/core/check.h"
#include "scene/core/error.h"

namespace seasense::channels {

namespace {

static_assert(sizeof(glm::vec3) == 3 * sizeof(float), "vertex copy assumes packed float3");

constexpr float kInf = std::numeric_limits<float>::infinity();

// Embree reads the last element of a buffer with a 16-byte SSE load (Embree 3 API manual,
// rtcSetGeometryBuffer), so every buffer we hand it carries this much zeroed slack.
constexpr size_t kBufferPadding_bytes = 16;

// Origins per parallel work item. Packets are gathered inside a block only, so the packet
// composition (and with it every result) does not depend on the thread count.
constexpr size_t kBlockSize = 1024;

const char* ErrorName(RTCError code) {
    switch (code) {
        case RTC_ERROR_NONE:
            return "no error";
        case RTC_ERROR_UNKNOWN:
            return "unknown error";
        case RTC_ERROR_INVALID_ARGUMENT:
            return "invalid argument";
        case RTC_ERROR_INVALID_OPERATION:
            return "invalid operation";
        case RTC_ERROR_OUT_OF_MEMORY:
            return "out of memory";
        case RTC_ERROR_UNSUPPORTED_CPU:
            return "unsupported CPU";
        case RTC_ERROR_CANCELLED:
            return "cancelled";
    }
    return "unrecognised error code";
}

bool Finite(const glm::vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

void OccludedPacket(const int* valid, RTCScene scene, RTCIntersectContext* context, RTCRay4* rays) {
    rtcOccluded4(valid, scene, context, rays);
}
void OccludedPacket(const int* valid, RTCScene scene, RTCIntersectContext* context, RTCRay8* rays) {
    rtcOccluded8(valid, scene, context, rays);
}
void OccludedPacket(const int* valid, RTCScene scene, RTCIntersectContext* context,
                    RTCRay16* rays) {
    rtcOccluded16(valid, scene, context, rays);
}

// Traces origins[lanes[0..count)] along direction in one packet of width N and writes
// visible[] for those lanes. Unused lanes repeat the last ray and are masked off, so Embree
// never reads uninitialised memory.
template <int N, typename RayN>
void TracePacket(RTCScene scene, RTCIntersectContext* context, std::span<const glm::vec3> origins,
                 const size_t* lanes, int count, const glm::vec3& direction, float tNear_m,
                 std::span<uint8_t> visible) {
    alignas(64) int valid[N];
    RayN rays;
    for (int lane = 0; lane < N; ++lane) {
        const glm::vec3& origin = origins[lanes[std::min(lane, count - 1)]];
        valid[lane] = lane < count ? -1 : 0;
        rays.org_x[lane] = origin.x;
        rays.org_y[lane] = origin.y;
        rays.org_z[lane] = origin.z;
        rays.tnear[lane] = tNear_m;
        rays.dir_x[lane] = direction.x;
        rays.dir_y[lane] = direction.y;
        rays.dir_z[lane] = direction.z;
        rays.time[lane] = 0.0f;
        rays.tfar[lane] = kInf;
        rays.mask[lane] = ~0u;
        rays.id[lane] = static_cast<unsigned>(lane);
        rays.flags[lane] = 0;
    }
    OccludedPacket(valid, scene, context, &rays);
    // Embree marks an occluded ray by setting its tfar to −∞ (rtcOccluded16 manual page).
    for (int lane = 0; lane < count; ++lane) visible[lanes[lane]] = rays.tfar[lane] < 0.0f ? 0 : 1;
}

}  // namespace

struct OcclusionScene::Impl {
    struct Mesh {
        RTCGeometry geometry = nullptr;
        RTCBuffer vertexBuffer = nullptr;
        RTCBuffer indexBuffer = nullptr;
        size_t vertexCount = 0;
        bool dynamic = false;
        AxisBox bounds;  // of its vertices, as last added or updated
    };

    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    std::vector<Mesh> meshes;
    bool committed = false;
    // Two-level mode (scene quality LOW): each mesh has its own BVH built with its own
    // quality, which is the only way Embree 3 honours per-geometry REFIT.
    bool twoLevel = false;
    glm::vec3 boundsMin{kInf};
    glm::vec3 boundsMax{-kInf};
    // Each mesh's bounds enlarged so that float rounding in the slab test never rejects a ray
    // that Embree's robust traversal would report as a hit (MeshBoxes).
    std::vector<AxisBox> testBoxes;

    mutable std::mutex errorMutex;
    mutable std::string errorMessage;
    mutable std::atomic<bool> errorPending{false};

    // Separate from construction so that ~Impl releases whatever was created when a later
    // step throws.
    void Init(const char* config) {
        device = rtcNewDevice(config);
        if (!device) {
            std::ostringstream message;
            message << "Embree: rtcNewDevice(\"" << (config ? config : "")
                    << "\") failed: " << ErrorName(rtcGetDeviceError(nullptr));
            throw RuntimeError(message.str());
        }
        rtcSetDeviceErrorFunction(device, &Impl::OnError, this);
        scene = rtcNewScene(device);
        ThrowIfError("rtcNewScene");
        rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
        // Static casters are built once and traced many times. (With ROBUST, Embree 3.13
        // builds its binned-SAH BVH8 at MEDIUM and HIGH alike; spatial splits are for the
        // non-robust kernels only.)
        rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
        ThrowIfError("scene setup");
    }

    ~Impl() {
        for (Mesh& mesh : meshes) {
            if (mesh.geometry) rtcReleaseGeometry(mesh.geometry);
            if (mesh.vertexBuffer) rtcReleaseBuffer(mesh.vertexBuffer);
            if (mesh.indexBuffer) rtcReleaseBuffer(mesh.indexBuffer);
        }
        if (scene) rtcReleaseScene(scene);
        if (device) rtcReleaseDevice(device);
    }

    // Embree calls this from inside its API functions; throwing here would unwind through
    // Embree's C interface, so the error is recorded and rethrown by ThrowIfError.
    static void OnError(void* user, RTCError code, const char* text) {
        auto* impl = static_cast<Impl*>(user);
        std::lock_guard lock(impl->errorMutex);
        if (impl->errorPending.load(std::memory_order_relaxed)) return;  // keep the first
        impl->errorMessage = std::string(ErrorName(code)) + ": " + (text ? text : "");
        impl->errorPending.store(true, std::memory_order_release);
    }

    // Build-side check: the callback's record, and the device's per-thread error code as a
    // second source. Queries use ThrowIfRecorded, a single atomic load, to stay out of
    // Embree's per-thread error storage on the hot path.
    void ThrowIfError(const char* operation) const {
        const RTCError code = rtcGetDeviceError(device);
        if (!errorPending.load(std::memory_order_acquire) && code == RTC_ERROR_NONE) return;
        Rethrow(operation, code);
    }

    void ThrowIfRecorded(const char* operation) const {
        if (errorPending.load(std::memory_order_acquire)) Rethrow(operation, RTC_ERROR_UNKNOWN);
    }

    [[noreturn]] void Rethrow(const char* operation, RTCError code) const {
        std::string message;
        {
            std::lock_guard lock(errorMutex);
            message = errorPending ? errorMessage : std::string(ErrorName(code));
            errorMessage.clear();
            errorPending.store(false, std::memory_order_release);
        }
        throw RuntimeError(std::string("Embree error in ") + operation + ": " + message);
    }

    // Copies positions into a padded Embree buffer; throws InputError for non-finite input.
    static void CopyPositions(std::span<const glm::vec3> positions, RTCBuffer buffer,
                              const char* where) {
        for (size_t i = 0; i < positions.size(); ++i) {
            if (!Finite(positions[i])) {
                std::ostringstream message;
                message << where << ": vertex " << i << " is not finite (" << positions[i].x << ", "
                        << positions[i].y << ", " << positions[i].z
                        << "); expected finite world ENU metres";
                throw InputError(message.str());
            }
        }
        std::memcpy(rtcGetBufferData(buffer), positions.data(),
                    positions.size() * sizeof(glm::vec3));
    }

    static AxisBox Bounds(std::span<const glm::vec3> positions) {
        AxisBox box{glm::vec3(kInf), glm::vec3(-kInf)};
        for (const glm::vec3& p : positions)
            box.min = glm::min(box.min, p), box.max = glm::max(box.max, p);
        return box;
    }

    RTCBuffer NewPaddedBuffer(size_t bytes) {
        RTCBuffer buffer = rtcNewBuffer(device, bytes + kBufferPadding_bytes);
        ThrowIfError("rtcNewBuffer");
        std::memset(rtcGetBufferData(buffer), 0, bytes + kBufferPadding_bytes);
        return buffer;
    }
};

OcclusionScene::OcclusionScene() : OcclusionScene(nullptr) {}

OcclusionScene::OcclusionScene(const char* embreeConfig) : impl_(std::make_unique<Impl>()) {
    impl_->Init(embreeConfig);
}

OcclusionScene::~OcclusionScene() = default;

uint32_t OcclusionScene::AddMesh(std::span<const glm::vec3> positions,
                                 std::span<const uint32_t> indices) {
    constexpr const char* kWhere = "OcclusionScene::AddMesh";
    if (positions.empty() || indices.empty()) {
        std::ostringstream message;
        message << kWhere << ": empty mesh (" << positions.size() << " vertices, " << indices.size()
                << " indices); expected at least one triangle";
        throw InputError(message.str());
    }
    if (indices.size() % 3 != 0) {
        std::ostringstream message;
        message << kWhere << ": " << indices.size()
                << " indices; expected a multiple of 3 (one triple per triangle)";
        throw InputError(message.str());
    }
    if (positions.size() > std::numeric_limits<uint32_t>::max() ||
        indices.size() / 3 > std::numeric_limits<uint32_t>::max()) {
        throw InputError(std::string(kWhere) + ": mesh too large; expected < 2^32 vertices " +
                         "and triangles");
    }
    for (size_t i = 0; i < indices.size(); ++i) {
        if (indices[i] >= positions.size()) {
            std::ostringstream message;
            message << kWhere << ": index " << i << " (triangle " << i / 3 << ") is " << indices[i]
                    << "; expected < vertex count " << positions.size();
            throw InputError(message.str());
        }
    }

    Impl& impl = *impl_;
    Impl::Mesh mesh;
    mesh.vertexCount = positions.size();
    // Released by ~Impl once the mesh is in the list; until then guard it here.
    struct Guard {
        Impl::Mesh* mesh;
        ~Guard() {
            if (!mesh) return;
            if (mesh->geometry) rtcReleaseGeometry(mesh->geometry);
            if (mesh->vertexBuffer) rtcReleaseBuffer(mesh->vertexBuffer);
            if (mesh->indexBuffer) rtcReleaseBuffer(mesh->indexBuffer);
        }
    } guard{&mesh};

    mesh.vertexBuffer = impl.NewPaddedBuffer(positions.size() * sizeof(glm::vec3));
    Impl::CopyPositions(positions, mesh.vertexBuffer, kWhere);
    mesh.bounds = Impl::Bounds(positions);
    mesh.indexBuffer = impl.NewPaddedBuffer(indices.size() * sizeof(uint32_t));
    std::memcpy(rtcGetBufferData(mesh.indexBuffer), indices.data(),
                indices.size() * sizeof(uint32_t));

    mesh.geometry = rtcNewGeometry(impl.device, RTC_GEOMETRY_TYPE_TRIANGLE);
    impl.ThrowIfError("rtcNewGeometry");
    rtcSetGeometryBuffer(mesh.geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                         mesh.vertexBuffer, 0, sizeof(glm::vec3), positions.size());
    rtcSetGeometryBuffer(mesh.geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                         mesh.indexBuffer, 0, 3 * sizeof(uint32_t), indices.size() / 3);
    // Used only once the scene is two-level (after the first UpdateMesh).
    rtcSetGeometryBuildQuality(mesh.geometry, RTC_BUILD_QUALITY_HIGH);
    rtcCommitGeometry(mesh.geometry);
    impl.ThrowIfError("AddMesh geometry setup");
    const unsigned id = rtcAttachGeometry(impl.scene, mesh.geometry);
    impl.ThrowIfError("rtcAttachGeometry");
    // Embree hands out ids 0, 1, 2, ... when none is ever detached; UpdateMesh relies on it.
    CHECK_MSG(id == impl.meshes.size(),
              "Embree geometry id " << id << " for mesh " << impl.meshes.size());
    impl.meshes.push_back(mesh);
    guard.mesh = nullptr;
    impl.committed = false;
    return id;
}

void OcclusionScene::UpdateMesh(uint32_t geometryId, std::span<const glm::vec3> positions) {
    Impl& impl = *impl_;
    CHECK_MSG(geometryId < impl.meshes.size(),
              "UpdateMesh: geometry id " << geometryId << " of " << impl.meshes.size());
    Impl::Mesh& mesh = impl.meshes[geometryId];
    if (positions.size() != mesh.vertexCount) {
        std::ostringstream message;
        message << "OcclusionScene::UpdateMesh: mesh " << geometryId << " got " << positions.size()
                << " vertices; expected " << mesh.vertexCount << " (the count given to AddMesh)";
        throw InputError(message.str());
    }
    Impl::CopyPositions(positions, mesh.vertexBuffer, "OcclusionScene::UpdateMesh");
    mesh.bounds = Impl::Bounds(positions);
    if (!impl.twoLevel) {
        // Embree 3 refits per geometry only in a two-level scene (scene quality LOW, see
        // rtcSetGeometryBuildQuality); static meshes keep their own high-quality BVHs there.
        rtcSetSceneFlags(impl.scene, RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_DYNAMIC);
        rtcSetSceneBuildQuality(impl.scene, RTC_BUILD_QUALITY_LOW);
        impl.twoLevel = true;
    }
    if (!mesh.dynamic) {
        rtcSetGeometryBuildQuality(mesh.geometry, RTC_BUILD_QUALITY_REFIT);
        mesh.dynamic = true;
    }
    rtcUpdateGeometryBuffer(mesh.geometry, RTC_BUFFER_TYPE_VERTEX, 0);
    rtcCommitGeometry(mesh.geometry);
    impl.ThrowIfError("UpdateMesh");
    impl.committed = false;
}

void OcclusionScene::Commit() {
    Impl& impl = *impl_;
    rtcCommitScene(impl.scene);
    impl.ThrowIfError("rtcCommitScene");
    impl.testBoxes.clear();
    if (impl.meshes.empty()) {
        impl.boundsMin = glm::vec3(kInf);
        impl.boundsMax = glm::vec3(-kInf);
    } else {
        RTCBounds bounds;
        rtcGetSceneBounds(impl.scene, &bounds);
        impl.ThrowIfError("rtcGetSceneBounds");
        impl.boundsMin = glm::vec3(bounds.lower_x, bounds.lower_y, bounds.lower_z);
        impl.boundsMax = glm::vec3(bounds.upper_x, bounds.upper_y, bounds.upper_z);
        // Relative part covers float rounding at the coordinates' magnitude (1e-5 ≈ 100 ulp),
        // the absolute part flat boxes (a single horizontal triangle). The meshes' own boxes
        // (their vertices', which hold their triangles') get the margin of the largest.
        glm::vec3 lo(kInf), hi(-kInf);
        for (const Impl::Mesh& mesh : impl.meshes)
            lo = glm::min(lo, mesh.bounds.min), hi = glm::max(hi, mesh.bounds.max);
        const glm::vec3 magnitude = glm::max(glm::abs(lo), glm::abs(hi));
        const float scale = std::max({magnitude.x, magnitude.y, magnitude.z});
        const float margin_m = 1e-5f * scale + 1e-4f;
        for (const Impl::Mesh& mesh : impl.meshes)
            impl.testBoxes.push_back({mesh.bounds.min - margin_m, mesh.bounds.max + margin_m});
    }
    impl.committed = true;
}

bool OcclusionScene::Empty() const { return impl_->meshes.empty(); }

glm::vec3 OcclusionScene::BoundsMin() const {
    CHECK_MSG(impl_->committed, "OcclusionScene::BoundsMin before Commit()");
    return impl_->boundsMin;
}

glm::vec3 OcclusionScene::BoundsMax() const {
    CHECK_MSG(impl_->committed, "OcclusionScene::BoundsMax before Commit()");
    return impl_->boundsMax;
}

std::span<const AxisBox> OcclusionScene::MeshBoxes() const {
    CHECK_MSG(impl_->committed, "OcclusionScene::MeshBoxes before Commit()");
    return impl_->testBoxes;
}

bool OcclusionScene::MayOcclude(const glm::vec3& origin, const glm::vec3& direction,
                                float maxDistance_m) const {
    const Impl& impl = *impl_;
    CHECK_MSG(impl.committed, "OcclusionScene::MayOcclude before Commit()");
    CHECK_MSG(Finite(origin) && Finite(direction) && !std::isnan(maxDistance_m),
              "MayOcclude: non-finite ray");
    return BoundsTest(direction, maxDistance_m).MayOcclude(origin);
}

OccluderBoundsTest OcclusionScene::BoundsTest(const glm::vec3& direction,
                                              float maxDistance_m) const {
    const Impl& impl = *impl_;
    CHECK_MSG(impl.committed, "OcclusionScene::BoundsTest before Commit()");
    CHECK_MSG(Finite(direction) && !std::isnan(maxDistance_m), "BoundsTest: non-finite ray");
    OccluderBoundsTest test;
    test.boxes_ = RayBoxesTest(impl.testBoxes, direction, maxDistance_m);
    return test;
}

bool OcclusionScene::Occluded(const glm::vec3& a, const glm::vec3& b) const {
    const Impl& impl = *impl_;
    CHECK_MSG(impl.committed, "OcclusionScene::Occluded before Commit()");
    CHECK_MSG(Finite(a) && Finite(b), "Occluded: non-finite segment end");
    if (impl.meshes.empty()) return false;
    const glm::vec3 delta = b - a;
    const float length_m = glm::length(delta);
    if (!(length_m > 0.0f)) return false;
    const glm::vec3 direction = delta / length_m;

    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay ray;
    ray.org_x = a.x;
    ray.org_y = a.y;
    ray.org_z = a.z;
    ray.tnear = kSegmentEpsilon * length_m;
    ray.dir_x = direction.x;
    ray.dir_y = direction.y;
    ray.dir_z = direction.z;
    ray.time = 0.0f;
    ray.tfar = length_m * (1.0f - kSegmentEpsilon);
    ray.mask = ~0u;
    ray.id = 0;
    ray.flags = 0;
    rtcOccluded1(impl.scene, &context, &ray);
    impl.ThrowIfRecorded("Occluded");
    return ray.tfar < 0.0f;
}

void OcclusionScene::DirectionalVisibility(std::span<const glm::vec3> origins,
                                           const glm::vec3& direction, float tNear_m,
                                           std::span<uint8_t> visible,
                                           bool originsMayOcclude) const {
    const Impl& impl = *impl_;
    CHECK_MSG(impl.committed, "OcclusionScene::DirectionalVisibility before Commit()");
    CHECK_MSG(visible.size() == origins.size(),
              "DirectionalVisibility: " << visible.size() << " outputs for " << origins.size()
                                        << " origins");
    CHECK_MSG(Finite(direction) && std::abs(glm::length(direction) - 1.0f) < 1e-3f,
              "DirectionalVisibility: direction must be a unit vector");
    CHECK_MSG(std::isfinite(tNear_m) && tNear_m >= 0.0f,
              "DirectionalVisibility: tNear_m = " << tNear_m << ", expected finite >= 0");
    if (impl.meshes.empty()) {
        for (size_t i = 0; i < origins.size(); ++i) {
            CHECK_MSG(Finite(origins[i]), "DirectionalVisibility: origin " << i << " not finite");
            visible[i] = 1;
        }
        return;
    }
    const OccluderBoundsTest occluders = BoundsTest(direction, kInf);

    auto traceBlock = [&](size_t begin, size_t end) {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        // Every ray of a call shares one direction and origins come in image order.
        context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
        size_t lanes[16];
        int count = 0;
        for (size_t i = begin; i < end; ++i) {
            CHECK_MSG(Finite(origins[i]), "DirectionalVisibility: origin " << i << " not finite");
            if (!originsMayOcclude && !occluders.MayOcclude(origins[i])) {
                visible[i] = 1;
                continue;
            }
            lanes[count++] = i;
            if (count == 16) {
                TracePacket<16, RTCRay16>(impl.scene, &context, origins, lanes, count, direction,
                                          tNear_m, visible);
                count = 0;
            }
        }
        if (count > 8)
            TracePacket<16, RTCRay16>(impl.scene, &context, origins, lanes, count, direction,
                                      tNear_m, visible);
        else if (count > 4)
            TracePacket<8, RTCRay8>(impl.scene, &context, origins, lanes, count, direction, tNear_m,
                                    visible);
        else if (count > 0)
            TracePacket<4, RTCRay4>(impl.scene, &context, origins, lanes, count, direction, tNear_m,
                                    visible);
    };

    const size_t blockCount = (origins.size() + kBlockSize - 1) / kBlockSize;
    if (blockCount <= 1) {
        traceBlock(0, origins.size());
    } else {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, blockCount),
                          [&](const tbb::blocked_range<size_t>& range) {
                              for (size_t block = range.begin(); block != range.end(); ++block)
                                  traceBlock(block * kBlockSize,
                                             std::min(origins.size(), (block + 1) * kBlockSize));
                          });
    }
    impl.ThrowIfRecorded("DirectionalVisibility");
}

}  // namespace seasense::channels
