// A sea-surface point as the wave models produce it: the displacement of a rest position and its
// derivatives, summed over models, and the sample (position, normal, folding) made from them.
#pragma once

#include <cmath>
#include <glm/glm.hpp>

namespace seasense::scene {

// Displacement D(x0, y0) of the surface particle at rest position (x0, y0) (world ENU, m) and its
// first derivatives with respect to the rest position; terms of several models add.
struct SurfaceTerms {
    glm::dvec3 displacement{0.0};  // (Dx east, Dy north, η up), m
    double dxx = 0.0;              // ∂Dx/∂x0
    double dyy = 0.0;              // ∂Dy/∂y0
    double dxy = 0.0;              // ∂Dx/∂y0 = ∂Dy/∂x0 (irrotational linear waves)
    double sx = 0.0;               // ∂η/∂x0
    double sy = 0.0;               // ∂η/∂y0
    glm::dvec3 velocity_mps{0.0};  // ∂D/∂t at fixed rest position

    SurfaceTerms& operator+=(const SurfaceTerms& o) {
        displacement += o.displacement;
        dxx += o.dxx, dyy += o.dyy, dxy += o.dxy, sx += o.sx, sy += o.sy;
        velocity_mps += o.velocity_mps;
        return *this;
    }
};

// The ocean surface at a rest position, world ENU metres.
struct OceanSample {
    glm::dvec3 position{0.0};          // displaced surface point
    glm::dvec3 normal{0.0, 0.0, 1.0};  // unit, upward
    glm::dvec3 velocity_mps{0.0};      // of the surface particle (orbital velocity)
    double jacobian = 1.0;             // det ∂(x, y)/∂(x0, y0); < 0 where the surface folds
    double minEigenvalue = 1.0;        // smaller eigenvalue of ∂(x, y)/∂(x0, y0)
};

// The sample whose displaced horizontal position is (x, y): evaluate(x0, y0) → OceanSample at
// rest position (x0, y0), inverted by the fixed-point iteration x0 ← x0 + (x − P_h(x0)), a
// contraction while the horizontal map is not folded (eigenvalues of ∂P_h/∂x0 in (0, 2)); at
// most 64 steps, to 1e-9 m. The rest position found is stored in *rest when given.
template <typename Evaluate>
OceanSample InvertHorizontalDisplacement(double x, double y, const Evaluate& evaluate,
                                         glm::dvec2* rest = nullptr) {
    constexpr int kMaxIterations = 64;
    constexpr double kTolerance_m = 1e-9;
    double x0 = x, y0 = y;
    OceanSample s = evaluate(x0, y0);
    for (int iter = 0; iter < kMaxIterations; ++iter) {
        const double ex = x - s.position.x, ey = y - s.position.y;
        if (ex * ex + ey * ey < kTolerance_m * kTolerance_m) break;
        x0 += ex;
        y0 += ey;
        s = evaluate(x0, y0);
    }
    if (rest) *rest = {x0, y0};
    return s;
}

// The sample of rest position (x0, y0) with the given terms: the tangents ∂P/∂x0 = (1 + Dxx, Dxy,
// ηx) and ∂P/∂y0 = (Dxy, 1 + Dyy, ηy) give the normal; the horizontal Jacobian matrix
// [[1 + Dxx, Dxy], [Dxy, 1 + Dyy]] (symmetric) its determinant and smaller eigenvalue.
inline OceanSample MakeOceanSample(double x0, double y0, const SurfaceTerms& t) {
    const double a = 1.0 + t.dxx, d = 1.0 + t.dyy, b = t.dxy;
    OceanSample s;
    s.position = {x0 + t.displacement.x, y0 + t.displacement.y, t.displacement.z};
    glm::dvec3 n = glm::cross(glm::dvec3(a, b, t.sx), glm::dvec3(b, d, t.sy));
    const double len = glm::length(n);
    n = len > 0.0 ? n / len : glm::dvec3(0.0, 0.0, 1.0);
    s.normal = n.z < 0.0 ? -n : n;  // folded surface: keep the normal upward
    s.velocity_mps = t.velocity_mps;
    s.jacobian = a * d - b * b;
    s.minEigenvalue = 0.5 * (a + d) - std::sqrt(0.25 * (a - d) * (a - d) + b * b);
    return s;
}

}  // namespace seasense::scene
