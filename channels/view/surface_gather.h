// Surface points of visibility-buffer samples: the hit mesh, and position and normal
// interpolated from the hit triangle, with the triangle's vertices kept between samples.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <glm/glm.hpp>
#include <limits>
#include <vector>

#include "channels/raster/rasterizer.h"
#include "scene/core/simd4.h"
#include "scene/core/simd_lanes.h"

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

// The components of a sea sample that SeaGather writes, one array each: position, (unnormalized)
// normal and the vertex attributes (depth, wet, foam) interpolated at the sample.
enum SeaComponent {
    kSeaPx,
    kSeaPy,
    kSeaPz,
    kSeaNx,
    kSeaNy,
    kSeaNz,
    kSeaDepth,
    kSeaWet,
    kSeaFoam,
    kSeaComponents
};

// Up to kCapacity gathered sea samples, component by component (structure of arrays, as the
// shading loops read them), with room past the last for the stores of a whole lane group.
template <size_t kCapacity>
struct SeaSamples {
    alignas(32) float c[kSeaComponents][kCapacity + simd::kLanes];
    // Whether some record holds attribute sums rather than SeaGather's deep records: set by
    // Gather, cleared by the consumer when it starts over, so that a chunk of deep records alone
    // can skip what they make redundant.
    bool sums = false;
};

// Sea-mesh samples of visibility-buffer rows gathered into SeaSamples: per sample each
// component interpolated as TriangleCache's sums ((w0 a0 + w1 a1) + w2 a2, w0 = 1 − b1 − b2,
// the attributes clamped to kMaxVertexAttribute first), so the same bits. Most samples of a
// row are sea, in runs of a few samples per triangle, so this is the shading pass's inner
// loop: the sea mesh is known (no search for the mesh) and a run's samples are interpolated a
// lane group at a time from its triangle's vertex components (each broadcast to the lanes).
//
// Deep water (optional): most sea triangles lie in open water, where a consumer that only asks
// whether the column exceeds a film and whether there is foam needs no attribute sums. A triangle
// is deep when each vertex's clamped attributes have depth ≥ deepDepth, foam 0 and a finite wet
// value (|wet| ≤ kMaxVertexAttribute). A lane group on a deep triangle whose weights w0, b1, b2
// are all ≥ 0 (so none is NaN or infinite, and each sum is a convex combination: within 2^-22
// of the vertices' range) gets the records (kMaxVertexAttribute, 0, 0) instead of the sums:
// its true sums have depth ≥ deepDepth·(1 − 2^-22), foam ±0 and a finite wet value. The test
// may be made once per vertex instead (DeepVertices): a gather meets each triangle again in
// every row it crosses, and the per-vertex flags make its test three loads.
class SeaGather {
  public:
    // sea: mesh 0 of the visibility buffer, its primitives [seaBase, seaBase + seaPrimitives).
    // deepDepth: see above; +∞ (the default) makes no triangle deep. deepVertices: optional,
    // DeepVertices' flags of the sea's vertices for the same deepDepth.
    SeaGather(const MeshArrays& sea, uint32_t seaBase, uint32_t seaPrimitives,
              float deepDepth = std::numeric_limits<float>::infinity(),
              const uint8_t* deepVertices = nullptr)
        : sea_(sea),
          base_(seaBase),
          count_(seaPrimitives),
          deepVertices_(deepVertices),
          deepLow_(DeepLow(deepDepth)),
          deepHigh_(DeepHigh()) {}

    // flags[v] = whether vertex v's clamped attributes lie within the deep bounds, for v <
    // count. A triangle is deep exactly where its three vertices are: the clamped values are
    // never NaN, so their minimum and maximum lie within bounds where each value does.
    static void DeepVertices(const glm::vec4* attributes, size_t count, float deepDepth,
                             uint8_t* flags) {
        const simd4::F4 low = DeepLow(deepDepth), high = DeepHigh();
        for (size_t v = 0; v < count; ++v) flags[v] = DeepVertex(attributes[v], low, high);
    }

    bool IsSea(uint32_t prim) const { return prim - base_ < count_; }

