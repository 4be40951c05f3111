// Camera-dependent sea mesh: a polar grid around the eye with world-fixed azimuths, sampling the
// surface band-limited to the local vertex spacing.
//
// Why a polar grid rather than clipmap rings or a projected grid. The sea is seen at grazing
// angles from low eyepoints (2 m: the horizon is 5 km away), where a patch of sea is compressed
// on screen radially by h/r relative to tangentially. A grid centred on the eye whose rings each
// subtend about the same angle gives a screen-uniform vertex density from the eye to the
// horizon: the spacing grows continuously with range (a continuous level of detail), so there
// are no level boundaries at all — nothing to stitch, no T-junctions, no cracks, and no level
// switches to pop (geomorphing has nothing to blend). Clipmap rings (Losasso & Hoppe 2004) keep
// square cells whose world size doubles per level; at a 2 m eye height their radial sampling is
// r/h times finer than the screen needs. For the same tangential density (a 640-pixel 60° view,
// vertices ~6 pixels apart, a 100° sector with margins) ten rings of 128 × 128 cells from 6 m to
// 5 km hold about 3 · 128² · 100/360 ≈ 14 k vertices each, ~140 k in all, against ~31 k for this
// grid (BM_OceanLodMesh) — and the CPU rasterizer pays per triangle. A projected grid (Johanson
// 2004) is screen-uniform too but its vertices move with every camera rotation and it handles the
// curved horizon poorly.
//
// The price of an eye-centred grid is that vertices move over the surface as the eye moves. The
// surface each vertex samples is therefore band-limited to the vertex spacing (the FFT cascades
// through box-filtered mip chains, Gerstner waves faded out before their Nyquist wavelength), so
// re-sampling a smooth field at shifted points changes it little: the distant sea does not
// shimmer. Rotation moves nothing: azimuths are multiples of 2π / circleSegments, fixed in the
// world, and the ring radii depend only on eye height, wave height and angular step, not on
// where the view looks; contiguous channels with equal angular steps get identical vertices.
//
// Work a vertex provably does not need is skipped, never changing a bit (OceanMeshRequest::
// shortcuts turns this off for the tests that compare): with a surf zone, rest positions
// seaward of OceanSurfaceFrame::OpenSeaFrom_m (most of a view from deep water) add the deep
// sea and the tide without the dry-land test, the surf terms or the seabed clamp's lookup; and
// rings whose Gerstner footprint weights are all 0 sum no Gerstner wave. Likewise the index
// buffer's corners are stepped along the rings instead of looked up by column.
#include "scene/ocean/ocean_mesh.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#include "scene/core/check.h"
#include "scene/surf/foam.h"

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

namespace {

// The eye's height above a typical trough (half the significant height), for foreshortening.
double TroughDepth_m(double eyeHeight_m, double significantHeight_m) {
    return std::max(eyeHeight_m, 0.05) + 0.5 * significantHeight_m;
}

// The ring step at range r for a surface H below the eye (see OceanMeshRadii), capped at 8× the
// tangential spacing, hEff the trough's depth.
double RingStep_m(double r, double H, double hEff, double dphi) {
    return std::min(dphi * (r * r + H * H) / H, std::max(8.0 * r, hEff) * dphi);
}

}  // namespace

std::vector<double> OceanMeshRadii(double eyeHeight_m, double significantHeight_m, double dphi,
                                   double maxRange_m) {
    CHECK(dphi > 0.0);
    const double hEff = TroughDepth_m(eyeHeight_m, significantHeight_m);
    std::vector<double> radii{0.0};  // a centre vertex under the eye
    // A ring at range r is seen at the depression angle atan(h / r), which changes by
    // h dr / (r² + h²): steps of dphi (r² + h²) / h subtend the angular step from the nadir to the
    // horizon (π/2 / dphi rings out to the grazing range), capped at 8× the tangential spacing
    // r dphi where grazing foreshortening would stretch the cells further.
    double r = hEff * dphi;
    while (r < maxRange_m) {
        radii.push_back(r);
        r += std::max(RingStep_m(r, hEff, hEff, dphi), 1e-3);
    }
    radii.push_back(maxRange_m);
    return radii;
}

