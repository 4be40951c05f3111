// Tile-binned, multithreaded triangle rasterizer producing a visibility buffer
// (depth, primitive id, perspective-correct barycentrics) shared by every channel kind.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

namespace seasense::channels {

inline constexpr uint32_t kNoPrimitive = 0xffffffffu;

// One triangle mesh to draw. Positions are in the frame that RasterCamera::clipFromWorld
// maps from (world ENU metres, or any frame the caller chooses consistently).
// Front faces are counter-clockwise when seen from outside (right-handed, OpenGL-style).
struct RasterMesh {
    std::span<const glm::vec3> positions;
    std::span<const uint32_t> indices;  // three per triangle
    bool cullBackFaces = true;
};

// Clip space follows OpenGL's x/y with an infinite reversed-Z projection:
//   clip = clipFromWorld · (p, 1); clip.w = view depth in metres (> 0 in front);
//   x_ndc = x/w ∈ [-1, 1] left→right; y_ndc = y/w ∈ [-1, 1] bottom→top.
// Sample (i, j) of a width×height sample grid has its centre at NDC
//   x = (2(i + 0.5) / width) - 1, y = 1 - (2(j + 0.5) / height)   (row 0 at the top).
// Geometry with w < near_m is clipped away.
struct RasterCamera {
    glm::mat4 clipFromWorld{1.0f};
    float near_m = 0.25f;
    int width = 0;   // samples (pixels × supersampling)
    int height = 0;
};

// Per-sample visibility. depth = near_m / w (1 at the near plane, → 0 far away, 0 = empty).
// primitive = global triangle id: mesh m's triangle t is primitiveBase[m] + t.
// b1, b2 are the perspective-correct barycentric weights of the triangle's second and third
// vertex (indices[3t+1], indices[3t+2]); the first vertex's weight is 1 - b1 - b2.
struct VisibilityBuffer {
    int width = 0;
    int height = 0;
    std::vector<float> depth;
    std::vector<uint32_t> primitive;
    std::vector<float> b1;
    std::vector<float> b2;
    std::vector<uint32_t> primitiveBase;  // one per mesh of the last Render call

    size_t Index(int x, int y) const { return size_t(y) * size_t(width) + size_t(x); }
};

struct RasterStats {
    uint64_t trianglesIn = 0;       // triangles submitted
    uint64_t trianglesCulled = 0;   // back-facing, degenerate or outside the frustum
    uint64_t trianglesClipped = 0;  // triangles that crossed the near plane or guard band
    uint64_t trianglesSetUp = 0;    // screen triangles after clipping that reached binning
};

class Rasterizer {
public:
    // tileSize in samples (square tiles).
    explicit Rasterizer(int tileSize = 64);

    // Draws all meshes into out (resized and cleared to empty). Runs in the caller's
    // oneTBB task arena; the result does not depend on the number of threads: the depth
    // test keeps the nearer sample and, at equal depth, the lower primitive id.
    void Render(std::span<const RasterMesh> meshes, const RasterCamera& camera,
                VisibilityBuffer& out);

    const RasterStats& Stats() const { return stats_; }

private:
    int tileSize_;
    RasterStats stats_;
};

}  // namespace seasense::channels
