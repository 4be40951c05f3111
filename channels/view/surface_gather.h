// Surface points of visibility-buffer samples: the hit mesh, and position and normal
// interpolated from the hit triangle, with the triangle's vertices kept between samples.
#pragma once

#include <algorithm>
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "channels/raster/rasterizer.h"
#include "scene/core/simd4.h"

namespace seasense::channels {

// Vertex attributes above this (the +∞ water column of a sea without a surf zone) are taken as
// this value, so that they interpolate finitely.
inline constexpr float kMaxVertexAttribute = 1.0e4f;

// Vertex arrays of one rasterized mesh (mesh 0 the sea, mesh i ≥ 1 entity i − 1). attributes:
// optional per-vertex values interpolated like the normals (the sea's
// ViewGeometry::OceanAttributes).
struct MeshArrays {
    const glm::vec3* positions;
    const glm::vec3* normals;
    const uint32_t* indices;
    const glm::vec4* attributes = nullptr;
};

// Mesh m's primitives are [primitiveBase[m], primitiveBase[m + 1]): the mesh of prim by binary
// search (the base list is sorted; meshes without triangles repeat a base).
inline int MeshOfPrimitive(const std::vector<uint32_t>& primitiveBase, uint32_t prim) {
    const auto it = std::upper_bound(primitiveBase.begin(), primitiveBase.end(), prim);
    return int(it - primitiveBase.begin()) - 1;
}

// The triangle last met in a sample row, its vertices as SSE (x, y, z, 0): neighbouring samples
// mostly see the same triangle, so its six vertices are gathered once.
class TriangleCache {
  public:
    // Position and (unnormalized) interpolated normal of the surface point with barycentrics
    // (1 − b1 − b2, b1, b2) on primitive prim, written as (x, y, z, 0) to position[4] and
    // normal[4]; mesh receives the mesh index. Sums in glm's
    // order ((b0 a0 + b1 a1) + b2 a2), so results equal the scalar interpolation.
    void Surface(const std::vector<uint32_t>& primitiveBase, const std::vector<MeshArrays>& meshes,
                 uint32_t prim, float b1, float b2, float* position, float* normal, int& mesh) {
        using namespace simd4;
        if (prim != prim_) {
            mesh_ = MeshOfPrimitive(primitiveBase, prim);
            const MeshArrays& m = meshes[size_t(mesh_)];
            const uint32_t t = prim - primitiveBase[size_t(mesh_)];
            const uint32_t i0 = m.indices[3 * t], i1 = m.indices[3 * t + 1],
                           i2 = m.indices[3 * t + 2];
            prim_ = prim;
            p_[0] = Load3(m.positions[i0]), p_[1] = Load3(m.positions[i1]);
            p_[2] = Load3(m.positions[i2]);
            n_[0] = Load3(m.normals[i0]), n_[1] = Load3(m.normals[i1]);
            n_[2] = Load3(m.normals[i2]);
            if (m.attributes) {
                const F4 top = Set4(kMaxVertexAttribute);
                a_[0] = _mm_min_ps(_mm_loadu_ps(&m.attributes[i0].x), top);
                a_[1] = _mm_min_ps(_mm_loadu_ps(&m.attributes[i1].x), top);
                a_[2] = _mm_min_ps(_mm_loadu_ps(&m.attributes[i2].x), top);
            } else {
                a_[0] = a_[1] = a_[2] = _mm_setzero_ps();
            }
        }
        const F4 w0 = Set4(1.0f - b1 - b2), w1 = Set4(b1), w2 = Set4(b2);
        _mm_storeu_ps(position, Interpolate(w0, w1, w2, p_));
        _mm_storeu_ps(normal, Interpolate(w0, w1, w2, n_));
        mesh = mesh_;
    }

    // The vertex attributes of the triangle of the last Surface call (0 for a mesh without them)
    // at barycentrics (1 − b1 − b2, b1, b2), written to attributes[4]; the same sums as Surface.
    void Attributes(float b1, float b2, float* attributes) const {
        using namespace simd4;
        const F4 w0 = Set4(1.0f - b1 - b2), w1 = Set4(b1), w2 = Set4(b2);
        _mm_storeu_ps(attributes, Interpolate(w0, w1, w2, a_));
    }

  private:
    static simd4::F4 Load3(const glm::vec3& v) { return _mm_setr_ps(v.x, v.y, v.z, 0.0f); }
    static simd4::F4 Interpolate(simd4::F4 w0, simd4::F4 w1, simd4::F4 w2, const simd4::F4* a) {
        return _mm_add_ps(_mm_add_ps(_mm_mul_ps(w0, a[0]), _mm_mul_ps(w1, a[1])),
                          _mm_mul_ps(w2, a[2]));
    }

    uint32_t prim_ = kNoPrimitive;
    int mesh_ = 0;
    simd4::F4 p_[3] = {}, n_[3] = {}, a_[3] = {};
};

}  // namespace seasense::channels
