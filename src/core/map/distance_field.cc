#include "pf_localization/core/map/distance_field.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "pf_localization/core/map/distance_transform.h"
#include "pf_localization/core/util/worker_pool.h"

namespace pf {

DistanceField::DistanceField(OccupancyGrid grid, double max_distance, int threads)
    : grid_(std::move(grid)), max_distance_(max_distance) {
  if (!(max_distance > 0.0) || !std::isfinite(max_distance)) {
    throw std::invalid_argument("likelihood field: max_distance must be positive and finite, got " +
                                std::to_string(max_distance));
  }
  const int w = grid_.width(), h = grid_.height();
  std::vector<bool> occupied(grid_.data().size());
  for (std::size_t i = 0; i < occupied.size(); ++i) {
    occupied[i] = OccupancyGrid::classify(grid_.data()[i]) == CellState::kOccupied;
  }
  const float cap = static_cast<float>(max_distance);
  const float res = static_cast<float>(grid_.resolution());
  // Inside an obstacle, how far past its surface: the distance to the nearest
  // cell that is not occupied, less the surface cell's own and kFreeDepth. A
  // map whose obstacles are all that thin (a real map's walls) needs no second
  // transform: its occupied cells' depths are all 0, which the +0 holds.
  const bool deep = hasDeepCells(occupied, w, h);
  // The two transforms are independent: each a task of its own, so that a
  // second core takes one (the same result on any number of threads).
  std::vector<float> depth;
  auto transform = [&](std::size_t k) {
    if (k == 0) {
      // Squared cells, turned into metres in place: +0 on occupied cells, > 0
      // elsewhere (at least a cell away).
      signed_ = squaredDistanceTransform(occupied, w, h);
      for (float& d : signed_) d = std::min(std::sqrt(d) * res, cap);  // sqrt(inf) = inf -> cap
    } else {
      std::vector<bool> open = occupied;
      open.flip();
      depth = squaredDistanceTransform(open, w, h);
    }
  };
  WorkerPool::instance().run(threads, deep ? 2 : 1, transform);
  if (deep) addDepths(occupied, depth, res, cap);
}

void DistanceField::addDepths(const std::vector<bool>& occupied, const std::vector<float>& depth,
                              float res, float cap) {
  for (std::size_t i = 0; i < depth.size(); ++i) {
    // The depth is >= +0 (max with +0), so its negation is <= 0; -0 where
    // it is 0, which distance() and surfaceDistance() both read as +0.
    if (occupied[i]) {
      signed_[i] = -std::min(std::max(std::sqrt(depth[i]) - 1.0f - kFreeDepth, 0.0f) * res, cap);
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

}  // namespace pf
