// Rasterizer against geometry: watertight coverage, top-left rule, perspective-correct
// barycentrics versus analytic ray casts, clipping, culling and thread-count determinism.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "channels/raster/rasterizer.h"
#include "channels/raster/shade_pass.h"
#include "scene/core/error.h"
#include "scene/core/rng.h"

namespace seasense::channels {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct Mesh {
    std::vector<glm::vec3> positions;
    std::vector<uint32_t> indices;
    RasterMesh Raster(bool cullBackFaces = true) const {
        return RasterMesh{positions, indices, cullBackFaces};
    }
};

// clipFromWorld for "sample space": world x, y are sample-grid coordinates (x right, y down,
// sample centres at i + 0.5), z is ignored and w = 1.
RasterCamera SampleSpaceCamera(int width, int height) {
    RasterCamera cam;
    glm::mat4 m(1.0f);
    m[0][0] = 2.0f / float(width);
    m[3][0] = -1.0f;
    m[1][1] = -2.0f / float(height);
    m[3][1] = 1.0f;
    cam.clipFromWorld = m;
    cam.width = width;
    cam.height = height;
    return cam;
}

// A pinhole camera given by its orthonormal basis; the clip matrix and the sample rays are
// both built from the basis here, independently of the rasterizer.
struct PinholeView {
    glm::dvec3 eye{0.0}, forward{0.0, 0.0, -1.0}, right{1.0, 0.0, 0.0}, up{0.0, 1.0, 0.0};
    double tanH = 1.0, tanV = 1.0;  // tangents of the half fields of view
    int width = 0, height = 0;
    float near_m = 0.25f;

    RasterCamera Camera() const {
        // clip = (right·(p-eye)/tanH, up·(p-eye)/tanV, near, forward·(p-eye)).
        glm::dmat4 m(0.0);
        for (int c = 0; c < 3; ++c) {
            m[c][0] = right[c] / tanH;
            m[c][1] = up[c] / tanV;
            m[c][3] = forward[c];
        }
        m[3][0] = -glm::dot(right, eye) / tanH;
        m[3][1] = -glm::dot(up, eye) / tanV;
        m[3][2] = near_m;
        m[3][3] = -glm::dot(forward, eye);
        RasterCamera cam;
        cam.clipFromWorld = glm::mat4(m);
        cam.near_m = near_m;
        cam.width = width;
        cam.height = height;
        return cam;
    }
    // Direction (not normalised) through sample-grid point (sx, sy).
    glm::dvec3 Ray(double sx, double sy) const {
        const double xNdc = 2.0 * sx / width - 1.0, yNdc = 1.0 - 2.0 * sy / height;
        return forward + xNdc * tanH * right + yNdc * tanV * up;
    }
    double Depth(const glm::dvec3& p) const { return glm::dot(p - eye, forward); }
    // Sample-grid position of a world point in front of the camera.
    glm::dvec2 Project(const glm::dvec3& p) const {
        const glm::dvec3 d = p - eye;
        const double w = glm::dot(d, forward);
        const double xNdc = glm::dot(d, right) / (w * tanH), yNdc = glm::dot(d, up) / (w * tanV);
        return {(xNdc + 1.0) * 0.5 * width, (1.0 - yNdc) * 0.5 * height};
    }
};

// Camera at eye looking along +y pitched by pitch_rad (negative = down), z up.
PinholeView GroundView(glm::dvec3 eye, double pitch_rad, double vfov_rad, int width, int height) {
    PinholeView v;
    v.eye = eye;
    v.forward = {0.0, std::cos(pitch_rad), std::sin(pitch_rad)};
    v.right = {1.0, 0.0, 0.0};
    v.up = glm::cross(v.right, v.forward);
    v.tanV = std::tan(0.5 * vfov_rad);
    v.tanH = v.tanV * double(width) / double(height);
    v.width = width;
    v.height = height;
    return v;
}

// Camera at the origin looking down −z, y up.
PinholeView LookDownMinusZ(int width, int height, double vfov_rad) {
    PinholeView v;
    v.tanV = std::tan(0.5 * vfov_rad);
    v.tanH = v.tanV * width / height;
    v.width = width;
    v.height = height;
    return v;
}

// (n+1)² vertices from position(i, j), two triangles per cell with alternating diagonals,
// counter-clockwise in the (i, j) parameter plane (or clockwise when flip is set).
Mesh MakeGrid(int n, const std::function<glm::dvec3(int, int)>& position, bool flip) {
    Mesh m;
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) m.positions.push_back(glm::vec3(position(i, j)));
    const auto id = [n](int i, int j) { return uint32_t(j * (n + 1) + i); };
    const auto tri = [&](uint32_t a, uint32_t b, uint32_t c) {
        m.indices.insert(m.indices.end(), {a, flip ? c : b, flip ? b : c});
    };
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const uint32_t a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
            if ((i + j) % 2 == 0) {
                tri(a, b, c);
                tri(a, c, d);
            } else {
                tri(a, b, d);
                tri(b, c, d);
            }
        }
    return m;
}

// True when p lies strictly inside triangle abc (either winding).
bool InsideTriangle(glm::dvec2 p, glm::dvec2 a, glm::dvec2 b, glm::dvec2 c) {
    const auto cross = [](glm::dvec2 u, glm::dvec2 v) { return u.x * v.y - u.y * v.x; };
    const double d0 = cross(b - a, p - a), d1 = cross(c - b, p - b), d2 = cross(a - c, p - c);
    return (d0 > 0 && d1 > 0 && d2 > 0) || (d0 < 0 && d1 < 0 && d2 < 0);
}

// Expected coverage of sample (i, j) from an analytic inside test: 1 or 0 when the centre and
// four points 0.01 sample away agree (far from the boundary compared with the 1/512-sample
// vertex snapping), −1 (not checked) otherwise.
int ExpectedCoverage(const std::function<bool(double, double)>& inside, int i, int j) {
    const double x = i + 0.5, y = j + 0.5, e = 0.01;
    const bool c = inside(x, y);
    if (inside(x + e, y) != c || inside(x - e, y) != c || inside(x, y + e) != c ||
        inside(x, y - e) != c)
        return -1;
    return c ? 1 : 0;
}

struct CoverageCheck {
    int inside = 0;    // samples expected covered
    int outside = 0;   // samples expected empty
    int gaps = 0;      // expected covered, count 0
    int doubles = 0;   // count > 1 anywhere
    int spurious = 0;  // expected empty, count > 0
    std::string first;
};

CoverageCheck CheckCoverage(const std::vector<uint32_t>& hits, int width, int height,
                            const std::function<bool(double, double)>& inside) {
    CoverageCheck r;
    for (int j = 0; j < height; ++j)
        for (int i = 0; i < width; ++i) {
            const uint32_t h = hits[size_t(j) * size_t(width) + size_t(i)];
            const int e = ExpectedCoverage(inside, i, j);
            bool bad = false;
            if (h > 1) ++r.doubles, bad = true;
            if (e == 1) {
                ++r.inside;
                if (h == 0) ++r.gaps, bad = true;
            } else if (e == 0) {
                ++r.outside;
                if (h > 0) ++r.spurious, bad = true;
            }
            if (bad && r.first.empty())
                r.first = "sample (" + std::to_string(i) + ", " + std::to_string(j) + ") count " +
                          std::to_string(h) + " expected " + std::to_string(e);
        }
    return r;
}

