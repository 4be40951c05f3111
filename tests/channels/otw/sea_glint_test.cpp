// The glint pre-test of OTW sea shading: GlintPossible never rules out a lane that the exact
// glint test (lit, GlintFacetTilt's tan² β below the limit) passes, also at the limit itself.
#include "channels/otw/sea_glint.h"

#include <gtest/gtest.h>

#include <cmath>
#include <glm/glm.hpp>
#include <vector>

namespace seasense::channels {
namespace {

using namespace simd;

struct Lane {
    glm::vec3 v, l, n;
};

// Counts the lanes of cases (kLanes at a time) that glint, and that GlintPossible rules out;
// fails where it rules out a lane that glints.
void CheckLanes(const std::vector<Lane>& cases, float slopeVariance, int& glints, int& ruledOut) {
    const float limit = GlintTan2Limit(slopeVariance), bound = GlintCos2Bound(limit);
    for (size_t i = 0; i < cases.size(); i += kLanes) {
        VF vx{}, vy{}, vz{}, wx{}, wy{}, wz{}, nx{}, ny{}, nz{}, cosS{};
        for (size_t k = 0; k < kLanes; ++k) {
            const Lane& c = cases[std::min(i + k, cases.size() - 1)];
            vx[k] = c.v.x, vy[k] = c.v.y, vz[k] = c.v.z;
            wx[k] = c.v.x + c.l.x, wy[k] = c.v.y + c.l.y, wz[k] = c.v.z + c.l.z;
            nx[k] = c.n.x, ny[k] = c.n.y, nz[k] = c.n.z;
            cosS[k] = glm::dot(c.n, c.l);
        }
        const VF ww = Dot(wx, wy, wz, wx, wy, wz);
        const GlintTilt tilt = GlintFacetTilt(vx, vy, vz, wx, wy, wz, ww, nx, ny, nz);
        const VI exact = (cosS > 0.0f) & (tilt.tan2 < limit);
        const VI possible =
            GlintPossible(cosS, Splat(1.0f), Dot(wx, wy, wz, nx, ny, nz), ww, bound);
        for (size_t k = 0; k < kLanes && i + k < cases.size(); ++k) {
            glints += exact[k] != 0;
            ruledOut += possible[k] == 0;
            EXPECT_TRUE(possible[k] || !exact[k])
                << "case " << i + k << " tan2 " << tilt.tan2[k] << " limit " << limit;
        }
    }
}

glm::vec3 Direction(double azimuth, double elevation) {
    return glm::vec3(float(std::cos(elevation) * std::sin(azimuth)),
                     float(std::cos(elevation) * std::cos(azimuth)), float(std::sin(elevation)));
}

// n tilted from unit h by angle beta toward a direction perpendicular to h (turned by phi).
glm::vec3 Tilted(const glm::vec3& h, double beta, double phi) {
    const glm::dvec3 hd(h);
    const glm::dvec3 a = glm::normalize(
        glm::cross(hd, std::abs(hd.z) < 0.9 ? glm::dvec3(0, 0, 1) : glm::dvec3(1, 0, 0)));
    const glm::dvec3 b = glm::cross(hd, a);
    const glm::dvec3 t = std::cos(phi) * a + std::sin(phi) * b;
    return glm::vec3(glm::normalize(std::cos(beta) * hd + std::sin(beta) * t));
}

TEST(SeaGlint, PreTestKeepsEveryGlintingLane) {
    for (double wind_mps : {0.0, 6.0, 30.0}) {
        const float slopeVariance = float(0.003 + 0.00512 * wind_mps);
        const double limitBeta =
            std::atan(std::sqrt(double(GlintTan2Limit(slopeVariance))));  // tan² β = limit
        std::vector<Lane> cases;
        // Random geometry: views a little above the horizon to steep, suns from the horizon
        // to high, normals tilted up to 80° (golden-ratio sequences).
        for (int i = 0; i < 20000; ++i) {
            const auto q = [&](double a) { return std::fmod(double(i) * a, 1.0); };
            const glm::vec3 v = Direction(2.0 * M_PI * q(0.618034), 0.002 + 1.2 * q(0.754878));
            const glm::vec3 l = Direction(2.0 * M_PI * q(0.569840), 1.5 * q(0.815945));
            const glm::vec3 n = Direction(2.0 * M_PI * q(0.438332), M_PI / 2 - 1.4 * q(0.7071));
            cases.push_back({v, l, n});
        }
        // Normals at the limit's tilt from the half vector, within ±1e-4 relative: the glint
        // test's edge, where rounding decides.
        for (int i = 0; i < 4000; ++i) {
            const auto q = [&](double a) { return std::fmod(double(i) * a, 1.0); };
            const glm::vec3 v = Direction(2.0 * M_PI * q(0.618034), 0.01 + 0.5 * q(0.754878));
            const glm::vec3 l = Direction(2.0 * M_PI * q(0.569840), 0.05 + 1.0 * q(0.815945));
            const glm::vec3 h = glm::normalize(v + l);
            const double beta = limitBeta * (1.0 + 1e-4 * (2.0 * q(0.3819660) - 1.0));
            cases.push_back({v, l, Tilted(h, beta, 2.0 * M_PI * q(0.1273240))});
        }
        int glints = 0, ruledOut = 0;
        CheckLanes(cases, slopeVariance, glints, ruledOut);
        // Both outcomes occur: lanes glint, and the pre-test rules lanes out.
        EXPECT_GT(glints, 1000) << wind_mps;
        EXPECT_GT(ruledOut, 5000) << wind_mps;
    }
}

}  // namespace
}  // namespace seasense::channels
