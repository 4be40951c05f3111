// OTW shading: Fresnel-weighted sky reflection, Cox–Munk sun glint and water-leaving radiance
// on the sea; Lambertian models lit by sun (shadowed) and sky; Koschmieder fog.
#include "channels/otw/otw_channel.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "radiometry/sky/analytic_sky.h"
#include "radiometry/surface/fresnel.h"

namespace seasense::channels {

namespace {

// Remote-sensing reflectance R_rs = L_w / E_d of clear oceanic (Case 1) water, sr⁻¹, at the
// Rec.709 primaries' dominant wavelengths (≈ 610, 550, 465 nm); order of magnitude from
// Mobley, "Light and Water" (1994), Fig. 11.x and Morel & Maritorena (2001) for chl ≈ 0.1 mg/m³.
constexpr glm::vec3 kSeaRrs{0.0003f, 0.0015f, 0.0050f};

// Albedo of the sea for light reflected up onto models (Payne 1972, J. Atmos. Sci. 29: ≈ 0.06).
constexpr float kSeaAlbedo = 0.06f;

// Koschmieder: extinction coefficient for a 2 % contrast threshold, β = 3.912 / V.
double ExtinctionFromVisibility(double visibility_m) { return 3.912 / visibility_m; }

// Gaussian isotropic slope density of Cox & Munk (1954), J. Opt. Soc. Am. 44(11), with the
// mean-square slope σ² = 0.003 + 0.00512·W (W wind speed at 12.5 m, m/s); p(tan β) per unit
// slope area.
// Sea mesh vertex spacing on screen: waves are smooth at this scale and their normals are
// interpolated per sample.
constexpr double kOceanVertexSpacing_px = 6.0;

float CoxMunkSlopeVariance(double windSpeed_mps) {
    return float(0.003 + 0.00512 * std::max(windSpeed_mps, 0.0));
}

}  // namespace

void FrustumAzimuthSector(const ChannelCamera& cam, double margin, double& lo, double& hi) {
    const glm::dvec3 axis = cam.worldFromCamera.worldFromBody * glm::dvec3(0, 1, 0);
    const double centre = std::atan2(axis.x, axis.y);
    double minRel = 0.0, maxRel = 0.0;
    bool full = false;
    // Walk the frustum boundary: its azimuth extremes lie on the boundary.
    const int steps = 32;
    for (int e = 0; e < 4 && !full; ++e) {
        for (int i = 0; i <= steps; ++i) {
            const double s = double(i) / steps;
            double u = 0, v = 0;
            switch (e) {
                case 0:
                    u = s, v = 0;
                    break;
                case 1:
                    u = 1, v = s;
                    break;
                case 2:
                    u = 1 - s, v = 1;
                    break;
                default:
                    u = 0, v = 1 - s;
                    break;
            }
            const glm::dvec3 d =
                cam.SampleDirection(u * cam.SampleWidth() - 0.5, v * cam.SampleHeight() - 0.5);
            if (std::hypot(d.x, d.y) < 0.05) {
                full = true;  // within ~3° of the zenith or nadir: all azimuths are near
                break;
            }
            double rel = std::atan2(d.x, d.y) - centre;
            rel = std::remainder(rel, 2.0 * M_PI);
            minRel = std::min(minRel, rel);
            maxRel = std::max(maxRel, rel);
        }
    }
    if (full || maxRel - minRel + 2.0 * margin >= 2.0 * M_PI) {
        lo = 0.0;
        hi = 2.0 * M_PI;
        return;
    }
    lo = centre + minRel - margin;
    hi = centre + maxRel + margin;
}

OtwChannel::OtwChannel(const scene::World& world, const scene::ChannelSettings& settings)
    : world_(world), settings_(settings) {
    const scene::SceneState s0 = world.State(0);
    for (const scene::EntityState& e : s0.entities) {
        worldMeshes_.push_back(scene::TransformMesh(*e.bodyMesh, e.pose));
        reflectance_.push_back(e.reflectanceRgb);
        occlusion_.AddMesh(worldMeshes_.back().positions, worldMeshes_.back().indices);
    }
    occlusion_.Commit();
}

void OtwChannel::Render(const scene::SceneState& state, Image& radiance) {
    const scene::Scenario& sc = world_.GetScenario();
    const scene::EnvironmentSettings& env = sc.environment;
    camera_ = MakeChannelCamera(state.eyepoint, settings_);
    const ChannelCamera& cam = camera_;
    const int sw = cam.SampleWidth(), sh = cam.SampleHeight();

    using Clock = std::chrono::steady_clock;
    const auto Ms = [](Clock::time_point a, Clock::time_point b) {
        return std::chrono::duration<double, std::milli>(b - a).count();
    };
    const Clock::time_point t0 = Clock::now();
    // Sea mesh for this view: vertices about 4 pixels apart on screen.
    scene::OceanMeshRequest req;
    req.eye_m = cam.worldFromCamera.position_m;
    req.time_s = state.time_s;
    req.angularStep_rad = kOceanVertexSpacing_px * cam.hfov_rad / double(cam.width);
    FrustumAzimuthSector(cam, 20.0 * M_PI / 180.0, req.azimuthMin_rad, req.azimuthMax_rad);
    scene::BuildOceanMesh(world_.Ocean(), req, ocean_);

    std::vector<RasterMesh> meshes;
    // The sea is seen from both sides only when a camera dips below it; cull back faces.
    meshes.push_back({ocean_.positions, ocean_.indices, true});
    for (const scene::TriangleMesh& m : worldMeshes_)
        meshes.push_back({m.positions, m.indices, true});
    const Clock::time_point t1 = Clock::now();
    rasterizer_.Render(meshes, cam.Raster(), vis_);
    const Clock::time_point t2 = Clock::now();

    stats_ = {};
    stats_.raster = rasterizer_.Stats();
    stats_.meshMs = Ms(t0, t1);
    stats_.rasterMs = Ms(t1, t2);
    stats_.oceanTriangles = ocean_.indices.size() / 3;
    for (const scene::TriangleMesh& m : worldMeshes_) stats_.modelTriangles += m.TriangleCount();

    if (!sky_ || skySun_ != state.sun.direction || skySunLux_ != state.sun.illuminance_lux) {
        sky_ = std::make_unique<radiometry::AnalyticSky>(
            state.sun.direction, state.sun.illuminance_lux, env.sky.turbidity);
        skySun_ = state.sun.direction;
        skySunLux_ = state.sun.illuminance_lux;
    }
    const radiometry::AnalyticSky& sky = *sky_;
    const glm::vec3 sunDir(state.sun.direction);
    const glm::vec3 sunE(sky.SunIlluminance());
    const glm::vec3 sunL(sky.SunRadiance());
    const glm::vec3 skyE(sky.HorizontalSkyIlluminance());
    // Downwelling irradiance on the sea surface (lx): direct sun on a level surface plus sky.
    const glm::vec3 downwelling = sunE * std::max(sunDir.z, 0.0f) + skyE;
    const float cosSunRadius = float(std::cos(radiometry::kSunAngularRadius_rad));
    const float beta = float(ExtinctionFromVisibility(env.visibility_m));
    const float slopeVar = CoxMunkSlopeVariance(env.windSpeed_mps);
    static const radiometry::FresnelTable fresnel(radiometry::kSeaWaterIndexVisible);
    const glm::vec3 eye(cam.worldFromCamera.position_m);
    const bool shadows = settings_.shadows && !occlusion_.Empty() && sunDir.z > 0.0f;

    if (radiance.width != sw || radiance.height != sh || radiance.channels != 3)
        radiance = Image(sw, sh, 3);
    constexpr int kRowsPerBlock = 8;
    const int blocks = (sh + kRowsPerBlock - 1) / kRowsPerBlock;
    std::vector<uint64_t> blockRays(size_t(blocks), 0);
    // View rays: direction = normalize(rowBase + x · colStep) (camera axes scaled by the
    // pinhole geometry), so sky samples need no trigonometry.
    const glm::dmat3& R = cam.worldFromCamera.worldFromBody;
    const double tanH = cam.TanHalfH(), tanV = cam.TanHalfV();
    const glm::vec3 colStep(R * glm::dvec3(2.0 * tanH / sw, 0.0, 0.0));
    const glm::dvec3 forward = R * glm::dvec3(0.0, 1.0, 0.0);

    struct Scratch {
        std::vector<glm::vec3> position, normal, origins;
        std::vector<int> meshOf;
        std::vector<uint8_t> lit, vis;
        std::vector<uint32_t> originOwner;
    };
    tbb::enumerable_thread_specific<Scratch> scratch;

    tbb::parallel_for(0, blocks, [&](int block) {
        const int y0 = block * kRowsPerBlock, y1 = std::min(sh, y0 + kRowsPerBlock);
        const size_t n = size_t(y1 - y0) * size_t(sw);
        Scratch& sc = scratch.local();
        sc.position.resize(n);
        sc.normal.resize(n);
        sc.meshOf.assign(n, -1);
        sc.lit.assign(n, 1);
        sc.origins.clear();
        sc.originOwner.clear();
        std::vector<glm::vec3>& position = sc.position;
        std::vector<glm::vec3>& normal = sc.normal;
        std::vector<int>& meshOf = sc.meshOf;
        std::vector<uint8_t>& lit = sc.lit;
        std::vector<glm::vec3>& origins = sc.origins;
        std::vector<uint32_t>& originOwner = sc.originOwner;

        // Pass 1: surface position and normal of each sample; gather shadow-ray origins.
        for (size_t k = 0; k < n; ++k) {
            const int x = int(k % size_t(sw)), y = y0 + int(k / size_t(sw));
            const size_t idx = vis_.Index(x, y);
            const uint32_t prim = vis_.primitive[idx];
            if (prim == kNoPrimitive) continue;
            int mesh = 0;
            while (mesh + 1 < int(vis_.primitiveBase.size()) &&
                   prim >= vis_.primitiveBase[size_t(mesh) + 1])
                ++mesh;
            const uint32_t tri = prim - vis_.primitiveBase[size_t(mesh)];
            const std::vector<glm::vec3>& P =
                mesh == 0 ? ocean_.positions : worldMeshes_[size_t(mesh) - 1].positions;
            const std::vector<glm::vec3>& N =
                mesh == 0 ? ocean_.normals : worldMeshes_[size_t(mesh) - 1].normals;
            const std::vector<uint32_t>& I =
                mesh == 0 ? ocean_.indices : worldMeshes_[size_t(mesh) - 1].indices;
            const uint32_t i0 = I[3 * tri], i1 = I[3 * tri + 1], i2 = I[3 * tri + 2];
            const float b1 = vis_.b1[idx], b2 = vis_.b2[idx], b0 = 1.0f - b1 - b2;
            position[k] = b0 * P[i0] + b1 * P[i1] + b2 * P[i2];
            glm::vec3 nrm = glm::normalize(b0 * N[i0] + b1 * N[i1] + b2 * N[i2]);
            if (glm::dot(nrm, eye - position[k]) < 0.0f && mesh != 0) nrm = -nrm;
            normal[k] = nrm;
            meshOf[k] = mesh;
            if (shadows) {
                // Offset along the normal by a range-proportional amount against self-shadowing.
                const float range = glm::length(eye - position[k]);
                const glm::vec3 o = position[k] + nrm * (1e-3f * range + 1e-3f);
                if (occlusion_.MayOcclude(o, sunDir, 1e30f)) {
                    origins.push_back(o);
                    originOwner.push_back(uint32_t(k));
                }
            }
        }
        if (!origins.empty()) {
            std::vector<uint8_t>& vis = sc.vis;
            vis.resize(origins.size());
            occlusion_.DirectionalVisibility(origins, sunDir, 0.0f, vis);
            for (size_t r = 0; r < origins.size(); ++r) lit[originOwner[r]] = vis[r];
            blockRays[size_t(block)] = origins.size();
        }

        glm::vec3 rowBase[kRowsPerBlock];
        for (int y = y0; y < y1; ++y) {
            const double ndcY = 1.0 - 2.0 * (y + 0.5) / sh;
            rowBase[y - y0] = glm::vec3(forward + R * glm::dvec3(-tanH, 0.0, ndcY * tanV));
        }

        // Pass 2: radiance.
        for (size_t k = 0; k < n; ++k) {
            const int x = int(k % size_t(sw)), y = y0 + int(k / size_t(sw));
            float* out = radiance.At(x, y);
            glm::vec3 L;
            if (meshOf[k] < 0) {
                const glm::vec3 d =
                    glm::normalize(rowBase[size_t(y - y0)] + (float(x) + 0.5f) * colStep);
                L = sky.LookUp(d);
                if (glm::dot(d, sunDir) >= cosSunRadius) L += sunL;
            } else {
                const glm::vec3 p = position[k], nrm = normal[k];
                const glm::vec3 toEye = eye - p;
                const float range = glm::length(toEye);
                const glm::vec3 v = toEye / range;
                const float sunVis = float(lit[k]);
                if (meshOf[k] == 0) {
                    const float cosV = std::max(glm::dot(nrm, v), 1e-3f);
                    glm::vec3 r = 2.0f * glm::dot(nrm, v) * nrm - v;
                    if (r.z < 0.0f)
                        r.z = -r.z;  // a ray reflected into the sea meets the next wave's sky
                    const float F = fresnel(cosV);
                    L = F * sky.LookUp(r) + (1.0f - F) * kSeaRrs * downwelling;
                    // Cox–Munk glint: L = E_sun ρ(ω) p(β) / (4 cos θ_v cos⁴ β) (Cox & Munk
                    // 1954), β the tilt of the reflecting facet from the local normal.
                    const float cosS = glm::dot(nrm, sunDir);
                    const glm::vec3 h = glm::normalize(v + sunDir);
                    const float cosB = std::max(glm::dot(h, nrm), 1e-3f);
                    const float cos2 = cosB * cosB;
                    const float tan2 = (1.0f - cos2) / cos2;
                    // Beyond e^-60 the glint is below float precision next to the sky term.
                    if (cosS > 0.0f && sunVis > 0.0f && tan2 < 60.0f * slopeVar) {
                        const float p = std::exp(-tan2 / slopeVar) / (float(M_PI) * slopeVar);
                        const float Fs = fresnel(glm::dot(v, h));
                        L += sunE * (Fs * p / (4.0f * cosV * cos2 * cos2)) * sunVis;
                    }
                } else {
                    const glm::vec3 rho(reflectance_[size_t(meshOf[k]) - 1]);
                    const glm::vec3 E = sunE * std::max(glm::dot(nrm, sunDir), 0.0f) * sunVis +
                                        skyE * (0.5f * (1.0f + nrm.z)) +
                                        kSeaAlbedo * downwelling * (0.5f * (1.0f - nrm.z));
                    L = rho * E * float(1.0 / M_PI);
                }
                // Koschmieder: the horizon sky is the airlight a long path converges to.
                const float t = std::exp(-beta * range);
                const glm::vec3 horizon = sky.HorizonLookUp(-v);
                L = L * t + horizon * (1.0f - t);
            }
            out[0] = L.r;
            out[1] = L.g;
            out[2] = L.b;
        }
    });
    for (uint64_t r : blockRays) stats_.shadowRays += r;
    stats_.shadeMs = Ms(t2, Clock::now());
}

}  // namespace seasense::channels