void ExpectWatertight(const CoverageCheck& c, int minInside) {
    EXPECT_EQ(c.gaps, 0) << c.first;
    EXPECT_EQ(c.doubles, 0) << c.first;
    EXPECT_EQ(c.spurious, 0) << c.first;
    EXPECT_GE(c.inside, minInside);
}

// ---------------------------------------------------------------------------------------
// 1. Triangle fans.

Mesh MakeFan(glm::dvec2 centre, double radius, int n, double phase) {
    Mesh m;
    m.positions.push_back(glm::vec3(centre.x, centre.y, 0.0));
    for (int k = 0; k < n; ++k) {
        const double a = phase + 2.0 * kPi * k / n;
        m.positions.push_back(
            glm::vec3(centre.x + radius * std::cos(a), centre.y + radius * std::sin(a), 0.0));
    }
    for (int k = 0; k < n; ++k) {
        // Angles grow clockwise on the y-down sample grid, so (centre, k+1, k) is
        // counter-clockwise in NDC: a front face.
        m.indices.insert(m.indices.end(), {0u, uint32_t(1 + (k + 1) % n), uint32_t(1 + k)});
    }
    return m;
}

// Inside test for the fan's hull: the convex polygon of its rim vertices (as stored, float).
std::function<bool(double, double)> FanHull(const Mesh& fan) {
    return [&fan](double x, double y) {
        const size_t n = fan.positions.size() - 1;
        for (size_t k = 0; k < n; ++k) {
            const glm::dvec3 a = fan.positions[1 + k], b = fan.positions[1 + (k + 1) % n];
            // The rim's angle grows from a to b, so inside has cross(b - a, p - a) >= 0.
            if ((b.x - a.x) * (y - a.y) - (b.y - a.y) * (x - a.x) < 0.0) return false;
        }
        return true;
    };
}

TEST(RasterWatertight, FanInsideViewportCoversHullExactlyOnce) {
    const RasterCamera cam = SampleSpaceCamera(256, 192);
    Rasterizer r;
    std::vector<uint32_t> hits;
    for (uint64_t seed = 1; seed <= 3; ++seed) {
        const glm::dvec2 centre(100.0 + 40.0 * scene::Uniform01(seed, 0, 0),
                                80.0 + 30.0 * scene::Uniform01(seed, 0, 1));
        const Mesh fan = MakeFan(centre, 60.0 + 10.0 * scene::Uniform01(seed, 0, 2), 37,
                                 2.0 * kPi * scene::Uniform01(seed, 0, 3));
        const RasterMesh meshes[] = {fan.Raster()};
        r.RenderCoverageCount(meshes, cam, hits);
        SCOPED_TRACE("seed " + std::to_string(seed));
        EXPECT_EQ(r.Stats().trianglesCulled, 0u);
        ExpectWatertight(CheckCoverage(hits, cam.width, cam.height, FanHull(fan)), 9000);
    }
}

TEST(RasterWatertight, FanCoveringViewportAndGuardBandCoversEverySampleOnce) {
    const RasterCamera cam = SampleSpaceCamera(256, 192);
    Rasterizer r;
    std::vector<uint32_t> hits;
    // Radius 1e4 samples stays inside the guard band; 3e6 samples exceeds the fixed-point
    // range (±2^19 samples) and must be clipped against the guard-band planes.
    for (double radius : {1.0e4, 3.0e6}) {
        const Mesh fan = MakeFan({117.3, 91.7}, radius, 37, 0.1234);
        const RasterMesh meshes[] = {fan.Raster()};
        r.RenderCoverageCount(meshes, cam, hits);
        SCOPED_TRACE("radius " + std::to_string(radius));
        if (radius > 1.0e6)
            EXPECT_GT(r.Stats().trianglesClipped, 0u);
        else
            EXPECT_EQ(r.Stats().trianglesClipped, 0u);
        ExpectWatertight(CheckCoverage(hits, cam.width, cam.height, FanHull(fan)),
                         cam.width * cam.height);
    }
}

// ---------------------------------------------------------------------------------------
// 2. 256×256 grid meshes (131072 triangles).

TEST(RasterWatertight, RotatedJitteredGridCoversInteriorExactlyOnce) {
    const RasterCamera cam = SampleSpaceCamera(400, 300);
    Rasterizer r;
    std::vector<uint32_t> hits;
    constexpr int kN = 256;
    for (uint64_t seed = 11; seed <= 14; ++seed) {
        const double angle = 2.0 * kPi * scene::Uniform01(seed, 1, 0);
        const double cell = 1.9;
        const glm::dvec2 offset(200.0 + scene::Uniform01(seed, 1, 1),
                                150.0 + scene::Uniform01(seed, 1, 2));
        const glm::dvec2 ex(std::cos(angle), std::sin(angle)), ey(-ex.y, ex.x);
        const double half = 0.5 * kN * cell;
        const Mesh grid = MakeGrid(
            kN,
            [&](int i, int j) {
                double u = i * cell - half, v = j * cell - half;
                if (i > 0 && i < kN && j > 0 && j < kN) {  // interior: jitter ±0.25 cell
                    const uint64_t k = uint64_t(j) * (kN + 1) + uint64_t(i);
                    u += 0.5 * cell * (scene::Uniform01(seed, 2, k) - 0.5);
                    v += 0.5 * cell * (scene::Uniform01(seed, 3, k) - 0.5);
                }
                const glm::dvec2 p = offset + u * ex + v * ey;
                return glm::dvec3(p, 0.0);
            },
            /*flip=*/true);  // (i, j) → (ex, ey) keeps orientation; y-down needs the flip
        ASSERT_EQ(grid.indices.size() / 3, 131072u);
        const RasterMesh meshes[] = {grid.Raster()};
        r.RenderCoverageCount(meshes, cam, hits);
        const auto inside = [&](double x, double y) {
            const glm::dvec2 d = glm::dvec2(x, y) - offset;
            return std::abs(glm::dot(d, ex)) <= half && std::abs(glm::dot(d, ey)) <= half;
        };
        SCOPED_TRACE("seed " + std::to_string(seed));
        ExpectWatertight(CheckCoverage(hits, cam.width, cam.height, inside), 100000);
    }
}

