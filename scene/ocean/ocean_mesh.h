// View-dependent sea-surface mesh: a polar grid around the eyepoint out past the horizon, the
// surface band-limited to the vertex spacing, dropped by the Earth's curvature.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <limits>
#include <vector>

#include "scene/ocean/ocean_surface.h"

namespace seasense::scene {

// Mean Earth radius, m (IUGG mean radius R1, Moritz 1980 "Geodetic Reference System 1980").
inline constexpr double kEarthRadius_m = 6371008.8;

// Distance to the geometric sea horizon for an eye height above the water (m):
// √(2 R h + h²), no refraction. 2 m → 5.05 km; 300 m → 61.8 km.
double HorizonDistance_m(double eyeHeight_m);

// Drop of the sea surface below the eye's tangent plane at horizontal distance r (m):
// R − √(R² − r²) ≈ r² / 2R.
double CurvatureDrop_m(double range_m);

struct OceanMeshRequest {
    glm::dvec3 eye_m{0.0};          // eyepoint in world ENU
    double azimuthMin_rad = 0.0;    // sector of azimuths to cover (clockwise from north);
    double azimuthMax_rad = 0.0;    // max − min ≥ 2π means the full circle
    double angularStep_rad = 0.01;  // target angle between neighbouring vertices seen from the eye
    // No sea nearer than this can be seen (e.g. below the view): the grid starts here rather
    // than under the eye. +∞ means no sea is visible at all (an empty mesh).
    double minRange_m = 0.0;
    // False: every ring covers [azimuthMin, azimuthMax] (which must then include any margin).
    // True: that sector is the view's own, and the band between rings j and j + 1 is widened on
    // both sides by asin(D / r_j) (and one column), D bounding the horizontal displacement of
    // the sea within r_{j+1} of the eye (OceanSurfaceFrame::BoundsNear): a point drawn in the
    // sector at rest radius r ≥ r_j lies at most D from its rest position, which the eye sees at
    // most asin(D / r) off its azimuth. Far rings, where D / r is small, then hold only the
    // view's columns. The widening is capped at kMaxReachMargin_rad (20°), the fixed margin used
    // before: within D / sin 20° of the eye (~9 m for D = 3 m) the bound would ask for up to the
    // whole circle, which costs more vertices than the rest of the mesh, while the displacement
    // actually synthesized near the eye stays far below D (0.4–0.8 m within 6 m of a 2 m eye in
    // configs/surf.yaml, against D ≈ 3 m), which 20° covers beyond ~2.3 m. So near the eye this
    // is the old margin, not a proof.
    bool widenByReach = false;
    // tan of the steepest depression below the horizontal of any view ray (∞: unknown). A sea
    // point at range r and height H below the eye is seen only if H ≤ r · tan: the rings are
    // thinned where that lowest visible surface lies above OceanMeshRadii's trough (see
    // ThinnedOceanMeshRadii).
    double maxDepressionTan = std::numeric_limits<double>::infinity();
    // False (tests only): no shortcut that provably changes no bit (see ocean_mesh.cpp): every
    // vertex of a surf zone through the whole surf path, also where
    // OceanSurfaceFrame::OpenSeaFrom_m proves it the deep sea's, and the Gerstner waves summed
    // also on rings where each wave's footprint weight is 0, and every triangle corner looked up
    // by its column rather than stepped to along its ring.
    bool shortcuts = true;
};

// The coarsest column stride of a ring near the eye with OceanMeshRequest::widenByReach.
inline constexpr int kMaxColumnStride = 16;
// The largest sideways widening of a band with OceanMeshRequest::widenByReach: 20°.
inline constexpr double kMaxReachMargin_rad = 20.0 * 3.14159265358979323846 / 180.0;

struct OceanMesh {
    std::vector<glm::vec3> positions;  // world ENU, curvature drop applied relative to the eye
    std::vector<glm::vec3> normals;    // unit, world
    std::vector<float> jacobian;       // surface folding measure (< 0 folded)
    // With a surf zone, per vertex: the surf's foam coverage (scene/surf/foam.h) at the vertex's
    // rest position where the still water is shallower than the fade depth, else 0; from the
    // same SurfWaves::Terms evaluation as the vertex; 0 on dry land that no water reaches
    // (OceanSurfaceFrame::DryLandSums). Empty without a surf zone.
    std::vector<float> surfFoam;
    std::vector<uint32_t> indices;  // counter-clockwise seen from above
    // Ring j's vertices are ringStart[j] … ringStart[j + 1] − 1, its columns ringFirstColumn[j],
    // ringFirstColumn[j] + 1, …: column c lies at azimuth c · 2π / circleSegments, fixed in the
    // world; a ring whose columns go round the whole circle wraps (column c is column
    // c mod circleSegments). Without widenByReach every ring
    // has the same columns: ring j, column i is vertex j · (segments + !fullCircle) + i, column
    // i at azimuth (firstColumn + i) · 2π / circleSegments. With it, segments, fullCircle and
    // firstColumn describe the widest ring.
    int rings = 0;
    int segments = 0;
    bool fullCircle = false;
    int circleSegments = 0;
    int firstColumn = 0;
    std::vector<uint32_t> ringStart;   // rings + 1 entries
    std::vector<int> ringFirstColumn;  // per ring (0 for whole circles)
    // Per ring: it holds every ringStride[j]-th column (1 without widenByReach; with it, coarser
    // near the eye, see ocean_mesh.cpp): vertex ringStart[j] + i is column ringFirstColumn[j]
    // + i · ringStride[j], and a whole circle has circleSegments / ringStride[j] vertices.
    std::vector<int> ringStride;
    // Per band (between rings j and j + 1): the columns [bandLo[j], bandHi[j]) its triangles
    // cover (a span of circleSegments or more: all round).
    std::vector<int64_t> bandLo, bandHi;
    std::vector<double> radii_m;     // rest-position radius of each ring
    std::vector<float> footprint_m;  // per ring: the sampling footprint the surface is filtered to
};

// Rest-position radii of the rings for an eye height above the mean sea (m), the waves'
// significant height (m) and an angular step (rad), out to maxRange_m (the last ring): a centre
// vertex, then rings spaced so that each step subtends the angular step in depression angle seen
// from the eye — h·dphi under the eye, growing as r²/h where grazing foreshortening compresses
// them, capped at 8× the tangential spacing. A function of these arguments only.
std::vector<double> OceanMeshRadii(double eyeHeight_m, double significantHeight_m,
                                   double angularStep_rad, double maxRange_m);
// OceanMeshRadii's rings thinned for a view whose rays look at most atan(maxDepressionTan) below
// the horizontal: a surface at range r is seen only if it lies at most H = r · maxDepressionTan
// below the eye, and two rings dr apart on a surface H' below the eye are seen H' dr / (r² + H'²)
// apart, which grows with H' up to H' = r; so where H is below the trough's depth h under the
// eye (and below r: else nothing is dropped) the rings need only be dphi (r² + H²) / H apart
// (the angular step for every surface the view can see there) rather than dphi (r² + h²) / h
// (capped as there). A subsequence of radii: each ring is followed by the farthest ring of radii
// within that step (at least the next), so from where the visible surface reaches the trough's
// depth on it keeps every ring.
std::vector<double> ThinnedOceanMeshRadii(const std::vector<double>& radii, double eyeHeight_m,
                                          double significantHeight_m, double dphi,
                                          double maxDepressionTan);

// An upper bound (m) of the footprint (OceanMesh::footprint_m) of every ring within radius_m of
// the eye, for an eye height, the waves' significant height and an angular step: a ring's
// footprint is its tangential spacing r·dphi or a radial spacing to a neighbour, which
// OceanMeshRadii caps at max(8 r, trough depth)·dphi (thinning keeps that cap), dphi ≤ the step.
// For OceanSurfaceFrame::LocalBoundsNear over discs about the eye.
double OceanMeshFootprintBound_m(double radius_m, double eyeHeight_m, double significantHeight_m,
                                 double angularStep_rad);

// Builds the mesh for one view from a surface frame (see ocean_mesh.cpp for the choice of a
// polar grid). Parallel over rings with oneTBB; bit-identical for any thread count.
void BuildOceanMesh(const OceanSurfaceFrame& frame, const OceanMeshRequest& request,
                    OceanMesh& out);

}  // namespace seasense::scene
