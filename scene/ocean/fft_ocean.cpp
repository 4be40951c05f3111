// FFT ocean synthesis after Tessendorf, "Simulating Ocean Water" (2001), §3.3–3.5, with
// cascades, finite-depth dispersion and orbits, and counter-based random amplitudes.
#include "scene/ocean/fft_ocean.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>

#include "scene/core/check.h"
#include "scene/core/error.h"
#include "scene/core/rng.h"
#include "scene/ocean/gerstner.h"

namespace seasense::scene {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
// Stream of the random numbers: a fixed tag so other users of the seed draw other numbers.
constexpr uint64_t kOceanStream = 0x6f6365616e464654ULL;  // "oceanFFT"
// Rows of the spectrum filled per task.
constexpr int kRowsPerTask = 16;

bool IsPowerOfTwo(int n) { return n > 0 && (n & (n - 1)) == 0; }

void Validate(const FftOceanSettings& s, bool patchSizesRequired) {
    std::ostringstream why;
    if (!IsPowerOfTwo(s.gridSize) || s.gridSize < 16 || s.gridSize > 2048)
        why << "grid size " << s.gridSize << " is not a power of two in [16, 2048]";
    else if (!(s.choppiness >= 0.0 && s.choppiness <= 10.0))
        why << "choppiness " << s.choppiness << " is not in [0, 10]";
    else if (s.patchSizes_m.empty() && (s.cascadeCount < 1 || s.cascadeCount > 8))
        why << "cascade count " << s.cascadeCount << " is not in [1, 8]";
    else if (s.patchSizes_m.empty() && patchSizesRequired)
        why << "patch sizes are required with a density of one's own";
    else if (s.patchSizes_m.size() > 8)
        why << s.patchSizes_m.size() << " patch sizes given; at most 8";
    for (size_t i = 0; why.str().empty() && i < s.patchSizes_m.size(); ++i) {
        const double l = s.patchSizes_m[i];
        if (!(std::isfinite(l) && l > 0.0))
            why << "patch size " << l << " m is not a finite number > 0";
        else if (i > 0 &&
                 !(l < s.patchSizes_m[i - 1] && s.patchSizes_m[i - 1] / l < 0.5 * s.gridSize))
            why << "patch sizes " << s.patchSizes_m[i - 1] << " m then " << l
                << " m: each must be smaller than the one before, by a ratio below N/2 = "
                << s.gridSize / 2;
    }
    if (!why.str().empty()) throw InputError("FFT ocean: " + why.str());
}

// Standard normal pair (Box–Muller) for a mode, a pure function of seed, cascade and the signed
// mode indices: the same wave gets the same amplitude whatever the grid size.
std::complex<double> GaussianPair(uint64_t seed, size_t cascade, int mx, int my) {
    const uint64_t counter = (uint64_t(uint32_t(mx)) << 32) | uint64_t(uint32_t(my));
    const uint64_t stream = kOceanStream + 2 * uint64_t(cascade);
    const double u1 = 1.0 - Uniform01(seed, stream, counter);  // (0, 1]
    const double u2 = Uniform01(seed, stream + 1, counter);
    const double r = std::sqrt(-2.0 * std::log(u1));
    return {r * std::cos(kTwoPi * u2), r * std::sin(kTwoPi * u2)};
}

}  // namespace

// ---- settings ---------------------------------------------------------------------------------

