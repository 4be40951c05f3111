// Embree 3 occlusion queries over the scene's meshes: sun/moon shadow rays and line of sight.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <memory>
#include <span>

namespace seasense::channels {

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

    // True when the ray from origin along unit direction can meet the casters' bounding
    // box within maxDistance_m: a cheap test that lets shading skip shadow rays.
    bool MayOcclude(const glm::vec3& origin, const glm::vec3& direction, float maxDistance_m) const;

    // True when the open segment from a to b hits any mesh.
    bool Occluded(const glm::vec3& a, const glm::vec3& b) const;

    // Shadow rays toward a directional light: for each origin, visible[i] = 0 when the ray
    // origin[i] + t·direction, t ∈ (tNear_m, ∞) hits a mesh, 1 otherwise. Traced in packets
    // of up to 16 (rtcOccluded16/8/4); origins for which MayOcclude is false are not traced.
    void DirectionalVisibility(std::span<const glm::vec3> origins, const glm::vec3& direction,
                               float tNear_m, std::span<uint8_t> visible) const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace seasense::channels
