#include "pf_localization/core/map/distance_field.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "pf_localization/core/map/distance_transform.h"

namespace pf {

DistanceField::DistanceField(const OccupancyGrid& grid, double max_distance)
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
  // Inside an obstacle, how far past its surface: the distance to the nearest
  // cell that is not occupied, less the surface cell's own and kFreeDepth. A
  // map whose obstacles are all that thin (a real map's walls) needs no second
  // transform: its surface distances are its distances.
  if (!hasDeepCells(occupied, grid.width(), grid.height())) return;
  addDepths(occupied, grid.width(), grid.height(), res, cap);
}

void DistanceField::addDepths(const std::vector<bool>& occupied, int width, int height, float res,
                              float cap) {
  // The transform runs over the obstacles' bounding box and one cell round
  // it: every cell beyond is open, and the nearest open cell of an obstacle
  // cell is never further than that ring (clamping a cell beyond into the
  // box brings it closer), so the depths are those of the whole map's.
  int x0 = width, y0 = height, x1 = -1, y1 = -1;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      if (!occupied[static_cast<std::size_t>(y) * width + x]) continue;
      x0 = std::min(x0, x);
      x1 = std::max(x1, x);
      y0 = std::min(y0, y);
      y1 = std::max(y1, y);
    }
  }
  x0 = std::max(0, x0 - 1);
  y0 = std::max(0, y0 - 1);
  x1 = std::min(width - 1, x1 + 1);
  y1 = std::min(height - 1, y1 + 1);
  const int w = x1 - x0 + 1, h = y1 - y0 + 1;
  std::vector<bool> open(static_cast<std::size_t>(w) * h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      open[static_cast<std::size_t>(y) * w + x] =
          !occupied[static_cast<std::size_t>(y + y0) * width + x + x0];
    }
  }
  std::vector<float> depth = squaredDistanceTransform(open, w, h);
  const auto surface = [&](float squared) {
    return std::min(std::max(std::sqrt(squared) - 1.0f - kFreeDepth, 0.0f) * res, cap);
  };
  if (w == width && h == height) {
    // The box is the whole map (walls round it): the depths' own array
    // becomes the surface distances, and no third array of the map's size
    // is held at once.
    for (std::size_t i = 0; i < depth.size(); ++i) {
      depth[i] = occupied[i] ? surface(depth[i]) : distances_[i];
    }
    surface_distances_ = std::move(depth);
    return;
  }
  surface_distances_ = distances_;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y + y0) * width + x + x0;
      if (occupied[i]) surface_distances_[i] = surface(depth[static_cast<std::size_t>(y) * w + x]);
    }
  }
}

bool DistanceField::hasDeepCells(const std::vector<bool>& occupied, int width, int height) {
  // Deeper than 1 + kFreeDepth cells: every cell within that radius occupied
  // or off the map (off the map is no free cell to measure to either).
  const int r = static_cast<int>(1.0f + kFreeDepth);
  const auto open = [&](int x, int y) {
    return x >= 0 && y >= 0 && x < width && y < height &&
           !occupied[static_cast<std::size_t>(y) * width + x];
  };
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      bool deep = true;
      for (int dy = -r; dy <= r && deep; ++dy) {
        for (int dx = -r; dx <= r && deep; ++dx) {
          if (dx * dx + dy * dy <= r * r) deep = !open(x + dx, y + dy);
        }
      }
      if (deep) return true;
    }
  }
  return false;
}

double DistanceField::distance(const CellIndex& c) const {
  return grid_.contains(c) ? distances_[grid_.linearIndex(c)] : max_distance_;
}

}  // namespace pf
