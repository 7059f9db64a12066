// Distance from every map cell to the nearest obstacle, capped.
//
// The likelihood field of Thrun, Burgard & Fox, "Probabilistic Robotics"
// (2005), ch. 6.4, scores a beam by how far its end point lands from the
// nearest occupied cell. The distances are computed once per map with an
// exact linear-time Euclidean distance transform.
//
// Unknown cells are not obstacles: their distance is measured to the nearest
// occupied cell like any other. Points outside the map are max_distance away,
// so a beam that leaves the map scores like one in open space.
// The surface distance differs inside obstacles: how far past the surface a
// point lies, less kFreeDepth cells, so that for the scan fit (bicubic
// distance field) a thick wall is not a better fit the deeper a beam goes.
//
// Both are held in one float a cell (a 200 x 600 m floor at 5 cm has 48
// million): the distance where it is not 0 (free and unknown cells, > 0),
// the depth past the surface negated on occupied cells (<= 0), where the
// distance is 0. So distance = max(v, 0) and surface distance = |v|.
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

#include "pf_localization/core/map/occupancy_grid.h"

namespace pf {

class DistanceField {
 public:
  /// Cells behind an obstacle's surface cell that still count as on it (a
  /// real map's walls are blurred over two or three cells).
  static constexpr float kFreeDepth = 1.0f;

  /// Throws std::invalid_argument when max_distance is not positive and
  /// finite. Keeps `grid` (moved in: a large map is not held twice). Its two
  /// transforms (to the obstacles, and inside them) run on up to `threads`
  /// threads (WorkerPool); the result is the same on any number.
  DistanceField(OccupancyGrid grid, double max_distance, int threads = 1);

  double maxDistance() const { return max_distance_; }
  const OccupancyGrid& grid() const { return grid_; }

  /// Distance in metres to the nearest occupied cell centre, at most max_distance.
  double distance(const CellIndex& c) const {
    return grid_.contains(c) ? distance(static_cast<std::size_t>(grid_.linearIndex(c)))
                             : max_distance_;
  }
  double distanceAt(double wx, double wy) const { return distance(grid_.worldToCell(wx, wy)); }

  /// Cell i's (row-major) distance: metres to the nearest occupied cell
  /// centre, at most max_distance; +0.0f on an occupied cell.
  float distance(std::size_t i) const { return signed_[i] > 0.0f ? signed_[i] : 0.0f; }
  /// Cell i's surface distance: its distance, but inside an obstacle how far
  /// past its surface (less kFreeDepth cells, at most max_distance; +0.0f
  /// near the surface): what the scan fit measures. See docs/design.md, "A
  /// map out of date is not a wrong pose".
  float surfaceDistance(std::size_t i) const { return std::fabs(signed_[i]); }
  /// Every cell's value v, row-major, for loops over many cells: the
  /// distance (v > 0) off obstacles, the surface distance negated (v <= 0)
  /// on them; distance(i) = max(v, 0), surfaceDistance(i) = |v|. A depth of
  /// 0 may be stored as -0.0f: read it through those two formulas.
  const std::vector<float>& signedDistances() const { return signed_; }
  std::size_t size() const { return signed_.size(); }

 private:
  // Whether any occupied cell lies deeper than 1 + kFreeDepth cells inside
  // its obstacle (the only cells whose surface distance is not 0).
  static bool hasDeepCells(const std::vector<bool>& occupied, int width, int height);
  // Stores each occupied cell's depth past the surface (from `depth`, the
  // squared distances in cells to the nearest open cell), negated, in
  // signed_ (which holds the distances; res: metres per cell; cap:
  // max_distance).
  void addDepths(const std::vector<bool>& occupied, const std::vector<float>& depth, float res,
                 float cap);

  OccupancyGrid grid_;
  double max_distance_;
  std::vector<float> signed_;  // see signedDistances()
};

}  // namespace pf
