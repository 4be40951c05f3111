// Rotations between the world ENU frame and body frames (x right/starboard, y forward, z up).
#pragma once

#include <cmath>
#include <glm/glm.hpp>

#include "scene/scenario/scenario.h"

namespace seasense::scene {

// worldFromBody rotation for heading ψ (clockwise from north), pitch θ (nose up) and roll φ
// (right side down), applied as Rz(−ψ)·Rx(θ)·Ry(φ). Body axes: x right, y forward, z up; at
// zero attitude the body's forward axis points north and its right axis east.
inline glm::dmat3 WorldFromBodyRotation(const Attitude& a) {
    const double ch = std::cos(a.heading_rad), sh = std::sin(a.heading_rad);
    const double cp = std::cos(a.pitch_rad), sp = std::sin(a.pitch_rad);
    const double cr = std::cos(a.roll_rad), sr = std::sin(a.roll_rad);
    // glm matrices are column-major: glm::dmat3(col0, col1, col2).
    const glm::dmat3 rz(glm::dvec3(ch, -sh, 0.0), glm::dvec3(sh, ch, 0.0), glm::dvec3(0, 0, 1));
    const glm::dmat3 rx(glm::dvec3(1, 0, 0), glm::dvec3(0.0, cp, sp), glm::dvec3(0.0, -sp, cp));
    const glm::dmat3 ry(glm::dvec3(cr, 0.0, -sr), glm::dvec3(0, 1, 0), glm::dvec3(sr, 0.0, cr));
    return rz * rx * ry;
}

// Unit ENU direction toward azimuth (clockwise from north) and elevation, radians.
inline glm::dvec3 DirectionFromAzimuthElevation(double azimuth_rad, double elevation_rad) {
    const double ce = std::cos(elevation_rad);
    return {ce * std::sin(azimuth_rad), ce * std::cos(azimuth_rad), std::sin(elevation_rad)};
}

// A rigid pose: worldFromBody = translation(position) · rotation.
struct Pose {
    glm::dvec3 position_m{0.0};
    glm::dmat3 worldFromBody{1.0};

    glm::dvec3 ToWorld(const glm::dvec3& pBody) const { return position_m + worldFromBody * pBody; }
};

inline Pose PoseFrom(const glm::dvec3& position_m, const Attitude& attitude) {
    return Pose{position_m, WorldFromBodyRotation(attitude)};
}

// Composition: the pose of a child given relative to parent's body frame.
inline Pose Compose(const Pose& parent, const Pose& childInParent) {
    return Pose{parent.ToWorld(childInParent.position_m),
                parent.worldFromBody * childInParent.worldFromBody};
}

}  // namespace seasense::scene