// A ground-plane grid around and behind a low camera: triangles cross the near plane (and
// project far into the guard band); coverage must match the analytic ray cast.
void CheckGroundGrid(const PinholeView& view, uint64_t seed, int minInside, int minClipped) {
    constexpr int kN = 256;
    const double half = 40.0, cell = 2.0 * half / kN;
    const double angle = 2.0 * kPi * scene::Uniform01(seed, 4, 0);
    const glm::dvec2 offset(cell * scene::Uniform01(seed, 4, 1),
                            cell * scene::Uniform01(seed, 4, 2));
    const glm::dvec2 ex(std::cos(angle), std::sin(angle)), ey(-ex.y, ex.x);
    const Mesh grid = MakeGrid(
        kN,
        [&](int i, int j) {
            double u = i * cell - half, v = j * cell - half;
            if (i > 0 && i < kN && j > 0 && j < kN) {
                const uint64_t k = uint64_t(j) * (kN + 1) + uint64_t(i);
                u += 0.5 * cell * (scene::Uniform01(seed, 5, k) - 0.5);
                v += 0.5 * cell * (scene::Uniform01(seed, 6, k) - 0.5);
            }
            return glm::dvec3(offset + u * ex + v * ey, 0.0);
        },
        /*flip=*/false);  // counter-clockwise seen from above (+z): front faces
    const RasterCamera cam = view.Camera();
    Rasterizer r;
    std::vector<uint32_t> hits;
    const RasterMesh meshes[] = {grid.Raster()};
    r.RenderCoverageCount(meshes, cam, hits);
    EXPECT_GE(r.Stats().trianglesClipped, uint64_t(minClipped));
    const auto inside = [&](double sx, double sy) {
        const glm::dvec3 d = view.Ray(sx, sy);
        if (d.z >= 0.0) return false;
        const glm::dvec3 p = view.eye + (-view.eye.z / d.z) * d;
        const glm::dvec2 q = glm::dvec2(p) - offset;
        return view.Depth(p) >= view.near_m && std::abs(glm::dot(q, ex)) <= half &&
               std::abs(glm::dot(q, ey)) <= half;
    };
    ExpectWatertight(CheckCoverage(hits, cam.width, cam.height, inside), minInside);
}

TEST(RasterWatertight, GroundGridAtGrazingAngleCrossingNearPlane) {
    // 8 cm above 31 cm cells, looking 3° down: the ground meets the near plane
    // atan(0.08 / 0.25) = 17.7° below the horizon, inside the ±25° view, so many triangles
    // straddle the near plane in view; beyond ~40 m the grid's far edge nears the horizon.
    const PinholeView view =
        GroundView({0.13, -0.29, 0.08}, -3.0 * kPi / 180.0, 50.0 * kPi / 180.0, 320, 240);
    for (uint64_t seed = 21; seed <= 22; ++seed) {
        SCOPED_TRACE("seed " + std::to_string(seed));
        CheckGroundGrid(view, seed, 20000, 3);
    }
}

TEST(RasterWatertight, GroundGridWithVisibleNearPlaneCut) {
    // 0.25 m above the ground, 60° down: a ray θ below the axis meets the ground at view depth
    // 0.25·cos θ / sin(60° + θ), below the 0.25 m near plane for θ > 15°: the bottom ~30% of
    // the rows must stay empty.
    const PinholeView view =
        GroundView({0.07, 0.11, 0.25}, -60.0 * kPi / 180.0, 70.0 * kPi / 180.0, 320, 240);
    CheckGroundGrid(view, 31, 30000, 3);
    // The analytic model itself predicts empty samples at the bottom edge (near cut) here.
    const glm::dvec3 d = view.Ray(160.0, 239.5);
    const glm::dvec3 p = view.eye + (-view.eye.z / d.z) * d;
    EXPECT_LT(view.Depth(p), view.near_m);
}

// Planar star-shaped fans in 3-D whose rims reach up to 3·10^5 m sideways and whose plane
// passes behind the camera: near-plane and guard-band clipping must stay watertight. The
// expected coverage is the sample ray's hit on the plane, inside the star polygon and at
// view depth >= near.
TEST(RasterWatertight, RandomStarFansThroughNearPlaneAndGuardBand) {
    const PinholeView view = LookDownMinusZ(256, 192, 60.0 * kPi / 180.0);
    const RasterCamera cam = view.Camera();
    Rasterizer r;
    std::vector<uint32_t> hits;
    uint64_t clipped = 0;
    for (uint64_t seed = 100; seed < 120; ++seed) {
        const auto u01 = [seed](uint64_t k) { return scene::Uniform01(seed, 7, k); };
        const glm::dvec3 centre(2.0 * u01(0) - 1.0, 2.0 * u01(1) - 1.0, -0.5 - 2.5 * u01(2));
        // Normal tilted up to ~80° from the view axis, on the camera's side of the plane.
        const double tilt = 1.4 * u01(3), azimuth = 2.0 * kPi * u01(4);
        glm::dvec3 n(std::sin(tilt) * std::cos(azimuth), std::sin(tilt) * std::sin(azimuth),
                     std::cos(tilt));
        if (glm::dot(n, view.eye - centre) < 0.0) n = -n;
        const glm::dvec3 eu = glm::normalize(glm::cross(n, glm::dvec3(0.3, 0.9, 0.1)));
        const glm::dvec3 ev = glm::cross(n, eu);  // eu × ev = n: counter-clockwise faces n
        const int rim = 11 + int(30.0 * u01(5));
        std::vector<double> angle(size_t(rim) + 1, 0.0);
        for (int k = 1; k <= rim; ++k) angle[size_t(k)] = angle[size_t(k) - 1] + 0.2 + u01(10 + k);
        for (double& a : angle) a *= 2.0 * kPi / angle.back();  // sectors < π/2: star-shaped
        Mesh fan;
        fan.positions.push_back(glm::vec3(centre));
        for (int k = 0; k < rim; ++k) {
            const double radius = 0.3 * std::pow(1.0e6, u01(100 + k));  // 0.3 m … 3e5 m
            const double a = angle[size_t(k)];
            fan.positions.push_back(
                glm::vec3(centre + radius * (std::cos(a) * eu + std::sin(a) * ev)));
        }
        for (int k = 0; k < rim; ++k)
            fan.indices.insert(fan.indices.end(),
                               {0u, uint32_t(1 + k), uint32_t(1 + (k + 1) % rim)});
        const RasterMesh meshes[] = {fan.Raster()};
        r.RenderCoverageCount(meshes, cam, hits);
        clipped += r.Stats().trianglesClipped;

        // Rim vertices as stored (float), in plane coordinates around the stored centre.
        const glm::dvec3 c(fan.positions[0]);
        std::vector<glm::dvec2> rim2;
        for (int k = 0; k < rim; ++k) {
            const glm::dvec3 d = glm::dvec3(fan.positions[size_t(1 + k)]) - c;
            rim2.push_back({glm::dot(d, eu), glm::dot(d, ev)});
        }
        const auto inside = [&](double sx, double sy) {
            const glm::dvec3 d = view.Ray(sx, sy);
            const double t = glm::dot(n, c - view.eye) / glm::dot(n, d);
            if (!(t > 0.0)) return false;
            const glm::dvec3 p = view.eye + t * d;
            if (view.Depth(p) < view.near_m) return false;
            const glm::dvec2 q(glm::dot(p - c, eu), glm::dot(p - c, ev));
            for (int k = 0; k < rim; ++k)
                if (InsideTriangle(q, glm::dvec2(0.0), rim2[size_t(k)],
                                   rim2[size_t((k + 1) % rim)]))
                    return true;
            return false;
        };
        SCOPED_TRACE("seed " + std::to_string(seed));
        const CoverageCheck check = CheckCoverage(hits, cam.width, cam.height, inside);
        EXPECT_EQ(check.gaps, 0) << check.first;
        EXPECT_EQ(check.doubles, 0) << check.first;
        EXPECT_EQ(check.spurious, 0) << check.first;
    }
    EXPECT_GT(clipped, 100u);  // the cases really exercise the clipper
}

