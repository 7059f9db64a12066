// A 2D occupancy grid in the ROS convention, reduced to the three states the
// filter reasons about.
//
// Cell (0, 0) is the lower-left cell; its lower-left corner sits at `origin`.
// Cell values follow nav_msgs/OccupancyGrid: -1 unknown, 0..100 the probability
// of occupancy in percent. A value at or above kOccupiedMin is an obstacle, at or
// below kFreeMax is free, and anything between (as map_server's "scale" mode
// writes for grey pixels) counts as unknown: we neither place particles there
// nor treat it as a wall.
#pragma once

#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pf_localization/core/map/free_cells.h"
#include "pf_localization/core/util/pose2.h"

namespace pf {

enum class CellState : uint8_t { kFree, kOccupied, kUnknown };

struct CellIndex {
  int x = 0;
  int y = 0;
};

class OccupancyGrid {
 public:
  static constexpr int8_t kOccupiedMin = 65;
  static constexpr int8_t kFreeMax = 19;

  OccupancyGrid() = default;

  /// `data` is row-major from the lower-left cell, width * height values.
  /// Throws std::invalid_argument on a size mismatch, a non-positive or
  /// non-finite resolution, a zero dimension or a non-finite origin. A rotated
  /// origin is accepted: world <-> cell conversions honour its yaw.
  OccupancyGrid(int width, int height, double resolution, const Pose2& origin,
                std::vector<int8_t> data);

  int width() const { return width_; }
  int height() const { return height_; }
  double resolution() const { return resolution_; }
  const Pose2& origin() const { return origin_; }
  const std::vector<int8_t>& data() const { return data_; }
  bool empty() const { return width_ == 0 || height_ == 0; }

  bool contains(const CellIndex& c) const {
    return c.x >= 0 && c.y >= 0 && c.x < width_ && c.y < height_;
  }
  int linearIndex(const CellIndex& c) const { return c.y * width_ + c.x; }
  /// The cell at linearIndex() `i`.
  CellIndex cellOf(int i) const { return {i % width_, i / width_}; }

  /// State of a cell; out-of-map cells are kUnknown.
  CellState state(const CellIndex& c) const;
  static CellState classify(int8_t value) {
    if (value < 0) return CellState::kUnknown;
    if (value >= kOccupiedMin) return CellState::kOccupied;
    return value <= kFreeMax ? CellState::kFree : CellState::kUnknown;
  }

  /// Cell containing a world point. A point off the map gives -1 or width
  /// (height) in the coordinate that is off: check contains().
  CellIndex worldToCell(double wx, double wy) const;
  /// World coordinates of a cell's centre.
  void cellToWorld(const CellIndex& c, double* wx, double* wy) const;

  /// True when the world point lies in a free cell of the map.
  bool isFreeAt(double wx, double wy) const;

  /// The free cells: their count, and the k-th one's linear index in
  /// increasing order.
  const FreeCells& freeCells() const { return free_cells_; }

 private:
  int width_ = 0;
  int height_ = 0;
  double resolution_ = 0.0;
  Pose2 origin_;
  std::vector<int8_t> data_;
  FreeCells free_cells_;
};

/// A grid's frame in cells, for walking rays cell by cell: world points and
/// directions in continuous cell coordinates of the grid's own frame (its
/// origin's position and rotation; cell (i, j) spans [i, i + 1) x [j, j + 1)).
class GridFrame {
 public:
  explicit GridFrame(const OccupancyGrid& grid)
      : origin_(grid.origin()),
        cos_yaw_(std::cos(origin_.yaw)),
        sin_yaw_(std::sin(origin_.yaw)),
        cells_per_metre_(1.0 / grid.resolution()) {}

  /// The grid's rotation in the world (rad).
  double yaw() const { return origin_.yaw; }
  double cellsPerMetre() const { return cells_per_metre_; }
  /// The world point (x, y) in cells.
  void pointInCells(double x, double y, double* cx, double* cy) const {
    const double dx = x - origin_.x, dy = y - origin_.y;
    *cx = (cos_yaw_ * dx + sin_yaw_ * dy) * cells_per_metre_;
    *cy = (-sin_yaw_ * dx + cos_yaw_ * dy) * cells_per_metre_;
  }
  /// The world direction (ux, uy) turned into the grid's frame.
  void directionInGrid(double ux, double uy, double* gx, double* gy) const {
    *gx = cos_yaw_ * ux + sin_yaw_ * uy;
    *gy = -sin_yaw_ * ux + cos_yaw_ * uy;
  }

 private:
  Pose2 origin_;
  double cos_yaw_, sin_yaw_, cells_per_metre_;
};

}  // namespace pf
