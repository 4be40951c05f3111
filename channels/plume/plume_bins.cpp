// Screen-space puff bins: per-puff tolerance footprints, tile lists and the per-ray trace.
#include "channels/plume/plume_bins.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iterator>
#include <limits>
#include <numbers>
#include <utility>

#include "scene/core/check.h"
#include "scene/core/int_div.h"
#include "scene/core/simd4.h"
#include "scene/core/simd_lanes.h"

namespace seasense::channels {

namespace {

// PlumeScreenBins::kStride, the floats of one puff's record (for the loaders below).
constexpr size_t kPuffRecord = 16;
// A copied list's groups of eight puffs: their records transposed, field f of puff l of a group
// at f · 8 + l of its kGroupFloats (List::data).
constexpr size_t kGroupPuffs = 8;
constexpr size_t kGroupFloats = kGroupPuffs * kPuffRecord;

// For each set of lanes (bit l for lane l), the indices of its lanes in increasing order,
// then the other lanes': a shuffle that moves the set's values to the front, in order. Stored
// as 32-bit lanes, the shuffle's own index vector (one load; widening bytes to it took ~27
// instructions, lane by lane, per use).
struct CompressIndices {
    uint32_t lanes[size_t(1) << simd::kLanes][simd::kLanes];
};
constexpr CompressIndices MakeCompressIndices() {
    CompressIndices table{};
    for (size_t bits = 0; bits < (size_t(1) << simd::kLanes); ++bits) {
        size_t at = 0;
        for (size_t l = 0; l < simd::kLanes; ++l)
            if ((bits >> l) & 1u) table.lanes[bits][at++] = uint32_t(l);
        for (size_t l = 0; l < simd::kLanes; ++l)
            if (!((bits >> l) & 1u)) table.lanes[bits][at++] = uint32_t(l);
    }
    return table;
}
constexpr CompressIndices kCompressIndices = MakeCompressIndices();

// Writes the values of the lanes set in bits (bit l for lane l) to dst, in lane order, and
// returns how many; writes kLanes values in all (dst must have room for them), one shuffle
// (AVX2's vpermd) instead of a test and a store per lane.
using VU = uint32_t __attribute__((vector_size(sizeof(simd::VI))));
inline size_t CompressStore(uint32_t* dst, VU values, unsigned bits) {
    VU lanes;
    std::memcpy(&lanes, kCompressIndices.lanes[bits], sizeof lanes);
    const VU packed = __builtin_shuffle(values, lanes);
    std::memcpy(dst, &packed, sizeof packed);
    return size_t(__builtin_popcount(bits));
}

// The screen ellipse of a puff's cutoff ellipsoid wholly in front of the eye: the pixel
// coordinates p = (x, y) whose rays meet the ellipsoid of Mahalanobis radius² r2, as
// {p : (p − centre)ᵀ Q (p − centre) ≤ 1}; out = centre x, y, Q_xx, Q_xy, Q_yy, √λmax(Q), or
// zeros when the conic is not a proper ellipse (then only the rectangle decides). q: eye −
// centre (world); camera frame x right, y forward, z up; pixel x = (a / tanH + 1) W / 2,
// y = (1 − b / tanV) H / 2 for the camera-frame direction (a, 1, b).
// Along the ray eye + s·d the squared Mahalanobis distance to the centre is smallest,
// m² = C − B²/A, at s = −B/A (A = dᵀMd, B = dᵀMq, C = qᵀMq, M = diag(σh⁻², σh⁻², σz⁻²)); so
// the ray meets the ellipsoid iff B² − (C − r2) A ≥ 0, a quadratic form dᵀ K d in d, and in
// the pixel coordinates, d = T (x, y, 1), a quadratic f(p) = pᵀ P p + 2 gᵀ p + h ≥ 0 (the
// projected quadric's conic, Hartley & Zisserman, "Multiple View Geometry" (2004) §8.3),
// with centre −P⁻¹ g, f(centre) = h + gᵀ centre and Q = −P / f(centre).
void FootprintEllipse(const glm::dmat3& cameraFromWorld, const glm::dvec3& q, double sh, double sz,
                      double r2, double W, double H, double tanH, double tanV, double (&out)[6]) {
    const glm::dvec3 m{1.0 / (sh * sh), 1.0 / (sh * sh), 1.0 / (sz * sz)};
    const glm::dvec3 mq = m * q;
    const double G = glm::dot(q, mq) - r2;
    if (!(G > 0.0)) return;
    const glm::dvec3 pc = cameraFromWorld * mq;
    const glm::dmat3 mc = cameraFromWorld *
                          glm::dmat3(glm::dvec3(m.x, 0.0, 0.0), glm::dvec3(0.0, m.y, 0.0),
                                     glm::dvec3(0.0, 0.0, m.z)) *
                          glm::transpose(cameraFromWorld);
    const glm::dmat3 K = glm::outerProduct(pc, pc) - G * mc;
    // Columns: the direction's change per pixel in x, per pixel in y, and at pixel (0, 0).
    const glm::dmat3 T(glm::dvec3(2.0 * tanH / W, 0.0, 0.0), glm::dvec3(0.0, 0.0, -2.0 * tanV / H),
                       glm::dvec3(-tanH, 1.0, tanV));
    const glm::dmat3 L = glm::transpose(T) * K * T;
    const double pxx = L[0][0], pxy = L[1][0], pyy = L[1][1], gx = L[2][0], gy = L[2][1];
    const double det = pxx * pyy - pxy * pxy;
    if (!(pxx < 0.0 && det > 0.0)) return;
    // centre = −P⁻¹ g.
    const double cx = -(pyy * gx - pxy * gy) / det, cy = -(pxx * gy - pxy * gx) / det;
    const double fc = L[2][2] + gx * cx + gy * cy;
    if (!(fc > 0.0)) return;
    // Q, shrunk (the ellipse widened) by more than its float rounding can change the form:
    // |xᵀ ΔQ x| ≤ 2⁻²⁴ (√Q_xx |x| + √Q_yy |y|)² ≤ 2⁻²³ (Q_xx x² + Q_yy y²) ≤ 2⁻²³ xᵀ Q x / (1 − κ),
    // κ = |Q_xy| / √(Q_xx Q_yy) < 1 (P is definite); 4× that plus 1e-6.
    const double kappa = std::abs(pxy) / std::sqrt(pxx * pyy);
    const double widen = 1.0 - 4.0 * 0x1p-23 / (1.0 - kappa) - 1e-6;
    if (!(widen > 0.5)) return;
    const double qxx = -pxx / fc * widen, qxy = -pxy / fc * widen, qyy = -pyy / fc * widen;
    const double halfTrace = 0.5 * (qxx + qyy);
    const double lambdaMax =
        halfTrace + std::sqrt(std::max(halfTrace * halfTrace - (qxx * qyy - qxy * qxy), 0.0));
    out[0] = cx, out[1] = cy, out[2] = qxx, out[3] = qxy, out[4] = qyy;
    out[5] = std::sqrt(lambdaMax);
}

}  // namespace

PlumeScreenBins::PlumeScreenBins(const scene::PlumeField& field, const ChannelCamera& camera,
                                 scene::ObscurantBand band, float tolerance) {
    CHECK(tolerance > 0.0f);
    static_assert(size_t(kStride) == kPuffRecord);
    UseWideTraces(true);
    width_ = camera.width + kMargin;
    height_ = camera.height + kMargin;
    tilesX_ = (width_ + kTile - 1) / kTile;
    tilesY_ = (height_ + kTile - 1) / kTile;
    const scene::PlumeField::PuffArrays puffs = field.Puffs();
    const size_t n = puffs.x.size();

    const glm::dmat3 cameraFromWorld = glm::transpose(camera.worldFromCamera.worldFromBody);
    const glm::dvec3 eye = camera.worldFromCamera.position_m;
    const double tanH = camera.TanHalfH(), tanV = camera.TanHalfV();
    const double W = camera.width, H = camera.height;
    const double pixelAngle = 2.0 * tanH / W;
    const size_t b = size_t(band);
    const double sqrt2Pi = std::sqrt(2.0 * std::numbers::pi);
    const double halfSqrtPi = 0.5 * std::sqrt(std::numbers::pi);
    const auto TauMax = [&](size_t i, double sh, double sz) {
        // Line integral through the centre: peak √(2π/A), largest for A = 1/max(σ)².
        return field.Optics(puffs.plume[i]).massExtinction_m2pkg[b] * double(puffs.peak_kgpm3[i]) *
               sqrt2Pi * std::max(sh, sz);
    };

    // The tolerance is shared by the puffs that can reach the view. Every ray lies in the
    // pyramid from the eye through the bin area, the intersection of five half-spaces
    // nᵀ x ≥ 0 (x camera-frame, from the eye): in front of the eye and inside the four sides.
    // Along any ray from the eye inside a half-space that the puff's centre lies outside of,
    // at Mahalanobis distance m_H (= −nᵀx_c / √(nᵀ Σ n), Σ the puff's covariance), the
    // squared Mahalanobis distance stays ≥ m_H², so the ray's optical depth is at most
    // τ_max e^(−m_H²/2): the whole line's integral through its closest approach, at most
    // τ_max e^(−m*²/2), if that lies on the ray (then m* ≥ m_H), else the tail beyond its
    // start, ≤ (τ_max / 2) e^(−m(0)²/2) (the Gaussian tail bound ∫_a^∞ e^(−At²/2) dt ≤
    // e^(−Aa²/2) √(π/2A)). A puff whose bound b over the five is at most 1e-3 tolerance / n
    // is out of view: dropped, its b counted (in field order, in double precision); the rest
    // of the tolerance is split among the n' others, ε = (tolerance − Σ b) / n'. So the
    // out-of-view puffs add at most a thousandth of the tolerance and ε is about tolerance /
    // n' instead of tolerance / n (the puffs behind the camera no longer count).
    const double aMin = -tanH, aMax = (2.0 * width_ / W - 1.0) * tanH;
    const double bMax = tanV, bMin = (1.0 - 2.0 * height_ / H) * tanV;
    const glm::dvec3 sides[5] = {{0.0, 1.0, 0.0},
                                 {1.0, -aMin, 0.0},
                                 {-1.0, aMax, 0.0},
                                 {0.0, bMax, -1.0},
                                 {0.0, -bMin, 1.0}};
    const double outOfView = 1e-3 * double(tolerance) / double(std::max<size_t>(n, 1));
    // The sides' normals in the world frame, where Σ is diagonal: nᵀ Σ n = σh² h + σz² z.
    double sideH[5], sideZ[5];
    for (int j = 0; j < 5; ++j) {
        const glm::dvec3 nw = glm::transpose(cameraFromWorld) * sides[j];
        sideH[j] = nw.x * nw.x + nw.y * nw.y, sideZ[j] = nw.z * nw.z;
    }
    std::vector<double> viewBound(n);
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, n, 256), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t i = r.begin(); i != r.end(); ++i) {
                const double sh = 1.0 / std::sqrt(double(puffs.invVarH[i]));
                const double sz = 1.0 / std::sqrt(double(puffs.invVarZ[i]));
                const glm::dvec3 xc =
                    cameraFromWorld * (glm::dvec3(puffs.x[i], puffs.y[i], puffs.z[i]) - eye);
                double mH = 0.0;
                for (int j = 0; j < 5; ++j) {
                    const double out = -glm::dot(sides[j], xc);
                    if (out > 0.0)
                        mH = std::max(mH, out / std::sqrt(sh * sh * sideH[j] + sz * sz * sideZ[j]));
                }
                // (In view: any value above outOfView.)
                viewBound[i] = mH > 0.0 ? TauMax(i, sh, sz) * std::exp(-0.5 * mH * mH)
                                        : std::numeric_limits<double>::infinity();
            }
        });
    double outOfViewSum = 0.0;
    size_t inView = 0;
    for (size_t i = 0; i < n; ++i) {
        if (viewBound[i] <= outOfView)
            outOfViewSum += viewBound[i];
        else
            ++inView;
    }
    puffTolerance_ =
        float((double(tolerance) - outOfViewSum) / double(std::max<size_t>(inView, 1)));
    const double eps = puffTolerance_;
    // Each puff is projected on its own (in parallel, into its own slot), then the kept ones
    // are compacted in field order, so the bins are the same for any thread count.
    struct Projected {
        bool kept = false;
        float values[kFields];
        Footprint footprint;
    };
    std::vector<Projected> projected(n);
    const auto Project = [&](size_t i, Projected& out) {
        if (viewBound[i] <= outOfView) return;
        const scene::ObscurantOptics& optics = field.Optics(puffs.plume[i]);
        const double alpha = optics.massExtinction_m2pkg[b];
        const double sh = 1.0 / std::sqrt(double(puffs.invVarH[i]));
        const double sz = 1.0 / std::sqrt(double(puffs.invVarZ[i]));
        const double tauMax = TauMax(i, sh, sz);
        if (!(tauMax > eps)) return;
        const double r2 = 2.0 * std::log(tauMax / eps);
        const double r = std::sqrt(r2);
        const glm::dvec3 c{puffs.x[i], puffs.y[i], puffs.z[i]};
        const glm::dvec3 lo = c - glm::dvec3(r * sh, r * sh, r * sz);
        const glm::dvec3 hi = c + glm::dvec3(r * sh, r * sh, r * sz);
        // Screen rectangle of the box, as pixel indices.
        double xMin = 1e300, xMax = -1e300, yMin = 1e300, yMax = -1e300, far = 0.0;
        int behind = 0;
        for (int k = 0; k < 8; ++k) {
            const glm::dvec3 p{k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z};
            far = std::max(far, glm::length(p - eye));
            const glm::dvec3 q = cameraFromWorld * (p - eye);  // x right, y forward, z up
            if (q.y < camera.near_m) {
                ++behind;
                continue;
            }
            const double x = (q.x / (q.y * tanH) + 1.0) * 0.5 * W;
            const double y = (1.0 - q.z / (q.y * tanV)) * 0.5 * H;
            xMin = std::min(xMin, x), xMax = std::max(xMax, x);
            yMin = std::min(yMin, y), yMax = std::max(yMax, y);
        }
        if (behind == 8) return;
        Rect rect{0, 0, width_, height_};
        // The footprint ellipse (zero: none, the rectangle decides).
        double ellipse[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
        if (behind == 0) {
            // The ellipsoid itself projects inside the box's rectangle; when it lies wholly in
            // front of the eye its exact extent is tighter (the box's corners reach √3 r).
            // A plane through the eye q_x = u q_y (camera frame) touches the ellipsoid
            // {c + S^½ w : |w| ≤ 1}, S = r² diag(σh², σh², σz²) turned into the camera
            // frame, where nᵀ S n = (nᵀ c)², n = (1, −u, 0): a quadratic in u whose roots bound
            // the ellipsoid's screen columns (likewise rows with n = (0, −v, 1)); the
            // tangent-plane test of the dual quadric (Hartley & Zisserman, "Multiple View
            // Geometry" (2004) §8.3).
            const glm::dvec3 cc = cameraFromWorld * (c - eye);
            const glm::dmat3 shape =
                r2 * cameraFromWorld *
                glm::dmat3(glm::dvec3(sh * sh, 0.0, 0.0), glm::dvec3(0.0, sh * sh, 0.0),
                           glm::dvec3(0.0, 0.0, sz * sz)) *
                glm::transpose(cameraFromWorld);
            const double syy = shape[1][1];
            if (cc.y - std::sqrt(syy) > camera.near_m) {
                // a u² − 2 b u + k = 0 with a < 0 (the eye outside, in front of the shape).
                const auto extent = [&](double sxx, double sxy, double cx, double& lo, double& hi) {
                    const double a = syy - cc.y * cc.y, b = sxy - cx * cc.y, k = sxx - cx * cx;
                    const double root = std::sqrt(std::max(b * b - a * k, 0.0));
                    lo = (b + root) / a, hi = (b - root) / a;
                };
                double u0, u1, v0, v1;
                extent(shape[0][0], shape[1][0], cc.x, u0, u1);
                extent(shape[2][2], shape[1][2], cc.z, v0, v1);
                // Rounding margin: a millionth of the extent.
                const double du = 1e-6 * (u1 - u0 + 1e-9), dv = 1e-6 * (v1 - v0 + 1e-9);
                xMin = std::max(xMin, ((u0 - du) / tanH + 1.0) * 0.5 * W);
                xMax = std::min(xMax, ((u1 + du) / tanH + 1.0) * 0.5 * W);
                yMin = std::max(yMin, (1.0 - (v1 + dv) / tanV) * 0.5 * H);
                yMax = std::min(yMax, (1.0 - (v0 - dv) / tanV) * 0.5 * H);
                FootprintEllipse(cameraFromWorld, eye - c, sh, sz, r2, W, H, tanH, tanV, ellipse);
            }
            const auto clampX = [&](double v) { return int(std::clamp(v, 0.0, double(width_))); };
            const auto clampY = [&](double v) { return int(std::clamp(v, 0.0, double(height_))); };
            rect = {clampX(std::floor(xMin) - 1.0), clampY(std::floor(yMin) - 1.0),
                    clampX(std::ceil(xMax) + 1.0), clampY(std::ceil(yMax) + 1.0)};
        }
        if (rect.x0 >= rect.x1 || rect.y0 >= rect.y1) return;
        const double nearest = glm::length(glm::clamp(eye, lo, hi) - eye);
        const glm::dvec3 qc = cameraFromWorld * (c - eye);
        const double sigmaPixels = qc.y > camera.near_m ? std::min(sh, sz) / (qc.y * pixelAngle)
                                                        : std::numeric_limits<double>::infinity();

        const double omega = optics.albedo[b];
        const double T = puffs.temperature_K[i];
        const double hot = T >= double(scene::kHotPuff_K) ? 1.0 - omega : 0.0;
        out.kept = true;
        const float values[kFields] = {
            float(eye.x - c.x), float(eye.y - c.y), float(eye.z - c.z), puffs.invVarH[i],
            puffs.invVarZ[i], float(r2), float(alpha * double(puffs.peak_kgpm3[i]) * halfSqrtPi),
            // Float margins: a little nearer and farther than the box.
            float(nearest * 0.999), float(omega), float((1.0 - omega) * T), float(hot),
            float(hot * T), float(omega * optics.asymmetry)};
        std::copy(std::begin(values), std::end(values), out.values);
        out.footprint = {rect,
                         float(ellipse[0]),
                         float(ellipse[1]),
                         float(ellipse[2]),
                         float(ellipse[3]),
                         float(ellipse[4]),
                         float(ellipse[5]),
                         values[kNear],
                         float(far * 1.001 + 1.0),
                         float(sigmaPixels),
                         float(tauMax)};
    };
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 64),
                      [&](const tbb::blocked_range<size_t>& r) {
                          for (size_t i = r.begin(); i != r.end(); ++i) Project(i, projected[i]);
                      });
    size_t keptCount = 0;
    for (const Projected& p : projected) keptCount += p.kept;
    kept_.reserve(keptCount);
    footprint_.reserve(keptCount);
    puffData_.assign((keptCount + 1) * kStride, 0.0f);
    for (size_t i = 0; i < n; ++i) {
        const Projected& p = projected[i];
        if (!p.kept) continue;
        kept_.push_back(uint32_t(i));
        footprint_.push_back(p.footprint);
        std::copy(std::begin(p.values), std::end(p.values),
                  puffData_.begin() + ptrdiff_t((kept_.size() - 1) * kStride));
    }

    // The inert puff: a unit sphere at the eye with a negative cutoff, beyond every range.
    inert_ = uint32_t(kept_.size());
    const float inert[kFields] = {0, 0, 0, 1, 1, -1, 0, std::numeric_limits<float>::infinity(),
                                  0, 0, 0, 0, 0};
    std::copy(std::begin(inert), std::end(inert), puffData_.begin() + ptrdiff_t(inert_ * kStride));

    // Counting sort of (tile, kept position) pairs: per tile in increasing kept position.
    tileStart_.assign(size_t(tilesX_) * size_t(tilesY_) + 1, 0);
    for (const Footprint& fp : footprint_) {
        const Rect& r = fp.rect;
        for (int ty = r.y0 / kTile; ty <= (r.y1 - 1) / kTile; ++ty)
            for (int tx = r.x0 / kTile; tx <= (r.x1 - 1) / kTile; ++tx)
                ++tileStart_[size_t(ty) * size_t(tilesX_) + size_t(tx) + 1];
    }
    for (size_t t = 1; t < tileStart_.size(); ++t) tileStart_[t] += tileStart_[t - 1];
    tileEntries_.resize(tileStart_.back());
    std::vector<uint32_t> fill(tileStart_.begin(), tileStart_.end() - 1);
    for (size_t k = 0; k < footprint_.size(); ++k) {
        const Rect& r = footprint_[k].rect;
        for (int ty = r.y0 / kTile; ty <= (r.y1 - 1) / kTile; ++ty)
            for (int tx = r.x0 / kTile; tx <= (r.x1 - 1) / kTile; ++tx)
                tileEntries_[fill[size_t(ty) * size_t(tilesX_) + size_t(tx)]++] = uint32_t(k);
    }
}