// ---------------------------------------------------------------------------------------
// 3. Perspective-correct barycentrics against analytic ray–plane intersections.

struct QuadScene {
    Mesh quad;
    glm::dvec3 centre, normal;
};

QuadScene TiltedQuad(bool reversedWinding) {
    // Plane through c, tilted 70° about x: the far edge is ~4.4× deeper than the near edge.
    QuadScene s;
    const double tilt = 70.0 * kPi / 180.0, half = 4.0;
    s.centre = {0.3, -0.2, -6.0};
    const glm::dvec3 e1(1.0, 0.0, 0.0), e2(0.0, std::cos(tilt), -std::sin(tilt));
    s.normal = glm::cross(e1, e2);
    const glm::dvec3 corners[] = {
        s.centre - half * e1 - half * e2, s.centre + half * e1 - half * e2,
        s.centre + half * e1 + half * e2, s.centre - half * e1 + half * e2};
    for (const glm::dvec3& c : corners) s.quad.positions.push_back(glm::vec3(c));
    // e1 × e2 faces the camera at the origin, so (0, 1, 2) is counter-clockwise from it.
    if (reversedWinding)
        s.quad.indices = {0, 2, 1, 0, 3, 2};
    else
        s.quad.indices = {0, 1, 2, 0, 2, 3};
    return s;
}

// For every covered sample: the barycentric point b0·p0 + b1·p1 + b2·p2 of the sample's
// triangle against the analytic intersection of the sample ray with the plane, and the depth
// against near / w of that intersection.
struct InterpolationError {
    int covered = 0;
    double maxPositionRel = 0.0;
    double maxDepthRel = 0.0;
    double minBary = 1.0, maxBary = 0.0;
};

InterpolationError CheckInterpolation(const VisibilityBuffer& vis, const Mesh& mesh,
                                      const PinholeView& view, const glm::dvec3& planePoint,
                                      const glm::dvec3& planeNormal) {
    InterpolationError e;
    for (int y = 0; y < vis.height; ++y)
        for (int x = 0; x < vis.width; ++x) {
            const size_t idx = vis.Index(x, y);
            if (vis.primitive[idx] == kNoPrimitive) continue;
            ++e.covered;
            const uint32_t t = vis.primitive[idx] - vis.primitiveBase[0];
            const double b1 = vis.b1[idx], b2 = vis.b2[idx], b0 = 1.0 - b1 - b2;
            const glm::dvec3 q = b0 * glm::dvec3(mesh.positions[mesh.indices[3 * t]]) +
                                 b1 * glm::dvec3(mesh.positions[mesh.indices[3 * t + 1]]) +
                                 b2 * glm::dvec3(mesh.positions[mesh.indices[3 * t + 2]]);
            const glm::dvec3 d = view.Ray(x + 0.5, y + 0.5);
            const double s =
                glm::dot(planeNormal, planePoint - view.eye) / glm::dot(planeNormal, d);
            const glm::dvec3 p = view.eye + s * d;
            const double dist = glm::length(p - view.eye);
            e.maxPositionRel = std::max(e.maxPositionRel, glm::length(q - p) / dist);
            const double depth = view.near_m / view.Depth(p);
            e.maxDepthRel = std::max(e.maxDepthRel, std::abs(vis.depth[idx] - depth) / depth);
            e.minBary = std::min({e.minBary, b0, b1, b2});
            e.maxBary = std::max({e.maxBary, b0, b1, b2});
        }
    return e;
}

TEST(RasterInterpolation, TiltedQuadMatchesAnalyticIntersection) {
    const PinholeView view = LookDownMinusZ(320, 240, 70.0 * kPi / 180.0);
    Rasterizer r;
    VisibilityBuffer vis;
    for (bool reversed : {false, true}) {
        SCOPED_TRACE(reversed ? "reversed winding, culling off" : "front faces, culling on");
        const QuadScene s = TiltedQuad(reversed);
        const RasterMesh meshes[] = {s.quad.Raster(/*cullBackFaces=*/!reversed)};
        r.Render(meshes, view.Camera(), vis);
        const InterpolationError e = CheckInterpolation(vis, s.quad, view, s.centre, s.normal);
        EXPECT_GT(e.covered, 15000);
        EXPECT_LT(e.maxPositionRel, 1e-4);
        EXPECT_LT(e.maxDepthRel, 1e-4);
        EXPECT_GE(e.minBary, -1e-4);
        EXPECT_LE(e.maxBary, 1.0 + 1e-4);
    }
    // The quad spans view depths 2.2 m … 9.8 m; screen-space (affine) interpolation would be
    // off by a large fraction of its size, so the tolerance above is meaningful.
    const QuadScene s = TiltedQuad(false);
    const glm::dvec3 p0 = s.quad.positions[0], p2 = s.quad.positions[2];
    const glm::dvec2 mid = 0.5 * (view.Project(p0) + view.Project(p2));
    const glm::dvec3 d = view.Ray(mid.x, mid.y);
    const glm::dvec3 hit = d * (glm::dot(s.normal, s.centre) / glm::dot(s.normal, d));
    EXPECT_GT(glm::length(hit - 0.5 * (p0 + p2)), 0.5);
}

// ---------------------------------------------------------------------------------------
// 4. Top-left fill rule on edges through sample centres.

