// Beams that see something move in front of a robot standing still
// (transient_beams.h): masked while it is new, taken once it stays, and never
// while the robot moves.
#include "pf_localization/core/transient_beams.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "pf_localization/core/particle_filter.h"
#include "small_world.h"

namespace pf {
namespace {

using small_world::castScan;
using small_world::kTruth;

// The odometry frame is not the map frame.
const Pose2 kOdomInMap{0.7, -0.4, 0.3};
Pose2 odomOf(const Pose2& truth) { return compose(inverse(kOdomInMap), truth); }

// `scan` with beams [first, last) cut short at `range`: something standing
// in front of the lidar.
LaserScan withObject(LaserScan scan, std::size_t first, std::size_t last, float range = 0.5f) {
  for (std::size_t i = first; i < last; ++i) scan.ranges[i] = range;
  return scan;
}

std::size_t nanCount(const LaserScan& scan) {
  std::size_t n = 0;
  for (float r : scan.ranges) n += std::isnan(r) ? 1 : 0;
  return n;
}

TEST(TransientBeams, BeamsCutShortWhileTheRobotStandsAreMasked) {
  const OccupancyGrid grid = small_world::room();
  const LaserScan before = castScan(grid, kTruth);
  const LaserScan now = withObject(before, 40, 60);
  TransientBeams transients;
  std::vector<LaserScan> storage;
  EXPECT_EQ(&transients.mask(odomOf(kTruth), before, {}, &storage)[0], &before);
  EXPECT_EQ(0, transients.masked());

  const ScanGroup seen = transients.mask(odomOf(kTruth), now, {}, &storage);
  EXPECT_EQ(20, transients.masked());
  ASSERT_EQ(1u, seen.size());
  for (std::size_t i = 0; i < now.ranges.size(); ++i) {
    if (i >= 40 && i < 60) {
      EXPECT_TRUE(std::isnan(seen[0].ranges[i])) << i;
    } else {
      EXPECT_EQ(now.ranges[i], seen[0].ranges[i]) << i;
    }
  }
}

TEST(TransientBeams, WhatStaysIsTakenAfterKMaxMaskedScans) {
  const OccupancyGrid grid = small_world::room();
  const LaserScan before = castScan(grid, kTruth);
  const LaserScan now = withObject(before, 40, 60);
  TransientBeams transients;
  std::vector<LaserScan> storage;
  transients.mask(odomOf(kTruth), before, {}, &storage);
  for (int k = 0; k < TransientBeams::kMaxMaskedScans; ++k) {
    transients.mask(odomOf(kTruth), now, {}, &storage);
    EXPECT_EQ(20, transients.masked()) << "scan " << k;
  }
  EXPECT_EQ(&transients.mask(odomOf(kTruth), now, {}, &storage)[0], &now);
  EXPECT_EQ(0, transients.masked());
}

TEST(TransientBeams, WhatLeavesIsNotMasked) {
  const OccupancyGrid grid = small_world::room();
  const LaserScan clear = castScan(grid, kTruth);
  TransientBeams transients;
  std::vector<LaserScan> storage;
  transients.mask(odomOf(kTruth), withObject(clear, 40, 60), {}, &storage);
  transients.mask(odomOf(kTruth), clear, {}, &storage);
  EXPECT_EQ(0, transients.masked());
}

TEST(TransientBeams, AMovingRobotMasksNothing) {
  const OccupancyGrid grid = small_world::room();
  const Pose2 moved{kTruth.x + 0.1, kTruth.y, kTruth.yaw};
  ASSERT_GT(0.1, TransientBeams::kStillDistance);
  TransientBeams transients;
  std::vector<LaserScan> storage;
  transients.mask(odomOf(kTruth), castScan(grid, kTruth), {}, &storage);
  transients.mask(odomOf(moved), withObject(castScan(grid, moved), 40, 60), {}, &storage);
  EXPECT_EQ(0, transients.masked());
}

TEST(TransientBeams, CreepingAndTurningAlittleIsNotAChange) {
  // The background is moved into the new scan's frame: the beams that slid
  // along the walls and across the boxes' edges are not taken for objects.
  const OccupancyGrid grid = small_world::room();
  TransientBeams transients;
  std::vector<LaserScan> storage;
  transients.mask(odomOf(kTruth), castScan(grid, kTruth), {}, &storage);
  for (const Pose2& step : {Pose2{0.03, 0.0, 0.0}, Pose2{0.0, 0.03, 0.0}, Pose2{0.02, -0.02, 0.015},
                            Pose2{0.0, 0.0, -0.017}}) {
    const Pose2 there = compose(kTruth, step);
    transients.mask(odomOf(there), castScan(grid, there), {}, &storage);
    EXPECT_EQ(0, transients.masked()) << step.x << " " << step.y << " " << step.yaw;
  }
}

TEST(TransientBeams, ABeamEndingOnTheMapIsKept) {
  const OccupancyGrid grid = small_world::room();
  const LaserScan before = castScan(grid, kTruth);
  TransientBeams transients;
  std::vector<LaserScan> storage;
  transients.mask(odomOf(kTruth), before, {}, &storage);
  int asked = 0;
  const TransientBeams::OnMap on_map = [&asked](double, double) { return ++asked > 0; };
  transients.mask(odomOf(kTruth), withObject(before, 40, 60), on_map, &storage);
  EXPECT_EQ(20, asked);
  EXPECT_EQ(0, transients.masked());
}

TEST(TransientBeams, EachSensorHasItsOwnBackground) {
  const OccupancyGrid grid = small_world::room();
  std::vector<LaserScan> two(2, castScan(grid, kTruth));
  two[1].sensor_pose = {0.0, 0.0, M_PI};
  two[1].ranges = castScan(grid, compose(kTruth, two[1].sensor_pose)).ranges;
  TransientBeams transients;
  std::vector<LaserScan> storage;
  transients.mask(odomOf(kTruth), two, {}, &storage);
  transients.mask(odomOf(kTruth), two, {}, &storage);
  EXPECT_EQ(0, transients.masked());
  two[1] = withObject(two[1], 10, 15);
  const ScanGroup seen = transients.mask(odomOf(kTruth), two, {}, &storage);
  EXPECT_EQ(5, transients.masked());
  EXPECT_EQ(0u, nanCount(seen[0]));
  EXPECT_EQ(5u, nanCount(seen[1]));
}

// The filter end to end: a robot stands, localized, and something steps up
// to it and fills half of its view for two scans. The published pose stays.
TEST(TransientBeams, AnObjectStandingInFrontOfTheRobotDoesNotMoveTheEstimate) {
  const OccupancyGrid grid = small_world::room();
  ParticleFilterParams p;
  p.kld.min_particles = 300;
  p.kld.max_particles = 2000;
  p.seed = 3;
  p.refine_estimate = true;
  ParticleFilter filter(p);
  filter.setMap(grid);
  filter.initializeGaussian(kTruth, Eigen::Vector3d(1e-4, 1e-4, 1e-4).asDiagonal());
  const Pose2 odom = odomOf(kTruth);
  const LaserScan clear = castScan(grid, kTruth);
  ASSERT_TRUE(filter.update(odom, clear).updated);
  const Pose2 before = compose(*filter.mapToOdom(), odom);
  // An arc 0.3 m from the lidar over half of its beams, on the side the
  // nearer walls are: it fits the map best shifted towards them.
  const LaserScan blocked = withObject(clear, 0, 90, 0.3f);
  for (int k = 0; k < 2; ++k) {
    const UpdateReport r = filter.update(odom, blocked);
    EXPECT_EQ(90, r.beams_masked);
    const Pose2 now = compose(*filter.mapToOdom(), odom);
    EXPECT_LT(std::hypot(now.x - before.x, now.y - before.y), 0.005) << "scan " << k;
    EXPECT_LT(std::fabs(angleDiff(now.yaw, before.yaw)), 0.005) << "scan " << k;
  }
}

}  // namespace
}  // namespace pf
