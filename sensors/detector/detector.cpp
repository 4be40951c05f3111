// Box-footprint detector integration and log-average auto exposure.
#include "sensors/detector/detector.h"

#include <emmintrin.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include "radiometry/color/rec709.h"

namespace seasense::sensors {

Image IntegrateFootprint(const Image& samples, int n) {
    Image out;
    IntegrateFootprint(samples, n, out);
    return out;
}

namespace {

// Sizes `out` for the footprints of `samples` (n×n samples per pixel), reusing its storage
// when the size already matches.
void PrepareFootprint(const Image& samples, int n, Image& out) {
    CHECK(n >= 1);
    CHECK(samples.width % n == 0 && samples.height % n == 0);
    if (out.width != samples.width / n || out.height != samples.height / n ||
        out.channels != samples.channels)
        out = Image(samples.width / n, samples.height / n, samples.channels);
}

// Row y of IntegrateFootprint.
void IntegrateFootprintRow(const Image& samples, int n, Image& out, int y) {
    const int c = samples.channels;
    const float inv = 1.0f / float(n * n);
    const size_t rowValues = size_t(c) * size_t(out.width);
    float* dst = out.At(0, y);
    // Rows of samples are summed in order sy = 0 … n−1, then each pixel's sx in order:
    // the same sums for any thread count.
    if (n == 2 && c == 3) {
        // The default 2×2 RGB case: a pixel's three sums in one SSE2 register (its left
        // and right samples are 3 floats apart; the fourth lane, the next sample's red, is
        // overwritten by the next pixel), scaled here; the same operations as below.
        const float* r0 = samples.At(0, 2 * y);
        const float* r1 = samples.At(0, 2 * y + 1);
        const __m128 scale = _mm_set1_ps(inv);
        int x = 0;
        for (; x + 1 < out.width; ++x) {
            const size_t i = size_t(6 * x);
            const __m128 top = _mm_add_ps(_mm_loadu_ps(r0 + i), _mm_loadu_ps(r0 + i + 3));
            const __m128 bottom = _mm_add_ps(_mm_loadu_ps(r1 + i), _mm_loadu_ps(r1 + i + 3));
            _mm_storeu_ps(dst + 3 * x, _mm_mul_ps(_mm_add_ps(top, bottom), scale));
        }
        for (; x < out.width; ++x)  // the last pixel: no reads or writes past the row
            for (int k = 0; k < 3; ++k) {
                const size_t i = size_t(6 * x + k);
                dst[3 * x + k] = ((r0[i] + r0[i + 3]) + (r1[i] + r1[i + 3])) * inv;
            }
        return;
    }
    for (int sy = 0; sy < n; ++sy) {
        const float* row = samples.At(0, y * n + sy);
        for (int x = 0; x < out.width; ++x) {
            for (int k = 0; k < c; ++k) {
                float sum = row[size_t((x * n) * c + k)];
                for (int sx = 1; sx < n; ++sx) sum += row[size_t((x * n + sx) * c + k)];
                float& d = dst[size_t(x * c + k)];
                d = sy == 0 ? sum : d + sum;
            }
        }
    }
    for (size_t i = 0; i < rowValues; ++i) dst[i] *= inv;
}

// Σ ln(δ + max(Y, 0)) over row y of `rgb`, LogAverageLuminance's row sum.
double RowLogLuminanceSum(const Image& rgb, int y) {
    // Σ ln v = Σ_blocks ln(Π m) + (Σ e) ln 2 for v = m·2^e, m ∈ [1, 2): one logarithm per
    // kBlock pixels instead of one per pixel (the logarithms were ~2.5 % of an OTW frame).
    // v ≥ 1e-4 is a normal double, and a block's product of mantissas lies in [1, 2^16),
    // so it neither overflows nor underflows; it differs from the sum of the logarithms
    // by rounding only (~kBlock ulp of the block's product). Four pixels at a time, each
    // lane of a four-double vector its own chain (lane l: the block's pixels ≡ l mod 4), the
    // lanes multiplied in order at the block's end: the same operations in any build (a
    // vector of four doubles is one AVX register or two SSE2 ones).
    using V4d = double __attribute__((vector_size(32)));
    using V4u = uint64_t __attribute__((vector_size(32)));
    using V4i = int64_t __attribute__((vector_size(32)));
    constexpr int kBlock = 16, kLanes = 4;
    constexpr uint64_t kMantissa = (uint64_t(1) << 52) - 1, kExponentOne = uint64_t(1023) << 52;
    const float* row = rgb.At(0, y);
    const size_t c = size_t(rgb.channels);
    // v = δ + max(Y, 0) of pixel x, Y in double as radiometry::LuminanceRec709.
    const auto value = [&](int x) {
        const float* p = row + size_t(x) * c;
        const double Y = radiometry::LuminanceRec709({p[0], p[1], p[2]});
        return 1e-4 + std::max(Y, 0.0);
    };
    double s = 0.0;
    V4i exponents = {0, 0, 0, 0};
    int64_t tailExponents = 0;
    V4u nonFinite = {0, 0, 0, 0};
    for (int x0 = 0; x0 < rgb.width; x0 += kBlock) {
        const int x1 = std::min(rgb.width, x0 + kBlock);
        V4d product = {1.0, 1.0, 1.0, 1.0};
        int x = x0;
        for (; x + kLanes <= x1; x += kLanes) {
            V4d r, g, b;
            for (int l = 0; l < kLanes; ++l) {
                const float* p = row + size_t(x + l) * c;
                r[l] = p[0], g[l] = p[1], b[l] = p[2];
            }
            const V4d Y = (0.2126 * r + 0.7152 * g) + 0.0722 * b;  // LuminanceRec709
            const V4d v = 1e-4 + (Y < 0.0 ? V4d{} : Y);            // std::max(Y, 0.0) per lane
            const V4u bits = (V4u)v;
            // The exponent field (a NaN may carry the sign bit; a number here is > 0).
            const V4u field = (bits >> 52) & 0x7ff;
            nonFinite |= (V4u)(field == 0x7ff);
            exponents += (V4i)field - 1023;
            product *= (V4d)((bits & kMantissa) | kExponentOne);
        }
        double p = ((product[0] * product[1]) * product[2]) * product[3];
        for (; x < x1; ++x) {  // the row's last pixels, fewer than four
            const uint64_t bits = std::bit_cast<uint64_t>(value(x));
            const uint64_t field = (bits >> 52) & 0x7ff;
            nonFinite[0] |= field == 0x7ff;
            tailExponents += int64_t(field) - 1023;
            p *= std::bit_cast<double>((bits & kMantissa) | kExponentOne);
        }
        s += std::log(p);
    }
    if (nonFinite[0] | nonFinite[1] | nonFinite[2] | nonFinite[3]) {
        // inf or NaN: the sum is too, as Σ ln v would be (and the same one).
        s = 0.0;
        for (int x = 0; x < rgb.width; ++x) s += std::log(value(x));
        return s;
    }
    const int64_t e =
        ((exponents[0] + exponents[1]) + (exponents[2] + exponents[3])) + tailExponents;
    return s + double(e) * std::numbers::ln2;
}

// exp of the mean of the logarithms from the row sums, added serially in row order: the same
// total for any thread count.
double LogAverageOfRowSums(const std::vector<double>& rowSums, const Image& rgb) {
    double total = 0.0;
    for (double s : rowSums) total += s;
    const double count = double(rgb.width) * double(rgb.height);
    return count > 0 ? std::exp(total / count) : 0.0;
}

}  // namespace

void IntegrateFootprint(const Image& samples, int n, Image& out) {
    PrepareFootprint(samples, n, out);
    tbb::parallel_for(0, out.height, [&](int y) { IntegrateFootprintRow(samples, n, out, y); });
}

double IntegrateFootprintLogAverage(const Image& samples, int n, Image& out) {
    CHECK(samples.channels >= 3);
    PrepareFootprint(samples, n, out);
    std::vector<double> rowSums(size_t(out.height), 0.0);
    tbb::parallel_for(0, out.height, [&](int y) {
        IntegrateFootprintRow(samples, n, out, y);
        rowSums[size_t(y)] = RowLogLuminanceSum(out, y);  // the row just written, in L1
    });
    return LogAverageOfRowSums(rowSums, out);
}

double LogAverageLuminance(const Image& rgb) {
    CHECK(rgb.channels >= 3);
    // Row sums first, then a serial sum of rows: the same order for any thread count.
    std::vector<double> rowSums(size_t(rgb.height), 0.0);
    tbb::parallel_for(0, rgb.height,
                      [&](int y) { rowSums[size_t(y)] = RowLogLuminanceSum(rgb, y); });
    return LogAverageOfRowSums(rowSums, rgb);
}

double ExposureEv(double Lavg_cdm2, double key) { return std::log2(key / Lavg_cdm2); }

double AutoExposureEv(const Image& rgb, double key) {
    return ExposureEv(LogAverageLuminance(rgb), key);
}

double AdaptedKey(double Lavg_cdm2) {
    CHECK(Lavg_cdm2 >= 0.0);
    return 1.03 - 2.0 / (2.0 + std::log10(Lavg_cdm2 + 1.0));
}

double AdaptedExposureEv(const Image& rgb) {
    const double Lavg = LogAverageLuminance(rgb);
    return ExposureEv(Lavg, AdaptedKey(Lavg));
}

}  // namespace seasense::sensors