int PlumeScreenBins::TileOf(int px, int py) const {
    CHECK(px >= 0 && px < width_ && py >= 0 && py < height_);
    return (py / kTile) * tilesX_ + px / kTile;
}

void PlumeScreenBins::Begin(List& out) {
    out.count = 0;
    out.index.clear();
    out.near_m = std::numeric_limits<float>::infinity();
    out.far_m = 0.0f;
    out.smallOpticalDepth = 0.0f;
    out.halfSmallOpticalDepth = 0.0f;
    out.twiceSmallOpticalDepth = 0.0f;
}

// Where the footprint ellipse can reach pixels [x0, x1) × [y0, y1): their centres lie in the
// square-cornered region [x0, x1] × [y0, y1] of pixel coordinates, inside the disc of radius
// ρ (its half diagonal) about its centre o, so if one meets the ellipse then
// ‖Q^½ (o − centre)‖ ≤ 1 + ρ √λmax(Q) (the triangle inequality in the norm of Q^½). For the
// row of o (o_y = centreY) that is an interval of o_x, a quadratic inequality solved here
// (false: none), so that a row of rectangles is tested with one root. The ellipse was widened
// for the float rounding of Q (FootprintEllipse) and ρ for that of the centre, and the roots
// in double precision err far less than that widening, so no puff whose ellipse reaches a
// pixel is dropped.
inline bool PlumeScreenBins::EllipseSpan(const Footprint& fp, float centreY, float rho, double& lo,
                                         double& hi) {
    const double dy = double(centreY) - double(fp.centreY);
    const double reach = 1.0 + double(rho) * double(fp.sqrtLambdaMax);
    // qxx dx² + 2 b dx + c ≤ 0.
    const double a = fp.qxx, b = double(fp.qxy) * dy, c = double(fp.qyy) * dy * dy - reach * reach;
    const double disc = b * b - a * c;
    if (disc < 0.0) return false;
    const double root = std::sqrt(disc);
    lo = double(fp.centreX) + (-b - root) / a, hi = double(fp.centreX) + (-b + root) / a;
    return true;
}

