// Beams that see something move in front of a robot standing still
// (transient_beams.h): masked while it is new, taken once it stays, and never
// while the robot moves.
#include "pf_localization/core/sensor/transient_beams.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/small_world.h"
#include "pf_localization/core/filter/particle_filter.h"

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

// A robot standing at kTruth in small_world's room, and the beams it masks.
class TransientBeamsTest : public ::testing::Test {
 protected:
  // What the lidar sees from `pose` (kTruth when omitted).
  LaserScan view(const Pose2& pose = kTruth) const { return castScan(grid_, pose); }
  // The scan taken at `pose`, masked: the beams masked.
  int mask(const LaserScan& scan, const Pose2& pose = kTruth,
           const TransientBeams::OnMap& on_map = {}) {
    seen_ = transients_.mask(odomOf(pose), scan, on_map, &storage_)[0];
    return transients_.masked();
  }

  const OccupancyGrid grid_ = small_world::room();
  TransientBeams transients_;
  std::vector<LaserScan> storage_;
  LaserScan seen_;  // the last scan mask() returned
};

TEST_F(TransientBeamsTest, BeamsCutShortWhileTheRobotStandsAreMasked) {
  const LaserScan before = view();
  EXPECT_EQ(0, mask(before));
  EXPECT_EQ(before.ranges, seen_.ranges);
  const LaserScan now = withObject(before, 40, 60);
  EXPECT_EQ(20, mask(now));
  for (std::size_t i = 0; i < now.ranges.size(); ++i) {
    if (i >= 40 && i < 60) {
      EXPECT_TRUE(std::isnan(seen_.ranges[i])) << i;
    } else {
      EXPECT_EQ(now.ranges[i], seen_.ranges[i]) << i;
    }
  }
}

TEST_F(TransientBeamsTest, WhatStaysIsTakenAfterKMaxMaskedScans) {
  mask(view());
  const LaserScan now = withObject(view(), 40, 60);
  for (int k = 0; k < TransientBeams::kMaxMaskedScans; ++k) EXPECT_EQ(20, mask(now)) << k;
  EXPECT_EQ(0, mask(now));
  EXPECT_EQ(now.ranges, seen_.ranges);
}

TEST_F(TransientBeamsTest, WhatLeavesIsNotMasked) {
  mask(withObject(view(), 40, 60));
  EXPECT_EQ(0, mask(view()));
}

TEST_F(TransientBeamsTest, AMovingRobotMasksNothing) {
  const Pose2 moved{kTruth.x + 0.1, kTruth.y, kTruth.yaw};
  ASSERT_GT(0.1, TransientBeams::kStillDistance);
  mask(view());
  EXPECT_EQ(0, mask(withObject(view(moved), 40, 60), moved));
}

TEST_F(TransientBeamsTest, CreepingAndTurningALittleIsNotAChange) {
  // The background is moved into the new scan's frame: the beams that slid
  // along the walls and across the boxes' edges are not taken for objects.
  mask(view());
  for (const Pose2& step : {Pose2{0.03, 0.0, 0.0}, Pose2{0.0, 0.03, 0.0}, Pose2{0.02, -0.02, 0.015},
                            Pose2{0.0, 0.0, -0.017}}) {
    const Pose2 there = compose(kTruth, step);
    EXPECT_EQ(0, mask(view(there), there)) << step.x << " " << step.y << " " << step.yaw;
  }
}

TEST_F(TransientBeamsTest, ABeamEndingOnTheMapIsKept) {
  mask(view());
  int asked = 0;
  EXPECT_EQ(0, mask(withObject(view(), 40, 60), kTruth, [&asked](double, double) {
              ++asked;
              return true;
            }));
  EXPECT_EQ(20, asked);
}

TEST_F(TransientBeamsTest, ABeamWithoutAReadingSaysNothing) {
  // A dropout, or a scan of NaNs: the next good scan is not taken for
  // objects everywhere.
  LaserScan dropouts = view();
  for (std::size_t i = 0; i < dropouts.ranges.size(); i += 2) dropouts.ranges[i] = NAN;
  mask(dropouts);
  EXPECT_EQ(0, mask(view()));
}

TEST_F(TransientBeamsTest, EachSensorHasItsOwnBackground) {
  std::vector<LaserScan> two(2, view());
  two[1].sensor_pose = {0.0, 0.0, M_PI};
  two[1].ranges = view(compose(kTruth, two[1].sensor_pose)).ranges;
  transients_.mask(odomOf(kTruth), two, {}, &storage_);
  transients_.mask(odomOf(kTruth), two, {}, &storage_);
  EXPECT_EQ(0, transients_.masked());
  two[1] = withObject(two[1], 10, 15);
  const ScanGroup seen = transients_.mask(odomOf(kTruth), two, {}, &storage_);
  EXPECT_EQ(5, transients_.masked());
  EXPECT_EQ(0u, nanCount(seen[0]));
  EXPECT_EQ(5u, nanCount(seen[1]));
}

// The filter end to end: a robot stands, localized, and something steps up
// to it and fills half of its view for two scans. The published pose stays.
TEST(TransientBeams, AnObjectStandingInFrontOfTheRobotDoesNotMoveTheEstimate) {
  const OccupancyGrid grid = small_world::room();
  ParticleFilter filter(small_world::refinedParams());
  filter.setMap(grid);
  filter.initializeGaussian(kTruth, Eigen::Vector3d(1e-4, 1e-4, 1e-4).asDiagonal());
  const Pose2 odom = odomOf(kTruth);
  const LaserScan clear = castScan(grid, kTruth);
  ASSERT_TRUE(filter.update(odom, clear).updated);
  const Pose2 before = compose(*filter.mapToOdom(), odom);
  // An arc 0.3 m from the lidar over half of its beams. Left in, it pulls
  // the published pose 2 cm.
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
