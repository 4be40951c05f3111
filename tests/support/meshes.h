// Small analytic meshes shared by tests and benchmarks.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

namespace seasense::testing {

struct SimpleMesh {
    std::vector<glm::vec3> positions;
    std::vector<uint32_t> indices;  // three per triangle, counter-clockwise from outside
};

// Axis-aligned box [lo, hi] as 8 corners and 12 triangles (two per face), faces
// counter-clockwise seen from outside in a right-handed frame.
inline SimpleMesh MakeBox(const glm::vec3& lo, const glm::vec3& hi) {
    SimpleMesh mesh;
    for (int corner = 0; corner < 8; ++corner)
        mesh.positions.emplace_back(corner & 1 ? hi.x : lo.x, corner & 2 ? hi.y : lo.y,
                                    corner & 4 ? hi.z : lo.z);
    // Each face as a quad of corner indices, split along one diagonal.
    const uint32_t faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                  {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (const auto& f : faces)
        mesh.indices.insert(mesh.indices.end(), {f[0], f[1], f[2], f[0], f[2], f[3]});
    return mesh;
}

}  // namespace seasense::testing
