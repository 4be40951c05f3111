// The shoreline frame: conversions between world ENU (x, y) and shore coordinates (cross-shore
// distance s, positive seaward, and alongshore distance u).
#pragma once

#include <cmath>
#include <glm/glm.hpp>

#include "scene/surf/surf_settings.h"

namespace seasense::scene {

// A point in the shore frame, m: s across the shore (0 on the still-water line at tide 0,
// positive seaward), u along it (0 at the shoreline origin, positive toward the shoreline
// azimuth).
struct ShorePoint {
    double s_m = 0.0;
    double u_m = 0.0;
};

class ShoreFrame {
  public:
    ShoreFrame() = default;
    explicit ShoreFrame(const ShorelineSettings& s)
        : origin_m_(s.origin_m),
          alongshore_(std::sin(s.azimuth_rad), std::cos(s.azimuth_rad)),
          // Land on the left of the shoreline direction: seaward is the direction turned 90°
          // clockwise, azimuth + 90°.
          seaward_(std::cos(s.azimuth_rad), -std::sin(s.azimuth_rad)) {}

    const glm::dvec2& Origin_m() const { return origin_m_; }
    // Unit ENU vectors along the shore (toward the azimuth) and across it (seaward).
    const glm::dvec2& Alongshore() const { return alongshore_; }
    const glm::dvec2& Seaward() const { return seaward_; }

    // World ENU (x, y), m → shore frame (s, u), m.
    ShorePoint ShoreFromWorld(double x, double y) const {
        const glm::dvec2 d{x - origin_m_.x, y - origin_m_.y};
        return {glm::dot(d, seaward_), glm::dot(d, alongshore_)};
    }
    // Shore frame (s, u), m → world ENU (x, y), m.
    glm::dvec2 WorldFromShore(double s_m, double u_m) const {
        return origin_m_ + s_m * seaward_ + u_m * alongshore_;
    }
    // A world direction (ENU vector) in shore components (seaward, alongshore) and back.
    glm::dvec2 ShoreFromWorldDirection(const glm::dvec2& v) const {
        return {glm::dot(v, seaward_), glm::dot(v, alongshore_)};
    }
    glm::dvec2 WorldFromShoreDirection(const glm::dvec2& v) const {
        return v.x * seaward_ + v.y * alongshore_;
    }

  private:
    glm::dvec2 origin_m_{0.0};
    glm::dvec2 alongshore_{0.0, 1.0};
    glm::dvec2 seaward_{1.0, 0.0};
};

}  // namespace seasense::scene
