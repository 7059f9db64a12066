// Test helper shared by the tests of the filter's parts: the world of
// test/support's asymmetricRoom, a scan taken in it, and the pose the
// robot is at.
#pragma once

#include "pf_localization/core/filter/particle_filter_params.h"
#include "support/rooms.h"
#include "support/scan_simulator.h"

namespace pf {
namespace small_world {

// 4 m x 3 m in 0.05 m cells, walled, with two boxes (nothing symmetric).
inline OccupancyGrid room() { return test::asymmetricRoom(); }

// 180 beams over a full turn from the robot's centre, exact ranges.
inline LaserScan castScan(const OccupancyGrid& grid, const Pose2& robot) {
  return test::simulateScan(grid, robot);
}

const Pose2 kTruth{1.6, 1.4, 0.2};

// A filter for this room, fitting its estimate to the scan: a cloud small
// enough for a quick test, seeded.
inline ParticleFilterParams refinedParams() {
  ParticleFilterParams p;
  p.kld.min_particles = 300;
  p.kld.max_particles = 2000;
  p.seed = 3;
  p.refine_estimate = true;
  return p;
}

}  // namespace small_world
}  // namespace pf