// Ownership predicted by the top-left rule for a sample centre on an edge shared by two
// triangles: it belongs to the triangle containing the point just to its right, or for a
// horizontal edge just below it (y down), since that edge is that triangle's left / top edge.
TEST(RasterTopLeft, SharedEdgeSamplesGoToTheLeftOrTopEdgeOwner) {
    const int kSize = 64;  // power of two: sample coordinates map to NDC exactly
    const RasterCamera cam = SampleSpaceCamera(kSize, kSize);
    struct Pair {
        glm::dvec2 e0, e1;  // shared edge, endpoints on sample centres
        glm::dvec2 apexA, apexB;
    };
    const Pair pairs[] = {
        {{8.5, 8.5}, {40.5, 40.5}, {40.5, 8.5}, {8.5, 40.5}},      // slope +1
        {{40.5, 8.5}, {8.5, 40.5}, {8.5, 8.5}, {40.5, 40.5}},      // slope −1
        {{2.5, 50.5}, {34.5, 58.5}, {20.3, 41.2}, {12.9, 63.1}},   // slope +1/4
        {{10.5, 20.5}, {30.5, 20.5}, {20.3, 5.2}, {17.7, 35.9}},   // horizontal
        {{50.5, 4.5}, {50.5, 36.5}, {41.2, 20.7}, {62.9, 19.3}},   // vertical
        {{44.5, 36.5}, {48.5, 48.5}, {56.3, 38.1}, {40.2, 47.9}},  // slope 3
    };
    Rasterizer r;
    VisibilityBuffer vis;
    int checked = 0;
    for (const Pair& pr : pairs) {
        for (bool flipped : {false, true}) {
            Mesh m;
            for (glm::dvec2 p : {pr.e0, pr.e1, pr.apexA, pr.apexB})
                m.positions.push_back(glm::vec3(p.x, p.y, 0.0));
            // Triangle 0 = (edge, apex A), triangle 1 = (edge, apex B), in either winding.
            if (flipped)
                m.indices = {0, 2, 1, 1, 3, 0};
            else
                m.indices = {0, 1, 2, 1, 0, 3};
            const RasterMesh meshes[] = {m.Raster(/*cullBackFaces=*/false)};
            r.Render(meshes, cam, vis);
            const glm::dvec2 dir = pr.e1 - pr.e0;
            const int steps = int(std::max(std::abs(dir.x), std::abs(dir.y)));
            const glm::dvec2 nudge = dir.y == 0.0 ? glm::dvec2(0.0, 1e-3) : glm::dvec2(1e-3, 0.0);
            for (int k = 1; k < steps; ++k) {
                const glm::dvec2 p = pr.e0 + dir * (double(k) / steps);
                if (p.x != std::floor(p.x) + 0.5 || p.y != std::floor(p.y) + 0.5) continue;
                const bool ownerA = InsideTriangle(p + nudge, pr.e0, pr.e1, pr.apexA);
                const bool ownerB = InsideTriangle(p + nudge, pr.e1, pr.e0, pr.apexB);
                ASSERT_NE(ownerA, ownerB);
                const uint32_t got = vis.primitive[vis.Index(int(p.x), int(p.y))];
                EXPECT_EQ(got, ownerA ? 0u : 1u)
                    << "edge sample (" << p.x << ", " << p.y << ") flipped " << flipped;
                ++checked;
            }
        }
    }
    EXPECT_EQ(checked, 2 * (31 + 31 + 7 + 19 + 31 + 3));
}

TEST(RasterTopLeft, AxisAlignedSquareOnSampleCentresCoversHalfOpenRange) {
    // The square [8.5, 40.5]² with corners on sample centres: top and left edges are in,
    // bottom and right edges out, so exactly the 32×32 samples i, j ∈ [8, 39] are covered.
    const RasterCamera cam = SampleSpaceCamera(64, 64);
    Mesh m;
    for (glm::dvec2 p : {glm::dvec2(8.5, 8.5), glm::dvec2(40.5, 8.5), glm::dvec2(40.5, 40.5),
                         glm::dvec2(8.5, 40.5)})
        m.positions.push_back(glm::vec3(p.x, p.y, 0.0));
    m.indices = {0, 2, 1, 0, 3, 2};  // clockwise on the y-down grid → counter-clockwise in NDC
    Rasterizer r;
    std::vector<uint32_t> hits;
    const RasterMesh meshes[] = {m.Raster()};
    r.RenderCoverageCount(meshes, cam, hits);
    int wrong = 0;
    for (int j = 0; j < 64; ++j)
        for (int i = 0; i < 64; ++i)
            wrong += hits[size_t(j) * 64 + size_t(i)] !=
                     uint32_t(i >= 8 && i < 40 && j >= 8 && j < 40 ? 1 : 0);
    EXPECT_EQ(wrong, 0);
}

// ---------------------------------------------------------------------------------------
// 5. Culling and near-plane clipping.

TEST(RasterCulling, BackFacesCulledPerMesh) {
    // Counter-clockwise in NDC (identity clipFromWorld, w = 1): a front face.
    const glm::dvec2 a(-0.6, -0.5), b(0.7, -0.4), c(0.1, 0.65);
    Mesh front, back;
    for (glm::dvec2 p : {a, b, c}) front.positions.push_back(glm::vec3(p.x, p.y, 0.0));
    back.positions = front.positions;
    front.indices = {0, 1, 2};
    back.indices = {0, 2, 1};
    RasterCamera cam;
    cam.width = 96;
    cam.height = 80;
    const auto inside = [&](double sx, double sy) {
        const glm::dvec2 p(2.0 * sx / cam.width - 1.0, 1.0 - 2.0 * sy / cam.height);
        return InsideTriangle(p, a, b, c);
    };
    Rasterizer r;
    std::vector<uint32_t> hits;
    // Returns (samples covered, samples contradicting the analytic coverage).
    const auto covered = [&](const Mesh& m, bool cull) {
        const RasterMesh meshes[] = {m.Raster(cull)};
        r.RenderCoverageCount(meshes, cam, hits);
        int n = 0;
        for (uint32_t h : hits) n += h > 0;
        const CoverageCheck check = CheckCoverage(hits, cam.width, cam.height, inside);
        return std::make_pair(n, check.gaps + check.doubles + check.spurious);
    };
    const std::pair<int, int> ref = covered(front, true);
    EXPECT_GT(ref.first, 1000);
    EXPECT_EQ(ref.second, 0);
    EXPECT_EQ(r.Stats().trianglesCulled, 0u);
    EXPECT_EQ(covered(back, true).first, 0);
    EXPECT_EQ(r.Stats().trianglesCulled, 1u);
    EXPECT_EQ(covered(back, false), ref);
    EXPECT_EQ(covered(front, false), ref);
}

TEST(RasterClipping, GroundPlanePassingBehindCameraFillsBelowHorizonOnly) {
    // Camera 2 m above a 20 km square, looking level: the horizon lies between rows 119 and
    // 120 of 240; even the first row below it meets the ground at ~830 m, inside the square.
    const PinholeView view = GroundView({0.0, 0.0, 2.0}, 0.0, 60.0 * kPi / 180.0, 320, 240);
    const float L = 1.0e4f;
    Mesh ground;
    ground.positions = {{-L, -L, 0.0f}, {L, -L, 0.0f}, {L, L, 0.0f}, {-L, L, 0.0f}};
    ground.indices = {0, 1, 2, 0, 2, 3};  // counter-clockwise seen from above
    Rasterizer r;
    VisibilityBuffer vis;
    const RasterMesh meshes[] = {ground.Raster()};
    r.Render(meshes, view.Camera(), vis);
    EXPECT_EQ(r.Stats().trianglesClipped, 2u);
    // The interpolated ground point must lie on the sample's ray: within 0.01 sample on
    // screen, or, close to the camera, within the resolution of float b1, b2 (2^-24 each,
    // rounded to nearest) times the 20 km triangle legs: 2 · 2^-24 · 2e4 m ≈ 2.4 mm.
    int wrongAbove = 0, wrongBelow = 0, offRay = 0;
    for (int y = 0; y < vis.height; ++y)
        for (int x = 0; x < vis.width; ++x) {
            const size_t idx = vis.Index(x, y);
            const uint32_t prim = vis.primitive[idx];
            if (y < vis.height / 2) {
                wrongAbove += prim != kNoPrimitive;
                continue;
            }
            if (prim == kNoPrimitive) {
                ++wrongBelow;
                continue;
            }
            const uint32_t t = prim;
            const double b1 = vis.b1[idx], b2 = vis.b2[idx], b0 = 1.0 - b1 - b2;
            const glm::dvec3 q = b0 * glm::dvec3(ground.positions[ground.indices[3 * t]]) +
                                 b1 * glm::dvec3(ground.positions[ground.indices[3 * t + 1]]) +
                                 b2 * glm::dvec3(ground.positions[ground.indices[3 * t + 2]]);
            const glm::dvec3 d = view.Ray(x + 0.5, y + 0.5);
            const glm::dvec3 p = view.eye + (-view.eye.z / d.z) * d;
            const double screenError = glm::length(view.Project(q) - glm::dvec2(x + 0.5, y + 0.5));
            const double worldError = glm::length(q - p);
            offRay += screenError > 0.01 && worldError > 2.0 * 0x1p-24 * 2.0 * L;
        }
    EXPECT_EQ(wrongAbove, 0);
    EXPECT_EQ(wrongBelow, 0);
    EXPECT_EQ(offRay, 0);
}

