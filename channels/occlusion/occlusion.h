// Embree 3 occlusion queries over the scene's meshes: sun/moon shadow rays and line of sight.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <limits>
#include <memory>
#include <span>
#include <utility>

namespace seasense::channels {

namespace occlusion_detail {

// Direction components smaller than this are treated as parallel to a slab: the ray would
// have to travel ~1e16 m to cross the bounds' enlargement margin along that axis.
inline constexpr float kParallelEpsilon = 1e-20f;

inline glm::vec3 InverseDirection(const glm::vec3& direction) {
    glm::vec3 inv(0.0f);
    for (int axis = 0; axis < 3; ++axis)
        if (std::abs(direction[axis]) >= kParallelEpsilon) inv[axis] = 1.0f / direction[axis];
    return inv;
}

// Ray/box slab test (Kay & Kajiya, "Ray tracing complex scenes", SIGGRAPH 1986) restricted
// to t ∈ [0, tMax_m]. invDirection holds 1/direction per axis (unused for parallel axes).
// Inlined into the box loops of RayBoxesTest (a call per box cost more than the test).
[[gnu::always_inline]] inline bool SlabHit(const glm::vec3& boxMin, const glm::vec3& boxMax,
                                           const glm::vec3& origin, const glm::vec3& direction,
                                           const glm::vec3& invDirection, float tMax_m) {
    float t0 = 0.0f;
    float t1 = tMax_m;
    for (int axis = 0; axis < 3; ++axis) {
        if (std::abs(direction[axis]) < kParallelEpsilon) {
            if (origin[axis] < boxMin[axis] || origin[axis] > boxMax[axis]) return false;
            continue;
        }
        float tA = (boxMin[axis] - origin[axis]) * invDirection[axis];
        float tB = (boxMax[axis] - origin[axis]) * invDirection[axis];
        if (tA > tB) std::swap(tA, tB);
        t0 = std::max(t0, tA);
        t1 = std::min(t1, tB);
        if (t0 > t1) return false;
    }
    return true;
}

}  // namespace occlusion_detail

// An axis-aligned box, world ENU metres.
struct AxisBox {
    glm::vec3 min{0.0f}, max{0.0f};
};

// Whether rays along one direction, t ∈ [0, maxDistance_m], from many origins may meet any of a
// few boxes (the shadow casters', one each): SlabHit per box, set up once (the inverse
// direction) and inline. The boxes' union is tested first, so that the many rays that miss all
// casters cost one test: it passes whenever some box's test passes (SlabHit is monotone in the
// box, float rounding included, and its min and max are exact), so the answer is that of the
// boxes alone. Refers to the boxes: valid while they are not changed.
class RayBoxesTest {
  public:
    RayBoxesTest() = default;
    RayBoxesTest(std::span<const AxisBox> boxes, const glm::vec3& direction, float maxDistance_m)
        : boxes_(boxes),
          direction_(direction),
          inverse_(occlusion_detail::InverseDirection(direction)),
          maxDistance_m_(maxDistance_m) {
        union_.min = glm::vec3(std::numeric_limits<float>::infinity());
        union_.max = -union_.min;
        for (const AxisBox& box : boxes)
            union_.min = glm::min(union_.min, box.min), union_.max = glm::max(union_.max, box.max);
        if (maxDistance_m < 0.0f) boxes_ = {};
    }

    // Whether the ray from origin may meet some box.
    bool MayHit(const glm::vec3& origin) const {
        if (boxes_.empty() || !Hit(union_.min, union_.max, origin)) return false;
        if (boxes_.size() == 1) return true;  // the union is the box
        for (const AxisBox& box : boxes_)
            if (Hit(box.min, box.max, origin)) return true;
        return false;
    }
    // Whether the ray from origin may meet some box grown by grow_m (≥ 0) on each side: also
    // whether any ray from a point within grow_m of origin per axis may meet that box itself
    // (Minkowski sum). The grown union is the union of the grown boxes (rounding is monotone).
    bool MayHit(const glm::vec3& origin, const glm::vec3& grow_m) const {
        if (boxes_.empty() || !Hit(union_.min - grow_m, union_.max + grow_m, origin)) return false;
        if (boxes_.size() == 1) return true;
        for (const AxisBox& box : boxes_)
            if (Hit(box.min - grow_m, box.max + grow_m, origin)) return true;
        return false;
    }

