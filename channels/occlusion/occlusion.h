// Embree 3 occlusion queries over the scene's meshes: sun/moon shadow rays and line of sight.
#pragma once

#include <cstdint>
#include <memory>
#include <span>

#include <glm/glm.hpp>

namespace seasense::channels {

// Build-then-commit: add meshes, Commit(), then query from any number of threads.
// Positions are world ENU metres (float precision: scenes within ~10 km of the origin).
class OcclusionScene {
public:
    OcclusionScene();
    ~OcclusionScene();
    OcclusionScene(const OcclusionScene&) = delete;
    OcclusionScene& operator=(const OcclusionScene&) = delete;

    // A static mesh (copied). Returns its geometry id.
    uint32_t AddMesh(std::span<const glm::vec3> positions, std::span<const uint32_t> indices);
    // Replaces a mesh's vertex positions (same count) for a moving instance; takes effect at
    // the next Commit() (refit).
    void UpdateMesh(uint32_t geometryId, std::span<const glm::vec3> positions);
    void Commit();

    bool Empty() const;
    // World bounds of every caster (valid after Commit()).
    glm::vec3 BoundsMin() const;
    glm::vec3 BoundsMax() const;

    // True when the ray from origin along unit direction can meet the casters' bounding
    // box within maxDistance_m: a cheap test that lets shading skip shadow rays.
    bool MayOcclude(const glm::vec3& origin, const glm::vec3& direction,
                    float maxDistance_m) const;

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
