// Rasterizer pipeline: vertex transform, homogeneous clipping, fixed-point triangle set-up,
// binning into tiles over triangle chunks, then per-tile half-space rasterization.
#include "channels/raster/rasterizer.h"

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>
#include <sstream>

#include "channels/raster/depth_test.h"
#include "scene/core/check.h"
#include "scene/core/error.h"
#include "scene/core/simd4.h"
#include "scene/core/simd_lanes.h"
#include "scene/core/stream_store.h"

namespace seasense::channels {
namespace {

// Fixed-point screen coordinates carry 8 sub-sample bits, as Direct3D 11 snaps vertices to
// 16.8 fixed point (Microsoft, "Direct3D 11.3 Functional Specification", rasterization
// rules).
constexpr int kSubBits = 8;
constexpr int64_t kSubScale = int64_t(1) << kSubBits;
constexpr int64_t kHalfSample = kSubScale / 2;
// Fixed-point coordinates stay within ±kGuardLimitSamples·256 = ±2^27 after guard-band
// clipping, so edge-function products stay below 2^57 in int64.
constexpr double kGuardLimitSamples = 524288.0;  // 2^19
// Triangles per binning chunk: fixed, so chunk boundaries never depend on the thread count.
constexpr uint32_t kTrianglesPerChunk = 8192;
constexpr size_t kVerticesPerTask = 4096;

// Per-vertex outcode bits. The frustum bits only drive trivial rejection; near and guard
// bits send a triangle through the clipper.
enum : uint32_t {
    kOutRight = 1u << 0,   // x > w
    kOutLeft = 1u << 1,    // x < -w
    kOutTop = 1u << 2,     // y > w
    kOutBottom = 1u << 3,  // y < -w
    kOutNear = 1u << 4,    // w < near
    kOutGuardXPos = 1u << 5,
    kOutGuardXNeg = 1u << 6,
    kOutGuardYPos = 1u << 7,
    kOutGuardYNeg = 1u << 8,
    kOutInvalid = 1u << 9,  // non-finite clip coordinates (overflow)
};
constexpr uint32_t kRejectMask = kOutRight | kOutLeft | kOutTop | kOutBottom | kOutNear;
constexpr uint32_t kClipMask =
    kOutNear | kOutGuardXPos | kOutGuardXNeg | kOutGuardYPos | kOutGuardYNeg;

// Clip planes in the order the clipper applies them; the distance is >= 0 inside.
enum ClipPlane { kPlaneNear, kPlaneGuardXPos, kPlaneGuardXNeg, kPlaneGuardYPos, kPlaneGuardYNeg };
constexpr int kNumClipPlanes = 5;

using raster_detail::Context;
using raster_detail::ScreenVertex;

// One screen triangle ready for rasterization (64 bytes: one cache line).
struct alignas(64) TriSetup {
    int32_t x[3], y[3];  // fixed-point vertices (1/256 sample)
    // near / (w_k · |2·area|): sum_k E_k c_k is the depth near/w at a sample, E_k the edge
    // function opposite vertex k (screen-space barycentric × |2·area|). Double, so that the
    // float barycentrics written out carry only their final rounding.
    double c[3];
    uint32_t prim;
    int32_t attr;                 // -1: vertices are the original ones; else Chunk::attrs offset
    uint16_t bx0, by0, bx1, by1;  // inclusive bounding box in samples, inside the grid
};
static_assert(sizeof(TriSetup) == 64);

// Triangles [begin, end) of one mesh.
struct ChunkRange {
    uint32_t mesh;
    uint32_t begin;
    uint32_t end;
};

// Set-up output of one chunk. Cache-line aligned: chunks are written by different threads.
struct alignas(64) Chunk {
    // setups[0 .. numSetups); the vector only grows, so that frames reuse its memory.
    std::vector<TriSetup> setups;
    uint32_t numSetups = 0;
    // For clipped triangles: c_k·β_k1 (3 values) then c_k·β_k2 (3 values), β_k the original
    // triangle's barycentrics of screen vertex k.
    std::vector<double> attrs;
    // Tile range of each set-up, kept apart from the set-ups so that the binning scatter
    // does not stream through them.
    struct TileRange {
        uint16_t tx0, ty0, tx1, ty1;
    };
    std::vector<TileRange> tileRanges;
    std::vector<uint32_t> tileStart;  // tiles + 1: setups of tile t are binned[tileStart[t]..]
    std::vector<uint32_t> cursor;
    std::vector<uint32_t> binned;
    RasterStats stats;
    bool badIndex = false;
    uint32_t badTriangle = 0;  // first triangle of the chunk with an out-of-range index
    uint32_t badValue = 0;
};

// Signed distance-like value of a clip-space point to a clip plane (>= 0 inside). The vertex
// classification and the clipper both use this one function so they agree exactly
// (TransformVertices4 evaluates the same expressions on lanes, tested bit for bit).
inline double PlaneDistance(int plane, double x, double y, double w, const Context& ctx) {
    switch (plane) {
        case kPlaneNear:
            return w - ctx.near;
        case kPlaneGuardXPos:
            return ctx.guard * w - x;
        case kPlaneGuardXNeg:
            return ctx.guard * w + x;
        case kPlaneGuardYPos:
            return ctx.guard * w - y;
        default:
            return ctx.guard * w + y;
    }
}

// Rounds v (|v| < 2^29) to the nearest integer, halves upward, without a libm call.
inline int32_t RoundToInt32(double v) {
    constexpr double kOffset = 1073741824.0;  // 2^30 makes the argument positive
    return int32_t(int64_t(v + (0.5 + kOffset)) - int64_t(kOffset));
}

// Fixed-point screen position (1/256 sample, origin at the grid's top-left corner, y down)
// of a clip-space point with w > 0. Every vertex, original or made by the clipper, goes
// through this one function (or TransformVertices4's lane copy of it, tested bit for bit),
// so equal clip coordinates give equal fixed-point coordinates.
// Returns 1 / w.
inline double SnapToFixed(double x, double y, double w, const Context& ctx, int32_t& fx,
                          int32_t& fy) {
    const double invW = 1.0 / w;
    const double sx = (x * invW + 1.0) * ctx.halfWidth;
    const double sy = (1.0 - y * invW) * ctx.halfHeight;
    fx = RoundToInt32(sx * double(kSubScale));
    fy = RoundToInt32(sy * double(kSubScale));
    return invW;
}

// First sample index whose centre i·256 + 128 is >= v, and last whose centre is <= v.
inline int64_t FirstSampleAtOrAfter(int64_t v) {
    return (v - kHalfSample + kSubScale - 1) >> kSubBits;
}
inline int64_t LastSampleAtOrBefore(int64_t v) { return (v - kHalfSample) >> kSubBits; }

// Writes one set-up record. On x86 it uses non-temporal stores: the records are read by
// whichever thread rasterizes the tile, so the next frame would otherwise have to take every
// line back from that core's cache before overwriting it, which made two-thread binning
// slower than one thread.
inline void StoreSetup(const int32_t (&fx)[3], const int32_t (&fy)[3], const double (&c)[3],
                       uint32_t prim, int32_t attr, uint16_t bx0, uint16_t by0, uint16_t bx1,
                       uint16_t by1, TriSetup* dst) {
#if defined(__SSE2__)
    // Little-endian field layout of TriSetup, 16 bytes per store.
    static_assert(offsetof(TriSetup, c) == 24 && offsetof(TriSetup, prim) == 48 &&
                  offsetof(TriSetup, bx0) == 56 && offsetof(TriSetup, by1) == 62);
    __m128i* q = reinterpret_cast<__m128i*>(dst);
    _mm_stream_si128(q, _mm_setr_epi32(fx[0], fx[1], fx[2], fy[0]));
    _mm_stream_si128(q + 1, _mm_set_epi64x(std::bit_cast<int64_t>(c[0]),
                                           int64_t(uint64_t(uint32_t(fy[2])) << 32 |
                                                   uint64_t(uint32_t(fy[1])))));
    _mm_stream_si128(q + 2, _mm_castpd_si128(_mm_setr_pd(c[1], c[2])));
    _mm_stream_si128(q + 3, _mm_setr_epi32(int32_t(prim), attr, int32_t(bx0 | uint32_t(by0) << 16),
                                           int32_t(bx1 | uint32_t(by1) << 16)));
#else
    for (int k = 0; k < 3; ++k) {
        dst->x[k] = fx[k];
        dst->y[k] = fy[k];
        dst->c[k] = c[k];
    }
    dst->prim = prim;
    dst->attr = attr;
    dst->bx0 = bx0;
    dst->by0 = by0;
    dst->bx1 = bx1;
    dst->by1 = by1;
#endif
}

// Sets up one screen triangle (fixed-point vertices, 1 / view depth w_k > 0, optional original
// barycentrics β_k = (β_k1, β_k2)) and counts it into the chunk's tiles. Returns false when it
// is culled (degenerate, back-facing or covering no sample centre's bounding box).
[[gnu::always_inline]] inline bool EmitTriangle(const int32_t (&fx)[3], const int32_t (&fy)[3],
                                                const double (&invW)[3], const double (*beta)[2],
                                                uint32_t prim, bool cullBackFaces,
                                                const Context& ctx, Chunk& chunk) {
    const int64_t area2 = (int64_t(fx[1]) - fx[0]) * (int64_t(fy[2]) - fy[0]) -
                          (int64_t(fy[1]) - fy[0]) * (int64_t(fx[2]) - fx[0]);
    if (area2 == 0) return false;
    // Counter-clockwise in NDC (y up) is clockwise on the y-down sample grid: 2·area < 0.
    const bool front = area2 < 0;
    if (cullBackFaces && !front) return false;

    const int64_t minX = std::min({fx[0], fx[1], fx[2]}), maxX = std::max({fx[0], fx[1], fx[2]});
    const int64_t minY = std::min({fy[0], fy[1], fy[2]}), maxY = std::max({fy[0], fy[1], fy[2]});
    const int64_t sx0 = std::max<int64_t>(FirstSampleAtOrAfter(minX), 0);
    const int64_t sx1 = std::min<int64_t>(LastSampleAtOrBefore(maxX), ctx.width - 1);
    if (sx0 > sx1) return false;
    const int64_t sy0 = std::max<int64_t>(FirstSampleAtOrAfter(minY), 0);
    const int64_t sy1 = std::min<int64_t>(LastSampleAtOrBefore(maxY), ctx.height - 1);
    if (sy0 > sy1) return false;

    const int32_t attr = beta ? int32_t(chunk.attrs.size()) : -1;
    const double nearPerArea = ctx.near / double(area2 < 0 ? -area2 : area2);
    const double c[3] = {nearPerArea * invW[0], nearPerArea * invW[1], nearPerArea * invW[2]};
    if (chunk.numSetups == chunk.setups.size())
        chunk.setups.resize(std::max<size_t>(1024, 2 * chunk.setups.size()));
    StoreSetup(fx, fy, c, prim, attr, uint16_t(sx0), uint16_t(sy0), uint16_t(sx1), uint16_t(sy1),
               &chunk.setups[chunk.numSetups++]);
    if (beta) {
        for (int k = 0; k < 3; ++k) chunk.attrs.push_back(c[k] * beta[k][0]);
        for (int k = 0; k < 3; ++k) chunk.attrs.push_back(c[k] * beta[k][1]);
    }

    const int tx0 = int(sx0) >> ctx.tileShift, tx1 = int(sx1) >> ctx.tileShift;
    const int ty0 = int(sy0) >> ctx.tileShift, ty1 = int(sy1) >> ctx.tileShift;
    chunk.tileRanges.push_back({uint16_t(tx0), uint16_t(ty0), uint16_t(tx1), uint16_t(ty1)});
    for (int ty = ty0; ty <= ty1; ++ty)
        for (int tx = tx0; tx <= tx1; ++tx) ++chunk.tileStart[size_t(ty * ctx.tilesX + tx) + 1];
    ++chunk.stats.trianglesSetUp;
    return true;
}

// A clip-space polygon vertex with the original triangle's barycentrics β1, β2.
struct PolyVertex {
    double x, y, w, b1, b2;
};
// Clipping a convex polygon adds at most one vertex per plane (Sutherland & Hodgman 1974),
// so 8 suffice in exact arithmetic. Rounding can make a clipped polygon slightly non-convex;
// one pass still emits at most two vertices per edge, so the near plane (3 → ≤ 4) and four
// guard planes (×2 each) stay within 64 whatever the rounding.
constexpr int kMaxPolyVertices = 64;

// Sutherland–Hodgman ("Reentrant polygon clipping", CACM 17(1), 1974) against one plane.
// Intersections are always computed from the inside endpoint toward the outside one, so
// two triangles sharing an edge compute bit-identical new vertices.
int ClipPolygon(const PolyVertex* in, int n, int plane, const Context& ctx, PolyVertex* out) {
    int m = 0;
    double dPrev = PlaneDistance(plane, in[n - 1].x, in[n - 1].y, in[n - 1].w, ctx);
    const PolyVertex* prev = &in[n - 1];
    for (int i = 0; i < n; ++i) {
        const PolyVertex& cur = in[i];
        const double dCur = PlaneDistance(plane, cur.x, cur.y, cur.w, ctx);
        const bool prevIn = dPrev >= 0.0, curIn = dCur >= 0.0;
        if (prevIn != curIn) {
            const PolyVertex& a = prevIn ? *prev : cur;  // inside
            const PolyVertex& b = prevIn ? cur : *prev;  // outside
            const double da = prevIn ? dPrev : dCur, db = prevIn ? dCur : dPrev;
            const double t = da / (da - db);
            out[m++] = {a.x + t * (b.x - a.x), a.y + t * (b.y - a.y), a.w + t * (b.w - a.w),
                        a.b1 + t * (b.b1 - a.b1), a.b2 + t * (b.b2 - a.b2)};
        }
        if (curIn) out[m++] = cur;
        prev = &cur;
        dPrev = dCur;
    }
    return m;
}

// Clips an original triangle (clip-space vertices) in homogeneous space against the near
// plane and, where needed, the guard band, then emits its fan. Returns the count emitted.
int ClipAndEmit(const glm::vec3 (&clip)[3], uint32_t prim, bool cullBackFaces, const Context& ctx,
                Chunk& chunk) {
    PolyVertex bufA[kMaxPolyVertices], bufB[kMaxPolyVertices];
    PolyVertex* cur = bufA;
    PolyVertex* next = bufB;
    cur[0] = {clip[0].x, clip[0].y, clip[0].z, 0.0, 0.0};
    cur[1] = {clip[1].x, clip[1].y, clip[1].z, 1.0, 0.0};
    cur[2] = {clip[2].x, clip[2].y, clip[2].z, 0.0, 1.0};
    int n = 3;
    for (int plane = 0; plane < kNumClipPlanes && n >= 3; ++plane) {
        // A plane is applied only when some vertex lies outside it; an edge that stays inside
        // is copied unchanged, so neighbours that skip the plane still agree on it.
        bool anyOut = false;
        for (int i = 0; i < n; ++i)
            anyOut |= PlaneDistance(plane, cur[i].x, cur[i].y, cur[i].w, ctx) < 0.0;
        if (!anyOut) continue;
        n = ClipPolygon(cur, n, plane, ctx, next);
        std::swap(cur, next);
    }
    if (n < 3) return 0;
    // Near-plane intersections have w = near up to rounding; only a near plane tiny against
    // the coordinates could round to w <= 0, where the polygon is dropped.
    for (int i = 0; i < n; ++i)
        if (!(cur[i].w > 0.0)) return 0;

    int32_t px[kMaxPolyVertices], py[kMaxPolyVertices];
    double pInvW[kMaxPolyVertices];
    for (int i = 0; i < n; ++i)
        pInvW[i] = SnapToFixed(cur[i].x, cur[i].y, cur[i].w, ctx, px[i], py[i]);
    int emitted = 0;
    for (int i = 1; i + 1 < n; ++i) {
        const int v[3] = {0, i, i + 1};
        int32_t fx[3], fy[3];
        double invW[3], beta[3][2];
        for (int k = 0; k < 3; ++k) {
            fx[k] = px[v[k]];
            fy[k] = py[v[k]];
            invW[k] = pInvW[v[k]];
            beta[k][0] = cur[v[k]].b1;
            beta[k][1] = cur[v[k]].b2;
        }
        emitted += EmitTriangle(fx, fy, invW, beta, prim, cullBackFaces, ctx, chunk);
    }
    return emitted;
}

// Output of the per-tile pass: a visibility buffer or a coverage count.
struct Targets {
    int width = 0;
    int x0 = 0, y0 = 0;  // the sample stored at index 0
    float* depth = nullptr;
    uint32_t* primitive = nullptr;
    float* b1 = nullptr;
    float* b2 = nullptr;
    uint32_t* hits = nullptr;
};

// Span lanes: four samples' doubles (one AVX register, two SSE2 ones) and their floats.
inline constexpr int64_t kSpanLanes = 4;
using D4 = double __attribute__((vector_size(32)));
using F4 = float __attribute__((vector_size(16)));
using I4 = int32_t __attribute__((vector_size(16)));
using U4 = uint32_t __attribute__((vector_size(16)));
using I8 = int32_t __attribute__((vector_size(32)));
using F8 = float __attribute__((vector_size(32)));

// Small triangles skip the span bounds (three divisions a row) and test their bounding box
// instead, kBoxLanes samples of a row at a time on int32 lanes: up to kBoxOctets·kBoxLanes
// samples wide (bounding box ∩ tile), as most of the sea's triangles are in every channel.
inline constexpr int kBoxLanes = 8;
inline constexpr int kBoxOctets = 2;
// Edge function values stay exact in int32 lanes where every edge's ∂E/∂x and ∂E/∂y lie in
// [−2^14, 2^14) (the triangle within 64 samples each way), see RasterTriangle.
inline constexpr int64_t kBoxMaxDelta = int64_t(1) << 14;

// Lanes whose sign bit is set, one bit each, lane 0 in bit 0.
inline int SignBits(I8 v) {
#if defined(__AVX__)
    return _mm256_movemask_ps(__m256(v));
#else
    return _mm_movemask_ps(__m128(__builtin_shufflevector(v, v, 0, 1, 2, 3))) |
           _mm_movemask_ps(__m128(__builtin_shufflevector(v, v, 4, 5, 6, 7))) << 4;
#endif
}
// Lane k of v in all eight lanes.
template <int k>
[[gnu::always_inline]] inline I8 Spread(I4 v) {
    return __builtin_shufflevector(v, v, k, k, k, k, k, k, k, k);
}
inline I4 LowHalf(I8 v) { return __builtin_shufflevector(v, v, 0, 1, 2, 3); }
inline I4 HighHalf(I8 v) { return __builtin_shufflevector(v, v, 4, 5, 6, 7); }
// Lanes of a where mask's sign bit is set, else b's (only the sign bits of mask matter).
template <class V>
inline V SelectBySign(I4 mask, V a, V b) {
#if defined(__SSE4_1__)
    return V(_mm_blendv_ps(__m128(b), __m128(a), __m128(mask)));
#else
    return (mask >> 31) ? a : b;
#endif
}
template <class V>
inline V SelectBySign(I8 mask, V a, V b) {
#if defined(__AVX__)
    return V(_mm256_blendv_ps(__m256(b), __m256(a), __m256(mask)));
#else
    return (mask >> 31) ? a : b;
#endif
}
inline F8 Concat(F4 lo, F4 hi) {
#if defined(__AVX__)
    // GCC's shufflevector form first zero-extends each half, one more instruction per half.
    return F8(_mm256_insertf128_ps(_mm256_castps128_ps256(__m128(lo)), __m128(hi), 1));
#else
    return __builtin_shufflevector(lo, hi, 0, 1, 2, 3, 4, 5, 6, 7);
#endif
}
// Exact int32 to double, lane for lane (GCC's generic conversion converts two halves).
inline D4 ToDouble(I4 v) {
#if defined(__AVX__)
    return _mm256_cvtepi32_pd(__m128i(v));
#else
    return __builtin_convertvector(v, D4);
#endif
}

struct TileRect {
    int x0, y0, x1, y1;  // inclusive samples
};

// A small triangle's three edges on int32 lanes (lane k: edge k, as RasterTriangle orients it;
// lane 3 repeats edge 0): E_k − unbias_k at one sample centre, its steps per sample in x and y,
// unbias_k, and |2·area|.
struct BoxEdges {
    I4 row, stepX, stepY, unbias;
    int32_t absArea2;
};

// RasterTriangle's edge set-up for the box rows, all three edges at once on lanes, at the sample
// centre (px, py) of its box ∩ tile. Returns false, and the box rows are not taken, unless every
// edge's ∂E/∂x and ∂E/∂y lie in [−kBoxMaxDelta, kBoxMaxDelta). The lanes compute modulo 2^32;
// when the test passes the values are the int64 set-up's: the differences of fixed-point
// coordinates (|x|, |y| <= 2^27) fit, so ±a, ±b pass only where |a|, |b| <= 2^14 whichever
// orientation was taken; then 2·area (two products below 2^28) is exact and orients the edges
// right, and E_k at a sample of the box (within 2^14 of every vertex) lies below 2^29.
[[gnu::always_inline]] inline bool SetUpBoxEdges(const TriSetup& s, int64_t px, int64_t py,
                                                 BoxEdges& e) {
    U4 x, y;
    static_assert(offsetof(TriSetup, y) == 12 && offsetof(TriSetup, c) == 24);
    std::memcpy(&x, &s.x[0], sizeof x);  // x0 x1 x2, then y0 (not used)
    std::memcpy(&y, &s.y[0], sizeof y);  // y0 y1 y2, then half of c[0] (not used)
    // Edge k runs from vertex i = k + 1 to j = k − 1 (mod 3) where 2·area > 0; else from j to i,
    // which negates a, b and E_k exactly.
    const U4 xi = __builtin_shufflevector(x, x, 1, 2, 0, 1);
    const U4 xj = __builtin_shufflevector(x, x, 2, 0, 1, 2);
    const U4 yi = __builtin_shufflevector(y, y, 1, 2, 0, 1);
    const U4 yj = __builtin_shufflevector(y, y, 2, 0, 1, 2);
    const U4 a = yi - yj, b = xj - xi;
    // a_k b_{k+1} − a_{k+1} b_k is 2·area for every k.
    const U4 area2 = a * __builtin_shufflevector(b, b, 1, 2, 0, 1) -
                     __builtin_shufflevector(a, a, 1, 2, 0, 1) * b;
    const U4 flip = U4(I4(area2) >> 31);  // all ones where 2·area < 0
    const U4 ao = (a ^ flip) - flip, bo = (b ^ flip) - flip;
    const U4 biased = (ao + uint32_t(kBoxMaxDelta)) | (bo + uint32_t(kBoxMaxDelta));
    if (_mm_movemask_ps(__m128((biased >> 15) != 0)) != 0) return false;
    const U4 rowU = a * (uint32_t(px) - xi) + b * (uint32_t(py) - yi);
    const I4 ai = I4(ao), bi = I4(bo);
    // RasterTriangle's top-left rule.
    const I4 topLeft = (ai > 0) | ((ai == 0) & (bi > 0));
    e.unbias = ~topLeft & 1;
    e.row = I4((rowU ^ flip) - flip) - e.unbias;
    e.stepX = ai * int32_t(kSubScale);
    e.stepY = bi * int32_t(kSubScale);
    e.absArea2 = int32_t((area2[0] ^ flip[0]) - flip[0]);
    return true;
}

// Half-space rasterization of one set-up triangle over its bounding box ∩ tile (Pineda, "A
// parallel algorithm for polygon rasterization", SIGGRAPH 1988): exact int64 edge functions,
// stepped incrementally from row to row and from sample to sample.
template <bool kCount, bool kClipped>
[[gnu::always_inline]] inline void RasterTriangle(const TriSetup& s, const double* attrs,
                                                  const TileRect& r, const Targets& t) {
    const int x0 = std::max<int>(s.bx0, r.x0), x1 = std::min<int>(s.bx1, r.x1);
    const int y0 = std::max<int>(s.by0, r.y0), y1 = std::min<int>(s.by1, r.y1);
    if (x0 > x1 || y0 > y1) return;

    const int64_t px = int64_t(x0) * kSubScale + kHalfSample;
    const int64_t py = int64_t(y0) * kSubScale + kHalfSample;
    // Small triangles (the coverage count keeps the spans) take the box rows below: up to
    // kBoxOctets·kBoxLanes samples wide (bounding box ∩ tile) and their edges set up on lanes.
    BoxEdges boxEdges;
    const bool inBox =
        !kCount && x1 - x0 < kBoxOctets * kBoxLanes && SetUpBoxEdges(s, px, py, boxEdges);
    // 2·area of the triangles that take the spans.
    const int64_t area2 = inBox ? 0
                                : (int64_t(s.x[1]) - s.x[0]) * (int64_t(s.y[2]) - s.y[0]) -
                                      (int64_t(s.y[1]) - s.y[0]) * (int64_t(s.x[2]) - s.x[0]);
    const uint32_t prim = s.prim;
    // E_0 + E_1 + E_2 = |2·area| exactly, so depth = Σ E_k c_k = k0 + E_1 Δc_1 + E_2 Δc_2
    // needs two conversions per sample instead of three.
    const int64_t absArea2 = inBox ? boxEdges.absArea2 : area2 < 0 ? -area2 : area2;
    const double c1 = s.c[1], c2 = s.c[2];
    const double k0 = double(absArea2) * s.c[0], dc1 = c1 - s.c[0], dc2 = c2 - s.c[0];
    double g0 = 0.0, g1 = 0.0, g2 = 0.0, h0 = 0.0, h1 = 0.0, h2 = 0.0;
    if constexpr (kClipped) {
        const double* g = attrs + s.attr;
        g0 = double(absArea2) * g[0];
        g1 = g[1] - g[0];
        g2 = g[2] - g[0];
        h0 = double(absArea2) * g[3];
        h1 = g[4] - g[3];
        h2 = g[5] - g[3];
    }
    size_t rowBase = size_t(y0 - t.y0) * size_t(t.width);
    const int64_t xo = t.x0;
    // kSpanLanes samples of a row, starting at index i of its targets, whose E_1, E_2 are
    // f1, f2 (exact integers): every operation is the one-sample form's, lane for lane.
    // Lanes whose sign bit is set in `out` (past the span or outside the triangle), and
    // samples failing the depth test, store back the values they loaded (the tile's targets
    // are this thread's and padded past their last sample).
    const I4 primV = I4{} + int32_t(prim);
    const I4 primKey = raster_detail::DepthTestKey(primV);
    // The samples from i (four or eight lanes) where wins is set take the new depth, primitive
    // and barycentrics; the others keep theirs.
    const auto blendStore = [&](size_t i, auto wins, auto depth, auto old, auto prims, auto oldPrim,
                                auto nb1, auto nb2) __attribute__((always_inline)) {
        decltype(nb1) oldB1, oldB2;
        std::memcpy(&oldB1, t.b1 + i, sizeof oldB1);
        std::memcpy(&oldB2, t.b2 + i, sizeof oldB2);
        const auto outDepth = SelectBySign(wins, depth, old);
        const auto outPrim = SelectBySign(wins, prims, oldPrim);
        const auto outB1 = SelectBySign(wins, nb1, oldB1);
        const auto outB2 = SelectBySign(wins, nb2, oldB2);
        std::memcpy(t.depth + i, &outDepth, sizeof outDepth);
        std::memcpy(t.primitive + i, &outPrim, sizeof outPrim);
        std::memcpy(t.b1 + i, &outB1, sizeof outB1);
        std::memcpy(t.b2 + i, &outB2, sizeof outB2);
    };
    const auto quad = [&](size_t i, D4 f1, D4 f2, I4 out) __attribute__((always_inline)) {
        const D4 d = k0 + f1 * dc1 + f2 * dc2;
        const F4 depth = __builtin_convertvector(d, F4);
        F4 old;
        I4 oldPrim;
        std::memcpy(&old, t.depth + i, sizeof old);
        std::memcpy(&oldPrim, t.primitive + i, sizeof oldPrim);
        // Every tile target sample is empty or holds depth > 0 and a primitive id below
        // kNoPrimitive (the test lets no depth <= 0 in), as DepthTestWins requires.
        const I4 wins = ~out & raster_detail::DepthTestWins(depth, primKey, old, oldPrim);
        if (!_mm_movemask_ps(F4(wins))) return;
        const D4 inv = 1.0 / d;
        F4 nb1, nb2;
        if constexpr (kClipped) {
            nb1 = __builtin_convertvector((g0 + f1 * g1 + f2 * g2) * inv, F4);
            nb2 = __builtin_convertvector((h0 + f1 * h1 + f2 * h2) * inv, F4);
        } else {
            nb1 = __builtin_convertvector(f1 * c1 * inv, F4);
            nb2 = __builtin_convertvector(f2 * c2 * inv, F4);
        }
        blendStore(i, wins, depth, old, primV, oldPrim, nb1, nb2);
    };
    // quad's work on eight samples whose E_1, E_2 are the int32 lanes f1, f2: the same operations
    // lane for lane, the doubles in two halves of four, the depth test, blends and stores on all
    // eight lanes at once (one test and one set of stores instead of two).
    const I8 primV8 = I8{} + int32_t(prim);
    const I8 primKey8 = raster_detail::DepthTestKey(primV8);
    const auto octet = [&](size_t i, I8 f1, I8 f2, I8 out) __attribute__((always_inline)) {
        const D4 f1l = ToDouble(LowHalf(f1)), f1h = ToDouble(HighHalf(f1));
        const D4 f2l = ToDouble(LowHalf(f2)), f2h = ToDouble(HighHalf(f2));
        const D4 dl = k0 + f1l * dc1 + f2l * dc2;
        const D4 dh = k0 + f1h * dc1 + f2h * dc2;
        const F8 depth = Concat(__builtin_convertvector(dl, F4), __builtin_convertvector(dh, F4));
        F8 old;
        I8 oldPrim;
        std::memcpy(&old, t.depth + i, sizeof old);
        std::memcpy(&oldPrim, t.primitive + i, sizeof oldPrim);
        const I8 wins = ~out & raster_detail::DepthTestWins(depth, primKey8, old, oldPrim);
        if (!SignBits(wins)) return;
        const D4 invl = 1.0 / dl, invh = 1.0 / dh;
        F8 nb1, nb2;
        if constexpr (kClipped) {
            nb1 = Concat(__builtin_convertvector((g0 + f1l * g1 + f2l * g2) * invl, F4),
                         __builtin_convertvector((g0 + f1h * g1 + f2h * g2) * invh, F4));
            nb2 = Concat(__builtin_convertvector((h0 + f1l * h1 + f2l * h2) * invl, F4),
                         __builtin_convertvector((h0 + f1h * h1 + f2h * h2) * invh, F4));
        } else {
            nb1 = Concat(__builtin_convertvector(f1l * c1 * invl, F4),
                         __builtin_convertvector(f1h * c1 * invh, F4));
            nb2 = Concat(__builtin_convertvector(f2l * c2 * invl, F4),
                         __builtin_convertvector(f2h * c2 * invh, F4));
        }
        blendStore(i, wins, depth, old, primV8, oldPrim, nb1, nb2);
    };

    if constexpr (!kCount) {
        // Small triangles: the box's samples kBoxLanes at a time, inside where all three
        // E_k − unbias_k are >= 0 (the span's own condition, without its divisions). With every
        // |a|, |b| <= 2^14 the box's sample centres, the lanes up to kBoxLanes − 1 past it and
        // the row stepped to past the last lie within 2^14 + 2^11 of every vertex in x and
        // 2^14 + 2^8 in y, so every E_k stays below 2^30 in magnitude: exact in int32 lanes, and
        // its double the span's. Only lane groups with a sample in the box are loaded and
        // stored, so they reach no further past the box than the span's.
        const auto box = [&]<int kOctets>() __attribute__((always_inline)) {
            const I8 lane8{0, 1, 2, 3, 4, 5, 6, 7};
            I8 e0[kOctets], e1[kOctets], e2[kOctets];
            // Unrolled, so that e0..e2 stay in registers (with octet inlined GCC no longer
            // unrolls these loops by itself: +4 M instructions a frame).
#pragma GCC unroll 2
            for (int o = 0; o < kOctets; ++o) {
                const I8 lane = lane8 + kBoxLanes * o;
                e0[o] = Spread<0>(boxEdges.row) + lane * Spread<0>(boxEdges.stepX);
                e1[o] = Spread<1>(boxEdges.row) + lane * Spread<1>(boxEdges.stepX);
                e2[o] = Spread<2>(boxEdges.row) + lane * Spread<2>(boxEdges.stepX);
            }
            const I8 outBox = lane8 + kBoxLanes * (kOctets - 1) > x1 - x0;
            const I8 dy0 = Spread<0>(boxEdges.stepY), dy1 = Spread<1>(boxEdges.stepY),
                     dy2 = Spread<2>(boxEdges.stepY);
            const I8 unbias1 = Spread<1>(boxEdges.unbias), unbias2 = Spread<2>(boxEdges.unbias);
            size_t i = rowBase + size_t(x0 - xo);
            for (int y = y0; y <= y1; ++y, i += size_t(t.width)) {
#pragma GCC unroll 2
                for (int o = 0; o < kOctets; ++o) {
                    // Sign bits: lanes outside the triangle or past the box (only the last
                    // octet reaches past it).
                    I8 signs = e0[o] | e1[o] | e2[o];
                    if (o == kOctets - 1) signs |= outBox;
                    const int outside = SignBits(signs);
                    if (outside != 0xff) {
                        const I8 f1 = e1[o] + unbias1, f2 = e2[o] + unbias2;
                        const size_t at = i + size_t(kBoxLanes * o);
                        // Both halves covered somewhere: one 8-lane group; else the half's quad.
                        if ((outside & 0xf) == 0xf)
                            quad(at + size_t(kSpanLanes), ToDouble(HighHalf(f1)),
                                 ToDouble(HighHalf(f2)), HighHalf(signs));
                        else if ((outside >> 4) == 0xf)
                            quad(at, ToDouble(LowHalf(f1)), ToDouble(LowHalf(f2)), LowHalf(signs));
                        else
                            octet(at, f1, f2, signs);
                    }
                    e0[o] += dy0;
                    e1[o] += dy1;
                    e2[o] += dy2;
                }
            }
        };
        if (inBox) {
            if (x1 - x0 < kBoxLanes)
                box.template operator()<1>();
            else
                box.template operator()<2>();
            return;
        }
    }

    // Edge k runs between the two vertices other than k, oriented so that the inside is
    // positive; E_k is then |2·area| times vertex k's screen-space barycentric.
    int64_t row[3], stepX[3], stepY[3], unbias[3];
    // One unrolled loop per orientation: every vertex index below is then a constant, not a
    // swapped index to load through.
    const auto edges = [&]<bool kPositive>() __attribute__((always_inline)) {
#pragma GCC unroll 3
        for (int k = 0; k < 3; ++k) {
            int i = k == 2 ? 0 : k + 1, j = k == 0 ? 2 : k - 1;
            if (!kPositive) std::swap(i, j);
            const int64_t ax = s.x[i], ay = s.y[i], bx = s.x[j], by = s.y[j];
            const int64_t a = ay - by;  // ∂E/∂x
            const int64_t b = bx - ax;  // ∂E/∂y
            // Top-left rule (Direct3D 11.3 functional specification, rasterization rules) for a
            // clockwise triangle on the y-down grid: a left edge runs upward (a > 0); a top edge
            // is horizontal and runs toward +x. Other edges exclude samples with E = 0.
            const bool topLeft = a > 0 || (a == 0 && b > 0);
            unbias[k] = topLeft ? 0 : 1;
            row[k] = a * (px - ax) + b * (py - ay) - unbias[k];
            stepX[k] = a * kSubScale;
            stepY[k] = b * kSubScale;
        }
    };
    if (area2 > 0)
        edges.template operator()<true>();
    else
        edges.template operator()<false>();
    const int64_t u1 = unbias[1], u2 = unbias[2];
    // Inside the triangle every E_k lies in [0, |2·area|]: below 2^53 the samples' E_1, E_2
    // are exact in doubles, and so are their sums, so the span steps them in doubles, the
    // same values as converting each sample's integer.
    const bool exactInDoubles = absArea2 <= (int64_t(1) << 53);
    const double step1 = double(stepX[1]), step2 = double(stepX[2]);
    for (int y = y0; y <= y1; ++y, rowBase += size_t(t.width)) {
        // The covered samples of a row form one span: each edge bounds it from one side,
        // found by exact integer division rather than by testing every sample of the box.
        int64_t lo = x0, hi = x1;
        for (int k = 0; k < 3; ++k) {
            const int64_t r = row[k], step = stepX[k];
            if (step > 0) {
                if (r < 0) lo = std::max(lo, x0 + (step - 1 - r) / step);
            } else if (step < 0) {
                hi = r < 0 ? -1 : std::min(hi, x0 + r / -step);
            } else if (r < 0) {
                hi = -1;
            }
        }
        const int64_t r1 = row[1], r2 = row[2];
        row[0] += stepY[0];
        row[1] += stepY[1];
        row[2] += stepY[2];
        if (lo > hi) continue;
        int64_t e1 = r1 + (lo - x0) * stepX[1] + u1;
        int64_t e2 = r2 + (lo - x0) * stepX[2] + u2;
        if constexpr (kCount) {
            uint32_t* __restrict hitsRow = t.hits + rowBase;
            for (int64_t x = lo; x <= hi; ++x) ++hitsRow[x - xo];
        } else {
            const size_t i0 = rowBase + size_t(lo - xo);
            if (exactInDoubles) [[likely]] {
                // kSpanLanes samples at a time: lane i holds the sample's E_1, E_2 as the scalar
                // steps would (exact integers, so stepping by kSpanLanes steps is exact).
                const D4 lane{0.0, 1.0, 2.0, 3.0};
                D4 f1 = double(e1) + lane * step1, f2 = double(e2) + lane * step2;
                const double groupStep1 = double(kSpanLanes) * step1;
                const double groupStep2 = double(kSpanLanes) * step2;
                const I4 laneI{0, 1, 2, 3};
                for (int64_t x = lo; x <= hi; x += kSpanLanes, f1 += groupStep1, f2 += groupStep2)
                    quad(i0 + size_t(x - lo), f1, f2, laneI > int32_t(hi - x));
            } else {
                float* __restrict depthRow = t.depth + rowBase;
                uint32_t* __restrict primRow = t.primitive + rowBase;
                float* __restrict b1Row = t.b1 + rowBase;
                float* __restrict b2Row = t.b2 + rowBase;
                for (int64_t x = lo; x <= hi; ++x, e1 += stepX[1], e2 += stepX[2]) {
                    const double f1 = double(e1), f2 = double(e2);
                    const double d = k0 + f1 * dc1 + f2 * dc2;
                    const float depth = float(d);
                    const int64_t i = x - xo;
                    const float old = depthRow[i];
                    if (depth > 0.0f && (depth > old || (depth == old && prim < primRow[i]))) {
                        depthRow[i] = depth;
                        primRow[i] = prim;
                        const double inv = 1.0 / d;
                        if constexpr (kClipped) {
                            b1Row[i] = float((g0 + f1 * g1 + f2 * g2) * inv);
                            b2Row[i] = float((h0 + f1 * h1 + f2 * h2) * inv);
                        } else {
                            b1Row[i] = float(f1 * c1 * inv);
                            b2Row[i] = float(f2 * c2 * inv);
                        }
                    }
                }
            }
        }
    }
}

// Samples per cache line in every plane of the visibility buffer (4-byte values).
constexpr size_t kLineSamples = 16;

// Streams one cache line (kLineSamples four-byte samples) from src to the line-aligned dst,
// whole, as simd::StreamCopy's inner loop does, and leaves fill in src's line: the tile's
// targets are cleared for the next tile while their lines are in the cache anyway.
inline void StreamLineAndRefill(void* dst, void* src, simd::VI fill) {
    char* from = static_cast<char*>(src);
    char* to = static_cast<char*>(dst);
    for (size_t at = 0; at < kLineSamples * 4; at += sizeof fill) {
        simd::VI v;
        std::memcpy(&v, from + at, sizeof v);
#if defined(__AVX__)
        _mm256_stream_si256(reinterpret_cast<__m256i*>(to + at), __m256i(v));
#else
        _mm_stream_si128(reinterpret_cast<__m128i*>(to + at), __m128i(v));
#endif
        std::memcpy(from + at, &fill, sizeof fill);
    }
}

// Streams one cache line of fill to the line-aligned dst.
inline void StreamLineOf(void* dst, simd::VI fill) {
    char* to = static_cast<char*>(dst);
    for (size_t at = 0; at < kLineSamples * 4; at += sizeof fill) {
#if defined(__AVX__)
        _mm256_stream_si256(reinterpret_cast<__m256i*>(to + at), __m256i(fill));
#else
        _mm_stream_si128(reinterpret_cast<__m128i*>(to + at), __m128i(fill));
#endif
    }
}

// Copies a w × h tile drawn into local (rows of w samples) to the frame's targets at (x0, y0),
// line by line, and clears local's first w·h samples. Every destination row starts on a cache
// line and w is a multiple of kLineSamples. kWidth, when not 0, is w known at compile time, so
// that a row is straight-line code. kEmpty: no triangle touched the tile, so local is still
// clear and its rows go out as the fill values without being read or cleared again.
template <size_t kWidth, bool kEmpty>
void StreamRowsOut(const Targets& t, int x0, int y0, const Targets& local, size_t w, size_t h,
                   simd::VI zeros, simd::VI empties) {
    if constexpr (kWidth != 0) w = kWidth;
    const size_t stride = size_t(t.width);
    const size_t b = size_t(y0) * stride + size_t(x0);
    float* outDepth = t.depth + b;
    uint32_t* outPrimitive = t.primitive + b;
    float* outB1 = t.b1 + b;
    float* outB2 = t.b2 + b;
    float* depth = local.depth;
    uint32_t* primitive = local.primitive;
    float* b1 = local.b1;
    float* b2 = local.b2;
    for (size_t y = 0; y < h; ++y) {
        for (size_t i = 0; i < w; i += kLineSamples) {
            if constexpr (kEmpty) {
                StreamLineOf(outDepth + i, zeros);
                StreamLineOf(outPrimitive + i, empties);
                StreamLineOf(outB1 + i, zeros);
                StreamLineOf(outB2 + i, zeros);
            } else {
                StreamLineAndRefill(outDepth + i, depth + i, zeros);
                StreamLineAndRefill(outPrimitive + i, primitive + i, empties);
                StreamLineAndRefill(outB1 + i, b1 + i, zeros);
                StreamLineAndRefill(outB2 + i, b2 + i, zeros);
            }
        }
        outDepth += stride;
        outPrimitive += stride;
        outB1 += stride;
        outB2 += stride;
        depth += w;
        primitive += w;
        b1 += w;
        b2 += w;
    }
}

// One tile's targets while it is drawn: small enough to stay in the core's cache.
struct TileTargets {
    std::vector<float> depth, b1, b2;
    std::vector<uint32_t> primitive;
    // Samples [0, clear) are empty (depth, b1, b2 zero, primitive kNoPrimitive). A tile's
    // triangles change only its first w·h samples (lanes past a span or box row store back
    // what they loaded).
    size_t clear = 0;
};

// Draws every triangle binned to one tile in global triangle order (chunks in order, set-ups
// in order within a chunk) into cleared tile-sized targets, then copies the tile out.
template <bool kCount>
void RasterTile(int tile, const Context& ctx, const std::vector<Chunk>& chunks, size_t numChunks,
                const Targets& t) {
    const int tileSize = 1 << ctx.tileShift;
    const int tx = tile % ctx.tilesX, ty = tile / ctx.tilesX;
    const TileRect r{tx * tileSize, ty * tileSize, std::min(ctx.width, (tx + 1) * tileSize) - 1,
                     std::min(ctx.height, (ty + 1) * tileSize) - 1};
    const size_t w = size_t(r.x1 - r.x0 + 1), h = size_t(r.y1 - r.y0 + 1);
    Targets local;
    thread_local TileTargets scratch;
    if constexpr (kCount) {
        for (int y = r.y0; y <= r.y1; ++y)
            std::fill_n(t.hits + size_t(y) * size_t(t.width) + size_t(r.x0), w, 0u);
        local = t;
    } else {
        // Padded for a span's or box row's last lane group, and to whole simd::kLanes for the
        // clear.
        const size_t padded =
            (w * h + size_t(kSpanLanes - 1) + simd::kLanes - 1) / simd::kLanes * simd::kLanes;
        if (scratch.depth.size() < padded) {
            scratch.depth.resize(padded);
            scratch.b1.resize(padded);
            scratch.b2.resize(padded);
            scratch.primitive.resize(padded);
        }
        local.width = int(w);
        local.x0 = r.x0;
        local.y0 = r.y0;
        local.depth = scratch.depth.data();
        local.primitive = scratch.primitive.data();
        local.b1 = scratch.b1.data();
        local.b2 = scratch.b2.data();
        // Cleared here only on a thread's first tile, after the targets grew, or after a tile
        // copied out without clearing behind it (see below).
        if (scratch.clear < padded) {
            // Plain vector stores: the compiler would make each fill a memset call, whose
            // `rep stosb` valgrind counts byte by byte, hiding the rest of a profile.
            float zero = 0.0f;
            uint32_t empty = kNoPrimitive;
            asm("" : "+r"(zero), "+r"(empty));
            const simd::VF zeros = simd::Splat(zero);
            const simd::VI empties = simd::VI{} + int32_t(empty);
            float* __restrict depth = local.depth;
            uint32_t* __restrict primitive = local.primitive;
            float* __restrict b1 = local.b1;
            float* __restrict b2 = local.b2;
            for (size_t i = 0; i < padded; i += simd::kLanes) {
                std::memcpy(depth + i, &zeros, sizeof zeros);
                std::memcpy(primitive + i, &empties, sizeof empties);
                std::memcpy(b1 + i, &zeros, sizeof zeros);
                std::memcpy(b2 + i, &zeros, sizeof zeros);
            }
            scratch.clear = padded;
        }
    }
    bool empty = true;  // no triangle binned to the tile
    for (size_t c = 0; c < numChunks; ++c) {
        const Chunk& chunk = chunks[c];
        const uint32_t begin = chunk.tileStart[size_t(tile)],
                       end = chunk.tileStart[size_t(tile) + 1];
        empty &= begin == end;
        const double* attrs = chunk.attrs.data();
        for (uint32_t k = begin; k < end; ++k) {
            const TriSetup& s = chunk.setups[chunk.binned[k]];
            if (s.attr < 0)
                RasterTriangle<kCount, false>(s, attrs, r, local);
            else
                RasterTriangle<kCount, true>(s, attrs, r, local);
        }
    }
    if constexpr (!kCount) {
        // The planes are cache-line aligned: where the frame's rows and the tile's columns
        // start on a line and the tile's rows are whole lines (every tile of the channels'
        // 1280-sample rows in 64-sample tiles), each tile row goes out line by line for all four
        // planes in one loop, without StreamCopy's per-call alignment prologue and epilogue,
        // clearing the tile targets behind it. 64 is the default tile size.
        if (t.width % kLineSamples == 0 && size_t(r.x0) % kLineSamples == 0 &&
            w % kLineSamples == 0) {
            const simd::VI zeros{}, empties = simd::VI{} + int32_t(kNoPrimitive);
            if (w == 64 && empty)
                StreamRowsOut<64, true>(t, r.x0, r.y0, local, w, h, zeros, empties);
            else if (w == 64)
                StreamRowsOut<64, false>(t, r.x0, r.y0, local, w, h, zeros, empties);
            else if (empty)
                StreamRowsOut<0, true>(t, r.x0, r.y0, local, w, h, zeros, empties);
            else
                StreamRowsOut<0, false>(t, r.x0, r.y0, local, w, h, zeros, empties);
        } else {
            scratch.clear = 0;
            for (size_t y = 0; y < h; ++y) {
                const size_t b = (size_t(r.y0) + y) * size_t(t.width) + size_t(r.x0);
                simd::StreamCopy(t.depth + b, local.depth + y * w, w);
                simd::StreamCopy(t.primitive + b, local.primitive + y * w, w);
                simd::StreamCopy(t.b1 + b, local.b1 + y * w, w);
                simd::StreamCopy(t.b2 + b, local.b2 + y * w, w);
            }
        }
        simd::StreamFence();
    }
}

// Sets up and bins the triangles of one chunk.
void BinChunk(const ChunkRange& range, const RasterMesh& mesh, uint32_t vertexBase,
              uint32_t primBase, const std::vector<ScreenVertex>& screen,
              const std::vector<glm::vec3>& clip, const Context& ctx, Chunk& chunk) {
    const size_t numTiles = size_t(ctx.tilesX) * size_t(ctx.tilesY);
    chunk.numSetups = 0;
    chunk.tileRanges.clear();
    chunk.attrs.clear();
    chunk.tileStart.assign(numTiles + 1, 0);
    chunk.stats = {};
    chunk.badIndex = false;

    const size_t numVertices = mesh.positions.size();
    const uint32_t* indices = mesh.indices.data();
    const ScreenVertex* sv = screen.data() + vertexBase;
    for (uint32_t t = range.begin; t < range.end; ++t) {
        const uint32_t i0 = indices[3 * size_t(t)], i1 = indices[3 * size_t(t) + 1],
                       i2 = indices[3 * size_t(t) + 2];
        if (i0 >= numVertices || i1 >= numVertices || i2 >= numVertices) {
            chunk.badIndex = true;
            chunk.badTriangle = t;
            chunk.badValue = std::max({i0, i1, i2});
            return;
        }
        ++chunk.stats.trianglesIn;
        const ScreenVertex& v0 = sv[i0];
        const ScreenVertex& v1 = sv[i1];
        const ScreenVertex& v2 = sv[i2];
        const uint32_t ocAnd = v0.outcode & v1.outcode & v2.outcode;
        const uint32_t ocOr = v0.outcode | v1.outcode | v2.outcode;
        if ((ocAnd & kRejectMask) || (ocOr & kOutInvalid)) {
            ++chunk.stats.trianglesCulled;
            continue;
        }
        const uint32_t prim = primBase + t;
        if (ocOr & kClipMask) {
            ++chunk.stats.trianglesClipped;
            const glm::vec3 c[3] = {clip[vertexBase + i0], clip[vertexBase + i1],
                                    clip[vertexBase + i2]};
            if (ClipAndEmit(c, prim, mesh.cullBackFaces, ctx, chunk) == 0)
                ++chunk.stats.trianglesCulled;
            continue;
        }
        const int32_t fx[3] = {v0.x, v1.x, v2.x};
        const int32_t fy[3] = {v0.y, v1.y, v2.y};
        const double invW[3] = {v0.invW, v1.invW, v2.invW};
        if (!EmitTriangle(fx, fy, invW, nullptr, prim, mesh.cullBackFaces, ctx, chunk))
            ++chunk.stats.trianglesCulled;
    }

#if defined(__SSE2__)
    _mm_sfence();  // order the streamed set-ups before the tasks that read them
#endif
    // Counting sort of the set-ups into tiles, keeping triangle order within each tile.
    for (size_t i = 0; i < numTiles; ++i) chunk.tileStart[i + 1] += chunk.tileStart[i];
    chunk.binned.resize(chunk.tileStart[numTiles]);
    chunk.cursor.assign(chunk.tileStart.begin(), chunk.tileStart.end() - 1);
    for (uint32_t k = 0; k < uint32_t(chunk.tileRanges.size()); ++k) {
        const Chunk::TileRange r = chunk.tileRanges[k];
        for (int ty = r.ty0; ty <= r.ty1; ++ty)
            for (int tx = r.tx0; tx <= r.tx1; ++tx)
                chunk.binned[chunk.cursor[size_t(ty * ctx.tilesX + tx)]++] = k;
    }
}

bool AllFinite(const glm::mat4& m) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(m[c][r])) return false;
    return true;
}

}  // namespace

