// Polar-grid sea mesh: a grid centred on the eye gives a screen-uniform vertex density from the
// eye to the horizon as one mesh, so there are no level-of-detail seams to stitch.
#include "scene/ocean/ocean_mesh.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "scene/core/check.h"

namespace seasense::scene {

double HorizonDistance_m(double h) {
    h = std::max(h, 0.0);
    return std::sqrt(2.0 * kEarthRadius_m * h + h * h);
}

double CurvatureDrop_m(double r) {
    const double R = kEarthRadius_m;
    r = std::min(std::abs(r), R);
    // r² / (R + √(R² − r²)) equals R − √(R² − r²) without cancellation.
    return r * r / (R + std::sqrt(R * R - r * r));
}

void BuildOceanMesh(const GerstnerOcean& ocean, const OceanMeshRequest& req, OceanMesh& out) {
    CHECK(req.angularStep_rad > 0.0);
    const double amplitude = ocean.MaxAmplitude_m();
    const double eyeHeight = std::max(req.eye_m.z, 0.05);
    // Crests up to `amplitude` high stay visible until the two horizon distances add up.
    const double maxRange = HorizonDistance_m(eyeHeight) + HorizonDistance_m(amplitude) + 100.0;
    // Heights seen from the eye: foreshortening uses the eye's height above the lowest trough.
    const double hEff = eyeHeight + amplitude;
    const double dphi = req.angularStep_rad;

    std::vector<double> radii;
    if (!(req.minRange_m < maxRange)) {  // nothing visible (also catches NaN)
        out.positions.clear();
        out.normals.clear();
        out.jacobian.clear();
        out.indices.clear();
        out.rings = out.segments = 0;
        out.fullCircle = false;
        return;
    }
    double r;
    if (req.minRange_m > 0.0) {
        r = req.minRange_m;
    } else {
        // A centre vertex under the eye, then rings from well inside the nearest water.
        radii.push_back(0.0);
        r = std::max(0.05, 0.25 * hEff);
    }
    while (r < maxRange) {
        radii.push_back(r);
        const double step = std::min(r * dphi * std::max(1.0, r / hEff), 8.0 * r * dphi);
        r += std::max(step, 1e-3);
    }
    radii.push_back(maxRange);

    const bool full = req.azimuthMax_rad - req.azimuthMin_rad >= 2.0 * M_PI - 1e-9;
    const double span = full ? 2.0 * M_PI : req.azimuthMax_rad - req.azimuthMin_rad;
    CHECK(span > 0.0);
    const int segments = std::max(3, int(std::ceil(span / dphi)));
    const int columns = full ? segments : segments + 1;  // the full circle wraps its last column
    const int rings = int(radii.size());

    // The index buffer depends only on the grid's shape: rebuilt when that changes.
    const bool sameShape = out.rings == rings && out.segments == segments &&
                           out.fullCircle == full && !out.indices.empty();
    out.rings = rings;
    out.segments = segments;
    out.fullCircle = full;
    std::vector<double> sinAz(static_cast<size_t>(columns)), cosAz(static_cast<size_t>(columns));
    for (int i = 0; i < columns; ++i) {
        const double az = req.azimuthMin_rad + span * double(i) / double(segments);
        sinAz[size_t(i)] = std::sin(az);
        cosAz[size_t(i)] = std::cos(az);
    }
    out.positions.resize(size_t(rings) * size_t(columns));
    out.normals.resize(out.positions.size());
    out.jacobian.resize(out.positions.size());
    const GerstnerOcean::LocalFrame local = ocean.Local(req.eye_m.x, req.eye_m.y, req.time_s);
    tbb::parallel_for(0, rings, [&](int j) {
        const double radius = radii[size_t(j)];
        const double drop = CurvatureDrop_m(radius);
        for (int i = 0; i < columns; ++i) {
            const float rx = float(radius * sinAz[size_t(i)]);
            const float ry = float(radius * cosAz[size_t(i)]);
            const size_t v = size_t(j) * size_t(columns) + size_t(i);
            glm::vec3 p;
            local.Evaluate(rx, ry, p, out.normals[v], out.jacobian[v]);
            out.positions[v] =
                glm::vec3(float(req.eye_m.x + double(p.x)), float(req.eye_m.y + double(p.y)),
                          float(double(p.z) - drop));
        }
    });

    if (sameShape) return;
    out.indices.clear();
    out.indices.reserve(size_t(rings - 1) * size_t(segments) * 6);
    for (int j = 0; j + 1 < rings; ++j) {
        for (int i = 0; i < segments; ++i) {
            const int i1 = full ? (i + 1) % segments : i + 1;
            const uint32_t a = uint32_t(j * columns + i), b = uint32_t(j * columns + i1);
            const uint32_t c = uint32_t((j + 1) * columns + i),
                           d = uint32_t((j + 1) * columns + i1);
            // Azimuth increases clockwise seen from above and radius outward, so (a, b, c)
            // and (b, d, c) are counter-clockwise seen from above.
            out.indices.insert(out.indices.end(), {a, b, c, b, d, c});
        }
    }
}

}  // namespace seasense::scene