TEST(RasterClipping, TriangleStraddlingNearPlaneKeepsOriginalBarycentrics) {
    const PinholeView view = LookDownMinusZ(320, 240, 60.0 * kPi / 180.0);
    const glm::dvec3 p0(-1.2, -0.9, -4.0), p1(1.5, -0.6, -3.0), p2(0.2, 0.7, 1.0);  // p2 behind
    Mesh tri;
    tri.positions = {glm::vec3(p0), glm::vec3(p1), glm::vec3(p2)};
    const glm::dvec3 normal = glm::normalize(glm::cross(p1 - p0, p2 - p0));
    // Wind it to face the camera so that back-face culling stays on.
    tri.indices = glm::dot(normal, view.eye - p0) > 0.0 ? std::vector<uint32_t>{0, 1, 2}
                                                        : std::vector<uint32_t>{0, 2, 1};
    Rasterizer r;
    VisibilityBuffer vis;
    const RasterMesh meshes[] = {tri.Raster()};
    r.Render(meshes, view.Camera(), vis);
    EXPECT_EQ(r.Stats().trianglesClipped, 1u);
    const InterpolationError e = CheckInterpolation(vis, tri, view, p0, normal);
    EXPECT_GT(e.covered, 5000);
    EXPECT_LT(e.maxPositionRel, 1e-4);
    EXPECT_LT(e.maxDepthRel, 1e-4);
    EXPECT_GE(e.minBary, -1e-4);
    EXPECT_LE(e.maxBary, 1.0 + 1e-4);

    // Coverage: the sample ray meets the triangle at view depth >= near.
    std::vector<uint32_t> hits(vis.primitive.size());
    for (size_t k = 0; k < hits.size(); ++k) hits[k] = vis.primitive[k] != kNoPrimitive;
    const auto inside = [&](double sx, double sy) {
        const glm::dvec3 d = view.Ray(sx, sy);
        const double s = glm::dot(normal, p0 - view.eye) / glm::dot(normal, d);
        if (s <= 0.0) return false;
        const glm::dvec3 p = view.eye + s * d;
        // Barycentric inside test in 3-D: same-side tests against the three edges.
        const auto side = [&](glm::dvec3 a, glm::dvec3 b) {
            return glm::dot(glm::cross(b - a, p - a), normal) >= 0.0;
        };
        return view.Depth(p) >= view.near_m && side(p0, p1) && side(p1, p2) && side(p2, p0);
    };
    const CoverageCheck c = CheckCoverage(hits, vis.width, vis.height, inside);
    EXPECT_EQ(c.gaps, 0) << c.first;
    EXPECT_EQ(c.spurious, 0) << c.first;
    EXPECT_GT(c.inside, 5000);
    EXPECT_GT(c.outside, 5000);
}

// ---------------------------------------------------------------------------------------
// 6. Determinism across thread counts and tile sizes.

TEST(RasterDeterminism, IdenticalBuffersForOneAndTwoThreadsAndAnyTileSize) {
    const PinholeView view =
        GroundView({0.13, -0.29, 1.5}, -12.0 * kPi / 180.0, 50.0 * kPi / 180.0, 400, 300);
    const double half = 40.0, cell = 2.0 * half / 256;
    const Mesh grid = MakeGrid(
        256,
        [&](int i, int j) {
            const uint64_t k = uint64_t(j) * 257 + uint64_t(i);
            return glm::dvec3(i * cell - half, j * cell - half,
                              0.05 * scene::Uniform01(77, 0, k));  // bumpy: real depth tests
        },
        false);
    // An identical copy (every sample ties in depth: the lower primitive id must win) and a
    // few large triangles crossing the near plane.
    Mesh extra;
    for (int k = 0; k < 24; ++k) {
        for (int v = 0; v < 3; ++v) {
            const uint64_t c = uint64_t(k * 3 + v);
            const uint64_t centre = uint64_t(k * 3);
            extra.positions.push_back(
                glm::vec3(16.0 * scene::Uniform01(78, 0, centre) - 8.0 + scene::Uniform01(78, 3, c),
                          8.0 * scene::Uniform01(78, 1, centre) - 2.0 + scene::Uniform01(78, 4, c),
                          1.5 * scene::Uniform01(78, 2, c)));
            extra.indices.push_back(uint32_t(c));
        }
    }
    const RasterMesh meshes[] = {grid.Raster(), grid.Raster(), extra.Raster(false)};
    const RasterCamera cam = view.Camera();

    const auto render = [&](int threads, int tileSize) {
        VisibilityBuffer vis;
        Rasterizer r(tileSize);
        tbb::task_arena arena(threads);
        arena.execute([&] { r.Render(meshes, cam, vis); });
        return vis;
    };
    const auto same = [](const VisibilityBuffer& a, const VisibilityBuffer& b) {
        const auto eq = [](const auto& u, const auto& v) {
            return u.size() == v.size() &&
                   std::memcmp(u.data(), v.data(), u.size() * sizeof(u[0])) == 0;
        };
        return eq(a.depth, b.depth) && eq(a.primitive, b.primitive) && eq(a.b1, b.b1) &&
               eq(a.b2, b.b2) && eq(a.primitiveBase, b.primitiveBase);
    };
    const VisibilityBuffer ref = render(1, 64);
    EXPECT_TRUE(same(ref, render(2, 64)));
    EXPECT_TRUE(same(ref, render(2, 16)));
    EXPECT_TRUE(same(ref, render(1, 128)));

    // Tie rule: no sample may show the copy (mesh 1) since mesh 0 has equal depth there.
    int fromCopy = 0, fromGrid = 0;
    for (uint32_t p : ref.primitive) {
        fromCopy += p != kNoPrimitive && p >= ref.primitiveBase[1] && p < ref.primitiveBase[2];
        fromGrid += p < ref.primitiveBase[1];
    }
    EXPECT_EQ(fromCopy, 0);
    EXPECT_GT(fromGrid, 40000);
}