namespace {

// EllipseSpan's ρ for a w × h rectangle: its half diagonal, plus a thousandth of a pixel for
// the float centre (which errs by under 1e-4 pixel on screens below 4000 pixels).
float HalfDiagonal(int w, int h) {
    return float(0.5 * std::sqrt(double(w) * double(w) + double(h) * double(h)) + 1e-3);
}

}  // namespace

inline bool PlumeScreenBins::Reaches(uint32_t k, int x0, int y0, int x1, int y1, float rho) const {
    const Footprint& fp = footprint_[k];
    const Rect& r = fp.rect;
    if (r.x1 <= x0 || r.x0 >= x1 || r.y1 <= y0 || r.y0 >= y1) return false;
    if (fp.sqrtLambdaMax == 0.0f) return true;
    double lo, hi;
    if (!EllipseSpan(fp, 0.5f * float(y0 + y1), rho, lo, hi)) return false;
    const double cx = 0.5 * double(x0 + x1);
    return cx >= lo && cx <= hi;
}

inline void PlumeScreenBins::Add(uint32_t k, float smallPixels, List& out) const {
    const Footprint& fp = footprint_[k];
    out.index.push_back(k);
    out.near_m = std::min(out.near_m, fp.near_m);
    out.far_m = std::max(out.far_m, fp.far_m);
    if (fp.sigmaPixels < smallPixels) out.smallOpticalDepth += fp.tauMax;
    if (fp.sigmaPixels < 0.5f * smallPixels) out.halfSmallOpticalDepth += fp.tauMax;
    if (fp.sigmaPixels < 2.0f * smallPixels) out.twiceSmallOpticalDepth += fp.tauMax;
}

inline void PlumeScreenBins::Take(uint32_t k, int x0, int y0, int x1, int y1, float rho,
                                  float smallPixels, List& out) const {
    if (Reaches(k, x0, y0, x1, y1, rho)) Add(k, smallPixels, out);
}

void PlumeScreenBins::Finish(bool copy, List& out) const {
    out.count = out.index.size();
    const size_t padded = (out.count + 3) & ~size_t(3);
    out.index.resize(padded, inert_);
    out.copied = false;
    if (copy) Copy(out);
}

void PlumeScreenBins::Gather(int x0, int y0, int x1, int y1, float smallPixels, bool copy,
                             List& out) const {
    Begin(out);
    x1 = std::min(x1, width_), y1 = std::min(y1, height_);
    if (x0 < x1 && y0 < y1) {
        // The rectangle's tiles; their lists are merged in kept order, each puff once.
        const int tx0 = x0 / kTile, tx1 = (x1 - 1) / kTile;
        const int ty0 = y0 / kTile, ty1 = (y1 - 1) / kTile;
        constexpr int kMaxTiles = 4;
        CHECK_MSG((tx1 - tx0 + 1) * (ty1 - ty0 + 1) <= kMaxTiles, "gather over > 4 tiles");
        const float rho = HalfDiagonal(x1 - x0, y1 - y0);
        const uint32_t* cur[kMaxTiles];
        const uint32_t* end[kMaxTiles];
        int lists = 0;
        for (int ty = ty0; ty <= ty1; ++ty)
            for (int tx = tx0; tx <= tx1; ++tx) {
                const size_t t = size_t(ty) * size_t(tilesX_) + size_t(tx);
                cur[lists] = tileEntries_.data() + tileStart_[t];
                end[lists] = tileEntries_.data() + tileStart_[t + 1];
                if (cur[lists] != end[lists]) ++lists;
            }
        if (lists == 1) {
            for (const uint32_t* p = cur[0]; p != end[0]; ++p)
                Take(*p, x0, y0, x1, y1, rho, smallPixels, out);
        } else if (lists == 2) {
            // Two tiles (a tile strip's usual case): a plain merge.
            const uint32_t *a = cur[0], *b = cur[1];
            while (a != end[0] && b != end[1]) {
                const uint32_t k = std::min(*a, *b);
                a += *a == k, b += *b == k;
                Take(k, x0, y0, x1, y1, rho, smallPixels, out);
            }
            for (; a != end[0]; ++a) Take(*a, x0, y0, x1, y1, rho, smallPixels, out);
            for (; b != end[1]; ++b) Take(*b, x0, y0, x1, y1, rho, smallPixels, out);
        } else {
            for (;;) {
                uint32_t k = std::numeric_limits<uint32_t>::max();
                for (int l = 0; l < lists; ++l)
                    if (cur[l] != end[l]) k = std::min(k, *cur[l]);
                if (k == std::numeric_limits<uint32_t>::max()) break;
                for (int l = 0; l < lists; ++l)
                    if (cur[l] != end[l] && *cur[l] == k) ++cur[l];
                Take(k, x0, y0, x1, y1, rho, smallPixels, out);
            }
        }
    }
    Finish(copy, out);
}

void PlumeScreenBins::Gather(const List& from, int x0, int y0, int x1, int y1, float smallPixels,
                             bool copy, List& out) const {
    CHECK(&from != &out);
    Begin(out);
    x1 = std::min(x1, width_), y1 = std::min(y1, height_);
    if (x0 < x1 && y0 < y1)
        for (size_t j = 0; j < from.count; ++j)
            Take(from.index[j], x0, y0, x1, y1, HalfDiagonal(x1 - x0, y1 - y0), smallPixels, out);
    Finish(copy, out);
}

