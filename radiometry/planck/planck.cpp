// Planck radiometry: closed-form band moments (Widger & Woodall 1976), Newton inversion and
// the cubic Hermite lookup table.
#include "radiometry/planck/planck.h"

#include <immintrin.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>

#include "scene/core/error.h"

namespace seasense::radiometry {

namespace {

void RequirePositiveFinite(double value, const char* what, const char* where) {
    if (!(std::isfinite(value) && value > 0.0)) {
        std::ostringstream msg;
        msg << where << ": " << what << " = " << value << "; expected a finite value > 0";
        throw InputError(msg.str());
    }
}

// Beyond this x = c2/(λT) every e^{−x} term underflows double precision.
constexpr double kXUnderflow = 700.0;

// Taylor coefficients B_2k/(2k)! of t/(eᵗ − 1) = Σ B_n tⁿ/n! (Abramowitz & Stegun 1964,
// eq. 23.1.1 and table 23.2), k = 1…13; the odd ones vanish beyond B_1 = −1/2.
constexpr std::array<double, 13> kBernoulliOverFactorial = {
    0.083333333333333329,    -0.0013888888888888889,  3.3068783068783071e-05,
    -8.2671957671957675e-07, 2.08767569878681e-08,    -5.2841901386874932e-10,
    1.3382536530684679e-11,  -3.3896802963225827e-13, 8.5860620562778452e-15,
    -2.1748686985580619e-16, 5.5090028283602295e-18,  -1.3954464685812522e-19,
    3.5347070396294673e-21};

// Bose–Einstein integrals over [0, ∞): ∫ tᵐ/(eᵗ − 1) dt = m! ζ(m + 1) for m = 1, 2, 3:
// π²/6, 2ζ(3) (Apéry's constant ζ(3) = 1.2020569031595942), π⁴/15.
constexpr std::array<double, 4> kBoseTotal = {0.0, 1.6449340668482264, 2.4041138063191885,
                                              6.4939394022668291};

// Upper incomplete Bose integral G_m(x) = ∫ₓ^∞ tᵐ/(eᵗ − 1) dt, m ∈ {1, 2, 3}, x > 0.
// For x ≥ 1 the series Σₙ e^{−nx} Σᵢ m!/(m−i)! x^{m−i}/n^{i+1} (Widger & Woodall, Bull. Am.
// Meteorol. Soc. 57, 1217, 1976; m = 3 is their eq. for ∫₀^λ L_λ dλ) converges like e^{−nx}.
// For x < 1 it would need ~40/x terms, so use the complement m!ζ(m+1) − ∫₀ˣ with the
// Bernoulli expansion ∫₀ˣ tᵐ/(eᵗ − 1) dt = Σ B_n x^{n+m}/(n!(n+m)), convergent for x < 2π.
double BoseTail(int m, double x) {
    if (x >= kXUnderflow) return 0.0;
    if (x >= 1.0) {
        const double q = std::exp(-x);
        double sum = 0.0, qn = 1.0;
        for (int n = 1; n <= 200; ++n) {
            qn *= q;
            const double invN = 1.0 / n;
            // Horner form of Σᵢ m!/(m−i)! x^{m−i} n^{−i−1}.
            double poly = 0.0;
            if (m == 1) poly = invN * (x + invN);
            if (m == 2) poly = invN * (x * x + invN * (2.0 * x + invN * 2.0));
            if (m == 3)
                poly = invN * (x * x * x + invN * (3.0 * x * x + invN * (6.0 * x + 6.0 * invN)));
            const double term = qn * poly;
            sum += term;
            if (term <= 1e-17 * sum) break;
        }
        return sum;
    }
    const double x2 = x * x;
    double xm = x;  // x^m
    for (int i = 1; i < m; ++i) xm *= x;
    // n = 0 and n = 1 terms, then the even Bernoulli terms.
    double head = xm / m - xm * x / (2.0 * (m + 1));
    double xp = xm;
    for (size_t k = 0; k < kBernoulliOverFactorial.size(); ++k) {
        xp *= x2;  // x^{2(k+1)+m}
        head += kBernoulliOverFactorial[k] * xp / double(2 * (k + 1) + m);
    }
    return kBoseTotal[size_t(m)] - head;
}

// Cumulative moment ∫₀^λ λ'^j L_λ(λ', T) dλ' for j ∈ {0, 1, 2}: substituting x = c2/(λT)
// gives c1 (T/c2)^{4−j} G_{3−j}(x). With derivative, ∂/∂T of it instead:
// c1 T^{3−j}/c2^{4−j} [(4−j) G_{3−j}(x) + x^{4−j}/(eˣ − 1)].
double CumulativeMoment(int j, double lambda_m, double T_K, bool derivative) {
    const double x = kPlanckC2_m_K / (lambda_m * T_K);
    if (x >= kXUnderflow) return 0.0;
    const int m = 3 - j, p = 4 - j;
    const double g = BoseTail(m, x);
    const double r = T_K / kPlanckC2_m_K;
    double rp = 1.0;
    for (int i = 0; i < p; ++i) rp *= r;  // (T/c2)^{4−j}
    if (!derivative) return kPlanckC1_W_m2_sr * rp * g;
    double xp = 1.0;
    for (int i = 0; i < p; ++i) xp *= x;
    return kPlanckC1_W_m2_sr * rp / T_K * (p * g + xp / std::expm1(x));
}

// ∫ R(λ) λ^power L_λ dλ (or its T derivative) over the band, power ∈ {0, 1}. On a segment
// [a, b] the response is R = w_a + s(λ − a), so the integral is
// w_a ΔM_p + s (ΔM_{p+1} − a ΔM_p) with M the cumulative moments: exact for linear R.
double BandMoment(const Band& band, int power, double T_K, bool derivative) {
    const std::vector<double>& lambda = band.Wavelengths_m();
    const std::vector<double>& w = band.Weights();
    double mp0 = CumulativeMoment(power, lambda[0], T_K, derivative);
    double mq0 = CumulativeMoment(power + 1, lambda[0], T_K, derivative);
    double sum = 0.0;
    for (size_t i = 0; i + 1 < lambda.size(); ++i) {
        const double a = lambda[i], b = lambda[i + 1];
        const double mp1 = CumulativeMoment(power, b, T_K, derivative);
        const double mq1 = CumulativeMoment(power + 1, b, T_K, derivative);
        const double dmp = mp1 - mp0, dmq = mq1 - mq0;
        const double slope = (w[i + 1] - w[i]) / (b - a);
        sum += w[i] * dmp;
        if (slope != 0.0) sum += slope * (dmq - a * dmp);
        mp0 = mp1;
        mq0 = mq1;
    }
    // Rounding in the differences may leave a tiny negative value where the band sees no
    // emission at all; radiance is never negative.
    return std::max(sum, 0.0);
}

constexpr double kHc_J_m = kPlanck_J_s * kSpeedOfLight_m_s;

}  // namespace

double PlanckRadiance(double lambda_m, double T_K) {
    RequirePositiveFinite(lambda_m, "wavelength (m)", "PlanckRadiance");
    RequirePositiveFinite(T_K, "temperature (K)", "PlanckRadiance");
    const double x = kPlanckC2_m_K / (lambda_m * T_K);
    const double l2 = lambda_m * lambda_m;
    return kPlanckC1_W_m2_sr / (l2 * l2 * lambda_m * std::expm1(x));
}

double PlanckRadianceDerivative(double lambda_m, double T_K) {
    const double L = PlanckRadiance(lambda_m, T_K);
    const double x = kPlanckC2_m_K / (lambda_m * T_K);
    // ∂L/∂T = L · (x/T) · eˣ/(eˣ − 1), written with e^{−x} so large x cannot overflow.
    return L * (x / T_K) / -std::expm1(-x);
}

double PlanckPhotonRadiance(double lambda_m, double T_K) {
    return PlanckRadiance(lambda_m, T_K) * lambda_m / kHc_J_m;
}

double PlanckPhotonRadianceDerivative(double lambda_m, double T_K) {
    return PlanckRadianceDerivative(lambda_m, T_K) * lambda_m / kHc_J_m;
}

double BandRadiance(const Band& band, double T_K) {
    RequirePositiveFinite(T_K, "temperature (K)", "BandRadiance");
    return BandMoment(band, 0, T_K, false);
}

double BandRadianceDerivative(const Band& band, double T_K) {
    RequirePositiveFinite(T_K, "temperature (K)", "BandRadianceDerivative");
    return BandMoment(band, 0, T_K, true);
}

double BandPhotonRadiance(const Band& band, double T_K) {
    RequirePositiveFinite(T_K, "temperature (K)", "BandPhotonRadiance");
    return BandMoment(band, 1, T_K, false) / kHc_J_m;
}

double BandPhotonRadianceDerivative(const Band& band, double T_K) {
    RequirePositiveFinite(T_K, "temperature (K)", "BandPhotonRadianceDerivative");
    return BandMoment(band, 1, T_K, true) / kHc_J_m;
}

double BandTemperature(const Band& band, double radiance_W_m2_sr) {
    RequirePositiveFinite(radiance_W_m2_sr, "band radiance (W/m²/sr)", "BandTemperature");
    constexpr double kMaxT_K = 1e9;
    const double lnTarget = std::log(radiance_W_m2_sr);
    // Bracket [lo, hi] with L(lo) < target < L(hi); hi = ∞ until found. Newton on ln L,
    // which is close to linear in 1/T, with bisection whenever a step leaves the bracket.
    double lo = 0.0, hi = std::numeric_limits<double>::infinity(), T = 300.0;
    for (int iter = 0; iter < 400; ++iter) {
        const double L = BandMoment(band, 0, T, false);
        double next;
        if (!(L > 0.0)) {
            lo = T;  // no representable emission yet: far too cold
            next = std::isfinite(hi) ? 0.5 * (lo + hi) : 2.0 * T;
        } else {
            const double f = std::log(L) - lnTarget;
            if (f == 0.0) return T;
            if (f < 0.0)
                lo = T;
            else
                hi = T;
            const double dlnL = BandMoment(band, 0, T, true) / L;
            next = T - f / dlnL;
            if (!(next > lo && next < hi)) {
                if (!std::isfinite(hi))
                    next = 2.0 * T;
                else if (lo > 0.0)
                    next = std::sqrt(lo * hi);
                else
                    next = 0.5 * hi;
            }
            if (std::abs(next - T) <= 1e-14 * T) return next;
        }
        if (lo > kMaxT_K) {
            std::ostringstream msg;
            msg << "BandTemperature: band '" << band.Name() << "' radiance " << radiance_W_m2_sr
                << " W/m²/sr needs a blackbody hotter than " << kMaxT_K << " K";
            throw InputError(msg.str());
        }
        if (std::isfinite(hi) && hi - lo <= 1e-14 * hi) return 0.5 * (lo + hi);
        T = next;
    }
    std::ostringstream msg;
    msg << "BandTemperature: band '" << band.Name() << "' radiance " << radiance_W_m2_sr
        << " W/m²/sr has no blackbody temperature in (0, " << kMaxT_K << "] K";
    throw InputError(msg.str());
}

BandRadianceTable::BandRadianceTable(Band band, double minT_K, double maxT_K, double step_K)
    : band_(std::move(band)), minT_K_(minT_K), maxT_K_(maxT_K) {
    const char* where = "BandRadianceTable";
    RequirePositiveFinite(minT_K, "minimum temperature (K)", where);
    RequirePositiveFinite(maxT_K, "maximum temperature (K)", where);
    RequirePositiveFinite(step_K, "temperature step (K)", where);
    if (!(maxT_K > minT_K) || step_K > maxT_K - minT_K) {
        std::ostringstream msg;
        msg << where << ": range [" << minT_K << ", " << maxT_K << "] K with step " << step_K
            << " K; expected min < max and step <= max - min";
        throw InputError(msg.str());
    }
    if (!(BandRadiance(band_, minT_K) >= std::numeric_limits<double>::min())) {
        std::ostringstream msg;
        msg << where << ": band '" << band_.Name() << "' has no representable emission at "
            << minT_K << " K; raise the table's minimum temperature";
        throw InputError(msg.str());
    }
    // Equal cells no wider than step_K that end exactly on maxT_K.
    const size_t cells = size_t(std::ceil((maxT_K - minT_K) / step_K - 1e-9));
    step_K_ = (maxT_K - minT_K) / double(cells);
    // ln L_B and d(ln L_B)/dT at the nodes, then each cell's polynomial: the cubic Hermite
    // basis on [0, 1] with the node slopes scaled to the cell (step_K_).
    lnL_.resize(cells + 1);
    std::vector<double> dlnLdT(cells + 1);
    for (size_t i = 0; i <= cells; ++i) {
        const double T = i == cells ? maxT_K : minT_K + double(i) * step_K_;
        const double L = BandRadiance(band_, T);
        lnL_[i] = std::log(L);
        dlnLdT[i] = BandRadianceDerivative(band_, T) / L;
    }
    cells_.resize(cells);
    for (size_t i = 0; i < cells; ++i) {
        const double m0 = dlnLdT[i] * step_K_, m1 = dlnLdT[i + 1] * step_K_;
        const double dy = lnL_[i + 1] - lnL_[i];
        cells_[i] = {lnL_[i], m0, 3.0 * dy - 2.0 * m0 - m1, m0 + m1 - 2.0 * dy};
    }
}

double BandRadianceTable::Interpolate(size_t i, double t, double* dlnLdt) const {
    const Cell& c = cells_[i];
    if (dlnLdt) *dlnLdt = c.m0 + t * (2.0 * c.c2 + 3.0 * t * c.c3);
    return c.lnL + t * (c.m0 + t * (c.c2 + t * c.c3));
}

double BandRadianceTable::Radiance(double T_K) const {
    if (!(T_K >= minT_K_ && T_K <= maxT_K_)) return BandRadiance(band_, T_K);
    const double u = (T_K - minT_K_) / step_K_;
    const size_t i = std::min(size_t(u), cells_.size() - 1);
    return std::exp(Interpolate(i, u - double(i), nullptr));
}

void BandRadianceTable::Radiances(size_t n, const double* T_K, double* out) const {
    // Radiance's steps for each value, split at the exponential, the first loop without a
    // branch: u = (T − min) / step and the cell i = min(⌊u⌋, last) as Radiance makes them where
    // T lies in the range (u ≥ 0 there, so the signed conversion is the unsigned one), u = 0
    // elsewhere (its polynomial then dropped).
    const double lo = minT_K_, hi = maxT_K_, step = step_K_;
    const auto last = int64_t(cells_.size()) - 1;
    size_t k = 0;
    bool allIn = true;  // every value in the range (the usual case): the exponentials alone
#if defined(__AVX2__)
    // Four values at a time (GCC leaves the loop below scalar): the same double operations per
    // value. u ≤ (hi − lo)/step ≈ the cell count, so ⌊u⌋ fits the 32-bit conversion; each
    // value's cell (lnL, m0, c2, c3) is one 32-byte load, transposed into one vector per
    // coefficient.
    if (last <= INT32_MAX / 2) {
        const __m256d vlo = _mm256_set1_pd(lo), vhi = _mm256_set1_pd(hi);
        const __m256d vstep = _mm256_set1_pd(step);
        const __m128i vlast = _mm_set1_epi32(int32_t(last));
        const double* const cells = &cells_.data()->lnL;
        for (; k + 4 <= n; k += 4) {
            const __m256d T = _mm256_loadu_pd(T_K + k);
            // T − lo where lo ≤ T ≤ hi, else +0 (the mask's and), as the branch-free form below.
            const __m256d in =
                _mm256_and_pd(_mm256_cmp_pd(T, vlo, _CMP_GE_OQ), _mm256_cmp_pd(T, vhi, _CMP_LE_OQ));
            allIn &= _mm256_movemask_pd(in) == 0xf;
            const __m256d u = _mm256_div_pd(_mm256_and_pd(in, _mm256_sub_pd(T, vlo)), vstep);
            const __m128i i = _mm_min_epi32(_mm256_cvttpd_epi32(u), vlast);
            const __m256d t = _mm256_sub_pd(u, _mm256_cvtepi32_pd(i));
            static_assert(sizeof(Cell) == 4 * sizeof(double));
            const auto Row = [&](int cell) {
                return _mm256_loadu_pd(cells + 4 * size_t(uint32_t(cell)));
            };
            const __m256d a0 = Row(_mm_cvtsi128_si32(i)), a1 = Row(_mm_extract_epi32(i, 1));
            const __m256d a2 = Row(_mm_extract_epi32(i, 2)), a3 = Row(_mm_extract_epi32(i, 3));
            const __m256d lo01 = _mm256_unpacklo_pd(a0, a1), hi01 = _mm256_unpackhi_pd(a0, a1);
            const __m256d lo23 = _mm256_unpacklo_pd(a2, a3), hi23 = _mm256_unpackhi_pd(a2, a3);
            const __m256d lnL = _mm256_permute2f128_pd(lo01, lo23, 0x20);
            const __m256d c2 = _mm256_permute2f128_pd(lo01, lo23, 0x31);
            const __m256d m0 = _mm256_permute2f128_pd(hi01, hi23, 0x20);
            const __m256d c3 = _mm256_permute2f128_pd(hi01, hi23, 0x31);
            // Interpolate's lnL + t (m0 + t (c2 + t c3)).
            const __m256d p = _mm256_add_pd(
                lnL, _mm256_mul_pd(
                         t, _mm256_add_pd(
                                m0, _mm256_mul_pd(t, _mm256_add_pd(c2, _mm256_mul_pd(t, c3))))));
            _mm256_storeu_pd(out + k, p);
        }
    }
#endif
    for (; k < n; ++k) {
        const double T = T_K[k];
        const bool in = T >= lo && T <= hi;
        allIn &= in;
        const double u = (in ? T - lo : 0.0) / step;
        const int64_t i = std::min(int64_t(u), last);
        out[k] = Interpolate(size_t(i), u - double(i), nullptr);
    }
    if (allIn) {
        for (k = 0; k < n; ++k) out[k] = std::exp(out[k]);
        return;
    }
    for (k = 0; k < n; ++k) {
        const double T = T_K[k];
        out[k] = T >= lo && T <= hi ? std::exp(out[k]) : BandRadiance(band_, T);
    }
}

double BandRadianceTable::RadianceDerivative(double T_K) const {
    if (!(T_K >= minT_K_ && T_K <= maxT_K_)) return BandRadianceDerivative(band_, T_K);
    const double u = (T_K - minT_K_) / step_K_;
    const size_t i = std::min(size_t(u), cells_.size() - 1);
    double dlnLdt;
    const double lnL = Interpolate(i, u - double(i), &dlnLdt);
    return std::exp(lnL) * dlnLdt / step_K_;
}

double BandRadianceTable::Temperature(double radiance_W_m2_sr) const {
    RequirePositiveFinite(radiance_W_m2_sr, "band radiance (W/m²/sr)",
                          "BandRadianceTable::Temperature");
    const double y = std::log(radiance_W_m2_sr);
    if (!(y >= lnL_.front() && y <= lnL_.back())) return BandTemperature(band_, radiance_W_m2_sr);
    // Cell i with lnL_[i] ≤ y ≤ lnL_[i+1] (ln L_B increases with T).
    const auto it = std::upper_bound(lnL_.begin(), lnL_.end(), y);
    const size_t i = std::min(size_t(it - lnL_.begin()), lnL_.size() - 1) - 1;
    // Newton on the cell's cubic from the chord's root; the cubic is monotone in the cell.
    const double dy = lnL_[i + 1] - lnL_[i];
    double t = dy > 0.0 ? (y - lnL_[i]) / dy : 0.0;
    for (int iter = 0; iter < 8; ++iter) {
        double slope;
        const double f = Interpolate(i, t, &slope) - y;
        const double next = std::clamp(t - f / slope, 0.0, 1.0);
        const bool done = std::abs(next - t) <= 1e-15;
        t = next;
        if (done) break;
    }
    return minT_K_ + (double(i) + t) * step_K_;
}

}  // namespace seasense::radiometry