SpectralOceanSettings ReadSpectralOceanSettings(ConfigMap& map,
                                                const SpectralOceanSettings& defaults) {
    SpectralOceanSettings s = defaults;
    s.sea = ReadSeaStateSettings(map, defaults.sea);
    if (std::optional<ConfigMap> fft = map.FindMap("fft")) {
        FftOceanSettings& f = s.fft;
        if (const std::optional<ConfigValue> grid = fft->Find("grid_size")) {
            f.gridSize = int(grid->AsInt(16, 2048));
            if (!IsPowerOfTwo(f.gridSize))
                grid->Fail("a power of two in [16, 2048] (e.g. 128, 256, 512)");
        }
        if (const std::optional<ConfigValue> sizes = fft->Find("patch_sizes_m")) {
            f.patchSizes_m.clear();
            for (const ConfigValue& item : sizes->AsList(1, 8, "numbers (m)")) {
                const double l = item.AsDouble(NumberRange::OpenClosed(0.0, 1.0e5, "m"));
                if (!f.patchSizes_m.empty() &&
                    !(l < f.patchSizes_m.back() && f.patchSizes_m.back() / l < 0.5 * f.gridSize))
                    item.Fail("a patch size below " + FormatNumber(f.patchSizes_m.back()) +
                              " m and above " +
                              FormatNumber(f.patchSizes_m.back() / (0.5 * f.gridSize)) +
                              " m (decreasing, ratio below grid_size / 2)");
                f.patchSizes_m.push_back(l);
            }
        }
        f.cascadeCount = int(fft->GetInt("cascades", 1, 8, f.cascadeCount));
        f.choppiness = fft->GetDouble("choppiness", NumberRange::Closed(0.0, 10.0), f.choppiness);
        f.seed =
            uint64_t(fft->GetInt("seed", 0, std::numeric_limits<int64_t>::max(), int64_t(f.seed)));
        fft->Finish();
    }
    return s;
}

SpectralOceanSettings ReadSpectralOceanSettings(const ConfigValue& value,
                                                const SpectralOceanSettings& defaults) {
    return ReadMap(value, [&](ConfigMap& map) { return ReadSpectralOceanSettings(map, defaults); });
}

std::vector<double> DefaultPatchSizes(const WaveSpectrum& spectrum, int cascadeCount) {
    CHECK(cascadeCount >= 1);
    std::vector<double> sizes{std::max(250.0, 10.0 * spectrum.LongestPeakWavelength_m())};
    for (int i = 1; i < cascadeCount; ++i) sizes.push_back(sizes.back() * 37.0 / 250.0);
    return sizes;
}

// ---- synthesis --------------------------------------------------------------------------------

FftOcean::FftOcean(const WaveSpectrum& spectrum, const FftOceanSettings& settings)
    : depth_m_(spectrum.Settings().depth_m) {
    Validate(settings, false);
    FftOceanSettings s = settings;
    if (s.patchSizes_m.empty()) s.patchSizes_m = DefaultPatchSizes(spectrum, s.cascadeCount);
    Build([&spectrum](double kx, double ky) { return spectrum.DensityK(kx, ky); }, s);
}

FftOcean::FftOcean(const Density& density, double depth_m, const FftOceanSettings& settings)
    : depth_m_(depth_m) {
    if (!(std::isfinite(depth_m) && depth_m > 0.0))
        throw InputError("FFT ocean: depth " + FormatNumber(depth_m) + " m is not > 0");
    Validate(settings, true);
    Build(density, settings);
}

size_t FftOcean::Index(int mx, int my) const {
    // Signed mode index → FFT storage order (negative frequencies after the positive ones).
    const int ix = mx < 0 ? mx + n_ : mx, iy = my < 0 ? my + n_ : my;
    return size_t(iy) * size_t(n_) + size_t(ix);
}