void PlumeScreenBins::ListRow::Clear() {
    index.clear();
    start.assign(1, 0);
    count.clear();
    near_m.clear(), far_m.clear();
    smallOpticalDepth.clear(), halfSmallOpticalDepth.clear(), twiceSmallOpticalDepth.clear();
}

void PlumeScreenBins::ListRow::Take(size_t c, List& out) const {
    CHECK(c < count.size());
    out.count = count[c];
    out.index.assign(index.begin() + start[c], index.begin() + start[c + 1]);
    out.near_m = near_m[c];
    out.far_m = far_m[c];
    out.smallOpticalDepth = smallOpticalDepth[c];
    out.halfSmallOpticalDepth = halfSmallOpticalDepth[c];
    out.twiceSmallOpticalDepth = twiceSmallOpticalDepth[c];
    out.copied = false;
}

void PlumeScreenBins::MergeBlocks(std::span<const List> blocks, RowSource& out) const {
    CHECK(blocks.size() <= 64);
    out.mark.assign(kept_.size(), 0);
    for (size_t b = 0; b < blocks.size(); ++b)
        for (size_t j = 0; j < blocks[b].count; ++j)
            out.mark[blocks[b].index[j]] |= uint64_t(1) << b;
    out.index.clear(), out.blocks.clear();
    for (size_t k = 0; k < out.mark.size(); ++k)
        if (out.mark[k] != 0) out.index.push_back(uint32_t(k)), out.blocks.push_back(out.mark[k]);
}

