// Colour conversions for the visible channel's scene-linear Rec.709 (D65) working space.
#pragma once

#include <glm/glm.hpp>

namespace seasense::radiometry {

// CIE XYZ → linear Rec.709 RGB, D65 white (IEC 61966-2-1:1999, sRGB primaries).
inline glm::dvec3 Rec709FromXyz(const glm::dvec3& xyz) {
    return {3.2406 * xyz.x - 1.5372 * xyz.y - 0.4986 * xyz.z,
            -0.9689 * xyz.x + 1.8758 * xyz.y + 0.0415 * xyz.z,
            0.0557 * xyz.x - 0.2040 * xyz.y + 1.0570 * xyz.z};
}

// Luminance Y of linear Rec.709 RGB (ITU-R BT.709-6, Table item 3.3).
inline double LuminanceRec709(const glm::dvec3& rgb) {
    return 0.2126 * rgb.r + 0.7152 * rgb.g + 0.0722 * rgb.b;
}

// Linear Rec.709 RGB of a colour with luminance Y and chromaticity (x, y).
inline glm::dvec3 Rec709FromYxy(double Y, double x, double y) {
    if (y <= 0.0) return glm::dvec3(0.0);
    return Rec709FromXyz({x / y * Y, Y, (1.0 - x - y) / y * Y});
}

}  // namespace seasense::radiometry
