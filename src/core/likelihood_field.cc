#include "pf_localization/core/likelihood_field.h"

#include <cmath>
#include <stdexcept>

#include "pf_localization/core/distance_transform.h"

namespace pf {

LikelihoodField::LikelihoodField(const OccupancyGrid& grid, double max_distance)
    : grid_(grid), max_distance_(max_distance) {
  if (!(max_distance > 0.0) || !std::isfinite(max_distance)) {
    throw std::invalid_argument("likelihood field: max_distance must be positive and finite, got " +
                                std::to_string(max_distance));
  }
  std::vector<bool> occupied(grid.data().size());
  for (std::size_t i = 0; i < occupied.size(); ++i) {
    occupied[i] = OccupancyGrid::classify(grid.data()[i]) == CellState::kOccupied;
  }
  // Squared cells, turned into metres in place.
  distances_ = squaredDistanceTransform(occupied, grid.width(), grid.height());
  const float cap = static_cast<float>(max_distance);
  const float res = static_cast<float>(grid.resolution());
  for (float& d : distances_) d = std::min(std::sqrt(d) * res, cap);  // sqrt(inf) = inf -> cap
}

double LikelihoodField::distance(const CellIndex& c) const {
  return grid_.contains(c) ? distances_[grid_.linearIndex(c)] : max_distance_;
}

}  // namespace pf