void PlumeScreenBins::GatherRow(const RowSource& from, int x0, int y0, int y1, int step, int width,
                                int cellsPerBlock, int cells, float smallPixels,
                                ListRow& out) const {
    CHECK(step > 0 && width > 0 && cells >= 0);
    CHECK(cellsPerBlock > 0 && cellsPerBlock <= kMaxRowCells);
    const int blockCount = (cells + cellsPerBlock - 1) / cellsPerBlock;
    CHECK(blockCount <= 64);
    std::vector<ListRow::Reach>& reached = out.reached;
    reached.clear();
    y1 = std::min(y1, height_);
    // The last rectangle of full width (width_ − width − x0 may be negative: none), and the
    // first of those clipped at the bin area's edge (each tested on its own, with its own ρ;
    // rectangles wholly beyond the edge are empty).
    const int lastFull =
        width_ - width - x0 >= 0 ? std::min((width_ - width - x0) / step, cells - 1) : -1;
    const int edge0 = lastFull + 1;
    const auto Right = [&](int c) { return std::min(x0 + c * step + width, width_); };
    if (y0 < y1 && cells > 0) {
        const float rho = HalfDiagonal(width, y1 - y0);
        const float centreY = 0.5f * float(y0 + y1);
        for (size_t j = 0; j < from.index.size(); ++j) {
            const uint32_t k = from.index[j];
            const Footprint& fp = footprint_[k];
            const Rect& r = fp.rect;
            if (r.y1 <= y0 || r.y0 >= y1) continue;
            // The ellipse's span for the row's full-width rectangles, as Reaches finds it.
            double spanLo = -std::numeric_limits<double>::infinity();
            double spanHi = std::numeric_limits<double>::infinity();
            if (fp.sqrtLambdaMax != 0.0f && !EllipseSpan(fp, centreY, rho, spanLo, spanHi))
                continue;
            // The rectangles c that the puff's rectangle overlaps, x0 + c·step < r.x1 and
            // x0 + c·step + width > r.x0: an interval of c, in integers.
            const int overlapLo = FloorDiv(r.x0 - x0 - width, step) + 1;
            const int overlapHi = FloorDiv(r.x1 - x0 - 1, step);
            // Those whose centres lie in the ellipse's span, as Reaches tests them: an interval
            // of c too (the centres increase with c), its ends estimated in double precision
            // (within far less than one step of the exact quotients, clamped to the row) and
            // then moved by one where the exact test of the centre says so.
            const auto Centre = [&](int c) {
                const int cx0 = x0 + c * step;
                return 0.5 * double(cx0 + (cx0 + width));
            };
            const double centre0 = Centre(0);
            int spanFirst = std::numeric_limits<int>::min() / 2;
            int spanLast = std::numeric_limits<int>::max() / 2;
            if (fp.sqrtLambdaMax != 0.0f) {
                spanFirst =
                    int(std::clamp(std::ceil((spanLo - centre0) / step), -2.0, double(cells)));
                if (Centre(spanFirst - 1) >= spanLo)
                    --spanFirst;
                else if (Centre(spanFirst) < spanLo)
                    ++spanFirst;
                spanLast =
                    int(std::clamp(std::floor((spanHi - centre0) / step), -2.0, double(cells)));
                if (Centre(spanLast + 1) <= spanHi)
                    ++spanLast;
                else if (Centre(spanLast) > spanHi)
                    --spanLast;
            }
            // The full-width rectangles (up to lastFull) that the puff reaches take it
            // without further tests.
            ListRow::Reach reach{k, std::max({overlapLo, spanFirst, 0}),
                                 std::min({overlapHi, spanLast, lastFull}), 0, from.blocks[j]};
            // Rectangles clipped at the bin area's edge: each with its own ρ.
            for (int c = std::max(overlapLo, edge0); c <= std::min(overlapHi, cells - 1); ++c) {
                const int cx0 = x0 + c * step, cx1 = Right(c);
                if (cx0 >= cx1) break;
                CHECK(c - edge0 < 64);
                if (Reaches(k, cx0, y0, cx1, y1, HalfDiagonal(cx1 - cx0, y1 - y0)))
                    reach.edge |= uint64_t(1) << (c - edge0);
            }
            // The blocks among from's that hold rectangles the puff reaches: those of cells
            // first … last and of its edge rectangles (the others would give it an empty mask).
            uint64_t reachBlocks = 0;
            if (reach.first <= reach.last) {
                const int b0 = reach.first / cellsPerBlock, b1 = reach.last / cellsPerBlock;
                reachBlocks = ((uint64_t(2) << b1) - 1) & ~((uint64_t(1) << b0) - 1);
            }
            for (uint64_t e = reach.edge; e != 0; e &= e - 1)
                reachBlocks |= uint64_t(1) << ((edge0 + __builtin_ctzll(e)) / cellsPerBlock);
            reach.blocks &= reachBlocks;
            if (reach.blocks != 0) reached.push_back(reach);
        }
    }
    using simd::kLanes;
    using simd::VF;
    using simd::VI;
    // Lane l of vector v is rectangle v·kLanes + l of a block: its bit in a puff's mask,
    // shifted down by v·kLanes.
    VI laneBit;
    for (size_t l = 0; l < kLanes; ++l) laneBit[l] = int32_t(1u << l);
    constexpr size_t kVectors = (kMaxRowCells + kLanes - 1) / kLanes;
    // Each block's puffs (in from's order) and the masks of its rectangles they reach, in
    // blockPuffs and blockMasks from b · stride on (room for every puff of the row, padded to
    // whole lane groups): each puff written to the blocks it reaches, rather than every block
    // passing over all the row's puffs. (The calling thread's scratch: a row's lists would
    // keep blockCount times its puffs.)
    thread_local std::vector<uint32_t> blockPuffs, blockMasks;
    const size_t stride = (reached.size() + kLanes - 1) / kLanes * kLanes;
    if (blockPuffs.size() < size_t(blockCount) * stride) {
        blockPuffs.resize(size_t(blockCount) * stride);
        blockMasks.resize(size_t(blockCount) * stride);
    }
    // Block b's next slot (b · stride + its puffs so far), and the slots' arrays.
    size_t next[64];
    for (int b = 0; b < blockCount; ++b) next[b] = size_t(b) * stride;
    uint32_t* const puffSlots = blockPuffs.data();
    uint32_t* const maskSlots = blockMasks.data();
    const auto Put = [&](int b, uint32_t k, uint32_t mask) {
        const size_t at = next[b]++;
        puffSlots[at] = k, maskSlots[at] = mask;
    };
    // All the rectangles of a block of cellsPerBlock.
    const uint32_t whole = uint32_t((uint64_t(1) << cellsPerBlock) - 1);
    for (const ListRow::Reach& reach : reached) {
        const uint32_t k = reach.k;
        uint64_t bits = reach.blocks;
        if (reach.edge == 0) {
            // Blocks of cells first … last alone: the first from bit first − cb0 on, the last
            // up to bit last − cb0, those between whole (they precede the last block, so they
            // hold cellsPerBlock rectangles): the masks of the general form below. Every block
            // takes the whole mask, then the first's and the last's (each block's last slot
            // now: a puff takes one slot per block) are cut to the puff's rectangles.
            const int b0 = reach.first / cellsPerBlock, b1 = reach.last / cellsPerBlock;
            for (; bits != 0; bits &= bits - 1) Put(__builtin_ctzll(bits), k, whole);
            if ((reach.blocks >> b0) & 1u)
                maskSlots[next[b0] - 1] &= ~uint32_t(0) << (reach.first - b0 * cellsPerBlock);
            if ((reach.blocks >> b1) & 1u)
                maskSlots[next[b1] - 1] &=
                    uint32_t((uint64_t(2) << (reach.last - b1 * cellsPerBlock)) - 1);
            continue;
        }
        for (; bits != 0; bits &= bits - 1) {
            const int b = __builtin_ctzll(bits);
            const int cb0 = b * cellsPerBlock, n = std::min(cellsPerBlock, cells - cb0);
            // The block's rectangles among the puff's: bits first − cb0 … last − cb0, and its
            // edge rectangles.
            const int first = std::max(reach.first, cb0), last = std::min(reach.last, cb0 + n - 1);
            uint32_t mask =
                first <= last
                    ? uint32_t((uint64_t(2) << (last - cb0)) - (uint64_t(1) << (first - cb0)))
                    : 0u;
            const int shift = edge0 - cb0;
            const uint64_t edge = shift >= 0    ? (shift < 64 ? reach.edge << shift : 0)
                                  : shift > -64 ? reach.edge >> -shift
                                                : 0;
            mask |= uint32_t(edge) & uint32_t((uint64_t(1) << n) - 1);
            Put(b, k, mask);
        }
    }
    // The row's lists' ranges, sums, counts and starts, written per block below (one resize
    // each instead of a push_back per list).
    const size_t base = out.count.size();
    out.count.resize(base + size_t(cells));
    out.start.resize(base + 1 + size_t(cells));
    out.near_m.resize(base + size_t(cells)), out.far_m.resize(base + size_t(cells));
    out.smallOpticalDepth.resize(base + size_t(cells));
    out.halfSmallOpticalDepth.resize(base + size_t(cells));
    out.twiceSmallOpticalDepth.resize(base + size_t(cells));
    alignas(32) float nearA[kVectors * kLanes], farA[kVectors * kLanes];
    alignas(32) float smallA[kVectors * kLanes], halfSmallA[kVectors * kLanes];
    alignas(32) float twiceSmallA[kVectors * kLanes];
    alignas(32) int32_t countA[kVectors * kLanes];
    // σ below this: small at one of the three sizes (a NaN smallPixels makes all three NaN,
    // and every comparison false, as in Add).
    const float smallBound = std::max({smallPixels, 0.5f * smallPixels, 2.0f * smallPixels});
    // The ranges, sums and counts of a block's n rectangles from its puffs and masks into the
    // arrays above, on V vectors of kLanes rectangles (V = ⌈n / kLanes⌉, a constant: the
    // vectors stay in registers). Every vector takes every puff: a lane whose rectangle the
    // puff does not reach keeps its values (the selects), so the lanes hold what adding the
    // puff to those it reaches alone gives. A puff that reaches all n rectangles and adds to no
    // sum changes only their ranges and counts, the same for every lane: those are kept in
    // scalars (wholeNear, wholeFar, wholeCount) and merged into the lanes at the end. The
    // ranges' order does not matter: the nearest and farthest of a set of floats without NaN
    // or −0 (distances ≥ +0) are the same in any order (PlumeScreenBins.
    // GatherRowOfBlocksEqualsGatherFromEachBlockForAnySmallSize).
    const auto accumulate = [&]<size_t V>(const uint32_t* puffs, const uint32_t* masks,
                                          size_t count, uint32_t all) {
        // As Begin starts them.
        VF nearV[V], farV[V], smallV[V], halfSmallV[V], twiceSmallV[V];
        VI countV[V];
        for (size_t v = 0; v < V; ++v) {
            nearV[v] = simd::Splat(std::numeric_limits<float>::infinity());
            farV[v] = smallV[v] = halfSmallV[v] = twiceSmallV[v] = simd::Splat(0.0f);
            countV[v] = VI{};
        }
        float wholeNear = std::numeric_limits<float>::infinity(), wholeFar = 0.0f;
        int32_t wholeCount = 0;
        for (size_t j = 0; j < count; ++j) {
            const uint32_t k = puffs[j], mask = masks[j];
            // The puff's ranges and sums into the rectangles it reaches, in from's order as Add
            // puts them in one list: std::min and std::max are simd::Min and Max lane for lane,
            // and a rectangle the puff does not reach keeps its values.
            const Footprint& fp = footprint_[k];
            if (mask == all && !(fp.sigmaPixels < smallBound)) {
                wholeNear = std::min(wholeNear, fp.near_m);
                wholeFar = std::max(wholeFar, fp.far_m);
                ++wholeCount;
                continue;
            }
            const bool small = fp.sigmaPixels < smallPixels;
            const bool halfSmall = fp.sigmaPixels < 0.5f * smallPixels;
            const bool twiceSmall = fp.sigmaPixels < 2.0f * smallPixels;
            const VF nearK = simd::Splat(fp.near_m), farK = simd::Splat(fp.far_m);
            const VF tau = simd::Splat(fp.tauMax);
            for (size_t v = 0; v < V; ++v) {
                const VI in = ((VI{} + int32_t(mask >> (v * kLanes))) & laneBit) != 0;
                nearV[v] = simd::Select(in, simd::Min(nearV[v], nearK), nearV[v]);
                farV[v] = simd::Select(in, simd::Max(farV[v], farK), farV[v]);
                countV[v] -= in;
                if (small) smallV[v] = simd::Select(in, smallV[v] + tau, smallV[v]);
                if (halfSmall) halfSmallV[v] = simd::Select(in, halfSmallV[v] + tau, halfSmallV[v]);
                if (twiceSmall)
                    twiceSmallV[v] = simd::Select(in, twiceSmallV[v] + tau, twiceSmallV[v]);
            }
        }
        for (size_t v = 0; v < V; ++v) {
            nearV[v] = simd::Min(nearV[v], simd::Splat(wholeNear));
            farV[v] = simd::Max(farV[v], simd::Splat(wholeFar));
            countV[v] += wholeCount;
            simd::Store(nearA + v * kLanes, nearV[v]);
            simd::Store(farA + v * kLanes, farV[v]);
            simd::Store(smallA + v * kLanes, smallV[v]);
            simd::Store(halfSmallA + v * kLanes, halfSmallV[v]);
            simd::Store(twiceSmallA + v * kLanes, twiceSmallV[v]);
            std::memcpy(countA + v * kLanes, &countV[v], sizeof(VI));
        }
    };
    // accumulate with V = vectors (1 … kVectors).
    const auto accumulateOn = [&]<size_t... I>(std::index_sequence<I...>, size_t vectors,
                                               const uint32_t* puffs, const uint32_t* masks,
                                               size_t count, uint32_t all) {
        ((vectors == I + 1 ? (accumulate.template operator()<I + 1>(puffs, masks, count, all), true)
                           : false) ||
         ...);
    };
    for (int b = 0; b < blockCount; ++b) {
        const int cb0 = b * cellsPerBlock, n = std::min(cellsPerBlock, cells - cb0);
        uint32_t* puffs = puffSlots + size_t(b) * stride;
        uint32_t* masks = maskSlots + size_t(b) * stride;
        const size_t fill = next[b] - size_t(b) * stride;
        accumulateOn(std::make_index_sequence<kVectors>{}, (size_t(n) + kLanes - 1) / kLanes, puffs,
                     masks, fill, uint32_t((uint64_t(1) << n) - 1));
        // The block's lists, one after the other, each padded to a multiple of 4 with the
        // inert puff.
        size_t end = out.index.size();
        for (int c = 0; c < n; ++c) end += (size_t(countA[c]) + 3) & ~size_t(3);
        // kLanes − 1 slots more: CompressStore writes a whole lane group at the list's end.
        out.index.resize(end + kLanes);
        // Whole lane groups: the padding puffs reach no rectangle.
        const size_t groups = (fill + kLanes - 1) / kLanes * kLanes;
        std::fill(puffs + fill, puffs + groups, inert_);
        std::fill(masks + fill, masks + groups, 0u);
        const size_t list0 = base + size_t(cb0);
        uint32_t* dst = out.index.data() + out.start[list0];
        for (int c = 0; c < n; ++c) {
            // The block's puffs whose masks hold bit c, in order, kLanes puffs at a time.
            size_t m = 0;
            for (size_t j = 0; j < groups; j += kLanes) {
                VU lanePuffs, laneMasks;
                std::memcpy(&lanePuffs, puffs + j, sizeof lanePuffs);
                std::memcpy(&laneMasks, masks + j, sizeof laneMasks);
                m += CompressStore(dst + m, lanePuffs, simd::LaneBits(VI(laneMasks << (31 - c))));
            }
            const size_t padded = (m + 3) & ~size_t(3);
            std::fill(dst + m, dst + padded, inert_);
            dst += padded;
            const size_t list = list0 + size_t(c);
            out.start[list + 1] = uint32_t(dst - out.index.data());
            out.count[list] = uint32_t(m);
            out.near_m[list] = nearA[c];
            out.far_m[list] = farA[c];
            out.smallOpticalDepth[list] = smallA[c];
            out.halfSmallOpticalDepth[list] = halfSmallA[c];
            out.twiceSmallOpticalDepth[list] = twiceSmallA[c];
        }
        out.index.resize(end);
    }
}

