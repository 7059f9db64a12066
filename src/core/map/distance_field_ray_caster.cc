#include "pf_localization/core/map/distance_field_ray_caster.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "pf_localization/core/map/distance_transform.h"

namespace pf {

DistanceFieldRayCaster::DistanceFieldRayCaster(const OccupancyGrid& grid)
    : stride_(grid.width() + 2),
      rows_(grid.height() + 2),
      resolution_(grid.resolution()),
      origin_(grid.origin()) {
  const int w = grid.width(), h = grid.height();
  std::vector<bool> occupied(static_cast<std::size_t>(w) * h, false);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      occupied[static_cast<std::size_t>(y) * w + x] = grid.state({x, y}) == CellState::kOccupied;
    }
  }
  const std::vector<float> d2 = squaredDistanceTransform(occupied, w, h);
  skip_.assign(static_cast<std::size_t>(stride_) * rows_, kTraceLeaves);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      float& s = skip_[static_cast<std::size_t>(y + 1) * stride_ + x + 1];
      if (occupied[i]) {
        s = kTraceStops;
      } else {
        // No obstacle at all: infinity, and any ray runs to max_range or the border.
        const float d = std::sqrt(d2[i]);
        s = d > 1.5f ? d - 1.5f : 0.0f;
      }
    }
  }
}

double DistanceFieldRayCaster::cast(double x, double y, double angle, double max_range) const {
  const double dx = x - origin_.x, dy = y - origin_.y;
  const double c = std::cos(origin_.yaw), s = std::sin(origin_.yaw);
  const double a = angle - origin_.yaw;
  return castInCells((c * dx + s * dy) / resolution_, (-s * dx + c * dy) / resolution_, std::cos(a),
                     std::sin(a), max_range);
}

double DistanceFieldRayCaster::castInCells(double cx, double cy, double dx, double dy,
                                           double max_range) const {
  return sphereTrace(cx, cy, dx, dy, max_range, resolution_, stride_, rows_, [this](int x, int y) {
    return skip_[static_cast<std::size_t>(y) * stride_ + x];
  });
}

}  // namespace pf