// ---------------------------------------------------------------------------------------
// Per-sample values against the integer edge functions.

// One triangle in sample space (w = 1) with vertices on a 1/32-sample grid, small to far
// beyond the screen, drawn alone: every sample's coverage, depth and barycentrics equal the
// straightforward per-sample form of the rasterizer's set-up (each sample's int64 edge
// functions E_k converted to double, depth Σ E_k c_k as k0 + E_1 Δc_1 + E_2 Δc_2, b_k =
// E_k c_k / depth), bit for bit. The span steps E_1, E_2 in doubles where |2·area| ≤ 2^53
// (exact there); the largest triangles, |2·area| beyond 2^53 in fixed point, take the
// integer path, and both kinds must occur.
TEST(RasterInterpolation, SpanValuesEqualEachSamplesEdgeFunctionsBitForBit) {
    constexpr int kSize = 256;
    const RasterCamera cam = SampleSpaceCamera(kSize, kSize);
    Rasterizer r;
    VisibilityBuffer vis;
    const double scales[] = {3.0, 40.0, 3000.0, 150000.0, 400000.0, 500000.0};
    int exactCovered = 0, largeCovered = 0;
    for (int t = 0; t < 90; ++t) {
        const double scale = scales[t % 6];
        int64_t fx[3], fy[3];  // fixed point, 1/256 sample
        Mesh m;
        for (int v = 0; v < 3; ++v) {
            const uint64_t c = uint64_t(t * 3 + v);
            // Multiples of 1/32 sample below 2^19: x / 128 − 1 is exact in a float clip
            // coordinate, so the snapped vertex is 256 x exactly.
            const auto coord = [&](int stream) {
                const double u = 2.0 * scene::Uniform01(91, uint64_t(stream), c) - 1.0;
                return std::round(32.0 * (128.0 + scale * u)) / 32.0;
            };
            const double x = coord(0), y = coord(1);
            m.positions.push_back(glm::vec3(float(x), float(y), 0.0f));
            m.indices.push_back(uint32_t(v));
            fx[v] = int64_t(x * 256.0), fy[v] = int64_t(y * 256.0);
        }
        r.Render(std::span<const RasterMesh>(std::vector<RasterMesh>{m.Raster(false)}), cam, vis);

        const int64_t area2 = (fx[1] - fx[0]) * (fy[2] - fy[0]) - (fy[1] - fy[0]) * (fx[2] - fx[0]);
        const bool positive = area2 > 0;
        const int64_t absArea2 = positive ? area2 : -area2;
        const double c = double(cam.near_m) / double(absArea2);  // every w is 1
        const double k0 = double(absArea2) * c, dc = c - c;
        int covered = 0, mismatches = 0;
        std::string first;
        for (int j = 0; j < kSize; ++j) {
            for (int i = 0; i < kSize; ++i) {
                const int64_t px = int64_t(i) * 256 + 128, py = int64_t(j) * 256 + 128;
                int64_t e[3];
                bool inside = area2 != 0;
                for (int k = 0; k < 3; ++k) {
                    int a = k == 2 ? 0 : k + 1, b = k == 0 ? 2 : k - 1;
                    if (!positive) std::swap(a, b);
                    const int64_t ex = fy[a] - fy[b], ey = fx[b] - fx[a];
                    e[k] = ex * (px - fx[a]) + ey * (py - fy[a]);
                    const bool topLeft = ex > 0 || (ex == 0 && ey > 0);
                    inside &= e[k] - (topLeft ? 0 : 1) >= 0;
                }
                float depth = 0.0f, b1 = 0.0f, b2 = 0.0f;
                uint32_t prim = kNoPrimitive;
                if (inside) {
                    const double f1 = double(e[1]), f2 = double(e[2]);
                    const double d = k0 + f1 * dc + f2 * dc;
                    if (float(d) > 0.0f) {
                        depth = float(d), prim = 0;
                        const double inv = 1.0 / d;
                        b1 = float(f1 * c * inv), b2 = float(f2 * c * inv);
                        ++covered;
                    }
                }
                const size_t s = vis.Index(i, j);
                const bool same =
                    std::memcmp(&depth, &vis.depth[s], 4) == 0 && prim == vis.primitive[s] &&
                    std::memcmp(&b1, &vis.b1[s], 4) == 0 && std::memcmp(&b2, &vis.b2[s], 4) == 0;
                if (!same && mismatches++ == 0)
                    first = "sample (" + std::to_string(i) + ", " + std::to_string(j) + ") b1 " +
                            std::to_string(b1) + " vs " + std::to_string(vis.b1[s]);
            }
        }
        EXPECT_EQ(mismatches, 0) << "triangle " << t << ", |2 area| " << absArea2 << ": " << first;
        (absArea2 <= (int64_t(1) << 53) ? exactCovered : largeCovered) += covered;
    }
    EXPECT_GT(exactCovered, 100000);
    EXPECT_GT(largeCovered, 100000);
}

// ---------------------------------------------------------------------------------------
// Shading helper and bad input.

// A visibility buffer drawn into again holds only the new frame's triangles: a screen-filling
// quad, then one small triangle into the same buffer (sides that are no multiple of the tile
// size, one and two threads). Every sample centre strictly inside the triangle — its
// hypotenuse x + y = 90.25 never passes through a centre — shows it at depth near_m / w; every
// other sample is empty (depth 0, no primitive, barycentrics 0).
TEST(RasterTargets, ReusedBufferHoldsOnlyTheLastFramesTriangles) {
    const RasterCamera cam = SampleSpaceCamera(150, 97);
    Mesh quad;
    quad.positions = {{-10.0f, -10.0f, 0.0f},
                      {160.0f, -10.0f, 0.0f},
                      {160.0f, 107.0f, 0.0f},
                      {-10.0f, 107.0f, 0.0f}};
    quad.indices = {0, 1, 2, 0, 2, 3};
    Mesh small;
    small.positions = {{20.0f, 30.0f, 0.0f}, {60.25f, 30.0f, 0.0f}, {20.0f, 70.25f, 0.0f}};
    small.indices = {0, 1, 2};
    for (int threads : {1, 2}) {
        SCOPED_TRACE("threads " + std::to_string(threads));
        tbb::task_arena arena(threads);
        Rasterizer r(32);
        VisibilityBuffer vis;
        const RasterMesh first[] = {quad.Raster(false)};
        arena.execute([&] { r.Render(first, cam, vis); });
        int uncovered = 0;
        for (uint32_t p : vis.primitive) uncovered += p == kNoPrimitive;
        EXPECT_EQ(uncovered, 0);

        const RasterMesh second[] = {small.Raster(false)};
        arena.execute([&] { r.Render(second, cam, vis); });
        int inside = 0, wrong = 0;
        for (int y = 0; y < cam.height; ++y) {
            for (int x = 0; x < cam.width; ++x) {
                const double cx = x + 0.5, cy = y + 0.5;
                const bool in = cx > 20.0 && cy > 30.0 && cx + cy < 90.25;
                const size_t i = vis.Index(x, y);
                inside += in;
                if (in)
                    wrong += vis.primitive[i] != 0u || vis.depth[i] != cam.near_m;
                else
                    wrong += vis.primitive[i] != kNoPrimitive || vis.depth[i] != 0.0f ||
                             vis.b1[i] != 0.0f || vis.b2[i] != 0.0f;
            }
        }
        EXPECT_EQ(wrong, 0);
        EXPECT_GT(inside, 700);  // about 40.25² / 2 ≈ 810 sample centres
    }
}