void FftOcean::Build(const Density& density, const FftOceanSettings& s) {
    n_ = s.gridSize;
    choppiness_ = s.choppiness;
    const size_t cascadeCount = s.patchSizes_m.size();
    // Band edges between neighbouring cascades: the geometric mean of the larger patch's
    // Nyquist wavenumber πN/L_i and the smaller patch's fundamental 2π/L_{i+1}, balancing the
    // spatial sampling of the one against the spectral resolution of the other; every
    // wavenumber belongs to exactly one cascade.
    for (size_t c = 0; c < cascadeCount; ++c) {
        CascadeBand band;
        band.patch_m = s.patchSizes_m[c];
        band.kMin_radpm = c == 0 ? 0.0 : bands_.back().kMax_radpm;
        band.kMax_radpm =
            c + 1 < cascadeCount
                ? std::sqrt(std::numbers::pi * n_ / band.patch_m * kTwoPi / s.patchSizes_m[c + 1])
                : std::numbers::pi * n_ / band.patch_m;  // a disc: isotropic
        bands_.push_back(band);
    }

    const int half = n_ / 2;
    const size_t count = size_t(n_) * size_t(n_);
    modes_.resize(cascadeCount);
    modeVariance_m2_ = 0.0;
    for (size_t c = 0; c < cascadeCount; ++c) {
        const CascadeBand& band = bands_[c];
        const double dk = kTwoPi / band.patch_m;
        Modes& m = modes_[c];
        m.h0.assign(count, 0.0f);
        m.h0MinusConj.assign(count, 0.0f);
        m.omega.assign(count, 0.0);
        m.kx.assign(count, 0.0f);
        m.ky.assign(count, 0.0f);
        m.chop.assign(count, 0.0f);
        // Rows are independent: evaluate the density (the costly part) in parallel, then sum
        // the variance serially in a fixed order.
        std::vector<double> variance(count, 0.0);
        tbb::parallel_for(
            tbb::blocked_range<int>(-half, half), [&](const tbb::blocked_range<int>& r) {
                for (int my = r.begin(); my != r.end(); ++my) {
                    for (int mx = -half; mx < half; ++mx) {
                        const size_t i = Index(mx, my);
                        const double kx = mx * dk, ky = my * dk, k = std::hypot(kx, ky);
                        m.kx[i] = float(kx);
                        m.ky[i] = float(ky);
                        // DC carries no wave; the Nyquist row and column have no distinct −k.
                        if (k == 0.0 || mx == -half || my == -half) continue;
                        m.omega[i] = DispersionOmega(k, depth_m_);
                        m.chop[i] = float(1.0 / (k * std::tanh(k * depth_m_)));
                        if (k < band.kMin_radpm || k >= band.kMax_radpm) continue;
                        const double f = density(kx, ky);
                        CHECK_MSG(std::isfinite(f) && f >= 0.0, "spectral density "
                                                                    << f << " at k = (" << kx
                                                                    << ", " << ky << ")");
                        variance[i] = f * dk * dk;
                        // E|h0|² = ½ F Δk², so that h0(k) and conj(h0(−k)) together carry F Δk².
                        m.h0[i] = std::complex<float>(GaussianPair(s.seed, c, mx, my) *
                                                      (0.5 * std::sqrt(variance[i])));
                    }
                }
            });
        maxRow_.push_back(0);
        std::vector<std::pair<double, double>> slope;  // (k, k² F Δk²), for the median
        for (int my = -half; my < half; ++my)
            for (int mx = -half; mx < half; ++mx) {
                const size_t i = Index(mx, my);
                modeVariance_m2_ += variance[i];
                bands_[c].variance_m2 += variance[i];
                if (variance[i] > 0.0) {
                    const double k2 = double(m.kx[i]) * m.kx[i] + double(m.ky[i]) * m.ky[i];
                    slope.emplace_back(std::sqrt(k2), k2 * variance[i]);
                }
                if (variance[i] > 0.0) maxRow_.back() = std::max(maxRow_.back(), std::abs(my));
                if (mx != -half && my != -half) m.h0MinusConj[i] = std::conj(m.h0[Index(-mx, -my)]);
            }
        std::sort(slope.begin(), slope.end());
        double slopeTotal = 0.0, slopeSum = 0.0;
        for (const auto& [k, v] : slope) slopeTotal += v;
        for (const auto& [k, v] : slope) {
            slopeSum += v;
            if (slopeSum >= 0.5 * slopeTotal) {
                bands_[c].slopeMedian_radpm = k;
                break;
            }
        }
    }
}

std::complex<double> FftOcean::HeightMode(size_t cascade, int mx, int my, double t) const {
    CHECK(cascade < modes_.size() && mx >= -n_ / 2 && mx < n_ / 2 && my >= -n_ / 2 && my < n_ / 2);
    const Modes& m = modes_[cascade];
    const size_t i = Index(mx, my);
    const std::complex<double> e = std::polar(1.0, -m.omega[i] * t);
    return std::complex<double>(m.h0[i]) * e +
           std::complex<double>(m.h0MinusConj[i]) * std::conj(e);
}

FftOceanFrame FftOcean::Synthesize(double t) const {
    FftOceanFrame frame;
    Synthesize(t, frame);
    return frame;
}

