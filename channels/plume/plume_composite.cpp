// Plume compositing for the OTW and FLIR channels: screen bounds, per-pixel traces and the
// source functions of scattered and emitted light.
#include "channels/plume/plume_composite.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>

#include "channels/flir/flir_channel.h"
#include "radiometry/atmosphere/atmosphere.h"
#include "radiometry/bands/builtin_bands.h"
#include "radiometry/color/rec709.h"
#include "scene/core/check.h"

namespace seasense::channels {

namespace {

constexpr float kPi = std::numbers::pi_v<float>;

// Albedo of the sea for light reflected up (Payne, J. Atmos. Sci. 29 (1972) 959: ≈ 0.06).
constexpr float kSeaAlbedo = 0.06f;

constexpr double kGlowMinT_K = 500.0, kGlowMaxT_K = 3000.0, kGlowStep_K = 10.0;

// Interpolation grid: pixels whose surfaces all lie beyond the plumes take their trace from
// the sky traces at the corners of their kCell × kCell cell, blended bilinearly, when the
// corners' optical depths differ by at most kInterpolationTolerance and their temperatures by
// at most kInterpolationTolerance_K; other pixels are traced one by one.
constexpr int kCell = 4;
constexpr float kInterpolationTolerance = 0.02f;
constexpr float kInterpolationTolerance_K = 10.0f;
// A pixel whose samples' surface ranges differ by more than this ratio traces a second ray.
constexpr float kDepthEdgeRatio = 1.1f;

// A screen rectangle of output pixels [x0, x1) × [y0, y1).
struct PixelRect {
    int x0, y0, x1, y1;
};

// Screen rectangle (output pixels) of the world box [lo, hi], widened by one pixel; the whole
// screen when a corner lies behind the near plane; empty (x0 ≥ x1) when the box is behind.
PixelRect ProjectBox(const ChannelCamera& cam, const glm::dvec3& lo, const glm::dvec3& hi) {
    const PixelRect full{0, 0, cam.width, cam.height};
    const glm::dmat3 cameraFromWorld = glm::transpose(cam.worldFromCamera.worldFromBody);
    const glm::dvec3 eye = cam.worldFromCamera.position_m;
    const double tanH = cam.TanHalfH(), tanV = cam.TanHalfV();
    double xMin = 1e300, xMax = -1e300, yMin = 1e300, yMax = -1e300;
    int behind = 0;
    for (int c = 0; c < 8; ++c) {
        const glm::dvec3 p{c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z};
        const glm::dvec3 q = cameraFromWorld * (p - eye);  // x right, y forward, z up
        if (q.y < cam.near_m) {
            ++behind;
            continue;
        }
        const double x = (q.x / (q.y * tanH) + 1.0) * 0.5 * cam.width;
        const double y = (1.0 - q.z / (q.y * tanV)) * 0.5 * cam.height;
        xMin = std::min(xMin, x), xMax = std::max(xMax, x);
        yMin = std::min(yMin, y), yMax = std::max(yMax, y);
    }
    if (behind == 8) return {0, 0, 0, 0};
    if (behind > 0) return full;
    const auto clampX = [&](double v) { return int(std::clamp(v, 0.0, double(cam.width))); };
    const auto clampY = [&](double v) { return int(std::clamp(v, 0.0, double(cam.height))); };
    return {clampX(std::floor(xMin) - 1.0), clampY(std::floor(yMin) - 1.0),
            clampX(std::ceil(xMax) + 1.0), clampY(std::ceil(yMax) + 1.0)};
}

// A plume's screen rectangle and the range (m) from the eye to the nearest and farthest point
// of its box.
struct PlumeBounds {
    PixelRect rect;
    float near_m, far_m;
};

std::vector<PlumeBounds> PlumeScreenBounds(const scene::PlumeField& field,
                                           const ChannelCamera& cam) {
    const scene::PlumeField::PuffArrays puffs = field.Puffs();
    const size_t plumes = field.PlumeCount();
    std::vector<glm::dvec3> lo(plumes, glm::dvec3(1e300)), hi(plumes, glm::dvec3(-1e300));
    for (size_t i = 0; i < puffs.x.size(); ++i) {
        const double rh = scene::kPuffCutoffSigmas / std::sqrt(double(puffs.invVarH[i]));
        const double rz = scene::kPuffCutoffSigmas / std::sqrt(double(puffs.invVarZ[i]));
        const glm::dvec3 c{puffs.x[i], puffs.y[i], puffs.z[i]}, r{rh, rh, rz};
        const uint32_t p = puffs.plume[i];
        lo[p] = glm::min(lo[p], c - r);
        hi[p] = glm::max(hi[p], c + r);
    }
    const glm::dvec3 eye = cam.worldFromCamera.position_m;
    std::vector<PlumeBounds> bounds;
    for (size_t p = 0; p < plumes; ++p) {
        if (lo[p].x > hi[p].x) continue;
        const PixelRect r = ProjectBox(cam, lo[p], hi[p]);
        if (r.x0 >= r.x1 || r.y0 >= r.y1) continue;
        const double nearest = glm::length(glm::clamp(eye, lo[p], hi[p]) - eye);
        double farthest = 0.0;
        for (int c = 0; c < 8; ++c) {
            const glm::dvec3 q{c & 1 ? hi[p].x : lo[p].x, c & 2 ? hi[p].y : lo[p].y,
                               c & 4 ? hi[p].z : lo[p].z};
            farthest = std::max(farthest, glm::length(q - eye));
        }
        // Float margins: a little nearer and farther than the box.
        bounds.push_back({r, float(nearest * 0.999), float(farthest * 1.001 + 1.0)});
    }
    return bounds;
}

// Bilinear blend of four traces (corners 00, 10, 01, 11) at fractions fx, fy: optical depths
// blend linearly; albedo, temperature and asymmetry as optical-depth weighted means.
scene::PlumeTrace Bilinear(const scene::PlumeTrace& t00, const scene::PlumeTrace& t10,
                           const scene::PlumeTrace& t01, const scene::PlumeTrace& t11, float fx,
                           float fy) {
    const float w[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
    const scene::PlumeTrace* t[4] = {&t00, &t10, &t01, &t11};
    scene::PlumeTrace out;
    for (int b = 0; b < scene::kObscurantBands; ++b) {
        float tau = 0.0f, albedo = 0.0f, temperature = 0.0f, absorbing = 0.0f;
        for (int k = 0; k < 4; ++k) {
            const float wt = w[k] * t[k]->opticalDepth[size_t(b)];
            tau += wt;
            albedo += wt * t[k]->albedo[size_t(b)];
            const float wa = wt * (1.0f - t[k]->albedo[size_t(b)]);
            temperature += wa * t[k]->temperature_K[size_t(b)];
            absorbing += wa;
        }
        out.opticalDepth[size_t(b)] = tau;
        out.albedo[size_t(b)] = tau > 0.0f ? albedo / tau : 0.0f;
        out.temperature_K[size_t(b)] = absorbing > 0.0f ? temperature / absorbing : 0.0f;
        float hot = 0.0f, hotT = 0.0f;
        for (int k = 0; k < 4; ++k) {
            const float wh = w[k] * t[k]->opticalDepth[size_t(b)] *
                             (1.0f - t[k]->albedo[size_t(b)]) * t[k]->hotFraction[size_t(b)];
            hot += wh;
            hotT += wh * t[k]->hotTemperature_K[size_t(b)];
        }
        out.hotFraction[size_t(b)] = absorbing > 0.0f ? std::min(hot / absorbing, 1.0f) : 0.0f;
        out.hotTemperature_K[size_t(b)] = hot > 0.0f ? hotT / hot : 0.0f;
    }
    float g = 0.0f, scattering = 0.0f;
    for (int k = 0; k < 4; ++k) {
        const float ws = w[k] * t[k]->opticalDepth[0] * t[k]->albedo[0];
        g += ws * t[k]->asymmetry;
        scattering += ws;
    }
    out.asymmetry = scattering > 0.0f ? g / scattering : 0.0f;
    return out;
}

// Absorption-weighted emission of the trace's puffs in band b: the hot (flame) part and the
// rest each at their own mean temperature. emit(T) is the band's blackbody radiance.
template <class Emission>
auto ThermalEmission(const scene::PlumeTrace& t, size_t b, const Emission& emit) {
    const float h = t.hotFraction[b];
    const float T = t.temperature_K[b], Thot = t.hotTemperature_K[b];
    decltype(emit(T)) sum = emit(0.0f) * 0.0f;
    if (h > 0.0f && Thot > 0.0f) sum = sum + emit(Thot) * h;
    if (h < 1.0f && T > 0.0f) {
        // T = (1 − h) T_rest + h T_hot.
        const float rest = std::max((T - h * Thot) / (1.0f - h), 0.0f);
        if (rest > 0.0f) sum = sum + emit(rest) * (1.0f - h);
    }
    return sum;
}

glm::vec3 VisibleSource(const scene::PlumeTrace& t, const glm::vec3& toEye,
                        const PlumeLighting& light) {
    constexpr size_t kVis = size_t(scene::ObscurantBand::Visible);
    const float omega = t.albedo[kVis];
    // Light from the sun travels along −sunDirection, light to the eye along toEye.
    const float cosTheta = -glm::dot(light.sunDirection, toEye);
    glm::vec3 S = omega * (light.sunIlluminance * HenyeyGreensteinPhase(cosTheta, t.asymmetry) +
                           light.ambientRgb);
    if (light.glow)
        S += (1.0f - omega) *
             ThermalEmission(t, kVis, [&](float T_K) { return (*light.glow)(T_K); });
    return S;
}

float InfraredSource(const scene::PlumeTrace& t, const PlumeLighting& light) {
    const size_t b = size_t(light.band);
    const float omega = t.albedo[b];
    return omega * light.ambient + (1.0f - omega) * ThermalEmission(t, b, [&](float T_K) {
                                       return T_K > 0.0f ? float(light.planck->Radiance(T_K))
                                                         : 0.0f;
                                   });
}

}  // namespace

float HenyeyGreensteinPhase(float cosTheta, float g) {
    const float denom = 1.0f + g * g - 2.0f * g * cosTheta;
    return (1.0f - g * g) / (4.0f * kPi * denom * std::sqrt(denom));
}

BlackbodyGlowTable::BlackbodyGlowTable() {
    const radiometry::Band X = radiometry::CieX(), Y = radiometry::CieY(), Z = radiometry::CieZ();
    // 683 lm/W: the luminous efficacy at 540 THz that defines the candela (SI, 16th CGPM 1979).
    constexpr double kLumensPerWatt = 683.0;
    for (double T = kGlowMinT_K; T <= kGlowMaxT_K + 1e-9; T += kGlowStep_K) {
        const glm::dvec3 xyz = kLumensPerWatt * glm::dvec3(radiometry::BandRadiance(X, T),
                                                           radiometry::BandRadiance(Y, T),
                                                           radiometry::BandRadiance(Z, T));
        // Out-of-gamut (too red for Rec.709) components are clipped to zero.
        rgb_.push_back(glm::vec3(glm::max(radiometry::Rec709FromXyz(xyz), glm::dvec3(0.0))));
    }
}

glm::vec3 BlackbodyGlowTable::operator()(float T_K) const {
    const double u = (double(T_K) - kGlowMinT_K) / kGlowStep_K;
    if (!(u >= 0.0)) return glm::vec3(0.0f);
    if (u >= double(rgb_.size() - 1)) return rgb_.back();
    const size_t i = size_t(u);
    const float f = float(u - double(i));
    return rgb_[i] * (1.0f - f) + rgb_[i + 1] * f;
}

PlumeCompositeStats CompositePlumes(const scene::PlumeField& field, const ChannelCamera& camera,
                                    const VisibilityBuffer& vis, const PlumeLighting& light,
                                    Image& radiance) {
    const auto start = std::chrono::steady_clock::now();
    PlumeCompositeStats stats;
    const bool visible = light.kind == PlumeLighting::Kind::Visible;
    const int N = camera.supersampling, W = camera.width, H = camera.height;
    CHECK(radiance.width == camera.SampleWidth() && radiance.height == camera.SampleHeight() &&
          radiance.channels == (visible ? 3 : 1));
    CHECK(vis.width == camera.SampleWidth() && vis.height == camera.SampleHeight());
    CHECK(visible || light.planck);
    if (field.PuffCount() == 0) return stats;
    const std::vector<PlumeBounds> bounds = PlumeScreenBounds(field, camera);
    if (bounds.empty()) return stats;

    const glm::vec3 eye(camera.worldFromCamera.position_m);
    const glm::vec3 forward(camera.worldFromCamera.worldFromBody * glm::dvec3(0.0, 1.0, 0.0));
    const float nearM = float(camera.near_m);
    const size_t band = size_t(visible ? int(scene::ObscurantBand::Visible) : int(light.band));
    const size_t samples = size_t(N) * size_t(N);
    const auto PixelDirection = [&](double px, double py) {
        return glm::vec3(camera.SampleDirection(px * N + 0.5 * (N - 1), py * N + 0.5 * (N - 1)));
    };
    // Composites one sample with trace t seen along dir.
    const auto Apply = [&](const scene::PlumeTrace& t, const glm::vec3& dir, int px, int py,
                           const float* range, float rMin, float rMax,
                           const scene::PlumeTrace* far) {
        const scene::PlumeTrace* traces[2] = {&t, far ? far : &t};
        float T[2], Sir[2] = {0.0f, 0.0f};
        glm::vec3 Svis[2];
        for (int k = 0; k < (far ? 2 : 1); ++k) {
            T[k] = std::exp(-traces[k]->opticalDepth[band]);
            if (visible)
                Svis[k] = VisibleSource(*traces[k], -dir, light);
            else
                Sir[k] = InfraredSource(*traces[k], light);
        }
        for (int j = 0; j < N; ++j) {
            for (int i = 0; i < N; ++i) {
                const float r = range[size_t(j * N + i)];
                const int k = far && (r - rMin > rMax - r) ? 1 : 0;
                if (!(traces[k]->opticalDepth[band] > 0.0f)) continue;
                float* o = radiance.At(px * N + i, py * N + j);
                if (visible) {
                    for (int c = 0; c < 3; ++c)
                        o[c] = CompositeThroughPlume(o[c], T[k], Svis[k][c]);
                } else {
                    o[0] = CompositeThroughPlume(o[0], T[k], Sir[k]);
                }
            }
        }
    };

    // Nodes of the interpolation grid: the centres of every kCell-th pixel, traced to the sky.
    const int nodesX = (W + kCell - 1) / kCell + 1, nodesY = (H + kCell - 1) / kCell + 1;
    const int cellsX = nodesX - 1, cellsY = nodesY - 1;
    const auto CellBounds = [&](int cx, int cy, float& dNear, float& dFar) {
        dNear = kPlumeSkyRange_m, dFar = 0.0f;
        const int x0 = cx * kCell, y0 = cy * kCell;
        bool any = false;
        for (const PlumeBounds& b : bounds) {
            if (b.rect.x1 <= x0 || b.rect.x0 >= x0 + kCell || b.rect.y1 <= y0 ||
                b.rect.y0 >= y0 + kCell)
                continue;
            dNear = std::min(dNear, b.near_m), dFar = std::max(dFar, b.far_m);
            any = true;
        }
        return any;
    };
    std::vector<uint8_t> nodeNeeded(size_t(nodesX) * size_t(nodesY), 0);
    for (int cy = 0; cy < cellsY; ++cy)
        for (int cx = 0; cx < cellsX; ++cx) {
            float dNear, dFar;
            if (!CellBounds(cx, cy, dNear, dFar)) continue;
            for (int k = 0; k < 4; ++k)
                nodeNeeded[size_t(cy + k / 2) * size_t(nodesX) + size_t(cx + k % 2)] = 1;
        }
    // Cells that a puff smaller than a cell (σ under kCell pixels) touches are traced pixel by
    // pixel: the corner nodes could miss it.
    std::vector<uint8_t> cellFine(size_t(cellsX) * size_t(cellsY), 0);
    {
        const scene::PlumeField::PuffArrays puffs = field.Puffs();
        const glm::dmat3 cameraFromWorld = glm::transpose(camera.worldFromCamera.worldFromBody);
        const double tanH = camera.TanHalfH(), tanV = camera.TanHalfV();
        const double pixelAngle = 2.0 * tanH / W;
        for (size_t i = 0; i < puffs.x.size(); ++i) {
            const glm::dvec3 q = cameraFromWorld * (glm::dvec3(puffs.x[i], puffs.y[i], puffs.z[i]) -
                                                    camera.worldFromCamera.position_m);
            if (q.y <= camera.near_m) continue;
            const double sh = 1.0 / std::sqrt(double(puffs.invVarH[i]));
            const double sz = 1.0 / std::sqrt(double(puffs.invVarZ[i]));
            const double perPixel = 1.0 / (q.y * pixelAngle);
            if (std::min(sh, sz) * perPixel >= kCell) continue;
            const double reach = scene::kPuffCutoffSigmas * std::max(sh, sz) * perPixel + 1.0;
            const double x = (q.x / (q.y * tanH) + 1.0) * 0.5 * W;
            const double y = (1.0 - q.z / (q.y * tanV)) * 0.5 * H;
            const int cx0 = std::max(0, int(std::floor((x - reach) / kCell)));
            const int cx1 = std::min(cellsX - 1, int(std::floor((x + reach) / kCell)));
            const int cy0 = std::max(0, int(std::floor((y - reach) / kCell)));
            const int cy1 = std::min(cellsY - 1, int(std::floor((y + reach) / kCell)));
            for (int cy = cy0; cy <= cy1; ++cy)
                for (int cx = cx0; cx <= cx1; ++cx)
                    cellFine[size_t(cy) * size_t(cellsX) + size_t(cx)] = 1;
        }
    }
    std::vector<scene::PlumeTrace> nodes(nodeNeeded.size());
    std::vector<uint64_t> rowCovered(size_t(cellsY), 0), rowTraces(size_t(cellsY), 0);
    std::vector<uint64_t> nodeTraces(size_t(nodesY), 0);
    tbb::parallel_for(tbb::blocked_range<int>(0, nodesY, 1), [&](const tbb::blocked_range<int>& r) {
        for (int ny = r.begin(); ny != r.end(); ++ny)
            for (int nx = 0; nx < nodesX; ++nx) {
                const size_t n = size_t(ny) * size_t(nodesX) + size_t(nx);
                if (!nodeNeeded[n]) continue;
                nodes[n] =
                    field.Trace(eye, PixelDirection(nx * kCell, ny * kCell), kPlumeSkyRange_m);
                ++nodeTraces[size_t(ny)];
            }
    });

    // Cells in parallel (a row of cells each); each pixel depends only on its own rays and the
    // cell's corner nodes.
    tbb::parallel_for(
        tbb::blocked_range<int>(0, cellsY, 1), [&](const tbb::blocked_range<int>& rows) {
            std::vector<float> range(samples);
            for (int cy = rows.begin(); cy != rows.end(); ++cy) {
                for (int cx = 0; cx < cellsX; ++cx) {
                    float dNear, dFar;
                    if (!CellBounds(cx, cy, dNear, dFar)) continue;
                    const scene::PlumeTrace* corner[4];
                    for (int k = 0; k < 4; ++k)
                        corner[k] =
                            &nodes[size_t(cy + k / 2) * size_t(nodesX) + size_t(cx + k % 2)];
                    // The corners agree: bilinear interpolation of the sky traces is accurate.
                    float lo = corner[0]->opticalDepth[band], hi = lo;
                    float tLo = corner[0]->temperature_K[band], tHi = tLo;
                    for (int k = 1; k < 4; ++k) {
                        lo = std::min(lo, corner[k]->opticalDepth[band]);
                        hi = std::max(hi, corner[k]->opticalDepth[band]);
                        tLo = std::min(tLo, corner[k]->temperature_K[band]);
                        tHi = std::max(tHi, corner[k]->temperature_K[band]);
                    }
                    const bool smooth = !cellFine[size_t(cy) * size_t(cellsX) + size_t(cx)] &&
                                        hi - lo <= kInterpolationTolerance &&
                                        tHi - tLo <= kInterpolationTolerance_K;
                    for (int py = cy * kCell; py < std::min(H, (cy + 1) * kCell); ++py) {
                        for (int px = cx * kCell; px < std::min(W, (cx + 1) * kCell); ++px) {
                            bool covered = false;
                            for (const PlumeBounds& b : bounds)
                                covered |= px >= b.rect.x0 && px < b.rect.x1 && py >= b.rect.y0 &&
                                           py < b.rect.y1;
                            if (!covered) continue;
                            ++rowCovered[size_t(cy)];
                            const glm::vec3 dir = PixelDirection(px, py);
                            const float cosForward = std::max(glm::dot(dir, forward), 1e-6f);
                            float rMin = kPlumeSkyRange_m, rMax = 0.0f;
                            for (int j = 0; j < N; ++j) {
                                for (int i = 0; i < N; ++i) {
                                    const size_t idx = vis.Index(px * N + i, py * N + j);
                                    // depth = near / w, w the distance along the optical axis.
                                    const float r =
                                        vis.primitive[idx] == kNoPrimitive || vis.depth[idx] <= 0.0f
                                            ? kPlumeSkyRange_m
                                            : std::min(nearM / vis.depth[idx] / cosForward,
                                                       kPlumeSkyRange_m);
                                    range[size_t(j * N + i)] = r;
                                    rMin = std::min(rMin, r), rMax = std::max(rMax, r);
                                }
                            }
                            // Every surface in front of the plumes: nothing to add.
                            if (rMax <= dNear) continue;
                            if (rMin >= dFar) {
                                // Every surface behind the plumes: the sky trace is the trace.
                                if (smooth) {
                                    const float fx = float(px - cx * kCell) / kCell;
                                    const float fy = float(py - cy * kCell) / kCell;
                                    const scene::PlumeTrace t = Bilinear(
                                        *corner[0], *corner[1], *corner[2], *corner[3], fx, fy);
                                    Apply(t, dir, px, py, range.data(), rMin, rMax, nullptr);
                                } else {
                                    const scene::PlumeTrace t =
                                        field.Trace(eye, dir, kPlumeSkyRange_m);
                                    ++rowTraces[size_t(cy)];
                                    Apply(t, dir, px, py, range.data(), rMin, rMax, nullptr);
                                }
                                continue;
                            }
                            const scene::PlumeTrace nearTrace = field.Trace(eye, dir, rMin);
                            ++rowTraces[size_t(cy)];
                            // Depth edge: the far samples see what lies beyond the near surface.
                            if (rMax > rMin * kDepthEdgeRatio) {
                                const scene::PlumeTrace farTrace = field.Trace(eye, dir, rMax);
                                ++rowTraces[size_t(cy)];
                                Apply(nearTrace, dir, px, py, range.data(), rMin, rMax, &farTrace);
                            } else {
                                Apply(nearTrace, dir, px, py, range.data(), rMin, rMax, nullptr);
                            }
                        }
                    }
                }
            }
        });
    for (int y = 0; y < cellsY; ++y) {
        stats.pixelsCovered += rowCovered[size_t(y)];
        stats.traces += rowTraces[size_t(y)];
    }
    for (uint64_t n : nodeTraces) stats.traces += n;
    stats.ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return stats;
}

glm::vec3 VisibleAmbientRadiance(const radiometry::AnalyticSky& sky) {
    constexpr int kMu = 16, kPhi = 32;
    std::vector<float> x, y, z;
    for (int m = 0; m < kMu; ++m) {
        const double mu = (m + 0.5) / kMu, s = std::sqrt(1.0 - mu * mu);
        for (int p = 0; p < kPhi; ++p) {
            const double phi = 2.0 * std::numbers::pi * (p + 0.5) / kPhi;
            x.push_back(float(s * std::sin(phi)));
            y.push_back(float(s * std::cos(phi)));
            z.push_back(float(mu));
        }
    }
    std::vector<float> r(x.size()), g(x.size()), b(x.size());
    sky.LookUp(x.size(), x.data(), y.data(), z.data(), r.data(), g.data(), b.data());
    glm::dvec3 upper(0.0);
    for (size_t i = 0; i < x.size(); ++i) upper += glm::dvec3(r[i], g[i], b[i]);
    upper /= double(x.size());
    const glm::dvec3 sunDir = sky.SunDirection();
    const glm::dvec3 down =
        sky.SunIlluminance() * std::max(sunDir.z, 0.0) + sky.HorizontalSkyIlluminance();
    const glm::dvec3 lower = double(kSeaAlbedo) * down / std::numbers::pi;
    return glm::vec3(0.5 * (upper + lower));
}

ChannelPlumes::ChannelPlumes(const scene::World& world) {
    const scene::Scenario& sc = world.GetScenario();
    if (sc.plumes.sources.empty()) return;
    scene::PlumesSettings settings = sc.plumes;
    if (!settings.airTemperatureGiven && sc.environment.atmosphere)
        settings.airTemperature_K =
            radiometry::ParseAtmosphereSettings(*sc.environment.atmosphere).airTemperature_K;
    scene::PlumeAmbient ambient;
    ambient.windSpeed_mps = sc.environment.windSpeed_mps;
    ambient.windDirection_rad = sc.environment.windDirection_rad;
    ambient.sunElevation_rad = world.Advance(0).sun.elevation_rad;
    // Pasquill–Turner stability follows the total cover (random overlap of the layers).
    ambient.cloudCover = world.Clouds() ? world.Clouds()->TotalCoverage() : 0.0;
    system_ = std::make_unique<scene::PlumeSystem>(settings, ambient);
    field_ = system_->MakeField();
}

const scene::PlumeField& ChannelPlumes::FieldAt(double time_s) {
    CHECK(system_);
    if (!(committed_s_ == time_s)) {
        system_->Commit(time_s, field_);
        committed_s_ = time_s;
    }
    return field_;
}

void ChannelPlumes::CompositeOtw(const scene::SceneState& state, const ChannelCamera& camera,
                                 const VisibilityBuffer& vis, const radiometry::AnalyticSky& sky,
                                 Image& radiance) {
    if (!Active()) return;
    const auto start = std::chrono::steady_clock::now();
    if (!glow_) glow_ = std::make_unique<BlackbodyGlowTable>();
    PlumeLighting light;
    light.kind = PlumeLighting::Kind::Visible;
    light.sunDirection = glm::vec3(state.sun.direction);
    light.sunIlluminance =
        state.sun.direction.z > 0.0 ? glm::vec3(sky.SunIlluminance()) : glm::vec3(0.0f);
    light.ambientRgb = VisibleAmbientRadiance(sky);
    light.glow = glow_.get();
    const scene::PlumeField& field = FieldAt(state.time_s);
    stats_ = CompositePlumes(field, camera, vis, light, radiance);
    stats_.ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

void ChannelPlumes::CompositeFlir(const scene::SceneState& state, const ChannelCamera& camera,
                                  const VisibilityBuffer& vis, const FlirChannel& channel,
                                  Image& radiance) {
    if (!Active()) return;
    const auto start = std::chrono::steady_clock::now();
    const radiometry::Band& band = channel.GetBand();
    PlumeLighting light;
    light.kind = PlumeLighting::Kind::Infrared;
    // The obscurant band nearest the channel's: MWIR below 6 µm, LWIR above.
    light.band = 0.5 * (band.MinWavelength_m() + band.MaxWavelength_m()) < 6e-6
                     ? scene::ObscurantBand::Mwir
                     : scene::ObscurantBand::Lwir;
    light.planck = &channel.RadianceTable();
    // Solid-angle mean of the sky (uniform in cos zenith, midpoints) and of the sea (band
    // emissivity at 60° from the normal, the hemisphere's solid-angle median, with the sky
    // reflected).
    const radiometry::Atmosphere& air = channel.GetAtmosphere();
    constexpr int kMu = 32;
    double sky = 0.0;
    for (int m = 0; m < kMu; ++m) sky += air.SkyLookUp(float((m + 0.5) / kMu));
    sky /= kMu;
    const double eps = channel.SeaEmissivity().Emissivity(0.5f);
    const double sea =
        eps * channel.RadianceTable().Radiance(channel.SeaTemperature_K()) + (1.0 - eps) * sky;
    light.ambient = float(0.5 * (sky + sea));
    const scene::PlumeField& field = FieldAt(state.time_s);
    stats_ = CompositePlumes(field, camera, vis, light, radiance);
    stats_.ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace seasense::channels