namespace raster_detail {

void TransformVertex(const ClipRows& rows, const Context& ctx, const glm::vec3& p, glm::vec3& clip,
                     ScreenVertex& screen) {
    const glm::dvec4 ph(p.x, p.y, p.z, 1.0);
    const float cx = float(glm::dot(rows.x, ph));
    const float cy = float(glm::dot(rows.y, ph));
    const float cw = float(glm::dot(rows.w, ph));
    clip = glm::vec3(cx, cy, cw);
    ScreenVertex s{0, 0, 0, 0.0};
    if (!std::isfinite(cx) || !std::isfinite(cy) || !std::isfinite(cw)) {
        s.outcode = kOutInvalid;
    } else {
        uint32_t oc = 0;
        oc |= cx > cw ? kOutRight : 0u;
        oc |= cx < -cw ? kOutLeft : 0u;
        oc |= cy > cw ? kOutTop : 0u;
        oc |= cy < -cw ? kOutBottom : 0u;
        oc |= PlaneDistance(kPlaneNear, cx, cy, cw, ctx) < 0.0 ? kOutNear : 0u;
        oc |= PlaneDistance(kPlaneGuardXPos, cx, cy, cw, ctx) < 0.0 ? kOutGuardXPos : 0u;
        oc |= PlaneDistance(kPlaneGuardXNeg, cx, cy, cw, ctx) < 0.0 ? kOutGuardXNeg : 0u;
        oc |= PlaneDistance(kPlaneGuardYPos, cx, cy, cw, ctx) < 0.0 ? kOutGuardYPos : 0u;
        oc |= PlaneDistance(kPlaneGuardYNeg, cx, cy, cw, ctx) < 0.0 ? kOutGuardYNeg : 0u;
        s.outcode = oc;
        if (!(oc & kClipMask)) s.invW = SnapToFixed(cx, cy, cw, ctx, s.x, s.y);
    }
    screen = s;
}

namespace {

// (F4, I4 and D4: the lane types of the raster loops above.)
using L4 = int64_t __attribute__((vector_size(32)));

// Lanes where v is finite: v − v is 0 exactly then, NaN for ±inf and NaN.
inline I4 Finite(F4 v) { return v - v == F4{}; }
inline bool AllSet(I4 mask) { return _mm_movemask_ps(__m128(mask)) == 0xf; }

}  // namespace

bool TransformVertices4(const ClipRows& rows, const Context& ctx, const glm::vec3* p,
                        glm::vec3* clip, ScreenVertex* screen) {
    static_assert(sizeof(glm::vec3) == 12);
    // Positions x0 y0 z0 x1 | y1 z1 x2 y2 | z2 x3 y3 z3, split into one vector per axis.
    F4 a, b, c;
    std::memcpy(&a, &p[0].x, sizeof a);
    std::memcpy(&b, &p[1].y, sizeof b);
    std::memcpy(&c, &p[2].z, sizeof c);
    const F4 fx = __builtin_shufflevector(__builtin_shufflevector(a, b, 0, 3, 6, 0), c, 0, 1, 2, 5);
    const F4 fy = __builtin_shufflevector(__builtin_shufflevector(a, b, 1, 4, 7, 0), c, 0, 1, 2, 6);
    const F4 fz = __builtin_shufflevector(__builtin_shufflevector(a, b, 2, 5, 0, 0), c, 0, 1, 4, 7);
    const I4 finite = Finite(fx) & Finite(fy) & Finite(fz);
    if (!AllSet(finite)) return false;

    // glm::dot's order, (x·x' + y·y') + (z·z' + w·w'), with w' = 1.
    const D4 px = simd4::ToDouble4(fx);
    const D4 py = simd4::ToDouble4(fy);
    const D4 pz = simd4::ToDouble4(fz);
    const auto Dot = [&](const glm::dvec4& r) {
        return (r.x * px + r.y * py) + (r.z * pz + r.w * 1.0);
    };
    const F4 cx = __builtin_convertvector(Dot(rows.x), F4);
    const F4 cy = __builtin_convertvector(Dot(rows.y), F4);
    const F4 cw = __builtin_convertvector(Dot(rows.w), F4);

    // Back to x0 y0 z0 x1 | y1 z1 x2 y2 | z2 x3 y3 z3 order.
    const F4 xy01 = __builtin_shufflevector(cx, cy, 0, 4, 1, 5);
    const F4 xy23 = __builtin_shufflevector(cx, cy, 2, 6, 3, 7);
    const F4 outA = __builtin_shufflevector(xy01, cw, 0, 1, 4, 2);
    const F4 outB =
        __builtin_shufflevector(__builtin_shufflevector(cy, cw, 1, 5, 0, 0), xy23, 0, 1, 4, 5);
    const F4 outC = __builtin_shufflevector(xy23, cw, 6, 2, 3, 7);
    std::memcpy(&clip[0].x, &outA, sizeof outA);
    std::memcpy(&clip[1].y, &outB, sizeof outB);
    std::memcpy(&clip[2].z, &outC, sizeof outC);

    // The comparisons of TransformVertex, all in double: the frustum ones compare floats
    // (cx > cw, cx < −cw), which their exact conversions to double order the same way.
    const D4 x = simd4::ToDouble4(cx);
    const D4 y = simd4::ToDouble4(cy);
    const D4 w = simd4::ToDouble4(cw);
    const D4 gw = ctx.guard * w;
    const L4 oc64 =
        ((x > w) & int64_t(kOutRight)) | ((x < -w) & int64_t(kOutLeft)) |
        ((y > w) & int64_t(kOutTop)) | ((y < -w) & int64_t(kOutBottom)) |
        ((w - ctx.near < 0.0) & int64_t(kOutNear)) | ((gw - x < 0.0) & int64_t(kOutGuardXPos)) |
        ((gw + x < 0.0) & int64_t(kOutGuardXNeg)) | ((gw - y < 0.0) & int64_t(kOutGuardYPos)) |
        ((gw + y < 0.0) & int64_t(kOutGuardYNeg));
    const I4 oc = __builtin_convertvector(oc64, I4);
    const I4 valid = Finite(cx) & Finite(cy) & Finite(cw);
    const I4 outcode = valid ? oc : I4{} + int32_t(kOutInvalid);
    const I4 snap = valid & ((oc & int32_t(kClipMask)) == 0);
    const L4 snap64 = __builtin_convertvector(snap, L4);

    // SnapToFixed and RoundToInt32. In snapped lanes w >= near > 0 and |x|, |y| <= guard·w, so
    // the sample coordinates times 256 stay within about ±2^27 and v + 0.5 + 2^30 lies in
    // (0, 2^31): truncation to int32 then gives RoundToInt32's int64 result. Other lanes
    // convert 0 (their values may be out of range) and are zeroed like TransformVertex's.
    constexpr double kOffset = 1073741824.0;
    const D4 invW = 1.0 / w;
    const D4 sx = (x * invW + 1.0) * ctx.halfWidth;
    const D4 sy = (1.0 - y * invW) * ctx.halfHeight;
    const D4 rx = snap64 ? sx * double(kSubScale) + (0.5 + kOffset) : D4{};
    const D4 ry = snap64 ? sy * double(kSubScale) + (0.5 + kOffset) : D4{};
    const I4 ix = snap ? __builtin_convertvector(rx, I4) - int32_t(kOffset) : I4{};
    const I4 iy = snap ? __builtin_convertvector(ry, I4) - int32_t(kOffset) : I4{};
    const D4 iw = snap64 ? invW : D4{};
    for (int l = 0; l < 4; ++l) screen[l] = ScreenVertex{ix[l], iy[l], uint32_t(outcode[l]), iw[l]};
    return true;
}

bool BoxEdgesAt(const int32_t (&x)[3], const int32_t (&y)[3], int64_t px, int64_t py,
                EdgeSetUp (&edges)[3], int64_t& absArea2) {
    TriSetup s{};
    std::copy_n(x, 3, s.x);
    std::copy_n(y, 3, s.y);
    BoxEdges e;
    if (!SetUpBoxEdges(s, px, py, e)) return false;
    for (int k = 0; k < 3; ++k) edges[k] = {e.row[k], e.stepX[k], e.stepY[k], e.unbias[k]};
    absArea2 = e.absArea2;
    return true;
}

}  // namespace raster_detail

