// View-dependent sea-surface mesh: a polar grid around the eyepoint out past the horizon, the
// surface band-limited to the vertex spacing, dropped by the Earth's curvature.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
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
};

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
    // Ring j, column i is vertex j · (segments + !fullCircle) + i. Column i lies at azimuth
    // (firstColumn + i) · 2π / circleSegments: azimuths are fixed in the world.
    int rings = 0;
    int segments = 0;
    bool fullCircle = false;
    int circleSegments = 0;
    int firstColumn = 0;
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

// Builds the mesh for one view from a surface frame (see ocean_mesh.cpp for the choice of a
// polar grid). Parallel over rings with oneTBB; bit-identical for any thread count.
void BuildOceanMesh(const OceanSurfaceFrame& frame, const OceanMeshRequest& request,
                    OceanMesh& out);

}  // namespace seasense::scene