void FftOcean::Synthesize(double t, FftOceanFrame& frame, bool withRates) const {
    CHECK(std::isfinite(t));
    const size_t cascadeCount = modes_.size();
    const int planeCount =
        withRates ? FftOceanFrame::kPlanes : FftOceanFrame::kPlanes - FftOceanFrame::kRatePlanes;
    frame.n_ = n_;
    frame.choppiness_ = choppiness_;
    frame.t_s_ = t;
    frame.hasRates_ = withRates;
    frame.cascades_.resize(cascadeCount);
    for (size_t c = 0; c < cascadeCount; ++c) {
        FftOceanFrame::Cascade& fc = frame.cascades_[c];
        fc.patch_m = bands_[c].patch_m;
        for (int p = 0; p < planeCount; ++p) {
            fc.spectrum[p].create(n_, n_, CV_32FC2);
            fc.scratch[p].create(n_, n_, CV_32FC2);
            fc.field[p].create(n_, n_, CV_32FC2);
        }
    }

    // 1. Spectra of the eleven fields at time t, packed two real fields per complex plane:
    //    a field with Hermitian spectrum F is real, so IDFT(F1 + i F2) = f1 + i f2.
    const int rowTasks = (n_ + kRowsPerTask - 1) / kRowsPerTask;
    tbb::parallel_for(0, int(cascadeCount) * rowTasks, [&](int task) {
        const size_t c = size_t(task / rowTasks);
        const int row0 = (task % rowTasks) * kRowsPerTask, row1 = std::min(n_, row0 + kRowsPerTask);
        const Modes& m = modes_[c];
        std::array<cv::Mat, FftOceanFrame::kPlanes>& planes = frame.cascades_[c].spectrum;
        using C = std::complex<float>;
        const C i1(0.0f, 1.0f);
        for (int iy = row0; iy < row1; ++iy) {
            // Rows outside the band (|my| > maxRow) are never read by the transform.
            if (std::min(iy, n_ - iy) > maxRow_[c]) continue;
            std::array<C*, FftOceanFrame::kPlanes> out{};
            for (int p = 0; p < planeCount; ++p) out[p] = planes[p].ptr<C>(iy);
            for (int ix = 0; ix < n_; ++ix) {
                const size_t i = size_t(iy) * size_t(n_) + size_t(ix);
                const C a = m.h0[i], b = m.h0MinusConj[i];
                if (a == C(0.0f) && b == C(0.0f)) {
                    for (int p = 0; p < planeCount; ++p) out[p][ix] = C(0.0f);
                    continue;
                }
                // e^{−iωt} with the phase reduced in double so float keeps it at any time.
                double phase = m.omega[i] * t;
                phase -= kTwoPi * std::nearbyint(phase / kTwoPi);
                const float cs = std::cos(float(phase)), sn = std::sin(float(phase));
                const C e(cs, -sn), ec(cs, sn);
                const C h = a * e + b * ec;
                const float kx = m.kx[i], ky = m.ky[i], q = m.chop[i];
                // Choppy displacement D = Σ i k̂ coth(kh) h e^{ik·x}: toward the crests, the
                // linear-theory surface orbit (Tessendorf's −i with his time sign convention).
                const C dx = i1 * (kx * q) * h, dy = i1 * (ky * q) * h;
                const C dxx = -(kx * kx * q) * h, dyy = -(ky * ky * q) * h;
                const C dxy = -(kx * ky * q) * h;
                const C sx = i1 * kx * h, sy = i1 * ky * h;
                out[0][ix] = h + i1 * dx;
                out[1][ix] = dy + i1 * sx;
                out[2][ix] = sy + i1 * dxx;
                out[3][ix] = dyy + i1 * dxy;
                if (!withRates) continue;
                // ∂h/∂t = −iω (h0 e^{−iωt} − conj(h0(−k)) e^{iωt}).
                const C ht = -i1 * float(m.omega[i]) * (a * e - b * ec);
                const C dxt = i1 * (kx * q) * ht, dyt = i1 * (ky * q) * ht;
                out[4][ix] = ht + i1 * dxt;
                out[5][ix] = dyt;
            }
        }
    });

    // 2. Unscaled inverse DFTs, η(x) = Σ_k h(k) e^{+ik·x}, one task per plane, done as two
    //    passes of 1-D row transforms around a transpose: the rows outside the cascade's band
    //    are zero and skipped in the first pass, and row transforms avoid OpenCV's slower
    //    column pass. The field is left transposed (row index x, column index y).
    tbb::parallel_for(0, int(cascadeCount) * planeCount, [&](int task) {
        const size_t c = size_t(task / planeCount);
        FftOceanFrame::Cascade& fc = frame.cascades_[c];
        const int p = task % planeCount;
        const int m = maxRow_[c];
        constexpr int kFlags = cv::DFT_INVERSE | cv::DFT_COMPLEX_OUTPUT | cv::DFT_ROWS;
        cv::Mat& rows = fc.scratch[p];
        if (n_ - m > m + 1) rows.rowRange(m + 1, n_ - m).setTo(cv::Scalar::all(0.0));
        // Rows my = 0..m and my = −m..−1 (stored at N − m .. N − 1).
        cv::Mat head = rows.rowRange(0, m + 1), tail = rows.rowRange(n_ - m, n_);
        cv::dft(fc.spectrum[p].rowRange(0, m + 1), head, kFlags);
        if (m > 0) cv::dft(fc.spectrum[p].rowRange(n_ - m, n_), tail, kFlags);
        cv::transpose(rows, fc.spectrum[p]);
        cv::dft(fc.spectrum[p], fc.field[p], kFlags);
    });
}