struct Rasterizer::Scratch {
    Context ctx;
    std::vector<uint32_t> vertexBase;  // per mesh, into screen / clip
    std::vector<ScreenVertex> screen;
    std::vector<glm::vec3> clip;  // (x, y, w) in clip space
    std::vector<ChunkRange> ranges;
    std::vector<Chunk> chunks;  // grows, never shrinks: keeps capacity between frames
};

Rasterizer::Rasterizer(int tileSize) : tileSize_(tileSize), tileShift_(0) {
    if (tileSize < 8 || tileSize > 1024 || (tileSize & (tileSize - 1)) != 0) {
        std::ostringstream msg;
        msg << "Rasterizer: tile size " << tileSize
            << " samples: expected a power of two in [8, 1024]";
        throw InputError(msg.str());
    }
    while ((1 << tileShift_) < tileSize) ++tileShift_;
    scratch_ = std::make_unique<Scratch>();
}

Rasterizer::~Rasterizer() = default;
Rasterizer::Rasterizer(Rasterizer&&) noexcept = default;
Rasterizer& Rasterizer::operator=(Rasterizer&&) noexcept = default;

void Rasterizer::Prepare(std::span<const RasterMesh> meshes, const RasterCamera& camera) {
    CHECK(scratch_ != nullptr);
    if (camera.width < 1 || camera.height < 1 || camera.width > kMaxRasterSamplesPerAxis ||
        camera.height > kMaxRasterSamplesPerAxis) {
        std::ostringstream msg;
        msg << "Rasterizer: sample grid " << camera.width << "x" << camera.height
            << ": expected each side in [1, " << kMaxRasterSamplesPerAxis << "]";
        throw InputError(msg.str());
    }
    if (!std::isfinite(camera.near_m) || camera.near_m <= 0.0f) {
        std::ostringstream msg;
        msg << "Rasterizer: near plane " << camera.near_m << " m: expected a finite value > 0";
        throw InputError(msg.str());
    }
    if (!AllFinite(camera.clipFromWorld))
        throw InputError("Rasterizer: clipFromWorld has non-finite entries");

    Scratch& sc = *scratch_;
    Context& ctx = sc.ctx;
    ctx.width = camera.width;
    ctx.height = camera.height;
    ctx.near = camera.near_m;
    ctx.halfWidth = 0.5 * camera.width;
    ctx.halfHeight = 0.5 * camera.height;
    // |x_ndc| <= guard keeps the sample coordinate (x_ndc + 1)·width/2 within ±2^19.
    ctx.guard = 2.0 * kGuardLimitSamples / double(std::max(camera.width, camera.height)) - 1.0;
    ctx.tileShift = tileShift_;
    ctx.tilesX = (camera.width + tileSize_ - 1) / tileSize_;
    ctx.tilesY = (camera.height + tileSize_ - 1) / tileSize_;

    stats_ = {};
    sc.vertexBase.resize(meshes.size());
    sc.ranges.clear();
    uint64_t totalVertices = 0, totalTriangles = 0;
    for (size_t m = 0; m < meshes.size(); ++m) {
        const RasterMesh& mesh = meshes[m];
        if (mesh.indices.size() % 3 != 0) {
            std::ostringstream msg;
            msg << "Rasterizer: mesh " << m << " has " << mesh.indices.size()
                << " indices: expected a multiple of 3";
            throw InputError(msg.str());
        }
        sc.vertexBase[m] = uint32_t(totalVertices);
        totalVertices += mesh.positions.size();
        const uint64_t tris = mesh.indices.size() / 3;
        for (uint64_t b = 0; b < tris; b += kTrianglesPerChunk)
            sc.ranges.push_back({uint32_t(m), uint32_t(b),
                                 uint32_t(std::min<uint64_t>(tris, b + kTrianglesPerChunk))});
        totalTriangles += tris;
        if (totalVertices >= kNoPrimitive || totalTriangles >= kNoPrimitive) {
            std::ostringstream msg;
            msg << "Rasterizer: meshes 0.." << m
                << " exceed 2^32 - 1 vertices or triangles in one frame";
            throw InputError(msg.str());
        }
    }

    // Vertex stage: clip coordinates (double arithmetic, stored as float), outcodes and
    // fixed-point positions of vertices that need no clipping.
    sc.screen.resize(totalVertices);
    sc.clip.resize(totalVertices);
    const glm::dmat4 m(camera.clipFromWorld);
    const raster_detail::ClipRows rows{glm::dvec4(m[0][0], m[1][0], m[2][0], m[3][0]),
                                       glm::dvec4(m[0][1], m[1][1], m[2][1], m[3][1]),
                                       glm::dvec4(m[0][3], m[1][3], m[2][3], m[3][3])};
    for (size_t mi = 0; mi < meshes.size(); ++mi) {
        const std::span<const glm::vec3> positions = meshes[mi].positions;
        const size_t base = sc.vertexBase[mi];
        std::atomic<size_t> firstBad{std::numeric_limits<size_t>::max()};
        tbb::parallel_for(
            tbb::blocked_range<size_t>(0, positions.size(), kVerticesPerTask),
            [&](const tbb::blocked_range<size_t>& r) {
                size_t v = r.begin();
                for (; v + 4 <= r.end(); v += 4)
                    if (!TransformVertices4(rows, ctx, &positions[v], &sc.clip[base + v],
                                            &sc.screen[base + v]))
                        break;  // a non-finite position: the loop below reports it
                for (; v < r.end(); ++v) {
                    const glm::vec3 p = positions[v];
                    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
                        size_t prev = firstBad.load();
                        while (v < prev && !firstBad.compare_exchange_weak(prev, v)) {
                        }
                        continue;
                    }
                    TransformVertex(rows, ctx, p, sc.clip[base + v], sc.screen[base + v]);
                }
            });
        if (firstBad.load() != std::numeric_limits<size_t>::max()) {
            const size_t v = firstBad.load();
            std::ostringstream msg;
            msg << "Rasterizer: mesh " << mi << " vertex " << v << " position (" << positions[v].x
                << ", " << positions[v].y << ", " << positions[v].z
                << "): expected finite coordinates";
            throw InputError(msg.str());
        }
    }

    // Set-up and binning over fixed triangle chunks.
    std::vector<uint32_t> primBase(meshes.size());
    uint32_t nextPrim = 0;
    for (size_t mi = 0; mi < meshes.size(); ++mi) {
        primBase[mi] = nextPrim;
        nextPrim += uint32_t(meshes[mi].indices.size() / 3);
    }
    if (sc.chunks.size() < sc.ranges.size()) sc.chunks.resize(sc.ranges.size());
    tbb::parallel_for(size_t(0), sc.ranges.size(), [&](size_t c) {
        const ChunkRange& r = sc.ranges[c];
        BinChunk(r, meshes[r.mesh], sc.vertexBase[r.mesh], primBase[r.mesh], sc.screen, sc.clip,
                 ctx, sc.chunks[c]);
    });
    for (size_t c = 0; c < sc.ranges.size(); ++c) {
        const Chunk& chunk = sc.chunks[c];
        if (chunk.badIndex) {
            const RasterMesh& mesh = meshes[sc.ranges[c].mesh];
            std::ostringstream msg;
            msg << "Rasterizer: mesh " << sc.ranges[c].mesh << " triangle " << chunk.badTriangle
                << " uses vertex index " << chunk.badValue << ": expected < "
                << mesh.positions.size() << " (the mesh's vertex count)";
            throw InputError(msg.str());
        }
        stats_.trianglesIn += chunk.stats.trianglesIn;
        stats_.trianglesCulled += chunk.stats.trianglesCulled;
        stats_.trianglesClipped += chunk.stats.trianglesClipped;
        stats_.trianglesSetUp += chunk.stats.trianglesSetUp;
    }
}

