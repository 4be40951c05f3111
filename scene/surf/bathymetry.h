// The seabed of the surf zone: the littoral zones' slopes across the shore, sandbars repeated
// per region along it, or a user depth grid; still-water depth below the tide.
#pragma once

#include <memory>
#include <vector>

#include "scene/surf/depth_grid.h"
#include "scene/surf/shore_frame.h"
#include "scene/surf/surf_settings.h"

namespace seasense::scene {

// Where a cross-shore position lies (seed 003, "The Littoral Zone").
enum class LittoralZone {
    Land,           // landward of the supralittoral zone (level ground)
    Supralittoral,  // beach above high water
    Intertidal,     // between high and low water
    Sublittoral,    // below low water, out to the zone's width
    Offshore,       // beyond, falling to the ocean depth
};

// Immutable after construction; every function is pure and thread-safe.
class Bathymetry {
  public:
    // oceanDepth_m: environment.ocean.depth_m, the depth below mean sea level the seabed falls
    // to offshore and keeps. Settings must be valid (ParseSurfSettings checks them).
    Bathymetry(const SurfSettings& settings, double oceanDepth_m);

    const SurfSettings& Settings() const { return settings_; }
    const ShoreFrame& Frame() const { return frame_; }
    double Tide_m() const { return settings_.tide_m; }
    double OceanDepth_m() const { return oceanDepth_m_; }

    // Seabed elevation (ENU z, m above mean sea level) under world point (x, y), m.
    double SeabedZ_m(double x, double y) const;
    // Still-water depth tide − z_bed at (x, y), m; negative on land.
    double Depth_m(double x, double y) const { return settings_.tide_m - SeabedZ_m(x, y); }

    // The same in shore coordinates (cross-shore s, alongshore u), m.
    double SeabedZAtShore_m(double s_m, double u_m) const;
    double DepthAtShore_m(double s_m, double u_m) const {
        return settings_.tide_m - SeabedZAtShore_m(s_m, u_m);
    }

    // An upper bound of the seabed elevation (ENU z, m) within radius_m of world point (x, y):
    // the plane profile falls monotonically seaward, a sandbar lifts it at most to its crest, a
    // grid never exceeds its largest node in the disc's bounding box. +∞ radius: the whole bed.
    double MaxSeabedZWithin_m(double x, double y, double radius_m) const;
    // A lower bound of the seabed elevation within radius_m of (x, y): the plane profile at the
    // disc's seaward edge (sandbars only lift it), or the smallest grid node in the disc's
    // bounding box (never below the ocean floor).
    double MinSeabedZWithin_m(double x, double y, double radius_m) const;

    // A cross-shore distance s (m) seaward of which the still-water depth is at least depth_m
    // everywhere: DepthAtShore_m(s', u) ≥ depth_m for every s' ≥ s and every u (the plane
    // profile falls monotonically seaward, no sandbar lies seaward of s). +∞ with a depth grid or
    // where the seabed never gets that deep.
    double DeepSeawardOf_m(double depth_m) const;

    // Whether every point within radius_m of cross-shore distance s_m (any u) lies on the level
    // ground landward of the beach, where SeabedZ_m is exactly ProfileZ_m(s_m), one constant:
    // no depth grid, no sandbar reaching it.
    bool LevelLandAround(double s_m, double radius_m) const {
        return !settings_.depthGrid && s_m + radius_m < sLand_m_ &&
               !(barSMax_m_ >= barSMin_m_ && s_m + radius_m >= barSMin_m_);
    }

    // The plane beach alone: seabed elevation of the littoral slopes at cross-shore distance s
    // (no sandbars, no grid), floored at −oceanDepth_m.
    double ProfileZ_m(double s_m) const;
    LittoralZone ZoneAt(double s_m) const;
    // Cross-shore distances (m) where the zones meet: land | supralittoral at Landward, high water
    // at HighWater, low water at LowWater, sublittoral | offshore at Offshore, and where the
    // seabed reaches the ocean depth (+∞ for a flat offshore slope above it).
    double LandwardEdge_m() const { return sLand_m_; }
    double HighWater_m() const { return sHigh_m_; }
    double LowWater_m() const { return sLow_m_; }
    double OffshoreEdge_m() const { return sOffshore_m_; }
    double OceanFloor_m() const { return sFloor_m_; }

    // Alongshore period of the region list (m; 0 without regions) and the region holding
    // alongshore position u with u's offset from the region's start (m).
    double RegionPeriod_m() const { return period_m_; }
    int RegionAt(double u_m, double* offset_m = nullptr) const;

  private:
    double BarLift(double s_m, double u_m, double profileZ_m) const;

    SurfSettings settings_;
    ShoreFrame frame_;
    double oceanDepth_m_;
    double sLand_m_, sHigh_m_, sLow_m_, sOffshore_m_, sFloor_m_;
    double zLand_m_, zOffshore_m_;
    std::vector<double> regionStart_m_;  // cumulative starts of the regions within one period
    double period_m_ = 0.0;
    // Cross-shore span outside which no sandbar lifts the seabed (empty without sandbars), so
    // that BarLift skips the region lookup there.
    double barSMin_m_ = 0.0, barSMax_m_ = -1.0;
};

}  // namespace seasense::scene
