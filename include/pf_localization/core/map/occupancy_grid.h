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

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

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

  /// State of a cell; out-of-map cells are kUnknown.
  CellState state(const CellIndex& c) const;
  static CellState classify(int8_t value);

  /// Cell containing a world point. A point off the map gives -1 or width
  /// (height) in the coordinate that is off: check contains().
  CellIndex worldToCell(double wx, double wy) const;
  /// World coordinates of a cell's centre.
  void cellToWorld(const CellIndex& c, double* wx, double* wy) const;

  /// True when the world point lies in a free cell of the map.
  bool isFreeAt(double wx, double wy) const;

  /// Linear indices of all free cells, in increasing order.
  const std::vector<int>& freeCells() const { return free_cells_; }

 private:
  int width_ = 0;
  int height_ = 0;
  double resolution_ = 0.0;
  Pose2 origin_;
  std::vector<int8_t> data_;
  std::vector<int> free_cells_;
};

}  // namespace pf