    // Gathers samples x, x + 1, … of a row (primitives prims, barycentrics b1 and b2, sw
    // samples) while they are sea, up to the row's end or until out holds kCapacity samples
    // (records of them). Returns the first sample not gathered. Entries past the last
    // record are overwritten with unspecified values.
    template <size_t kCapacity>
    int Gather(const uint32_t* prims, const float* b1, const float* b2, int x, int sw,
               SeaSamples<kCapacity>& out, size_t& records) {
        using simd::VF, simd::VI, simd::kLanes;
        const VF top = simd::Broadcast(kMaxVertexAttribute);
        // The mesh and the triangle's state in locals: the record stores could alias the
        // members. The triangle's vertices as float offsets 3·index into the positions and
        // normals (three registers rather than six pointers).
        const float* const positions = reinterpret_cast<const float*>(sea_.positions);
        const float* const normals = reinterpret_cast<const float*>(sea_.normals);
        const uint32_t* const indices = sea_.indices;
        const glm::vec4* const attributes = sea_.attributes;
        const uint8_t* const deepVertices = deepVertices_;
        uint32_t last = prim_;
        bool deep = deep_;
        size_t o0 = offset_[0], o1 = offset_[1], o2 = offset_[2];
        size_t r = records;
        // A lane group of samples at a time: all lanes interpolated on the first sample's
        // triangle and stored, its leading lanes on that triangle (up to the row's end or a full
        // chunk) kept. The loads stay inside the row.
        while (x < sw && r < kCapacity) {
            const uint32_t prim = prims[x];
            if (!IsSea(prim)) break;
            if (prim != last) {
                last = prim;
                const uint32_t* i = indices + 3 * size_t(prim - base_);
                o0 = 3 * size_t(i[0]), o1 = 3 * size_t(i[1]), o2 = 3 * size_t(i[2]);
                if (deepVertices)
                    deep = deepVertices[i[0]] & deepVertices[i[1]] & deepVertices[i[2]];
                else if (attributes)
                    deep = Deep(attributes + i[0], attributes + i[1], attributes + i[2]);
            }
            const size_t inRow = std::min(kLanes, size_t(sw - x));
            VI p;
            VF u, v;
            if (inRow == kLanes) {
                std::memcpy(&p, prims + x, sizeof p);
                u = simd::Load(b1 + x), v = simd::Load(b2 + x);
            } else {
                p = VI{};
                for (size_t l = 0; l < inRow; ++l) p[l] = int32_t(prims[size_t(x) + l]);
                u = simd::Load(b1 + x, inRow), v = simd::Load(b2 + x, inRow);
            }
            const unsigned on = simd::LaneBits(p == int32_t(prim));
            const int run = std::min({__builtin_ctz(~on), sw - x, int(kCapacity - r)});
            const VF w0 = 1.0f - u - v;
            const auto Sum = [&](VF c0, VF c1, VF c2) { return (w0 * c0 + u * c1) + v * c2; };
            const auto B = [](const float* c) { return simd::Broadcast(*c); };
            // min(a, top) as TriangleCache's _mm_min_ps(a, top): top where a is NaN.
            const auto Clamped = [&](const float* c) { return simd::Min(top, B(c)); };
            for (int c = 0; c < 3; ++c) {
                const float* const pc = positions + c;
                const float* const nc = normals + c;
                simd::Store(out.c[kSeaPx + c] + r, Sum(B(pc + o0), B(pc + o1), B(pc + o2)));
                simd::Store(out.c[kSeaNx + c] + r, Sum(B(nc + o0), B(nc + o1), B(nc + o2)));
            }
            if (deep && simd::All((w0 >= 0.0f) & (u >= 0.0f) & (v >= 0.0f))) {
                simd::Store(out.c[kSeaDepth] + r, top);
                simd::Store(out.c[kSeaWet] + r, VF{});
                simd::Store(out.c[kSeaFoam] + r, VF{});
            } else {
                out.sums = true;
                // Zeros for a sea without attributes.
                const float *a0 = kNone, *a1 = kNone, *a2 = kNone;
                if (attributes) {
                    const uint32_t* i = indices + 3 * size_t(last - base_);
                    a0 = &attributes[i[0]].x, a1 = &attributes[i[1]].x, a2 = &attributes[i[2]].x;
                }
                for (int c = 0; c < 3; ++c)
                    simd::Store(out.c[kSeaDepth + c] + r,
                                Sum(Clamped(a0 + c), Clamped(a1 + c), Clamped(a2 + c)));
            }
            r += size_t(run);
            x += run;
        }
        prim_ = last;
        deep_ = deep;
        offset_[0] = o0, offset_[1] = o1, offset_[2] = o2;
        records = r;
        return x;
    }

  private:
    // The deep bounds: (deepDepth, −top, 0, −∞) and (∞, ∞, 0, ∞).
    static simd4::F4 DeepLow(float deepDepth) {
        return _mm_setr_ps(deepDepth, -kMaxVertexAttribute, 0.0f,
                           -std::numeric_limits<float>::infinity());
    }
    static simd4::F4 DeepHigh() {
        return _mm_setr_ps(std::numeric_limits<float>::infinity(),
                           std::numeric_limits<float>::infinity(), 0.0f,
                           std::numeric_limits<float>::infinity());
    }
    // Whether a vertex with attributes a (x, y, z, w) is deep: its clamped attributes
    // (_mm_min_ps(a, top) as the sums' clamp) within [low, high] component by component (w
    // unconstrained). The one definition behind both Deep and DeepVertices.
    static bool DeepVertex(const glm::vec4& a, simd4::F4 low, simd4::F4 high) {
        const simd4::F4 c = _mm_min_ps(_mm_loadu_ps(&a.x), _mm_set1_ps(kMaxVertexAttribute));
        return _mm_movemask_ps(_mm_and_ps(_mm_cmpge_ps(c, low), _mm_cmple_ps(c, high))) == 0xf;
    }
    // Whether the triangle with vertex attributes a0, a1, a2 is deep: all three vertices are.
    bool Deep(const glm::vec4* a0, const glm::vec4* a1, const glm::vec4* a2) const {
        return DeepVertex(*a0, deepLow_, deepHigh_) && DeepVertex(*a1, deepLow_, deepHigh_) &&
               DeepVertex(*a2, deepLow_, deepHigh_);
    }

    const MeshArrays& sea_;
    uint32_t base_, count_;
    const uint8_t* deepVertices_;   // DeepVertices' flags, or none
    simd4::F4 deepLow_, deepHigh_;  // DeepLow(deepDepth), DeepHigh()
    uint32_t prim_ = kNoPrimitive;
    bool deep_ = false;      // whether prim_ is deep
    size_t offset_[3] = {};  // prim_'s vertices, 3·index (floats into positions and normals)
    static constexpr float kNone[3] = {};  // the attributes of a sea without them
};

}  // namespace seasense::channels
