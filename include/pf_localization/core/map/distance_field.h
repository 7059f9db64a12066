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
// surfaceDistances() differ inside obstacles: how far past the surface a
// point lies, less kFreeDepth cells, so that for the scan fit (bicubic
// distance field) a thick wall is not a better fit the deeper a beam goes.
#pragma once

#include <vector>

#include "pf_localization/core/map/occupancy_grid.h"

namespace pf {

class DistanceField {
 public:
  /// Cells behind an obstacle's surface cell that still count as on it (a
  /// real map's walls are blurred over two or three cells).
  static constexpr float kFreeDepth = 1.0f;

  /// Throws std::invalid_argument when max_distance is not positive and
  /// finite. Keeps `grid` (moved in: a large map is not held twice).
  DistanceField(OccupancyGrid grid, double max_distance);

  double maxDistance() const { return max_distance_; }
  const OccupancyGrid& grid() const { return grid_; }

  /// Distance in metres to the nearest occupied cell centre, at most max_distance.
  double distance(const CellIndex& c) const;
  double distanceAt(double wx, double wy) const { return distance(grid_.worldToCell(wx, wy)); }

  /// Row-major distances of every map cell (metres, capped).
  const std::vector<float>& distances() const { return distances_; }
  /// The same, but inside an obstacle how far past its surface (less
  /// kFreeDepth cells): what the scan fit measures. See docs/design.md, "A
  /// map out of date is not a wrong pose".
  const std::vector<float>& surfaceDistances() const {
    return surface_distances_.empty() ? distances_ : surface_distances_;
  }

 private:
  // Whether any occupied cell lies deeper than 1 + kFreeDepth cells inside
  // its obstacle (the only cells whose surface distance is not 0).
  static bool hasDeepCells(const std::vector<bool>& occupied, int width, int height);
  // Makes surface_distances_: distances_, with each occupied cell's depth
  // past the surface (res: metres per cell; cap: max_distance).
  void addDepths(const std::vector<bool>& occupied, int width, int height, float res, float cap);

  OccupancyGrid grid_;
  double max_distance_;
  std::vector<float> distances_;
  std::vector<float> surface_distances_;  // empty when equal to distances_
};

}  // namespace pf