void Rasterizer::Render(std::span<const RasterMesh> meshes, const RasterCamera& camera,
                        VisibilityBuffer& out) {
    Prepare(meshes, camera);
    const Scratch& sc = *scratch_;
    const size_t n = size_t(camera.width) * size_t(camera.height);
    out.width = camera.width;
    out.height = camera.height;
    out.depth.resize(n);
    out.primitive.resize(n);
    out.b1.resize(n);
    out.b2.resize(n);
    out.primitiveBase.resize(meshes.size());
    uint32_t nextPrim = 0;
    for (size_t mi = 0; mi < meshes.size(); ++mi) {
        out.primitiveBase[mi] = nextPrim;
        nextPrim += uint32_t(meshes[mi].indices.size() / 3);
    }
    Targets t;
    t.width = camera.width;
    t.depth = out.depth.data();
    t.primitive = out.primitive.data();
    t.b1 = out.b1.data();
    t.b2 = out.b2.data();
    const int numTiles = sc.ctx.tilesX * sc.ctx.tilesY;
    tbb::parallel_for(0, numTiles, [&](int tile) {
        RasterTile<false>(tile, sc.ctx, sc.chunks, sc.ranges.size(), t);
    });
}

void Rasterizer::RenderCoverageCount(std::span<const RasterMesh> meshes, const RasterCamera& camera,
                                     std::vector<uint32_t>& hits) {
    Prepare(meshes, camera);
    const Scratch& sc = *scratch_;
    hits.resize(size_t(camera.width) * size_t(camera.height));
    Targets t;
    t.width = camera.width;
    t.hits = hits.data();
    const int numTiles = sc.ctx.tilesX * sc.ctx.tilesY;
    tbb::parallel_for(0, numTiles, [&](int tile) {
        RasterTile<true>(tile, sc.ctx, sc.chunks, sc.ranges.size(), t);
    });
}

}  // namespace seasense::channels
