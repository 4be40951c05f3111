// Triangle meshes for placed models, and loading them from OBJ / glTF 2.0 files with assimp.
#pragma once

#include <cstdint>
#include <filesystem>
#include <glm/glm.hpp>
#include <vector>

#include "scene/core/frames.h"

namespace seasense::scene {

// Positions and normals in one frame (body or world); counter-clockwise front faces.
struct TriangleMesh {
    std::vector<glm::vec3> positions;
    std::vector<glm::vec3> normals;  // one per vertex, unit
    std::vector<uint32_t> indices;   // three per triangle

    size_t TriangleCount() const { return indices.size() / 3; }
};

// Loads every mesh of an OBJ or glTF 2.0 file, flattened through its node hierarchy, into the
// body frame (x right, y forward, z up) from the files' glTF convention (+Y up, +Z forward,
// metres), scaled by scale. Throws InputError naming the file on any failure.
TriangleMesh LoadModel(const std::filesystem::path& file, double scale);

// The mesh moved into the world frame by pose.
TriangleMesh TransformMesh(const TriangleMesh& body, const Pose& worldFromBody);

}  // namespace seasense::scene
