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
  skip_.assign(static_cast<std::size_t>(stride_) * rows_, kOutside);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      float& s = skip_[static_cast<std::size_t>(y + 1) * stride_ + x + 1];
      if (occupied[i]) {
        s = kOccupied;
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
  // Past a cell boundary by this much (in cells), so that the next lookup is
  // in the next cell; 1e-6 cells is far below any range resolution.
  constexpr double kNudge = 1e-6;
  const double limit = max_range / resolution_;
  // Bordered coordinates: cell (0, 0) of the map is (1, 1) of the table.
  const double sx = cx + 1.0, sy = cy + 1.0;
  const double inf = std::numeric_limits<double>::infinity();
  double t = 0.0;
  while (t < limit) {
    const double fx = sx + t * dx, fy = sy + t * dy;
    // Compared as doubles first: a point far outside must not become an undefined int.
    if (!(fx >= 0.0 && fy >= 0.0 && fx < stride_ && fy < rows_)) return max_range;
    const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
    const float v = skip_[static_cast<std::size_t>(iy) * stride_ + ix];
    if (v == kOccupied) return t * resolution_;
    if (v == kOutside) return max_range;
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

}  // namespace pf
