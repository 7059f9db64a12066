#include "pf_localization/core/map/occupancy_grid.h"

#include <cmath>
#include <stdexcept>

namespace pf {

OccupancyGrid::OccupancyGrid(int width, int height, double resolution, const Pose2& origin,
                             std::vector<int8_t> data)
    : width_(width),
      height_(height),
      resolution_(resolution),
      origin_(origin),
      data_(std::move(data)) {
  if (width <= 0 || height <= 0) {
    throw std::invalid_argument("OccupancyGrid: width and height must be positive, got " +
                                std::to_string(width) + " x " + std::to_string(height));
  }
  if (!(resolution > 0.0) || !std::isfinite(resolution)) {
    throw std::invalid_argument("OccupancyGrid: resolution must be positive and finite, got " +
                                std::to_string(resolution));
  }
  if (!origin.isFinite()) {
    throw std::invalid_argument("OccupancyGrid: origin must be finite");
  }
  if (data_.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height)) {
    throw std::invalid_argument("OccupancyGrid: " + std::to_string(data_.size()) +
                                " cell values for a " + std::to_string(width) + " x " +
                                std::to_string(height) + " grid");
  }
  static_assert(kFreeMax >= 0, "classify: free is [0, kFreeMax]");
  free_cells_ = FreeCells::ofValues(data_.data(), data_.size(), kFreeMax);
}

CellState OccupancyGrid::state(const CellIndex& c) const {
  return contains(c) ? classify(data_[linearIndex(c)]) : CellState::kUnknown;
}

CellIndex OccupancyGrid::worldToCell(double wx, double wy) const {
  // Anything off the map lands one cell outside it (NaN included), so that
  // the conversion to int is always defined.
  const Pose2 local = between(origin_, {wx, wy, 0.0});
  const auto cell = [this](double v, int size) {
    const double c = std::floor(v / resolution_);
    return c >= 0.0 && c < size ? static_cast<int>(c) : (c >= size ? size : -1);
  };
  return {cell(local.x, width_), cell(local.y, height_)};
}

void OccupancyGrid::cellToWorld(const CellIndex& c, double* wx, double* wy) const {
  const Pose2 w = compose(origin_, {(c.x + 0.5) * resolution_, (c.y + 0.5) * resolution_, 0.0});
  *wx = w.x;
  *wy = w.y;
}

bool OccupancyGrid::isFreeAt(double wx, double wy) const {
  return state(worldToCell(wx, wy)) == CellState::kFree;
}

}  // namespace pf
