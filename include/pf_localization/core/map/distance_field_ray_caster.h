// Ray casting on an occupancy grid, sped up by the map's distance transform.
//
// The beam model needs, for every particle and beam, the range at which the
// beam would hit the map: millions of rays per update. Walking every cell a
// ray crosses (Amanatides & Woo, "A Fast Voxel Traversal Algorithm for Ray
// Tracing", Eurographics 1987) costs one step per cell, 80 steps for a 4 m
// beam on a 0.05 m map. Sphere tracing (Hart, "Sphere tracing: a geometric
// method for the antialiased ray tracing of implicit surfaces", The Visual
// Computer 12, 1996) on the exact Euclidean distance transform of the
// obstacles skips the empty space instead: from a cell whose centre lies D
// cells from the nearest occupied cell's centre, no occupied cell can be
// entered within D - sqrt(2) cells along any ray (both ends may be sqrt(2)/2
// off their cell's centre), so the ray jumps D - 1.5 cells at once. Near
// obstacles (D <= 1.5) it falls back to the cell walk, so the first occupied
// cell is found exactly and the range is where the ray enters it, as the
// simulator's ray caster measures it (not rounded to cell centres).
//
// The skip distances are computed once per map, uncapped, into a table with
// a one-cell border that stands for "outside the map". Unknown cells are
// transparent, as in the likelihood field (nothing mapped is there to
// reflect); a ray that leaves the map, or reaches max_range first, returns
// max_range.
#pragma once

#include <algorithm>
#include <cstddef>
#include <limits>
#include <vector>

#include "pf_localization/core/map/occupancy_grid.h"
#include "pf_localization/core/util/pose2.h"

namespace pf {

/// What a sphere trace's lookup says of a cell besides how far to jump.
constexpr float kTraceStops = -1.0f;   // an obstacle: the range is where the ray enters it
constexpr float kTraceLeaves = -2.0f;  // outside the map: max_range

/// Sphere tracing on a grid of `columns` x `rows` cells with a one-cell
/// border (the map's cell (0, 0) is (1, 1) here) from (cx, cy) along the
/// unit vector (dx, dy), both in the map's cells: `skip(ix, iy)` says of a
/// bordered cell kTraceStops, kTraceLeaves, or how many cells the ray may
/// jump from anywhere in it (0: walk to the next cell). The range in metres
/// (`resolution` a cell) where the ray enters the first cell that stops it,
/// or max_range when none does within max_range.
template <typename Skip>
double sphereTrace(double cx, double cy, double dx, double dy, double max_range, double resolution,
                   int columns, int rows, const Skip& skip) {
  // Past a cell boundary by this much (in cells), so that the next lookup is
  // in the next cell; 1e-6 cells is far below any range resolution.
  constexpr double kNudge = 1e-6;
  const double limit = max_range / resolution;
  const double sx = cx + 1.0, sy = cy + 1.0;
  const double inf = std::numeric_limits<double>::infinity();
  double t = 0.0;
  while (t < limit) {
    const double fx = sx + t * dx, fy = sy + t * dy;
    // Compared as doubles first: a point far outside must not become an undefined int.
    if (!(fx >= 0.0 && fy >= 0.0 && fx < columns && fy < rows)) return max_range;
    const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
    const float v = skip(ix, iy);
    if (v == kTraceStops) return t * resolution;
    if (v == kTraceLeaves) return max_range;
    if (v > 0.0f) {
      t += v;
      continue;
    }
    const double tx = dx > 0.0 ? (ix + 1 - fx) / dx : dx < 0.0 ? (ix - fx) / dx : inf;
    const double ty = dy > 0.0 ? (iy + 1 - fy) / dy : dy < 0.0 ? (iy - fy) / dy : inf;
    t += std::min(tx, ty) + kNudge;
  }
  return max_range;
}

class DistanceFieldRayCaster {
 public:
  explicit DistanceFieldRayCaster(const OccupancyGrid& grid);

  /// The range in metres from (x, y) along `angle` (world frame) to the first
  /// occupied cell, or max_range when there is none within max_range on the map.
  double cast(double x, double y, double angle, double max_range) const;

  /// The same from a point and direction already in the grid's frame, in cells
  /// (max_range too): the form the beam model's inner loop uses.
  double castInCells(double cx, double cy, double dx, double dy, double max_range) const;

  double resolution() const { return resolution_; }
  const Pose2& origin() const { return origin_; }

 private:
  // Per cell of the bordered table: what sphereTrace's lookup says of it.
  std::vector<float> skip_;
  int stride_ = 0;
  int rows_ = 0;
  double resolution_ = 0.0;
  Pose2 origin_;
};

}  // namespace pf
