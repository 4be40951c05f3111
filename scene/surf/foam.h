// Surf-zone foam coverage: white water born where waves break, left behind shoreward of the
// breaker line and decaying with a persistence time, broken into streaks by seeded noise; a pure
// function of position and time (no state between frames).
#pragma once

#include <cstdint>

#include "scene/surf/surf_settings.h"
#include "scene/surf/surf_waves.h"

namespace seasense::scene {

// Seeded 2-D value noise in [0, 1] at (x, y) in units of its cells: smoothstep-interpolated
// hashes of the integer lattice (Perlin 1985's value-noise variant), two octaves.
double FoamNoise(double x, double y, uint64_t seed);

// Streak pattern in [0, 1] at rest position (x0, y0) (world ENU, m) and time t_s: the noise in
// coordinates along and across the dominant direction of travel (azimuth direction_rad),
// stretched along it by streakElongation and carried with the water at drift_mps along that
// direction (the pattern moves with the surface; evaluated statelessly). A soft threshold turns
// the noise into patches with gaps between them.
double FoamStreaks(double x0, double y0, double t_s, double direction_rad, double drift_mps,
                   const FoamSettings& settings);

// Foam left by broken waves at a point timeSinceBreaking_s behind the breaker line, before the
// streaks: exp(−age / persistence_s) for age ≥ 0 (shoreward of the line), 0 seaward of it.
double ResidualFoam(const SurfBreaking& breaking, const FoamSettings& settings);

// Foam coverage in [0, 1] at rest position (x0, y0), time t_s, from the point's surf information
// (SurfWaves::Terms): the larger of the foam being made right now (the breaking intensity, the
// fraction of the wave energy being dissipated) and the residual foam broken into streaks.
double SurfFoamCoverage(const SurfPointInfo& info, double x0, double y0, double t_s,
                        const FoamSettings& settings);

// Deep-water whitecaps from the folding of the surface: 0 where the horizontal Jacobian
// determinant J is at or above the threshold τ (environment.ocean.foam_threshold), rising
// linearly to 1 where the surface folds (J ≤ 0). (OceanSurface uses the smaller eigenvalue for
// queries; on a mesh only J is stored, and J ≤ λ_min when λ_max ≤ 1, i.e. where crests pinch.)
double WhitecapCoverage(double jacobian, double threshold);

}  // namespace seasense::scene