double OceanMeshFootprintBound_m(double radius_m, double eyeHeight_m, double significantHeight_m,
                                 double angularStep_rad) {
    // (+ 1 mm: OceanMeshRadii's smallest step.)
    return std::max(8.0 * radius_m, TroughDepth_m(eyeHeight_m, significantHeight_m)) *
               angularStep_rad +
           1e-3;
}

std::vector<double> ThinnedOceanMeshRadii(const std::vector<double>& radii, double eyeHeight_m,
                                          double significantHeight_m, double dphi,
                                          double maxDepressionTan) {
    CHECK(dphi > 0.0 && maxDepressionTan > 0.0);
    const double hEff = TroughDepth_m(eyeHeight_m, significantHeight_m);
    std::vector<double> out;
    out.reserve(radii.size());
    for (size_t i = 0; i < radii.size();) {
        out.push_back(radii[i]);
        const double r = radii[i];
        size_t next = i + 1;
        // The largest visible H. (Where it exceeds r, the step below is shorter than
        // OceanMeshRadii's: (r² + H²) / H grows with H beyond r, and H < h; nothing is dropped.)
        const double H = std::min(hEff, r * maxDepressionTan);
        if (r > 0.0 && H < hEff) {
            // The step of OceanMeshRadii with H for h (a hair shorter, for its rounding).
            const double step = RingStep_m(r, H, hEff, dphi);
            while (next + 1 < radii.size() && radii[next + 1] <= r + step * (1.0 - 1e-12)) ++next;
        }
        i = next;
    }
    return out;
}