namespace {

using simd4::Exp4;
using simd4::F4;

// The coefficients a5 … a1 of Abramowitz & Stegun 7.1.26, erf x ≈ 1 − t Σ a_k t^(k−1) e^(−x²)
// with t = 1 / (1 + 0.3275911 x), highest degree first.
constexpr float kErfAS[] = {1.061405429f, -1.453152027f, 1.421413741f, -0.284496736f, 0.254829592f};

// FastErf on four lanes (A&S 7.1.26 with Exp4; |error| ≤ 1.5e-7 + 2e-7).
inline F4 Erf4(F4 x) {
    const F4 sign = _mm_and_ps(x, _mm_set1_ps(-0.0f));
    const F4 ax = simd4::Abs4(x);
    const F4 t = _mm_div_ps(_mm_set1_ps(1.0f),
                            _mm_add_ps(_mm_set1_ps(1.0f), _mm_mul_ps(_mm_set1_ps(0.3275911f), ax)));
    F4 poly = _mm_set1_ps(kErfAS[0]);
    for (size_t i = 1; i < std::size(kErfAS); ++i)
        poly = _mm_add_ps(_mm_mul_ps(poly, t), _mm_set1_ps(kErfAS[i]));
    poly = _mm_mul_ps(poly, t);
    F4 e = _mm_sub_ps(_mm_set1_ps(1.0f),
                      _mm_mul_ps(poly, Exp4(_mm_sub_ps(_mm_setzero_ps(), _mm_mul_ps(ax, ax)))));
    e = simd4::Select4(_mm_cmpge_ps(ax, _mm_set1_ps(3.9f)), _mm_set1_ps(1.0f), e);
    return _mm_or_ps(e, sign);
}

// Erf4, skipped when every lane is at or beyond ±3.9 where Erf4 is ±1: rays that start well
// before a puff and end well beyond it, the common case.
inline F4 ErfOrSign4(F4 x) {
    const F4 saturated = _mm_cmpge_ps(simd4::Abs4(x), _mm_set1_ps(3.9f));
    if (_mm_movemask_ps(saturated) == 0xF)
        return _mm_or_ps(_mm_set1_ps(1.0f), _mm_and_ps(x, _mm_set1_ps(-0.0f)));
    return Erf4(x);
}

inline float Sum4(F4 v) {
    alignas(16) float f[4];
    _mm_store_ps(f, v);
    return (f[0] + f[1]) + (f[2] + f[3]);
}

struct BandAccumulator {
    F4 extinction, scattering, absorption, absorptionT, hotAbsorption, hotAbsorptionT, scatteringG;

    BandAccumulator() {
        extinction = scattering = absorption = absorptionT = hotAbsorption = hotAbsorptionT =
            scatteringG = _mm_setzero_ps();
    }
    // Weights w[0..4]: scattering, absorption × T, hot absorption, hot absorption × T,
    // scattering × g per unit optical depth.
    void Add(const F4 (&w)[5], F4 tau) {
        extinction = _mm_add_ps(extinction, tau);
        const F4 scattered = _mm_mul_ps(tau, w[0]);
        scattering = _mm_add_ps(scattering, scattered);
        absorption = _mm_add_ps(absorption, _mm_sub_ps(tau, scattered));
        absorptionT = _mm_add_ps(absorptionT, _mm_mul_ps(tau, w[1]));
        hotAbsorption = _mm_add_ps(hotAbsorption, _mm_mul_ps(tau, w[2]));
        hotAbsorptionT = _mm_add_ps(hotAbsorptionT, _mm_mul_ps(tau, w[3]));
        scatteringG = _mm_add_ps(scatteringG, _mm_mul_ps(tau, w[4]));
    }
};

// The trace from the sums of the lanes of the even (lo) and odd (hi) groups of four puffs,
// lane by lane first, then across the lanes.
inline BandTrace Result(const BandAccumulator& lo, const BandAccumulator& hi) {
    const auto sum = [](F4 a, F4 b) { return Sum4(_mm_add_ps(a, b)); };
    const float ext = sum(lo.extinction, hi.extinction);
    const float scat = sum(lo.scattering, hi.scattering);
    const float abs = sum(lo.absorption, hi.absorption);
    const float hot = sum(lo.hotAbsorption, hi.hotAbsorption);
    BandTrace t;
    t.opticalDepth = ext;
    t.albedo = ext > 0.0f ? scat / ext : 0.0f;
    t.temperature_K = abs > 0.0f ? sum(lo.absorptionT, hi.absorptionT) / abs : 0.0f;
    t.hotFraction = abs > 0.0f ? std::min(hot / abs, 1.0f) : 0.0f;
    t.hotTemperature_K = hot > 0.0f ? sum(lo.hotAbsorptionT, hi.hotAbsorptionT) / hot : 0.0f;
    t.asymmetry = scat > 0.0f ? sum(lo.scatteringG, hi.scatteringG) / scat : 0.0f;
    return t;
}

// Four values of field f from k on (k a multiple of 4): contiguous in a copied list's group
// (copied: its data), else gathered by index from the records.
template <bool Copied>
inline F4 Load4(const float* copied, const float* records, const uint32_t* index, size_t k, int f) {
    if constexpr (Copied) {
        return _mm_loadu_ps(copied + k / kGroupPuffs * kGroupFloats + size_t(f) * kGroupPuffs +
                            k % kGroupPuffs);
    } else {
        const uint32_t* i = index + k;
        const float* field = records + f;
        constexpr size_t m = kPuffRecord;
        return _mm_setr_ps(field[i[0] * m], field[i[1] * m], field[i[2] * m], field[i[3] * m]);
    }
}

#if defined(__x86_64__) && defined(__GNUC__)
#define SEASENSE_PLUME_WIDE 1
using F8 = __m256;

// Exp4 on eight lanes (AVX2), the same operations lane for lane.
__attribute__((target("avx2"), always_inline)) inline F8 Exp8(F8 x) {
    x = _mm256_min_ps(_mm256_max_ps(x, _mm256_set1_ps(-87.0f)), _mm256_set1_ps(88.0f));
    const __m256i n = _mm256_cvtps_epi32(_mm256_mul_ps(x, _mm256_set1_ps(1.44269504f)));
    const F8 fn = _mm256_cvtepi32_ps(n);
    F8 r = _mm256_sub_ps(x, _mm256_mul_ps(fn, _mm256_set1_ps(0.693359375f)));
    r = _mm256_sub_ps(r, _mm256_mul_ps(fn, _mm256_set1_ps(-2.12194440e-4f)));
    F8 p = _mm256_set1_ps(simd4::kExpTaylor6[0]);
    for (size_t i = 1; i < std::size(simd4::kExpTaylor6); ++i)
        p = _mm256_add_ps(_mm256_mul_ps(p, r), _mm256_set1_ps(simd4::kExpTaylor6[i]));
    const F8 scale =
        _mm256_castsi256_ps(_mm256_slli_epi32(_mm256_add_epi32(n, _mm256_set1_epi32(127)), 23));
    return _mm256_mul_ps(p, scale);
}

// ErfOrSign4 on eight lanes (Erf4's operations lane for lane; the shortcut, taken when every
// lane that is used saturates, gives what Erf4 gives there, ±1; the unused lanes' values are
// discarded).
__attribute__((target("avx2"), always_inline)) inline F8 ErfOrSign8(F8 x, F8 use) {
    const F8 sign = _mm256_and_ps(x, _mm256_set1_ps(-0.0f));
    const F8 ax = _mm256_andnot_ps(_mm256_set1_ps(-0.0f), x);
    const F8 saturated = _mm256_cmp_ps(ax, _mm256_set1_ps(3.9f), _CMP_GE_OS);
    if ((_mm256_movemask_ps(saturated) | (~_mm256_movemask_ps(use) & 0xFF)) == 0xFF)
        return _mm256_or_ps(_mm256_set1_ps(1.0f), sign);
    const F8 t = _mm256_div_ps(
        _mm256_set1_ps(1.0f),
        _mm256_add_ps(_mm256_set1_ps(1.0f), _mm256_mul_ps(_mm256_set1_ps(0.3275911f), ax)));
    F8 poly = _mm256_set1_ps(kErfAS[0]);
    for (size_t i = 1; i < std::size(kErfAS); ++i)
        poly = _mm256_add_ps(_mm256_mul_ps(poly, t), _mm256_set1_ps(kErfAS[i]));
    poly = _mm256_mul_ps(poly, t);
    F8 e = _mm256_sub_ps(
        _mm256_set1_ps(1.0f),
        _mm256_mul_ps(poly, Exp8(_mm256_sub_ps(_mm256_setzero_ps(), _mm256_mul_ps(ax, ax)))));
    e = _mm256_blendv_ps(e, _mm256_set1_ps(1.0f), saturated);
    return _mm256_or_ps(e, sign);
}

// The fields of the eight records at records + index[l] · kPuffRecord, l = 0 … 7: out[f] holds
// field f of the eight puffs in lane order. Two 8 × 8 transposes (AVX shuffles: the values
// are moved, not changed) instead of eight scattered loads for each of thirteen fields.
__attribute__((target("avx2"))) inline void TransposeRecords8(const float* records,
                                                              const uint32_t* index,
                                                              F8 (&out)[kPuffRecord]) {
    for (size_t half = 0; half < kPuffRecord; half += 8) {
        F8 r[8];
        for (int l = 0; l < 8; ++l)
            r[l] = _mm256_loadu_ps(records + size_t(index[l]) * kPuffRecord + half);
        const F8 t0 = _mm256_unpacklo_ps(r[0], r[1]), t1 = _mm256_unpackhi_ps(r[0], r[1]);
        const F8 t2 = _mm256_unpacklo_ps(r[2], r[3]), t3 = _mm256_unpackhi_ps(r[2], r[3]);
        const F8 t4 = _mm256_unpacklo_ps(r[4], r[5]), t5 = _mm256_unpackhi_ps(r[4], r[5]);
        const F8 t6 = _mm256_unpacklo_ps(r[6], r[7]), t7 = _mm256_unpackhi_ps(r[6], r[7]);
        constexpr int kLow = _MM_SHUFFLE(1, 0, 1, 0), kHigh = _MM_SHUFFLE(3, 2, 3, 2);
        const F8 u0 = _mm256_shuffle_ps(t0, t2, kLow), u1 = _mm256_shuffle_ps(t0, t2, kHigh);
        const F8 u2 = _mm256_shuffle_ps(t1, t3, kLow), u3 = _mm256_shuffle_ps(t1, t3, kHigh);
        const F8 u4 = _mm256_shuffle_ps(t4, t6, kLow), u5 = _mm256_shuffle_ps(t4, t6, kHigh);
        const F8 u6 = _mm256_shuffle_ps(t5, t7, kLow), u7 = _mm256_shuffle_ps(t5, t7, kHigh);
        out[half + 0] = _mm256_permute2f128_ps(u0, u4, 0x20);
        out[half + 1] = _mm256_permute2f128_ps(u1, u5, 0x20);
        out[half + 2] = _mm256_permute2f128_ps(u2, u6, 0x20);
        out[half + 3] = _mm256_permute2f128_ps(u3, u7, 0x20);
        out[half + 4] = _mm256_permute2f128_ps(u0, u4, 0x31);
        out[half + 5] = _mm256_permute2f128_ps(u1, u5, 0x31);
        out[half + 6] = _mm256_permute2f128_ps(u2, u6, 0x31);
        out[half + 7] = _mm256_permute2f128_ps(u3, u7, 0x31);
    }
}

// BandAccumulator on eight lanes: lanes 0–3 those of the even groups of four, 4–7 of the odd.
struct BandAccumulator8 {
    F8 extinction, scattering, absorption, absorptionT, hotAbsorption, hotAbsorptionT, scatteringG;

