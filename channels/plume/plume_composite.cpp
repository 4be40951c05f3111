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

// Screen rectangles of the field's plumes (one per plume with puffs in front of the camera).
std::vector<PixelRect> PlumeRects(const scene::PlumeField& field, const ChannelCamera& cam) {
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
    std::vector<PixelRect> rects;
    for (size_t p = 0; p < plumes; ++p) {
        if (lo[p].x > hi[p].x) continue;
        const PixelRect r = ProjectBox(cam, lo[p], hi[p]);
        if (r.x0 < r.x1 && r.y0 < r.y1) rects.push_back(r);
    }
    return rects;
}

glm::vec3 VisibleSource(const scene::PlumeTrace& t, const glm::vec3& toEye,
                        const PlumeLighting& light) {
    constexpr int kVis = int(scene::ObscurantBand::Visible);
    const float omega = t.albedo[kVis];
    // Light from the sun travels along −sunDirection, light to the eye along toEye.
    const float cosTheta = -glm::dot(light.sunDirection, toEye);
    glm::vec3 S = omega * (light.sunIlluminance * HenyeyGreensteinPhase(cosTheta, t.asymmetry) +
                           light.ambientRgb);
    if (t.temperature_K[kVis] > 0.0f && light.glow)
        S += (1.0f - omega) * (*light.glow)(t.temperature_K[kVis]);
    return S;
}

float InfraredSource(const scene::PlumeTrace& t, const PlumeLighting& light) {
    const int b = int(light.band);
    const float omega = t.albedo[size_t(b)];
    float S = omega * light.ambient;
    if (t.temperature_K[size_t(b)] > 0.0f)
        S += (1.0f - omega) * float(light.planck->Radiance(t.temperature_K[size_t(b)]));
    return S;
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
    const int N = camera.supersampling, sw = camera.SampleWidth(), sh = camera.SampleHeight();
    CHECK(radiance.width == sw && radiance.height == sh && radiance.channels == (visible ? 3 : 1));
    CHECK(vis.width == sw && vis.height == sh);
    CHECK(visible || light.planck);
    if (field.PuffCount() == 0) return stats;
    const std::vector<PixelRect> rects = PlumeRects(field, camera);
    if (rects.empty()) return stats;

    const glm::vec3 eye(camera.worldFromCamera.position_m);
    const glm::vec3 forward(camera.worldFromCamera.worldFromBody * glm::dvec3(0.0, 1.0, 0.0));
    const float nearM = float(camera.near_m);
    const int band = visible ? int(scene::ObscurantBand::Visible) : int(light.band);
    const size_t samples = size_t(N) * size_t(N);

    // Rows of output pixels in parallel; each pixel depends only on its own rays.
    std::vector<uint64_t> rowCovered(size_t(camera.height), 0), rowTraces(size_t(camera.height), 0);
    tbb::parallel_for(
        tbb::blocked_range<int>(0, camera.height, 4), [&](const tbb::blocked_range<int>& rows) {
            std::vector<uint8_t> covered(size_t(camera.width));
            std::vector<float> range(samples);
            for (int py = rows.begin(); py != rows.end(); ++py) {
                std::fill(covered.begin(), covered.end(), uint8_t(0));
                bool any = false;
                for (const PixelRect& r : rects) {
                    if (py < r.y0 || py >= r.y1) continue;
                    std::fill(covered.begin() + r.x0, covered.begin() + r.x1, uint8_t(1));
                    any = true;
                }
                if (!any) continue;
                for (int px = 0; px < camera.width; ++px) {
                    if (!covered[size_t(px)]) continue;
                    ++rowCovered[size_t(py)];
                    const glm::vec3 dir(
                        camera.SampleDirection(px * N + 0.5 * (N - 1), py * N + 0.5 * (N - 1)));
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
                    const scene::PlumeTrace nearTrace = field.Trace(eye, dir, rMin);
                    ++rowTraces[size_t(py)];
                    // Depth edge: the far samples see what lies beyond the near surface.
                    const bool edge = rMax > rMin * 1.001f;
                    scene::PlumeTrace farTrace = nearTrace;
                    if (edge) {
                        farTrace = field.Trace(eye, dir, rMax);
                        ++rowTraces[size_t(py)];
                    }
                    if (!(nearTrace.opticalDepth[size_t(band)] > 0.0f) &&
                        !(farTrace.opticalDepth[size_t(band)] > 0.0f))
                        continue;
                    const scene::PlumeTrace* traces[2] = {&nearTrace, &farTrace};
                    float T[2];
                    glm::vec3 Svis[2];
                    float Sir[2];
                    for (int k = 0; k < (edge ? 2 : 1); ++k) {
                        T[k] = std::exp(-traces[k]->opticalDepth[size_t(band)]);
                        if (visible)
                            Svis[k] = VisibleSource(*traces[k], -dir, light);
                        else
                            Sir[k] = InfraredSource(*traces[k], light);
                    }
                    for (int j = 0; j < N; ++j) {
                        for (int i = 0; i < N; ++i) {
                            const float r = range[size_t(j * N + i)];
                            const int k = edge && (r - rMin > rMax - r) ? 1 : 0;
                            if (!(traces[k]->opticalDepth[size_t(band)] > 0.0f)) continue;
                            float* o = radiance.At(px * N + i, py * N + j);
                            if (visible) {
                                for (int c = 0; c < 3; ++c)
                                    o[c] = CompositeThroughPlume(o[c], T[k], Svis[k][c]);
                            } else {
                                o[0] = CompositeThroughPlume(o[0], T[k], Sir[k]);
                            }
                        }
                    }
                }
            }
        });
    for (int y = 0; y < camera.height; ++y) {
        stats.pixelsCovered += rowCovered[size_t(y)];
        stats.traces += rowTraces[size_t(y)];
    }
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
    ambient.cloudCover = 0.0;  // the scenario has no cloud cover yet
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