// Tiles whose rows are whole cache lines of the frame go out line by line and clear the
// thread's tile targets behind them (tiles no triangle was binned to go out as empty lines
// without reading the targets); the others (a frame width or tile column off the 16-sample
// lines, tile rows not whole lines) are copied sample-exactly and cleared before the next tile.
// Frames of different content drawn one after another into one buffer, in grids that mix both
// kinds of tile within a thread, must equal tile size 8 (never whole lines: every tile cleared
// before it is drawn) bit for bit.
TEST(RasterTargets, LineCopyOutAndClearBehindEqualClearingEveryTile) {
    const auto bumpyGrid = [](uint64_t seed) {
        const double half = 6.0, cell = 2.0 * half / 48;
        return MakeGrid(
            48,
            [&](int i, int j) {
                const uint64_t k = uint64_t(j) * 49 + uint64_t(i);
                return glm::dvec3(i * cell - half, j * cell - half + 4.0,
                                  0.3 * scene::Uniform01(seed, 0, k));
            },
            false);
    };
    const Mesh gridA = bumpyGrid(91), gridC = bumpyGrid(92);
    Mesh fan;  // a few triangles near the view's middle: most of frame B is empty
    for (int k = 0; k < 5; ++k) {
        fan.positions.push_back({0.0f, 5.0f, 0.4f});
        fan.positions.push_back({0.6f * float(k) - 1.5f, 5.5f, 0.0f});
        fan.positions.push_back({0.6f * float(k) - 1.2f, 5.5f, 0.0f});
        fan.indices.insert(fan.indices.end(),
                           {uint32_t(3 * k), uint32_t(3 * k + 1), uint32_t(3 * k + 2)});
    }
    const std::vector<std::vector<RasterMesh>> frames = {
        {gridA.Raster(false)}, {fan.Raster(false)}, {gridC.Raster(false), fan.Raster(false)}};
    const auto same = [](const VisibilityBuffer& a, const VisibilityBuffer& b) {
        const auto eq = [](const auto& u, const auto& v) {
            return u.size() == v.size() &&
                   std::memcmp(u.data(), v.data(), u.size() * sizeof(u[0])) == 0;
        };
        return eq(a.depth, b.depth) && eq(a.primitive, b.primitive) && eq(a.b1, b.b1) &&
               eq(a.b2, b.b2);
    };
    const std::pair<int, int> sizes[] = {{96, 50}, {104, 70}, {112, 33}, {128, 64}, {150, 97}};
    for (const auto& [width, height] : sizes) {
        const RasterCamera cam =
            GroundView({0.1, -0.2, 1.2}, -20.0 * kPi / 180.0, 60.0 * kPi / 180.0, width, height)
                .Camera();
        for (int threads : {1, 2}) {
            tbb::task_arena arena(threads);
            std::vector<VisibilityBuffer> ref(frames.size());
            int empty = 0, drawn = 0;
            Rasterizer eight(8);
            for (size_t f = 0; f < frames.size(); ++f) {
                arena.execute([&] { eight.Render(frames[f], cam, ref[f]); });
                for (uint32_t p : ref[f].primitive) (p == kNoPrimitive ? empty : drawn) += 1;
            }
            EXPECT_GT(empty, width * height / 2);
            EXPECT_GT(drawn, width * height);
            for (int tileSize : {16, 32, 64}) {
                SCOPED_TRACE(std::to_string(width) + "x" + std::to_string(height) + ", " +
                             std::to_string(threads) + " threads, tile size " +
                             std::to_string(tileSize));
                Rasterizer r(tileSize);
                VisibilityBuffer vis;
                for (size_t f = 0; f < frames.size(); ++f) {
                    arena.execute([&] { r.Render(frames[f], cam, vis); });
                    EXPECT_TRUE(same(vis, ref[f])) << "frame " << f;
                }
            }
        }
    }
}

TEST(RasterShadePass, VisitsEverySampleOnceWithItsIndex) {
    VisibilityBuffer vis;
    vis.width = 37;
    vis.height = 29;
    std::vector<uint32_t> visits(size_t(vis.width * vis.height), 0);
    std::vector<uint8_t> indexOk(visits.size(), 0);
    tbb::task_arena arena(2);
    arena.execute([&] {
        ShadeSamples(vis, [&](int x, int y, size_t index) {
            ++visits[index];
            indexOk[index] = index == size_t(y) * 37 + size_t(x);
        });
    });
    for (size_t k = 0; k < visits.size(); ++k) {
        EXPECT_EQ(visits[k], 1u) << k;
        EXPECT_EQ(indexOk[k], 1) << k;
    }
}

TEST(RasterInput, BadInputThrowsInputError) {
    Mesh m;
    m.positions = {{0.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}};
    m.indices = {0, 1, 3};
    const RasterCamera cam = SampleSpaceCamera(16, 16);
    Rasterizer r;
    VisibilityBuffer vis;
    {
        const RasterMesh meshes[] = {m.Raster()};
        EXPECT_THROW(r.Render(meshes, cam, vis), InputError);  // index out of range
    }
    m.indices = {0, 1};
    {
        const RasterMesh meshes[] = {m.Raster()};
        EXPECT_THROW(r.Render(meshes, cam, vis), InputError);  // not a multiple of 3
    }
    m.indices = {0, 1, 2};
    m.positions[1].y = std::nanf("");
    {
        const RasterMesh meshes[] = {m.Raster()};
        EXPECT_THROW(r.Render(meshes, cam, vis), InputError);  // non-finite position
    }
    m.positions[1].y = 0.0f;
    const RasterMesh meshes[] = {m.Raster()};
    RasterCamera bad = cam;
    bad.width = 0;
    EXPECT_THROW(r.Render(meshes, bad, vis), InputError);
    bad = cam;
    bad.height = kMaxRasterSamplesPerAxis + 1;
    EXPECT_THROW(r.Render(meshes, bad, vis), InputError);
    bad = cam;
    bad.near_m = 0.0f;
    EXPECT_THROW(r.Render(meshes, bad, vis), InputError);
    bad = cam;
    bad.clipFromWorld[2][1] = INFINITY;
    EXPECT_THROW(r.Render(meshes, bad, vis), InputError);
    EXPECT_THROW(Rasterizer(48), InputError);
    EXPECT_THROW(Rasterizer(4), InputError);
    // Valid input after errors still renders.
    EXPECT_NO_THROW(r.Render(meshes, cam, vis));
    EXPECT_EQ(r.Stats().trianglesIn, 1u);
}

}  // namespace
}  // namespace seasense::channels