void BuildOceanMesh(const OceanSurfaceFrame& frame, const OceanMeshRequest& req, OceanMesh& out) {
    CHECK(req.angularStep_rad > 0.0);
    const double eyeHeight = std::max(req.eye_m.z, 0.05);
    // Crests up to the highest stay visible until the two horizon distances add up.
    const double maxRange =
        HorizonDistance_m(eyeHeight) + HorizonDistance_m(frame.MaxHeight_m()) + 100.0;
    if (!(req.minRange_m < maxRange)) {  // nothing visible (also catches NaN)
        out = OceanMesh{};
        return;
    }
    // World-fixed azimuths: a whole number of segments around the circle (for a view mesh a
    // multiple of kMaxColumnStride, so that every stride divides it).
    int circle = std::max(8, int(std::ceil(2.0 * M_PI / req.angularStep_rad)));
    if (req.widenByReach)
        circle = (circle + kMaxColumnStride - 1) / kMaxColumnStride * kMaxColumnStride;
    const double dphi = 2.0 * M_PI / circle;
    const bool sectorFull = req.azimuthMax_rad - req.azimuthMin_rad >= 2.0 * M_PI - 1e-9;
    if (!sectorFull) CHECK(req.azimuthMax_rad > req.azimuthMin_rad);

    // Rings: the fixed sequence, from the last ring at or inside the nearest visible range.
    std::vector<double> all =
        OceanMeshRadii(req.eye_m.z, frame.SignificantHeight_m(), dphi, maxRange);
    if (std::isfinite(req.maxDepressionTan))
        all = ThinnedOceanMeshRadii(all, req.eye_m.z, frame.SignificantHeight_m(), dphi,
                                    req.maxDepressionTan);
    size_t j0 = 0;
    while (j0 + 1 < all.size() && all[j0 + 1] <= req.minRange_m) ++j0;
    std::vector<double> radii(all.begin() + std::ptrdiff_t(j0), all.end());
    const int rings = int(radii.size());
    CHECK(rings >= 2);
    // Footprint of a ring: the larger of its tangential spacing and its radial spacing to
    // either neighbour in the full sequence (so it does not depend on the nearest range).
    std::vector<float> footprint(radii.size());
    for (size_t j = 0; j < radii.size(); ++j) {
        const size_t a = j + j0;
        const double inner = a > 0 ? all[a] - all[a - 1] : 0.0;
        const double outer = a + 1 < all.size() ? all[a + 1] - all[a] : inner;
        footprint[j] = float(std::max({all[a] * dphi, inner, outer}));
    }

    // Each band's columns [lo, hi) (world column indices; hi − lo ≥ circle: the whole circle),
    // then each ring's: the union of the two bands it bounds (they share the sector's centre).
    const auto sectorColumns = [&](double margin_rad, int64_t& lo, int64_t& hi) {
        if (sectorFull ||
            req.azimuthMax_rad - req.azimuthMin_rad + 2.0 * margin_rad >= 2.0 * M_PI - 1e-9) {
            lo = 0, hi = circle;
            return;
        }
        lo = int64_t(std::floor((req.azimuthMin_rad - margin_rad) / dphi));
        hi = int64_t(std::ceil((req.azimuthMax_rad + margin_rad) / dphi));
        if (hi - lo >= circle) lo = 0, hi = circle;
    };
    // Column stride per ring: near the eye a ring's columns are seen much closer together than
    // its radius times the azimuth step, since the eye looks down on them: two columns r · dphi
    // apart at rest radius r lie r · dphi / √(r² + h²) apart in view angle (h the eye's height
    // over the trough, as in OceanMeshRadii), so every s-th column, s ≤ √(1 + (h / r)²), keeps
    // them within the angular step. s is a power of two, at most kMaxColumnStride, and never
    // grows outward, so each coarse ring's columns are also the next ring's.
    std::vector<int> stride(size_t(rings), 1);
    if (req.widenByReach) {
        const double hEff = TroughDepth_m(req.eye_m.z, frame.SignificantHeight_m());
        for (int j = 0; j < rings; ++j) {
            const double r = radii[size_t(j)];
            const double allowed =
                r > 0.0 ? std::sqrt(1.0 + (hEff / r) * (hEff / r)) : double(kMaxColumnStride);
            int sj = 1;
            while (2 * sj <= kMaxColumnStride && 2.0 * sj <= allowed) sj *= 2;
            stride[size_t(j)] = j > 0 ? std::min(sj, stride[size_t(j) - 1]) : sj;
        }
    }
    std::vector<int64_t> bandLo(size_t(rings - 1)), bandHi(size_t(rings - 1));
    if (req.widenByReach) {
        // Displacement bounds over discs of radius 2^k m around the eye (k = 0 … 12, then the
        // whole sea): a band uses the smallest disc holding its outer ring (halving the radius
        // steps from 4^k kept 2-3 % of the five-channel views' vertices). Up to 64 m the
        // bounds of the waves near the eye (LocalBoundsNear: in the five-channel demo's surf zone
        // ~1.2 m against BoundsNear's ~1.9 m, which widened the rings within ~6 m of the eye by
        // the full 20°); farther discs cover whole cascade patches, where the local bound would
        // scan every texel for about the same value.
        std::vector<double> discR, discReach;
        for (double R = 1.0; R < 5000.0; R *= 2.0) {
            discR.push_back(R);
            // (The rings within R have footprints of at most OceanMeshFootprintBound_m: the
            // cascades' bound then takes only the mip levels those read.)
            discReach.push_back(
                R <= 64.0
                    ? frame
                          .LocalBoundsNear(req.eye_m.x, req.eye_m.y, R,
                                           OceanMeshFootprintBound_m(
                                               R, req.eye_m.z, frame.SignificantHeight_m(), dphi))
                          .horizontal_m
                    : frame.BoundsNear(req.eye_m.x, req.eye_m.y, R).horizontal_m);
        }
        discR.push_back(std::numeric_limits<double>::infinity());
        discReach.push_back(frame.MaxHorizontal_m());
        size_t k = 0;
        for (int j = 0; j + 1 < rings; ++j) {
            while (discR[k] < radii[size_t(j) + 1]) ++k;
            const double reach = discReach[k], r = radii[size_t(j)];
            // One column more on each side for the chords between columns; never more than
            // kMaxReachMargin_rad (see OceanMeshRequest::widenByReach).
            const double margin = r > reach
                                      ? std::min(std::asin(reach / r) + dphi, kMaxReachMargin_rad)
                                      : kMaxReachMargin_rad;
            int64_t& lo = bandLo[size_t(j)];
            int64_t& hi = bandHi[size_t(j)];
            sectorColumns(margin, lo, hi);
            // Whole segments of the band's inner (coarser) ring.
            const int64_t sj = stride[size_t(j)];
            lo = lo >= 0 ? lo / sj * sj : -((-lo + sj - 1) / sj * sj);
            hi = hi >= 0 ? (hi + sj - 1) / sj * sj : -(-hi / sj * sj);
            if (hi - lo >= circle) lo = 0, hi = circle;
        }
    } else {
        int64_t lo = 0, hi = 0;
        sectorColumns(0.0, lo, hi);
        std::fill(bandLo.begin(), bandLo.end(), lo);
        std::fill(bandHi.begin(), bandHi.end(), hi);
    }
    std::vector<uint32_t> ringStart(size_t(rings) + 1, 0);
    std::vector<int> ringFirst(size_t(rings), 0);
    int widest = 0;
    for (int j = 0; j < rings; ++j) {
        const size_t a = size_t(std::max(j - 1, 0)), b = size_t(std::min(j, rings - 2));
        const int64_t lo = std::min(bandLo[a], bandLo[b]), hi = std::max(bandHi[a], bandHi[b]);
        const int sj = stride[size_t(j)];
        // Columns all round (then stored as a whole circle, so that its count identifies it).
        const bool whole = hi - lo >= circle - sj;
        const int count = whole ? circle / sj : int(hi - lo) / sj + 1;
        ringFirst[size_t(j)] = whole ? 0 : int(lo);
        ringStart[size_t(j) + 1] = ringStart[size_t(j)] + uint32_t(count);
        if (count > widest) {
            widest = count;
            out.fullCircle = whole;
            out.segments = whole ? circle : count - 1;
            out.firstColumn = ringFirst[size_t(j)];
        }
    }
    // The index buffer depends only on the grid's shape, the rings' columns and the bands'
    // (a band may change while both its rings keep the columns a neighbouring band gives
    // them): rebuilt when that changes.
    const bool sameShape = out.rings == rings && out.circleSegments == circle &&
                           out.ringStart == ringStart && out.ringFirstColumn == ringFirst &&
                           out.ringStride == stride && out.bandLo == bandLo &&
                           out.bandHi == bandHi && !out.indices.empty();
    out.rings = rings;
    out.bandLo = bandLo;
    out.bandHi = bandHi;
    out.circleSegments = circle;
    out.ringStart = ringStart;
    out.ringFirstColumn = ringFirst;
    out.ringStride = stride;
    out.radii_m = radii;
    out.footprint_m = footprint;
    // Sine and cosine of every column any ring uses, from the leftmost.
    int64_t colLo = INT64_MAX, colHi = INT64_MIN;
    for (int j = 0; j < rings; ++j) {
        colLo = std::min<int64_t>(colLo, ringFirst[size_t(j)]);
        colHi =
            std::max<int64_t>(colHi, int64_t(ringFirst[size_t(j)]) +
                                         int64_t(ringStart[size_t(j) + 1] - ringStart[size_t(j)]) *
                                             stride[size_t(j)]);
    }
    std::vector<double> sinAz(size_t(colHi - colLo)), cosAz(size_t(colHi - colLo));
    for (int64_t c = colLo; c < colHi; ++c) {
        const double az = dphi * double(c);
        sinAz[size_t(c - colLo)] = std::sin(az);
        cosAz[size_t(c - colLo)] = std::cos(az);
    }
    out.positions.resize(ringStart.back());
    out.normals.resize(out.positions.size());
    out.jacobian.resize(out.positions.size());
    const GerstnerOcean::LocalFrame local =
        frame.Gerstner().Local(req.eye_m.x, req.eye_m.y, frame.Time_s());
    const size_t waveCount = frame.Gerstner().WaveCount();
    const bool gerstner = waveCount > 0;
    const bool surf = frame.Surf() != nullptr;
    // Seaward of this cross-shore distance a vertex is the deep sea's plus the tide.
    const double openSea =
        req.shortcuts ? frame.OpenSeaFrom_m() : std::numeric_limits<double>::infinity();
    if (surf)
        out.surfFoam.resize(out.positions.size());
    else
        out.surfFoam.clear();
    tbb::parallel_for(0, rings, [&](int j) {
        const double radius = radii[size_t(j)];
        const double drop = CurvatureDrop_m(radius);
        const float fp = footprint[size_t(j)];
        const FftFilter filter = frame.Filter(fp);
        std::array<float, kMaxWaves> gerstnerWeights;  // the ring's footprint weights
        local.FootprintWeights(fp, gerstnerWeights.data());
        // A ring whose footprint weights are all 0 (far rings: waves shorter than twice the
        // footprint) gets +0 in every Gerstner term (LocalFrame::Accumulate skips such waves),
        // and x + 0 (or + w · 0) is x for every x but −0, which the sums never hold: they start
        // at +0 and only ever add, and a rounded sum is −0 only when both addends are.
        const bool ringGerstner =
            gerstner &&
            (!req.shortcuts || std::any_of(gerstnerWeights.begin(),
                                           gerstnerWeights.begin() + std::ptrdiff_t(waveCount),
                                           [](float w) { return !(w <= 0.0f); }));
        const int columns = int(ringStart[size_t(j) + 1] - ringStart[size_t(j)]);
        const size_t c0 = size_t(ringFirst[size_t(j)] - colLo), sj = size_t(stride[size_t(j)]);
        const auto store = [&](size_t v, double rx, double ry, const GeometrySums& s) {
            out.positions[v] = glm::vec3(float(req.eye_m.x + rx + double(s[kTermDispX])),
                                         float(req.eye_m.y + ry + double(s[kTermDispY])),
                                         float(double(s[kTermHeight]) - drop));
            out.normals[v] = GeometryNormal(s);
            out.jacobian[v] = GeometryJacobian(s);
        };
        // The surf vertices are held until SurfWaves::kBatch of them have their surf terms
        // made at once (TermsBatch, the same bits as Terms at each: the surf path asks for no
        // velocity, the dominant component only where the foam reads it, no variance shares,
        // the seabed DryLandSums looked up); each vertex writes only its own outputs, so the
        // order they are finished in changes nothing.
        struct Pending {
            size_t v;
            double rx, ry;
        };
        std::array<Pending, SurfWaves::kBatch> pending;
        alignas(32) std::array<double, SurfWaves::kBatch> px, py, pz;
        size_t held = 0;
        const auto flush = [&] {
            if (held == 0) return;
            const SurfWaves& waves = *frame.Surf();
            std::array<SurfPointInfo, SurfWaves::kBatch> infos;
            std::array<SurfaceTerms, SurfWaves::kBatch> terms;
            waves.TermsBatch(px.data(), py.data(), pz.data(), held, frame.Time_s(), infos.data(),
                             terms.data());
            for (size_t b = 0; b < held; ++b) {
                const SurfPointInfo& info = infos[b];
                const double x0 = px[b], y0 = py[b];
                const float rx = float(pending[b].rx), ry = float(pending[b].ry);
                // Each part of the deep sea with its depth weight, then the surf components.
                GeometrySums s{};
                frame.AccumulateFft(x0, y0, filter, s, info.weights.cascade.data());
                const double wg = info.weights.gerstner;
                if (ringGerstner && wg == 1.0) {
                    local.Accumulate(rx, ry, gerstnerWeights.data(), s.data());
                } else if (ringGerstner && wg > 0.0) {
                    GeometrySums g{};
                    local.Accumulate(rx, ry, gerstnerWeights.data(), g.data());
                    for (int k = 0; k < kGeometryTerms; ++k)
                        s[size_t(k)] += float(wg) * g[size_t(k)];
                }
                frame.AddSurf(x0, y0, terms[b], s);
                out.surfFoam[pending[b].v] =
                    info.depth_m < waves.FadeDeep_m()
                        ? float(SurfFoamCoverage(info, x0, y0, frame.Time_s(),
                                                 waves.Bathy().Settings().foam))
                        : 0.0f;
                store(pending[b].v, pending[b].rx, pending[b].ry, s);
            }
            held = 0;
        };
        for (int i = 0; i < columns; ++i) {
            const double rx = radius * sinAz[c0 + sj * size_t(i)],
                         ry = radius * cosAz[c0 + sj * size_t(i)];
            const size_t v = size_t(ringStart[size_t(j)]) + size_t(i);
            GeometrySums s{};
            const double x0 = req.eye_m.x + rx, y0 = req.eye_m.y + ry;
            double seabedZ = 0.0;
            if (!surf || frame.Surf()->Bathy().Frame().ShoreFromWorld(x0, y0).s_m >= openSea) {
                frame.AccumulateFft(x0, y0, filter, s);
                if (ringGerstner)
                    local.Accumulate(float(rx), float(ry), gerstnerWeights.data(), s.data());
                if (surf) {
                    frame.AddOpenSea(s);
                    out.surfFoam[v] = 0.0f;  // deeper than FadeDeep_m
                }
            } else if (frame.DryLandSums(x0, y0, s, &seabedZ)) {
                out.surfFoam[v] = 0.0f;  // dry sand, never wet: no foam
            } else {
                pending[held] = {v, rx, ry};
                px[held] = x0, py[held] = y0, pz[held] = seabedZ;
                if (++held == SurfWaves::kBatch) flush();
                continue;
            }
            store(v, rx, ry, s);
        }
        flush();
    });

    if (sameShape) return;
    // Vertex of world column c (a multiple of the ring's stride) on ring j.
    // One remainder, and the stride (a power of two) as a mask and a shift: the integer
    // divisions were most of the index buffer's cost.
    std::vector<int> strideShift(static_cast<size_t>(rings));
    for (int j = 0; j < rings; ++j) {
        const int sj = stride[size_t(j)];
        CHECK(sj > 0 && (sj & (sj - 1)) == 0);
        strideShift[size_t(j)] = std::countr_zero(unsigned(sj));
    }
    const auto vertex = [&](int j, int64_t c) {
        const uint32_t n = ringStart[size_t(j) + 1] - ringStart[size_t(j)];
        const int shift = strideShift[size_t(j)];
        const bool whole = int64_t(n) << shift == circle;
        int64_t col = c - ringFirst[size_t(j)];
        if (whole) {
            col = c % circle;  // wrapped into [0, circle)
            if (col < 0) col += circle;
        }
        CHECK((col & ((int64_t(1) << shift) - 1)) == 0);
        const int64_t i = col >> shift;
        CHECK(i >= 0 && i < int64_t(n));
        return ringStart[size_t(j)] + uint32_t(i);
    };
    // Each band's triangles: one per inner segment and one per outer segment; bands are
    // written in parallel at their offsets, so the buffer is the same for any thread count.
    std::vector<size_t> bandOffset(size_t(rings), 0);
    for (int j = 0; j + 1 < rings; ++j) {
        const int64_t span = std::min<int64_t>(bandHi[size_t(j)] - bandLo[size_t(j)], circle);
        bandOffset[size_t(j) + 1] =
            bandOffset[size_t(j)] +
            3 * size_t(span / stride[size_t(j)] + span / stride[size_t(j) + 1]);
    }
    out.indices.resize(bandOffset.back());
    // Where the shortcuts are on, a band's corners are stepped to along its two rings instead
    // of looked up by column (vertex above) at every corner, which was most of the index
    // buffer's cost: a ring's next column (its stride on) is its next vertex, wrapped to its
    // first on a whole circle (vertex's remainder). A walk starts at vertex(j, lo) and must end
    // at vertex(j, hi), the band's last corners.
    struct RingWalk {
        uint32_t start, i, n;
        bool whole;
        uint32_t Vertex() const { return start + i; }
        void Step() {
            if (++i == n && whole) i = 0;
        }
    };
    const auto walk = [&](int j, int64_t c) {
        const uint32_t start = ringStart[size_t(j)], n = ringStart[size_t(j) + 1] - start;
        return RingWalk{start, vertex(j, c) - start, n,
                        int64_t(n) << strideShift[size_t(j)] == circle};
    };
    tbb::parallel_for(0, rings - 1, [&](int j) {
        const bool whole = bandHi[size_t(j)] - bandLo[size_t(j)] >= circle;
        const int64_t lo = whole ? 0 : bandLo[size_t(j)], hi = whole ? circle : bandHi[size_t(j)];
        const int64_t s = stride[size_t(j)], t = stride[size_t(j) + 1], m = s / t;
        uint32_t* dst = out.indices.data() + bandOffset[size_t(j)];
        const auto emit = [&](uint32_t p, uint32_t q, uint32_t r) {
            dst[0] = p, dst[1] = q, dst[2] = r;
            dst += 3;
        };
        // Azimuth increases clockwise seen from above and radius outward, so (a, b, o) and
        // (x, o', o) with o' clockwise of o are counter-clockwise seen from above. Where the
        // outer ring is finer (m > 1 columns per inner segment) its vertices are fanned to the
        // nearer inner vertex: no T-junction, since every vertex of both rings on the segment
        // is a corner of the band's triangles.
        if (!req.shortcuts) {
            for (int64_t c = lo; c < hi; c += s) {
                const uint32_t a = vertex(j, c), b = vertex(j, c + s);
                for (int64_t k = 0; k < m / 2; ++k)
                    emit(a, vertex(j + 1, c + (k + 1) * t), vertex(j + 1, c + k * t));
                emit(a, b, vertex(j + 1, c + (m / 2) * t));
                for (int64_t k = m / 2; k < m; ++k)
                    emit(b, vertex(j + 1, c + (k + 1) * t), vertex(j + 1, c + k * t));
            }
        } else {
            // The same triangles in the same order.
            RingWalk inner = walk(j, lo), outer = walk(j + 1, lo);
            int64_t c = lo;
            for (; c < hi; c += s) {
                const uint32_t a = inner.Vertex();
                inner.Step();
                const uint32_t b = inner.Vertex();
                uint32_t o = outer.Vertex();  // column c + k t, k = 0 … m
                if (m == 1) {                 // most bands: one outer segment
                    outer.Step();
                    emit(a, b, o);
                    emit(b, outer.Vertex(), o);
                    continue;
                }
                for (int64_t k = 0; k < m / 2; ++k) {
                    outer.Step();
                    emit(a, outer.Vertex(), o);
                    o = outer.Vertex();
                }
                emit(a, b, o);
                for (int64_t k = m / 2; k < m; ++k) {
                    outer.Step();
                    emit(b, outer.Vertex(), o);
                    o = outer.Vertex();
                }
            }
            CHECK(inner.Vertex() == vertex(j, c) && outer.Vertex() == vertex(j + 1, c));
        }
        CHECK(dst == out.indices.data() + bandOffset[size_t(j) + 1]);
    });
}

}  // namespace seasense::scene