    __attribute__((target("avx2"))) BandAccumulator8() {
        extinction = scattering = absorption = absorptionT = hotAbsorption = hotAbsorptionT =
            scatteringG = _mm256_setzero_ps();
    }
    // BandAccumulator::Add lane for lane, of the optical depths kept where use and τ > 0.
    __attribute__((target("avx2"), always_inline)) void Add(const F8 (&w)[5], F8 use, F8 tau) {
        tau = _mm256_and_ps(_mm256_and_ps(use, _mm256_cmp_ps(tau, _mm256_setzero_ps(), _CMP_GT_OS)),
                            tau);
        extinction = _mm256_add_ps(extinction, tau);
        const F8 scattered = _mm256_mul_ps(tau, w[0]);
        scattering = _mm256_add_ps(scattering, scattered);
        absorption = _mm256_add_ps(absorption, _mm256_sub_ps(tau, scattered));
        absorptionT = _mm256_add_ps(absorptionT, _mm256_mul_ps(tau, w[1]));
        hotAbsorption = _mm256_add_ps(hotAbsorption, _mm256_mul_ps(tau, w[2]));
        hotAbsorptionT = _mm256_add_ps(hotAbsorptionT, _mm256_mul_ps(tau, w[3]));
        scatteringG = _mm256_add_ps(scatteringG, _mm256_mul_ps(tau, w[4]));
    }
    // The even and odd groups' sums.
    __attribute__((target("avx2"))) void Split(BandAccumulator& lo, BandAccumulator& hi) const {
        const auto split = [](F8 v, F4 & l, F4 & h) __attribute__((target("avx2"))) {
            l = _mm256_castps256_ps128(v), h = _mm256_extractf128_ps(v, 1);
        };
        split(extinction, lo.extinction, hi.extinction);
        split(scattering, lo.scattering, hi.scattering);
        split(absorption, lo.absorption, hi.absorption);
        split(absorptionT, lo.absorptionT, hi.absorptionT);
        split(hotAbsorption, lo.hotAbsorption, hi.hotAbsorption);
        split(hotAbsorptionT, lo.hotAbsorptionT, hi.hotAbsorptionT);
        split(scatteringG, lo.scatteringG, hi.scatteringG);
    }
};
#endif

}  // namespace

void PlumeScreenBins::UseWideTraces(bool on) {
#ifdef SEASENSE_PLUME_WIDE
    wide_ = on && __builtin_cpu_supports("avx2");
#else
    wide_ = false;
    (void)on;
#endif
}

#ifdef SEASENSE_PLUME_WIDE
// TraceImpl's loop body on eight lanes, into the even and odd groups' sums, as the four-lane
// loop adds them.
template <bool Copied, int Ranges>
__attribute__((target("avx2"))) void PlumeScreenBins::TraceWide(const List& l, const glm::vec3& dir,
                                                                const float* range_m,
                                                                BandTrace* out) const {
    const F8 dx = _mm256_set1_ps(dir.x), dy = _mm256_set1_ps(dir.y), dz = _mm256_set1_ps(dir.z);
    const F8 dh2 = _mm256_set1_ps(dir.x * dir.x + dir.y * dir.y);
    const F8 dz2 = _mm256_set1_ps(dir.z * dir.z);
    // The ranges and each pair's end (named, not arrays, so the sums stay in registers).
    const auto range = [&](int i) { return range_m[std::min(i, Ranges - 1)]; };
    const F8 r0 = _mm256_set1_ps(range(0)), r1 = _mm256_set1_ps(range(1));
    const F8 r2 = _mm256_set1_ps(range(2)), r3 = _mm256_set1_ps(range(3));
    const F8 end01 = _mm256_set1_ps(std::max(range(0), range(1)));
    const F8 end23 = _mm256_set1_ps(std::max(range(2), range(3)));
    const F8 zero = _mm256_setzero_ps(), half = _mm256_set1_ps(0.5f);
    BandAccumulator8 s0, s1, s2, s3;
    // Eight puffs, their fields given by load(field).
    const auto eight = [&](const auto& load) __attribute__((target("avx2"), always_inline)) {
        const F8 qx = load(kQx), qy = load(kQy), qz = load(kQz);
        const F8 ivh = load(kIvh), ivz = load(kIvz);
        const F8 A = _mm256_add_ps(_mm256_mul_ps(dh2, ivh), _mm256_mul_ps(dz2, ivz));
        const F8 B = _mm256_add_ps(
            _mm256_mul_ps(_mm256_add_ps(_mm256_mul_ps(dx, qx), _mm256_mul_ps(dy, qy)), ivh),
            _mm256_mul_ps(_mm256_mul_ps(dz, qz), ivz));
        const F8 sStar = _mm256_sub_ps(zero, _mm256_div_ps(B, A));
        const F8 rx = _mm256_add_ps(qx, _mm256_mul_ps(sStar, dx));
        const F8 ry = _mm256_add_ps(qy, _mm256_mul_ps(sStar, dy));
        const F8 rz = _mm256_add_ps(qz, _mm256_mul_ps(sStar, dz));
        const F8 m2 = _mm256_add_ps(
            _mm256_mul_ps(_mm256_add_ps(_mm256_mul_ps(rx, rx), _mm256_mul_ps(ry, ry)), ivh),
            _mm256_mul_ps(_mm256_mul_ps(rz, rz), ivz));
        const F8 inside = _mm256_cmp_ps(m2, load(kCutoff2), _CMP_LE_OS);
        const F8 nearest = load(kNear);
        // Per pair of ranges the puffs it uses; any: those some range uses (the erfs' shortcut
        // gives ±1 exactly where the full form does, so the wider mask changes no used lane).
        const F8 use01 = _mm256_and_ps(inside, _mm256_cmp_ps(nearest, end01, _CMP_LT_OS));
        F8 use23 = use01, any = use01;
        if constexpr (Ranges == 4) {
            use23 = _mm256_and_ps(inside, _mm256_cmp_ps(nearest, end23, _CMP_LT_OS));
            any = _mm256_or_ps(use01, use23);
        }
        if (_mm256_movemask_ps(any) == 0) return;
        const F8 scale = _mm256_sqrt_ps(_mm256_mul_ps(half, A));
        const F8 u0 = _mm256_sub_ps(zero, _mm256_mul_ps(sStar, scale));
        const F8 amplitude = _mm256_div_ps(
            _mm256_mul_ps(load(kKappa), Exp8(_mm256_mul_ps(_mm256_set1_ps(-0.5f), m2))), scale);
        const F8 e0 = ErfOrSign8(u0, any);
        const F8 w[5] = {load(kWs), load(kWAbsT), load(kWHot), load(kWHotT), load(kWg)};
        const auto to = [&](F8 r, F8 use, BandAccumulator8 & sums)
            __attribute__((target("avx2"), always_inline)) {
            const F8 e = ErfOrSign8(_mm256_add_ps(u0, _mm256_mul_ps(r, scale)), any);
            sums.Add(w, use, _mm256_mul_ps(amplitude, _mm256_sub_ps(e, e0)));
        };
        to(r0, use01, s0);
        if constexpr (Ranges >= 2) to(r1, use01, s1);
        if constexpr (Ranges == 4) to(r2, use23, s2), to(r3, use23, s3);
    };
    if constexpr (Copied) {
        // Whole groups: the last one of four puffs holds the inert puff in its high lanes (Copy
        // pads it), the values the last group of four below gives.
        const float* group = l.data.data();
        for (size_t k = 0; k < l.index.size(); k += kGroupPuffs, group += kGroupFloats)
            eight([&](int f) __attribute__((target("avx2"), always_inline)) {
                return _mm256_loadu_ps(group + size_t(f) * kGroupPuffs);
            });
    } else {
        size_t k = 0;
        for (; k + 8 <= l.index.size(); k += 8) {
            F8 fields[kPuffRecord];
            TransposeRecords8(puffData_.data(), l.index.data() + k, fields);
            eight([&](int f) __attribute__((target("avx2"), always_inline)) { return fields[f]; });
        }
        // A last group of four (lists hold a multiple of four): in the low lanes, the inert
        // puff in the high ones (unused, so they add zeros to the odd groups' sums).
        if (k < l.index.size())
            eight([&](int f) __attribute__((target("avx2"), always_inline)) {
                return _mm256_insertf128_ps(_mm256_castps128_ps256(Load4<false>(
                                                nullptr, puffData_.data(), l.index.data(), k, f)),
                                            _mm_set1_ps(puffData_[inert_ * kStride + size_t(f)]),
                                            1);
            });
    }
    const auto result = [](const BandAccumulator8& sums) __attribute__((target("avx2"))) {
        BandAccumulator lo, hi;
        sums.Split(lo, hi);
        return Result(lo, hi);
    };
    out[0] = result(s0);
    if constexpr (Ranges >= 2) out[1] = result(s1);
    if constexpr (Ranges == 4) out[2] = result(s2), out[3] = result(s3);
}
#endif