// ---- queries ----------------------------------------------------------------------------------

float FftOceanFrame::Field(size_t cascade, OceanField field, int ix, int iy) const {
    CHECK(cascade < cascades_.size() && ix >= 0 && ix < n_ && iy >= 0 && iy < n_);
    const int f = int(field);
    CHECK_MSG(hasRates_ || f / 2 < kPlanes - kRatePlanes, "rate field of a geometry-only frame");
    const cv::Vec2f v = cascades_[cascade].field[f / 2].at<cv::Vec2f>(ix, iy);  // transposed
    return v[f % 2];
}

namespace {
constexpr uint32_t kFrameTag = 0x46414553;  // "SEAF"
// Tag, grid size, cascades, rates flag; choppiness and time; per cascade its patch size.
constexpr size_t kFrameHeaderBytes = 4 * sizeof(uint32_t) + 2 * sizeof(double);
}  // namespace

size_t FftOceanFrame::EncodedBytesFor(int n, size_t cascades, bool withRates) {
    const size_t planes = size_t(withRates ? kPlanes : kPlanes - kRatePlanes);
    return kFrameHeaderBytes +
           cascades * (sizeof(double) + planes * size_t(n) * size_t(n) * sizeof(cv::Vec2f));
}

size_t FftOceanFrame::EncodedBytes() const {
    return EncodedBytesFor(n_, cascades_.size(), hasRates_);
}

void FftOceanFrame::Encode(uint8_t* out) const {
    const auto put = [&out](const auto& v) {
        std::memcpy(out, &v, sizeof v);
        out += sizeof v;
    };
    put(kFrameTag);
    put(uint32_t(n_));
    put(uint32_t(cascades_.size()));
    put(uint32_t(hasRates_));
    put(choppiness_);
    put(t_s_);
    const int planes = hasRates_ ? kPlanes : kPlanes - kRatePlanes;
    const size_t rowBytes = size_t(n_) * sizeof(cv::Vec2f);
    for (const Cascade& c : cascades_) {
        put(c.patch_m);
        for (int p = 0; p < planes; ++p)
            for (int row = 0; row < n_; ++row, out += rowBytes)
                std::memcpy(out, c.field[size_t(p)].ptr<uint8_t>(row), rowBytes);
    }
}

void FftOceanFrame::Decode(const uint8_t* in, size_t bytes) {
    const auto fail = [&](const std::string& what) {
        throw RuntimeError("sea fields (" + std::to_string(bytes) + " bytes): " + what);
    };
    if (bytes < kFrameHeaderBytes) fail("shorter than their header");
    const auto get = [&in](auto& v) {
        std::memcpy(&v, in, sizeof v);
        in += sizeof v;
    };
    uint32_t tag = 0, n = 0, cascades = 0, rates = 0;
    get(tag), get(n), get(cascades), get(rates);
    if (tag != kFrameTag) fail("bad tag");
    if (n == 0 || n > (1u << 14) || cascades > 64 || rates > 1) fail("bad grid");
    if (EncodedBytesFor(int(n), cascades, rates != 0) != bytes)
        fail("expected " + std::to_string(EncodedBytesFor(int(n), cascades, rates != 0)) +
             " bytes for " + std::to_string(cascades) + " cascades of " + std::to_string(n) +
             "² nodes");
    n_ = int(n);
    hasRates_ = rates != 0;
    get(choppiness_), get(t_s_);
    cascades_.resize(cascades);
    const int planes = hasRates_ ? kPlanes : kPlanes - kRatePlanes;
    const size_t rowBytes = size_t(n_) * sizeof(cv::Vec2f);
    for (Cascade& c : cascades_) {
        get(c.patch_m);
        for (int p = 0; p < planes; ++p) {
            c.field[size_t(p)].create(n_, n_, CV_32FC2);
            for (int row = 0; row < n_; ++row, in += rowBytes)
                std::memcpy(c.field[size_t(p)].ptr<uint8_t>(row), in, rowBytes);
        }
    }
}

