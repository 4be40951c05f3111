// Tile-binned, multithreaded triangle rasterizer producing a visibility buffer
// (depth, primitive id, perspective-correct barycentrics) shared by every channel kind.
#pragma once

#include <tbb/cache_aligned_allocator.h>

#include <cstdint>
#include <glm/glm.hpp>
#include <memory>
#include <span>
#include <vector>

namespace seasense::channels {

inline constexpr uint32_t kNoPrimitive = 0xffffffffu;

// Largest sample grid side the rasterizer accepts: it keeps fixed-point vertex coordinates,
// after guard-band clipping, inside ±2^27 (8 sub-sample bits), so edge functions are exact
// in 64-bit integers.
inline constexpr int kMaxRasterSamplesPerAxis = 32768;

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
// Geometry with w < near_m is clipped away. clip.z is not used.
struct RasterCamera {
    glm::mat4 clipFromWorld{1.0f};
    float near_m = 0.25f;
    int width = 0;  // samples (pixels × supersampling), 1 … kMaxRasterSamplesPerAxis
    int height = 0;
};

// Per-sample visibility. depth = near_m / w (1 at the near plane, → 0 far away, 0 = empty).
// primitive = global triangle id: mesh m's triangle t is primitiveBase[m] + t.
// b1, b2 are the perspective-correct barycentric weights of the triangle's second and third
// vertex (indices[3t+1], indices[3t+2]); the first vertex's weight is 1 - b1 - b2. They refer
// to the original triangle also where it was clipped. Empty samples have b1 = b2 = 0.
struct VisibilityBuffer {
    // Cache-line aligned, so that the rasterizer writes whole lines (see simd::StreamCopy).
    template <class T>
    using Plane = std::vector<T, tbb::cache_aligned_allocator<T>>;

    int width = 0;
    int height = 0;
    Plane<float> depth;
    Plane<uint32_t> primitive;
    Plane<float> b1;
    Plane<float> b2;
    std::vector<uint32_t> primitiveBase;  // one per mesh of the last Render call

    size_t Index(int x, int y) const { return size_t(y) * size_t(width) + size_t(x); }
};

struct RasterStats {
    uint64_t trianglesIn = 0;  // triangles submitted
    // Back-facing, degenerate, outside the frustum, or covering no sample centre's
    // bounding box (nothing reached binning).
    uint64_t trianglesCulled = 0;
    uint64_t trianglesClipped = 0;  // triangles that crossed the near plane or guard band
    uint64_t trianglesSetUp = 0;    // screen triangles after clipping that reached binning
};

namespace raster_detail {

// Per-frame parameters of the rasterizer's stages.
struct Context {
    int width = 0;
    int height = 0;
    double near = 0.0;
    double halfWidth = 0.0;
    double halfHeight = 0.0;
    double guard = 0.0;  // guard band half-extent in NDC units
    int tileShift = 6;
    int tilesX = 0;
    int tilesY = 0;
};

struct ScreenVertex {
    int32_t x, y;  // fixed point, valid when outcode has no clip or invalid bits
    uint32_t outcode;
    double invW;  // 1 / clip w, valid with x, y
};

// Rows 0, 1 and 3 of clipFromWorld: the clip coordinates x, y and w.
struct ClipRows {
    glm::dvec4 x, y, w;
};

// Vertex stage of one vertex with a finite position: clip coordinates (double arithmetic,
// stored as float), outcode and, when no clipping is needed, the fixed-point position.
void TransformVertex(const ClipRows& rows, const Context& ctx, const glm::vec3& p, glm::vec3& clip,
                     ScreenVertex& screen);

// TransformVertex on p[0..3], four vertices at a time on lanes with the same results bit for
// bit. Writes nothing and returns false when a position is not finite.
bool TransformVertices4(const ClipRows& rows, const Context& ctx, const glm::vec3* p,
                        glm::vec3* clip, ScreenVertex* screen);

// One edge of a screen triangle as the rasterizer sets it up at a sample centre: E − unbias
// there (E > 0 inside, unbias 1 where the top-left rule leaves E = 0 outside, else 0) and E's
// steps to the next sample in x and in y.
struct EdgeSetUp {
    int64_t row, stepX, stepY, unbias;
};

// The small triangles' edge set-up (int32 lanes) for fixed-point vertices (x[k], y[k]) of a
// non-degenerate triangle at a sample centre (px, py) inside their bounding box: false where
// some edge's ∂E/∂x or ∂E/∂y lies outside [−2^14, 2^14) and the rasterizer sets the triangle up
// in int64 instead; else edge k and |2·area| as that int64 set-up has them.
bool BoxEdgesAt(const int32_t (&x)[3], const int32_t (&y)[3], int64_t px, int64_t py,
                EdgeSetUp (&edges)[3], int64_t& absArea2);

}  // namespace raster_detail

// Coverage rule: a sample belongs to a triangle when its centre is inside the triangle with
// vertices snapped to 1/256 sample; centres exactly on an edge belong to the triangle for
// which that edge is a top edge (horizontal, triangle below it on screen) or a left edge
// (triangle to its right), as in Direct3D's top-left rule. Meshes whose triangles share
// edges (same vertex positions) therefore cover every sample exactly once, also across
// near-plane and guard-band clipping.
//
// One Rasterizer keeps scratch memory between calls; call it from one thread at a time.
class Rasterizer {
  public:
    // tileSize in samples (square tiles): a power of two in [8, 1024], else InputError.
    explicit Rasterizer(int tileSize = 64);
    ~Rasterizer();
    Rasterizer(Rasterizer&&) noexcept;
    Rasterizer& operator=(Rasterizer&&) noexcept;

    // Draws all meshes into out (resized and cleared to empty). Runs in the caller's
    // oneTBB task arena; the result does not depend on the number of threads: the depth
    // test keeps the nearer sample and, at equal depth, the lower primitive id.
    // Throws InputError for a bad camera, non-finite positions or bad indices.
    void Render(std::span<const RasterMesh> meshes, const RasterCamera& camera,
                VisibilityBuffer& out);

    // Diagnostic for watertightness: the same clipping, set-up and coverage as Render, but
    // hits[Index(x, y)] counts every screen triangle covering the sample (no depth test).
    // hits is resized to width×height.
    void RenderCoverageCount(std::span<const RasterMesh> meshes, const RasterCamera& camera,
                             std::vector<uint32_t>& hits);

    const RasterStats& Stats() const { return stats_; }

  private:
    struct Scratch;
    void Prepare(std::span<const RasterMesh> meshes, const RasterCamera& camera);

    int tileSize_;
    int tileShift_;
    RasterStats stats_;
    std::unique_ptr<Scratch> scratch_;
};

}  // namespace seasense::channels