#ifdef SEASENSE_PLUME_WIDE
namespace {

// Copy of one group: the eight records' fields transposed (AVX2).
__attribute__((target("avx2"))) void CopyGroup8(const float* records, const uint32_t* index,
                                                float* out) {
    F8 fields[kPuffRecord];
    TransposeRecords8(records, index, fields);
    for (size_t f = 0; f < kPuffRecord; ++f) _mm256_storeu_ps(out + f * kGroupPuffs, fields[f]);
}

}  // namespace
#endif

void PlumeScreenBins::Copy(List& list) const {
    static_assert(size_t(kStride) == kPuffRecord);
    if (list.copied) return;
    const size_t n = list.index.size();  // a multiple of 4
    const size_t groups = (n + kGroupPuffs - 1) / kGroupPuffs;
    list.data.resize(groups * kGroupFloats);
    for (size_t g = 0; g < groups; ++g) {
        // The group's puffs, a last group of four padded with the inert puff.
        const uint32_t* index = list.index.data() + g * kGroupPuffs;
        uint32_t padded[kGroupPuffs];
        if (n - g * kGroupPuffs < kGroupPuffs) {
            std::fill(std::begin(padded), std::end(padded), inert_);
            std::copy(index, index + (n - g * kGroupPuffs), padded);
            index = padded;
        }
        float* out = list.data.data() + g * kGroupFloats;
#ifdef SEASENSE_PLUME_WIDE
        if (wide_) {
            CopyGroup8(puffData_.data(), index, out);
            continue;
        }
#endif
        // Four puffs at a time: each block of four fields of their records transposed into
        // four fields of four puffs (SSE2 shuffles: the values are moved, not changed).
        for (size_t half = 0; half < kGroupPuffs; half += 4) {
            const float* rec[4];
            for (size_t l = 0; l < 4; ++l)
                rec[l] = puffData_.data() + size_t(index[half + l]) * kStride;
            for (size_t f0 = 0; f0 < kPuffRecord; f0 += 4) {
                __m128 r0 = _mm_loadu_ps(rec[0] + f0), r1 = _mm_loadu_ps(rec[1] + f0);
                __m128 r2 = _mm_loadu_ps(rec[2] + f0), r3 = _mm_loadu_ps(rec[3] + f0);
                _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
                const __m128 fields[4] = {r0, r1, r2, r3};
                for (size_t f = f0; f < f0 + 4; ++f)
                    _mm_storeu_ps(out + f * kGroupPuffs + half, fields[f - f0]);
            }
        }
    }
    list.copied = true;
}

// Four puffs at a time. Per puff, along the ray the exponent of the Gaussian is
// −(A s² + 2 B s + C) / 2, so ∫ over [0, S] = e^(−m²/2) (√π / 2) / √(A/2) · (erf u1 − erf u0),
// m² the squared Mahalanobis distance of the closest approach s* = −B / A, u0 = −s* √(A/2),
// u1 = u0 + S √(A/2).
void PlumeScreenBins::Trace2(const List& list, const glm::vec3& dir, float range_m, float range2_m,
                             BandTrace& first, BandTrace& second) const {
    if (range2_m == range_m) {
        first = Trace(list, dir, range_m);
        second = first;
        return;
    }
    const float range[2] = {range_m, range2_m};
    BandTrace out[2];
    TraceRanges<2>(list, dir, range, out);
    first = out[0], second = out[1];
}

void PlumeScreenBins::Trace4(const List& list, const glm::vec3& dir, const float (&range_m)[4],
                             BandTrace (&out)[4]) const {
    TraceRanges<4>(list, dir, range_m, out);
}

template <bool Copied, int Ranges>
void PlumeScreenBins::TraceImpl(const List& l, const glm::vec3& dir, const float* range_m,
                                BandTrace* out) const {
    static_assert(Ranges == 1 || Ranges == 2 || Ranges == 4);
    const auto load = [&](int f, size_t k) {
        return Load4<Copied>(l.data.data(), puffData_.data(), l.index.data(), k, f);
    };
#ifdef SEASENSE_PLUME_WIDE
    if (wide_) {
        TraceWide<Copied, Ranges>(l, dir, range_m, out);
        return;
    }
#endif
    // The even groups' sums and the odd groups'.
    BandAccumulator even[Ranges], odd[Ranges];
    size_t k = 0;
    const F4 dx = _mm_set1_ps(dir.x), dy = _mm_set1_ps(dir.y), dz = _mm_set1_ps(dir.z);
    const F4 dh2 = _mm_set1_ps(dir.x * dir.x + dir.y * dir.y), dz2 = _mm_set1_ps(dir.z * dir.z);
    const auto range = [&](int i) { return range_m[std::min(i, Ranges - 1)]; };
    const F4 end01 = _mm_set1_ps(std::max(range(0), range(1)));
    const F4 end23 = _mm_set1_ps(std::max(range(2), range(3)));
    const F4 zero = _mm_setzero_ps(), half = _mm_set1_ps(0.5f);
    // One group of four puffs from k on, into sums.
    const auto group = [&](size_t k, BandAccumulator(&sums)[Ranges])
        __attribute__((always_inline)) {
        const F4 qx = load(kQx, k), qy = load(kQy, k), qz = load(kQz, k);
        const F4 ivh = load(kIvh, k), ivz = load(kIvz, k);
        const F4 A = _mm_add_ps(_mm_mul_ps(dh2, ivh), _mm_mul_ps(dz2, ivz));
        const F4 B = _mm_add_ps(_mm_mul_ps(_mm_add_ps(_mm_mul_ps(dx, qx), _mm_mul_ps(dy, qy)), ivh),
                                _mm_mul_ps(_mm_mul_ps(dz, qz), ivz));
        // The offset at the closest approach rather than C − B²/A, which cancels
        // catastrophically in float for far rays.
        const F4 sStar = _mm_sub_ps(zero, _mm_div_ps(B, A));
        const F4 rx = _mm_add_ps(qx, _mm_mul_ps(sStar, dx));
        const F4 ry = _mm_add_ps(qy, _mm_mul_ps(sStar, dy));
        const F4 rz = _mm_add_ps(qz, _mm_mul_ps(sStar, dz));
        const F4 m2 =
            _mm_add_ps(_mm_mul_ps(_mm_add_ps(_mm_mul_ps(rx, rx), _mm_mul_ps(ry, ry)), ivh),
                       _mm_mul_ps(_mm_mul_ps(rz, rz), ivz));
        const F4 inside = _mm_cmple_ps(m2, load(kCutoff2, k));
        const F4 nearest = load(kNear, k);
        const F4 use01 = _mm_and_ps(inside, _mm_cmplt_ps(nearest, end01));
        F4 use23 = use01, any = use01;
        if constexpr (Ranges == 4) {
            use23 = _mm_and_ps(inside, _mm_cmplt_ps(nearest, end23));
            any = _mm_or_ps(use01, use23);
        }
        if (_mm_movemask_ps(any) == 0) return;
        const F4 scale = _mm_sqrt_ps(_mm_mul_ps(half, A));
        const F4 u0 = _mm_sub_ps(zero, _mm_mul_ps(sStar, scale));
        const F4 amplitude = _mm_div_ps(
            _mm_mul_ps(load(kKappa, k), Exp4(_mm_mul_ps(_mm_set1_ps(-0.5f), m2))), scale);
        const F4 e0 = ErfOrSign4(u0);
        const F4 w[5] = {load(kWs, k), load(kWAbsT, k), load(kWHot, k), load(kWHotT, k),
                         load(kWg, k)};
        for (int i = 0; i < Ranges; ++i) {
            const F4 e = ErfOrSign4(_mm_add_ps(u0, _mm_mul_ps(_mm_set1_ps(range(i)), scale)));
            const F4 tau = _mm_mul_ps(amplitude, _mm_sub_ps(e, e0));
            const F4 use = i < 2 ? use01 : use23;
            sums[i].Add(w, _mm_and_ps(_mm_and_ps(use, _mm_cmpgt_ps(tau, zero)), tau));
        }
    };
    // The even groups into the first accumulators, the odd ones into the second (k is a
    // multiple of 8 here).
    for (; k < l.index.size(); k += 8) {
        group(k, even);
        if (k + 4 < l.index.size()) group(k + 4, odd);
    }
    for (int i = 0; i < Ranges; ++i) out[i] = Result(even[i], odd[i]);
}

BandTrace PlumeScreenBins::Trace(const List& list, const glm::vec3& dir, float range_m) const {
    BandTrace t;
    TraceRanges<1>(list, dir, &range_m, &t);
    return t;
}

}  // namespace seasense::channels