const cv::Mat& FftOceanFrame::FieldPlane(size_t cascade, int plane) const {
    CHECK(cascade < cascades_.size() && plane >= 0 && plane < kPlanes);
    CHECK_MSG(hasRates_ || plane < kPlanes - kRatePlanes, "rate plane of a geometry-only frame");
    return cascades_[cascade].field[size_t(plane)];
}

SurfaceTerms FftOceanFrame::Terms(double x0, double y0, const double* cascadeWeights) const {
    CHECK_MSG(!cascades_.empty(), "FftOceanFrame used before FftOcean::Synthesize filled it");
    const int planes = hasRates_ ? kPlanes : kPlanes - kRatePlanes;
    std::array<double, 2 * kPlanes> sum{};
    for (size_t ci = 0; ci < cascades_.size(); ++ci) {
        const Cascade& c = cascades_[ci];
        // × 1 is exact: unweighted cascades add the same bits as without weights.
        const double cw = cascadeWeights ? cascadeWeights[ci] : 1.0;
        if (cw == 0.0) continue;
        // Grid node j lies at j L / N; bilinear weights within the periodic cell.
        const double u = x0 / c.patch_m * n_, v = y0 / c.patch_m * n_;
        const double fu = std::floor(u), fv = std::floor(v);
        const double wx = u - fu, wy = v - fv;
        const int ix0 = int(fu - n_ * std::floor(fu / n_)),
                  iy0 = int(fv - n_ * std::floor(fv / n_));
        const int ix1 = (ix0 + 1) & (n_ - 1), iy1 = (iy0 + 1) & (n_ - 1);
        const double w00 = (1 - wx) * (1 - wy), w10 = wx * (1 - wy), w01 = (1 - wx) * wy,
                     w11 = wx * wy;
        for (int p = 0; p < planes; ++p) {
            // Fields are stored transposed: row ix, column iy.
            const cv::Mat& m = c.field[p];
            const cv::Vec2f* r0 = m.ptr<cv::Vec2f>(ix0);
            const cv::Vec2f* r1 = m.ptr<cv::Vec2f>(ix1);
            for (int q = 0; q < 2; ++q)
                sum[2 * p + q] += cw * (w00 * r0[iy0][q] + w10 * r1[iy0][q] + w01 * r0[iy1][q] +
                                        w11 * r1[iy1][q]);
        }
    }
    const auto f = [&](OceanField field) { return sum[size_t(field)]; };
    const double l = choppiness_;
    SurfaceTerms t;
    t.displacement = {l * f(OceanField::DispX), l * f(OceanField::DispY), f(OceanField::Height)};
    t.dxx = l * f(OceanField::DispXX);
    t.dyy = l * f(OceanField::DispYY);
    t.dxy = l * f(OceanField::DispXY);
    t.sx = f(OceanField::SlopeX);
    t.sy = f(OceanField::SlopeY);
    t.velocity_mps = hasRates_ ? glm::dvec3(l * f(OceanField::DispXRate),
                                            l * f(OceanField::DispYRate), f(OceanField::HeightRate))
                               : glm::dvec3(std::numeric_limits<double>::quiet_NaN());
    return t;
}

OceanSample FftOceanFrame::SampleAt(double x, double y) const {
    return InvertHorizontalDisplacement(x, y,
                                        [this](double x0, double y0) { return Evaluate(x0, y0); });
}

}  // namespace seasense::scene
