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
#pragma once

#include <vector>

#include "pf_localization/core/occupancy_grid.h"

namespace pf {

class LikelihoodField {
 public:
  /// Throws std::invalid_argument when max_distance is not positive and finite.
  LikelihoodField(const OccupancyGrid& grid, double max_distance);

  double maxDistance() const { return max_distance_; }
  const OccupancyGrid& grid() const { return grid_; }

  /// Distance in metres to the nearest occupied cell centre, at most max_distance.
  double distance(const CellIndex& c) const;
  double distanceAt(double wx, double wy) const { return distance(grid_.worldToCell(wx, wy)); }

  /// Row-major distances of every map cell (metres, capped).
  const std::vector<float>& distances() const { return distances_; }

 private:
  OccupancyGrid grid_;
  double max_distance_;
  std::vector<float> distances_;
};

}  // namespace pf
