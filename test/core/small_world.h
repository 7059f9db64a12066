// Test helper shared by the tests of the filter's parts: a small room with
// two boxes in it (nothing symmetric), and a lidar ray cast in it.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "pf_localization/core/laser_scan.h"
#include "pf_localization/core/occupancy_grid.h"
#include "pf_localization/core/pose2.h"

namespace pf {
namespace small_world {

constexpr double kRes = 0.05;

// A 4 m x 3 m room in 0.05 m cells: one-cell walls, a box near its lower
// right and a smaller one near its upper left.
inline OccupancyGrid room() {
  const int w = 80, h = 60;
  std::vector<int8_t> data(static_cast<std::size_t>(w) * h, 0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const double cx = (x + 0.5) * kRes, cy = (y + 0.5) * kRes;
      const bool wall = x == 0 || y == 0 || x == w - 1 || y == h - 1;
      const bool box = cx > 2.5 && cx < 3.0 && cy > 0.5 && cy < 1.2;
      const bool small_box = cx > 0.6 && cx < 1.0 && cy > 2.0 && cy < 2.4;
      data[static_cast<std::size_t>(y) * w + x] = wall || box || small_box ? 100 : 0;
    }
  }
  return OccupancyGrid(w, h, kRes, {}, data);
}

// 180 beams over a full turn from the robot's centre, ray cast in 1 mm steps.
inline LaserScan castScan(const OccupancyGrid& grid, const Pose2& robot) {
  LaserScan scan;
  scan.angle_min = -M_PI;
  scan.angle_increment = 2.0 * M_PI / 180;
  scan.range_min = 0.05;
  scan.range_max = 8.0;
  scan.ranges.assign(180, std::numeric_limits<float>::quiet_NaN());
  for (std::size_t i = 0; i < scan.ranges.size(); ++i) {
    const double a = robot.yaw + scan.angle_min + i * scan.angle_increment;
    for (double t = 0.0; t < scan.range_max; t += 0.001) {
      const CellIndex c = grid.worldToCell(robot.x + t * std::cos(a), robot.y + t * std::sin(a));
      if (!grid.contains(c)) break;
      if (grid.state(c) == CellState::kOccupied) {
        scan.ranges[i] = static_cast<float>(t);
        break;
      }
    }
  }
  return scan;
}

const Pose2 kTruth{1.6, 1.4, 0.2};

}  // namespace small_world
}  // namespace pf
