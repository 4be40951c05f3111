// The surf zone's seabed: a piecewise-linear cross-shore profile of the littoral zones with
// sandbars per alongshore region, or a bilinear user grid, floored at the ocean depth.
#include "scene/surf/bathymetry.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "scene/core/check.h"

namespace seasense::scene {

Bathymetry::Bathymetry(const SurfSettings& settings, double oceanDepth_m)
    : settings_(settings), frame_(settings.shoreline), oceanDepth_m_(oceanDepth_m) {
    CHECK(oceanDepth_m_ > 0.0);
    CHECK(settings_.intertidal.slope > 0.0);
    CHECK(settings_.lowTide_m <= 0.0 && settings_.highTide_m >= 0.0);
    const SurfSettings& s = settings_;
    // The intertidal slope passes through the still-water line at tide 0 (s = 0, z = 0).
    sHigh_m_ = -s.highTide_m / s.intertidal.slope;
    sLow_m_ = -s.lowTide_m / s.intertidal.slope;
    sLand_m_ = sHigh_m_ - s.supralittoral.width_m;
    zLand_m_ = s.highTide_m + s.supralittoral.slope * s.supralittoral.width_m;
    sOffshore_m_ = sLow_m_ + s.sublittoral.width_m;
    zOffshore_m_ = s.lowTide_m - s.sublittoral.slope * s.sublittoral.width_m;

    const double floor = -oceanDepth_m_;
    if (floor >= 0.0) {
        sFloor_m_ = 0.0;
    } else if (floor >= s.lowTide_m) {
        sFloor_m_ = -floor / s.intertidal.slope;
    } else if (floor >= zOffshore_m_) {
        sFloor_m_ = sLow_m_ + (s.lowTide_m - floor) / s.sublittoral.slope;
    } else if (s.offshoreSlope > 0.0) {
        sFloor_m_ = sOffshore_m_ + (zOffshore_m_ - floor) / s.offshoreSlope;
    } else {
        sFloor_m_ = std::numeric_limits<double>::infinity();
    }

    double start = 0.0;
    for (const SurfRegionSettings& r : s.regions) {
        CHECK(r.width_m > 0.0);
        regionStart_m_.push_back(start);
        start += r.width_m;
        if (!r.sandbar) continue;
        // The lift is zero where |s − distance| − width/2 ≥ side slope; 1 mm more for rounding.
        const double reach = 0.5 * r.sandbar->width_m + r.sandbar->sideSlope_m + 1e-3;
        const double lo = r.sandbar->distance_m - reach, hi = r.sandbar->distance_m + reach;
        const bool first = barSMax_m_ < barSMin_m_;
        barSMin_m_ = first ? lo : std::min(barSMin_m_, lo);
        barSMax_m_ = first ? hi : std::max(barSMax_m_, hi);
    }
    period_m_ = start;
    CHECK(!s.depthGrid || (s.depthGrid->grid && s.depthGrid->cell_m > 0.0));
}

double Bathymetry::ProfileZ_m(double s_m) const {
    const SurfSettings& s = settings_;
    double z;
    if (s_m <= sLand_m_)
        z = zLand_m_;
    else if (s_m <= sHigh_m_)
        z = s.highTide_m + s.supralittoral.slope * (sHigh_m_ - s_m);
    else if (s_m <= sLow_m_)
        z = -s.intertidal.slope * s_m;
    else if (s_m <= sOffshore_m_)
        z = s.lowTide_m - s.sublittoral.slope * (s_m - sLow_m_);
    else
        z = zOffshore_m_ - s.offshoreSlope * (s_m - sOffshore_m_);
    return std::max(z, -oceanDepth_m_);
}

LittoralZone Bathymetry::ZoneAt(double s_m) const {
    if (s_m < sLand_m_) return LittoralZone::Land;
    if (s_m < sHigh_m_) return LittoralZone::Supralittoral;
    if (s_m <= sLow_m_) return LittoralZone::Intertidal;
    if (s_m <= sOffshore_m_) return LittoralZone::Sublittoral;
    return LittoralZone::Offshore;
}

int Bathymetry::RegionAt(double u_m, double* offset_m) const {
    if (regionStart_m_.empty()) {
        if (offset_m) *offset_m = 0.0;
        return -1;
    }
    double u = u_m - period_m_ * std::floor(u_m / period_m_);
    if (u < 0.0 || u >= period_m_) u = 0.0;  // rounding just below a multiple of the period
    const auto next = std::upper_bound(regionStart_m_.begin(), regionStart_m_.end(), u);
    const int index = int(next - regionStart_m_.begin()) - 1;
    if (offset_m) *offset_m = u - regionStart_m_[size_t(index)];
    return index;
}

// How far a sandbar raises the seabed at (s, u) above the plane profile: up to the crest level
// on the crest rectangle, blended down over the side-slope distance with a smoothstep (zero slope
// change at both ends, so the bar's flanks join the beach and the crest without kinks).
double Bathymetry::BarLift(double s_m, double u_m, double profileZ_m) const {
    if (!(s_m >= barSMin_m_ && s_m <= barSMax_m_)) return 0.0;  // beyond every bar's flanks
    double offset_m = 0.0;
    const int region = RegionAt(u_m, &offset_m);
    if (region < 0) return 0.0;
    const SurfRegionSettings& r = settings_.regions[size_t(region)];
    if (!r.sandbar) return 0.0;
    const SandbarSettings& bar = *r.sandbar;
    const double zCrest = settings_.tide_m - bar.crestDepth_m;
    if (zCrest <= profileZ_m) return 0.0;
    const double ds = std::max(std::abs(s_m - bar.distance_m) - 0.5 * bar.width_m, 0.0);
    const double du = std::max(std::abs(offset_m - 0.5 * r.width_m) - 0.5 * bar.length_m, 0.0);
    const double d = std::sqrt(ds * ds + du * du);
    if (d >= bar.sideSlope_m) return 0.0;
    const double t = 1.0 - d / bar.sideSlope_m;
    return (zCrest - profileZ_m) * t * t * (3.0 - 2.0 * t);
}

double Bathymetry::SeabedZAtShore_m(double s_m, double u_m) const {
    if (settings_.depthGrid) {
        const glm::dvec2 p = frame_.WorldFromShore(s_m, u_m);
        return SeabedZ_m(p.x, p.y);
    }
    const double z = ProfileZ_m(s_m);
    return z + BarLift(s_m, u_m, z);
}

namespace {

// The extreme (pick: std::max or std::min of two) of a depth grid's seabed elevations over the
// nodes of the bounding box of the disc of radius_m about (x, y): bilinear samples lie between
// their four nodes; outside, the border extends.
template <class Pick>
double GridSeabedZWithin(const DepthGridSettings& g, double x, double y, double radius_m,
                         double start, Pick pick) {
    const DepthGrid& grid = *g.grid;
    const double c0 = (x - radius_m - g.origin_m.x) / g.cell_m;
    const double c1 = (x + radius_m - g.origin_m.x) / g.cell_m;
    const double r0 = (g.origin_m.y - y - radius_m) / g.cell_m;
    const double r1 = (g.origin_m.y - y + radius_m) / g.cell_m;
    const auto clampIndex = [](double v, int n) { return int(std::clamp(v, 0.0, double(n - 1))); };
    const int ca = clampIndex(std::floor(c0), grid.Width());
    const int cb = clampIndex(std::ceil(c1), grid.Width());
    const int ra = clampIndex(std::floor(r0), grid.Height());
    const int rb = clampIndex(std::ceil(r1), grid.Height());
    double z = start;
    for (int r = ra; r <= rb; ++r)
        for (int c = ca; c <= cb; ++c) {
            const double v = grid.At(c, r);
            z = pick(z, g.values == DepthGridValues::Depth ? -v : v);
        }
    return z;
}

}  // namespace

double Bathymetry::MinSeabedZWithin_m(double x, double y, double radius_m) const {
    CHECK(radius_m >= 0.0);
    if (settings_.depthGrid)
        return std::max(GridSeabedZWithin(*settings_.depthGrid, x, y, radius_m,
                                          std::numeric_limits<double>::infinity(),
                                          [](double a, double b) { return std::min(a, b); }),
                        -oceanDepth_m_);
    // The profile falls monotonically seaward and sandbars only lift it (BarLift ≥ 0).
    return ProfileZ_m(frame_.ShoreFromWorld(x, y).s_m + radius_m);
}

double Bathymetry::MaxSeabedZWithin_m(double x, double y, double radius_m) const {
    CHECK(radius_m >= 0.0);
    if (settings_.depthGrid)
        return std::max(GridSeabedZWithin(*settings_.depthGrid, x, y, radius_m,
                                          -std::numeric_limits<double>::infinity(),
                                          [](double a, double b) { return std::max(a, b); }),
                        -oceanDepth_m_);
    const double s = frame_.ShoreFromWorld(x, y).s_m;
    const double sNear = s - radius_m, sFar = s + radius_m;
    double z = ProfileZ_m(sNear);  // the profile is highest at its landward end
    for (const SurfRegionSettings& r : settings_.regions) {
        if (!r.sandbar) continue;
        const SandbarSettings& bar = *r.sandbar;
        const double reach = 0.5 * bar.width_m + bar.sideSlope_m;
        if (bar.distance_m + reach >= sNear && bar.distance_m - reach <= sFar)
            z = std::max(z, settings_.tide_m - bar.crestDepth_m);
    }
    return z;
}

double Bathymetry::DeepSeawardOf_m(double depth_m) const {
    constexpr double kInf = std::numeric_limits<double>::infinity();
    // The profile's pieces are each monotone in floating point too (rounding is monotone); where
    // they meet, the two sides' values differ by rounding (~1e-15 m), which the margin covers.
    constexpr double kMargin_m = 1e-6;
    const double z = settings_.tide_m - depth_m - kMargin_m;  // the seabed must lie at or below
    if (settings_.depthGrid || !(-oceanDepth_m_ <= z)) return kInf;
    // Bisection between a landward s where the profile is too high and a seaward one where it
    // is low enough: keeps the seaward end, at which (and beyond which) the profile is low enough.
    double lo = std::min(sLand_m_, 0.0) - 1.0, hi = std::max(sOffshore_m_, 1.0);
    if (ProfileZ_m(lo) <= z) return kInf;  // level land that deep: not a beach this code knows
    while (!(ProfileZ_m(hi) <= z)) {
        hi = 2.0 * hi;
        if (!std::isfinite(hi)) return kInf;
    }
    for (int i = 0; i < 100 && hi - lo > 1e-9 * std::max(1.0, std::abs(hi)); ++i) {
        const double mid = 0.5 * (lo + hi);
        (ProfileZ_m(mid) <= z ? hi : lo) = mid;
    }
    // Sandbars lift the seabed only within [barSMin, barSMax] (BarLift).
    return barSMax_m_ >= barSMin_m_ ? std::max(hi, std::nextafter(barSMax_m_, kInf)) : hi;
}

double Bathymetry::SeabedZ_m(double x, double y) const {
    if (settings_.depthGrid) {
        const DepthGridSettings& g = *settings_.depthGrid;
        // Rows run south from the origin pixel.
        const double v =
            g.grid->Sample((x - g.origin_m.x) / g.cell_m, (g.origin_m.y - y) / g.cell_m);
        const double z = g.values == DepthGridValues::Depth ? -v : v;
        return std::max(z, -oceanDepth_m_);
    }
    const ShorePoint p = frame_.ShoreFromWorld(x, y);
    return SeabedZAtShore_m(p.s_m, p.u_m);
}

}  // namespace seasense::scene
