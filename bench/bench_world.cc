#include "bench_world.h"

#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

namespace pf_bench {

pf::OccupancyGrid pillarMap(int side) {
  std::vector<int8_t> data(static_cast<std::size_t>(side) * side, 0);
  for (int y = 0; y < side; ++y) {
    for (int x = 0; x < side; ++x) {
      const bool wall = x == 0 || y == 0 || x == side - 1 || y == side - 1;
      const bool pillar = x % 40 < 4 && y % 40 < 4;
      if (wall || pillar) data[static_cast<std::size_t>(y) * side + x] = 100;
    }
  }
  return pf::OccupancyGrid(side, side, 0.05, {0.0, 0.0, 0.0}, std::move(data));
}

pf::LaserScan fullScan(int beams) {
  pf::LaserScan scan;
  scan.angle_min = -M_PI;
  scan.angle_increment = 2.0 * M_PI / beams;
  scan.range_min = 0.02;
  scan.range_max = 5.0;
  for (int i = 0; i < beams; ++i) scan.ranges.push_back(1.0f + 3.0f * (i % 7) / 7.0f);
  return scan;
}

pf::ParticleSet scatter(std::size_t n, pf::Random* random) {
  pf::ParticleSet set;
  set.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    set.setPose(i, {10.0 + random->gaussian(1.0), 10.0 + random->gaussian(1.0),
                    random->uniform(-M_PI, M_PI)});
  }
  set.setUniformWeights();
  return set;
}

pf::LaserScan castScan(const pf::OccupancyGrid& grid, const pf::Pose2& pose, int beams) {
  pf::LaserScan scan = fullScan(beams);
  scan.range_max = 20.0;  // so that every beam finds a pillar or the outer wall
  for (int i = 0; i < beams; ++i) {
    const double a = pose.yaw + scan.angle_min + i * scan.angle_increment;
    scan.ranges[i] = 0.0f;  // no return
    for (double r = 0.05; r < scan.range_max; r += 0.005) {
      const pf::CellIndex c = grid.worldToCell(pose.x + r * std::cos(a), pose.y + r * std::sin(a));
      if (grid.state(c) == pf::CellState::kOccupied) {
        scan.ranges[i] = static_cast<float>(r);
        break;
      }
    }
  }
  return scan;
}

}  // namespace pf_bench
