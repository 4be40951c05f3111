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

// A vertex as (x, y, z, 0).
inline simd4::F4 Load3(const glm::vec3& v) { return _mm_setr_ps(v.x, v.y, v.z, 0.0f); }
// w0 a[0] + w1 a[1] + w2 a[2] in glm's order ((b0 a0 + b1 a1) + b2 a2), so results equal the
// scalar interpolation.
inline simd4::F4 Interpolate(simd4::F4 w0, simd4::F4 w1, simd4::F4 w2, const simd4::F4* a) {
    return _mm_add_ps(_mm_add_ps(_mm_mul_ps(w0, a[0]), _mm_mul_ps(w1, a[1])), _mm_mul_ps(w2, a[2]));
}

// The triangle last met in a sample row, its vertices as SSE (x, y, z, 0): neighbouring samples
// mostly see the same triangle, so its six vertices are gathered once.
class TriangleCache {
  public:
    // Position and (unnormalized) interpolated normal of the surface point with barycentrics
    // (1 − b1 − b2, b1, b2) on primitive prim, written as (x, y, z, 0) to position[4] and
    // normal[4]; mesh receives the mesh index (Interpolate's sums).
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
        }
        const F4 w0 = Set4(1.0f - b1 - b2), w1 = Set4(b1), w2 = Set4(b2);
        _mm_storeu_ps(position, Interpolate(w0, w1, w2, p_));
        _mm_storeu_ps(normal, Interpolate(w0, w1, w2, n_));
        mesh = mesh_;
    }

  private:
    uint32_t prim_ = kNoPrimitive;
    int mesh_ = 0;
    simd4::F4 p_[3] = {}, n_[3] = {};
};

// Sea-mesh samples of visibility-buffer rows gathered into records: per sample the
// position and (unnormalized) normal as one record (x, y, z, 0, nx, ny, nz, 0) and the vertex
// attributes (depth, wet, foam, ·), all interpolated with TriangleCache's sums, so the same
// bits. Most samples of a row are sea, so this is the shading pass's inner loop: the sea mesh
// is known (no search for the mesh) and the last triangle's vertices stay in registers.
class SeaGather {
  public:
    // sea: mesh 0 of the visibility buffer, its primitives [seaBase, seaBase + seaPrimitives).
    SeaGather(const MeshArrays& sea, uint32_t seaBase, uint32_t seaPrimitives)
        : sea_(sea), base_(seaBase), count_(seaPrimitives) {}

    bool IsSea(uint32_t prim) const { return prim - base_ < count_; }

    // Gathers samples x, x + 1, … of a row (primitives prims, barycentrics b1 and b2) while
    // they are sea, up to the row's end sw or until records holds kCapacity samples. Returns the
    // first sample not gathered.
    template <size_t kCapacity>
    int Gather(const uint32_t* prims, const float* b1, const float* b2, int x, int sw, float* pn,
               float* attributes, size_t& records) {
        using namespace simd4;
        size_t r = records;
        // A run of samples on one triangle at a time, its vertices in locals (registers: the
        // record stores could alias the members, which would be reloaded for every sample).
        while (x < sw && r < kCapacity) {
            const uint32_t prim = prims[x];
            if (!IsSea(prim)) break;
            if (prim != prim_) Fetch(prim);
            const int first = x, end = x + int(std::min(size_t(sw - x), kCapacity - r));
            float* record = pn + 8 * r;
            float* attribute = attributes + 4 * r;
#if defined(__AVX__)
            const __m256 v0 = pn_[0], v1 = pn_[1], v2 = pn_[2];
#else
            const F4 p[3] = {p_[0], p_[1], p_[2]}, n[3] = {n_[0], n_[1], n_[2]};
#endif
            const F4 a[3] = {a_[0], a_[1], a_[2]};
            do {
                const float u = b1[x], v = b2[x];
#if defined(__AVX__)
                const __m256 w0 = _mm256_set1_ps(1.0f - u - v), w1 = _mm256_set1_ps(u),
                             w2 = _mm256_set1_ps(v);
                _mm256_storeu_ps(record, _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(w0, v0),
                                                                     _mm256_mul_ps(w1, v1)),
                                                       _mm256_mul_ps(w2, v2)));
                _mm_storeu_ps(attribute,
                              Interpolate(_mm256_castps256_ps128(w0), _mm256_castps256_ps128(w1),
                                          _mm256_castps256_ps128(w2), a));
#else
                const F4 w0 = Set4(1.0f - u - v), w1 = Set4(u), w2 = Set4(v);
                _mm_storeu_ps(record, Interpolate(w0, w1, w2, p));
                _mm_storeu_ps(record + 4, Interpolate(w0, w1, w2, n));
                _mm_storeu_ps(attribute, Interpolate(w0, w1, w2, a));
#endif
                record += 8;
                attribute += 4;
            } while (++x < end && prims[x] == prim);
            r += size_t(x - first);
        }
        records = r;
        return x;
    }

  private:
    void Fetch(uint32_t prim) {
        using namespace simd4;
        const uint32_t t = prim - base_;
        const uint32_t i[3] = {sea_.indices[3 * t], sea_.indices[3 * t + 1],
                               sea_.indices[3 * t + 2]};
        prim_ = prim;
        const F4 top = Set4(kMaxVertexAttribute);
        for (int v = 0; v < 3; ++v) {
#if defined(__AVX__)
            pn_[v] = _mm256_set_m128(Load3(sea_.normals[i[v]]), Load3(sea_.positions[i[v]]));
#else
            p_[v] = Load3(sea_.positions[i[v]]);
            n_[v] = Load3(sea_.normals[i[v]]);
#endif
            a_[v] = sea_.attributes ? _mm_min_ps(_mm_loadu_ps(&sea_.attributes[i[v]].x), top)
                                    : _mm_setzero_ps();
        }
    }

    const MeshArrays& sea_;
    uint32_t base_, count_;
    uint32_t prim_ = kNoPrimitive;
#if defined(__AVX__)
    __m256 pn_[3] = {};  // (position, normal) of each vertex
#else
    simd4::F4 p_[3] = {}, n_[3] = {};
#endif
    simd4::F4 a_[3] = {};
};

}  // namespace seasense::channels