  private:
    [[gnu::always_inline]] bool Hit(const glm::vec3& lo, const glm::vec3& hi,
                                    const glm::vec3& origin) const {
        return occlusion_detail::SlabHit(lo, hi, origin, direction_, inverse_, maxDistance_m_);
    }

    std::span<const AxisBox> boxes_;  // none: nothing is hit
    AxisBox union_;
    glm::vec3 direction_{0.0f, 0.0f, 1.0f}, inverse_{0.0f};
    float maxDistance_m_ = 0.0f;
};

// OcclusionScene::MayOcclude for one direction and distance, set up once and inline, for the
// many shadow-ray origins of a frame: MayOcclude(o) equals the scene's MayOcclude(o, direction,
// maxDistance_m) for every finite o (checked by the scene's call, not here). Valid while the
// scene is not changed.
class OccluderBoundsTest {
  public:
    bool MayOcclude(const glm::vec3& origin) const { return boxes_.MayHit(origin); }

  private:
    friend class OcclusionScene;
    RayBoxesTest boxes_;  // the meshes' boxes, each enlarged as OcclusionScene::MeshBoxes says
};

// Build-then-commit: add meshes, Commit(), then query from any number of threads.
// Positions are world ENU metres (float precision: scenes within ~10 km of the origin).
// AddMesh, UpdateMesh and Commit must not run concurrently with queries or with each other.
// Embree failures (out of memory, unsupported CPU, bad device config) throw RuntimeError.
class OcclusionScene {
  public:
    // Relative epsilon of Occluded(a, b): the segment is traced over
    // t ∈ (ε·|b−a|, (1−ε)·|b−a|) so that endpoints lying on a surface do not hit it.
    static constexpr float kSegmentEpsilon = 1e-4f;

    OcclusionScene();
    // embreeConfig is passed to rtcNewDevice (e.g. "isa=sse4.2" pins the kernel ISA,
    // "verbose=1" prints the selected acceleration structures).
    explicit OcclusionScene(const char* embreeConfig);
    ~OcclusionScene();
    OcclusionScene(const OcclusionScene&) = delete;
    OcclusionScene& operator=(const OcclusionScene&) = delete;

    // A static mesh (copied). Returns its geometry id.
    // Throws InputError for non-finite positions, an index count that is not a multiple of
    // 3, an index out of range or an empty mesh.
    uint32_t AddMesh(std::span<const glm::vec3> positions, std::span<const uint32_t> indices);
    // Replaces a mesh's vertex positions (same count) for a moving instance; takes effect at
    // the next Commit() (refit). The mesh is treated as dynamic from then on.
    void UpdateMesh(uint32_t geometryId, std::span<const glm::vec3> positions);
    void Commit();

    // True when no mesh was added.
    bool Empty() const;
    // World bounds of every caster (valid after Commit()). An empty scene has
    // BoundsMin() = +∞ and BoundsMax() = −∞.
    glm::vec3 BoundsMin() const;
    glm::vec3 BoundsMax() const;

    // Each mesh's bounding box (in AddMesh order; valid after Commit()), enlarged so that
    // float rounding in a slab test never rejects a ray that Embree's robust traversal reports
    // as meeting the mesh: by 1e-5 of the largest coordinate of any mesh plus 0.1 mm.
    std::span<const AxisBox> MeshBoxes() const;

    // True when the ray from origin along unit direction can meet some mesh's box (MeshBoxes)
    // within maxDistance_m: a cheap test that lets shading skip shadow rays.
    bool MayOcclude(const glm::vec3& origin, const glm::vec3& direction, float maxDistance_m) const;
    // MayOcclude along one direction, prepared for many origins (OccluderBoundsTest).
    OccluderBoundsTest BoundsTest(const glm::vec3& direction, float maxDistance_m) const;

    // True when the open segment from a to b hits any mesh.
    bool Occluded(const glm::vec3& a, const glm::vec3& b) const;

    // Shadow rays toward a directional light: for each origin, visible[i] = 0 when the ray
    // origin[i] + t·direction, t ∈ (tNear_m, ∞) hits a mesh, 1 otherwise. Traced in packets
    // of up to 16 (rtcOccluded16/8/4); origins for which MayOcclude is false are not traced.
    // originsMayOcclude: the caller kept only origins for which MayOcclude(origin, direction,
    // d) is true (any d ≥ 0), so that test is not repeated here (it is true with d = ∞ too).
    void DirectionalVisibility(std::span<const glm::vec3> origins, const glm::vec3& direction,
                               float tNear_m, std::span<uint8_t> visible,
                               bool originsMayOcclude = false) const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace seasense::channels
