// View-dependent sea-surface mesh: a polar grid around the eyepoint out past the horizon,
// displaced by the wave model and dropped by the Earth's curvature.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "scene/ocean/gerstner.h"

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
    double time_s = 0.0;
    // No sea nearer than this can be seen (e.g. below the view): the grid starts here rather
    // than under the eye. +∞ means no sea is visible at all (an empty mesh).
    double minRange_m = 0.0;
};

struct OceanMesh {
    std::vector<glm::vec3> positions;  // world ENU, curvature drop applied relative to the eye
    std::vector<glm::vec3> normals;    // unit, world
    std::vector<float> jacobian;       // surface folding measure (< 0 folded)
    std::vector<uint32_t> indices;     // counter-clockwise seen from above
    int rings = 0;
    int segments = 0;
    bool fullCircle = false;
};

// Builds the mesh for one view. Rings are spaced so that each step subtends about
// angularStep seen from the eye: geometric near the eye, growing as r²/h where grazing
// foreshortening compresses them, capped at 8× the tangential spacing so waves stay sampled,
// out to the horizon distance of eye height plus the highest crest. Parallel over rings with
// oneTBB; deterministic.
void BuildOceanMesh(const GerstnerOcean& ocean, const OceanMeshRequest& request, OceanMesh& out);

}  // namespace seasense::scene
