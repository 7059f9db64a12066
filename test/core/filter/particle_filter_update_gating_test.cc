// Which calls of ParticleFilter::update update: none without a map, particles,
// a usable scan or finite odometry (each skip with its reason); the first scan,
// then only after update_min_d or update_min_a of motion or on request; and the
// motion since the last update is what the next one applies.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "core/filter/particle_filter_world.h"
#include "pf_localization/core/filter/particle_filter.h"

namespace pf {
namespace {

using filter_world::asymmetricRoom;
using filter_world::baseParams;
using filter_world::diag;
using filter_world::emptyScan;
using filter_world::exactParams;
using filter_world::simulateScan;

// --- Update gating -------------------------------------------------------------------

TEST(ParticleFilterUpdate, SkipsWithoutMap) {
  ParticleFilter filter(baseParams());
  filter.initializeGaussian({1.0, 1.5, 0.0}, diag(0.1, 0.1, 0.1));
  const UpdateReport r = filter.update({0, 0, 0}, simulateScan(asymmetricRoom(), {1.0, 1.5, 0.0}));
  EXPECT_FALSE(r.updated);
  EXPECT_EQ(SkipReason::kNoMap, r.skip_reason) << skipMessage(r);
}

TEST(ParticleFilterUpdate, SkipsWhenNotInitialised) {
  ParticleFilter filter(baseParams());
  filter.setMap(asymmetricRoom());
  const UpdateReport r = filter.update({0, 0, 0}, simulateScan(asymmetricRoom(), {1.0, 1.5, 0.0}));
  EXPECT_FALSE(r.updated);
  EXPECT_EQ(SkipReason::kNotInitialized, r.skip_reason) << skipMessage(r);
}

TEST(ParticleFilterUpdate, SkipsBadScansAndBadOdometry) {
  const OccupancyGrid grid = asymmetricRoom();
  ParticleFilter filter(baseParams());
  filter.setMap(grid);
  filter.initializeGaussian({1.0, 1.5, 0.0}, diag(0.1, 0.1, 0.1));
  const LaserScan good = simulateScan(grid, {1.0, 1.5, 0.0});

  LaserScan empty = good;
  empty.ranges.clear();
  UpdateReport r = filter.update({0, 0, 0}, empty);
  EXPECT_FALSE(r.updated);
  EXPECT_EQ(SkipReason::kBadScan, r.skip_reason) << skipMessage(r);

  LaserScan zero_increment = good;
  zero_increment.angle_increment = 0.0;
  r = filter.update({0, 0, 0}, zero_increment);
  EXPECT_FALSE(r.updated);
  EXPECT_EQ(SkipReason::kBadScan, r.skip_reason) << skipMessage(r);
  // The detail names what is wrong.
  EXPECT_NE(std::string::npos, r.skip_detail.find("angle_increment")) << r.skip_detail;

  r = filter.update({NAN, 0, 0}, good);
  EXPECT_FALSE(r.updated);
  EXPECT_EQ(SkipReason::kOdometryNotFinite, r.skip_reason) << skipMessage(r);

  // None of that counted as the first update.
  EXPECT_FALSE(filter.mapToOdom().has_value());
  EXPECT_TRUE(filter.update({0, 0, 0}, good).updated);
}

TEST(ParticleFilterUpdate, RunsOnTheFirstScanThenOnlyAfterMotion) {
  const OccupancyGrid grid = asymmetricRoom();
  ParticleFilterParams params = baseParams();  // update_min_d 0.2 m, update_min_a pi/6
  // The odometry below moves while the scan stays: only the thresholds are
  // under test here, not the check that the scan still fits (see
  // AScanThatStopsFittingThePredictedPoseUpdatesAtOnce), nor the odometry
  // faults the stalled particles would find (SuspectOdometryUpdatesOnEveryScan).
  params.update_fit_drop = 0.0;
  params.motion.fault_fraction = 0.0;
  ParticleFilter filter(params);
  filter.setMap(grid);
  filter.initializeGaussian({1.0, 1.5, 0.0}, diag(0.1, 0.1, 0.1));
  const LaserScan scan = simulateScan(grid, {1.0, 1.5, 0.0});
  const Pose2 odom0{5.0, 5.0, 2.0};

  UpdateReport r = filter.update(odom0, scan);
  EXPECT_TRUE(r.updated) << skipMessage(r);
  EXPECT_EQ(SkipReason::kNone, r.skip_reason);
  EXPECT_TRUE(r.skip_detail.empty());
  EXPECT_GT(r.beams_used, 0);
  EXPECT_LE(r.beams_used, 60);  // max_beams

  r = filter.update(odom0, scan);
  EXPECT_FALSE(r.updated);
  EXPECT_EQ(SkipReason::kNotMoved, r.skip_reason) << skipMessage(r);

  // 0.19 m, then 0.5 rad: below both thresholds.
  EXPECT_FALSE(filter.update(compose(odom0, {0.19, 0.0, 0.0}), scan).updated);
  EXPECT_FALSE(filter.update(compose(odom0, {0.0, 0.0, 0.5}), scan).updated);
  // The robot went back: still not moved since the last update.
  EXPECT_FALSE(filter.update(odom0, scan).updated);

  // requestNoMotionUpdate forces one update, once.
  filter.requestNoMotionUpdate();
  EXPECT_TRUE(filter.update(odom0, scan).updated);
  EXPECT_FALSE(filter.update(odom0, scan).updated);

  // 0.21 m sideways (the direction does not matter) or 0.55 rad is enough.
  const Pose2 odom1 = compose(odom0, {0.0, -0.21, 0.0});
  EXPECT_TRUE(filter.update(odom1, scan).updated);
  const Pose2 odom2 = compose(odom1, {0.0, 0.0, -0.55});
  EXPECT_TRUE(filter.update(odom2, scan).updated);
  EXPECT_FALSE(filter.update(odom2, scan).updated);
}

TEST(ParticleFilterUpdate, NanOnlyScanIsSkippedWithAReason) {
  const OccupancyGrid grid = asymmetricRoom();
  ParticleFilter filter(baseParams());
  filter.setMap(grid);
  filter.initializeGaussian({1.0, 1.5, 0.0}, diag(0.1, 0.1, 0.1));
  const std::vector<double> before = filter.particles().x;

  const UpdateReport r = filter.update({0, 0, 0}, emptyScan());  // 180 NaN ranges
  EXPECT_FALSE(r.updated);
  EXPECT_EQ(SkipReason::kNoValidBeam, r.skip_reason) << skipMessage(r);
  EXPECT_EQ(0, r.beams_used);
  EXPECT_EQ(180, r.beams_dropped);
  EXPECT_EQ(before, filter.particles().x);
  EXPECT_FALSE(filter.mapToOdom().has_value());
  // The next usable scan is still the first one.
  EXPECT_TRUE(filter.update({0, 0, 0}, simulateScan(grid, {1.0, 1.5, 0.0})).updated);
}

TEST(ParticleFilterUpdate, MotionIsAppliedFromTheLastUpdateOnly) {
  const OccupancyGrid grid = asymmetricRoom();
  ParticleFilter filter(exactParams());
  filter.setMap(grid);
  const Pose2 start{1.0, 1.5, 0.2};
  filter.initializeGaussian(start, Eigen::Matrix3d::Zero());
  const LaserScan scan = simulateScan(grid, start);

  // The first update after an initialisation does not move the particles,
  // whatever odometry came before.
  const Pose2 odom0{-3.0, 4.0, 1.0};
  ASSERT_TRUE(filter.update(odom0, scan).updated);
  for (std::size_t i = 0; i < filter.particles().size(); ++i) {
    EXPECT_EQ(start.x, filter.particles().x[i]);
    EXPECT_EQ(start.y, filter.particles().y[i]);
    EXPECT_EQ(start.yaw, filter.particles().yaw[i]);
  }
  // Motion seen with a scan without usable beams is not lost: it is applied
  // with the next usable scan.
  const Pose2 odom1 = compose(odom0, {0.15, 0.0, 0.0});
  EXPECT_FALSE(filter.update(odom1, emptyScan()).updated);
  const Pose2 odom2 = compose(odom1, {0.3, 0.1, 0.2});
  ASSERT_TRUE(filter.update(odom2, scan).updated);
  const Pose2 expected = compose(start, between(odom0, odom2));
  for (std::size_t i = 0; i < filter.particles().size(); ++i) {
    EXPECT_NEAR(expected.x, filter.particles().x[i], 1e-9);
    EXPECT_NEAR(expected.y, filter.particles().y[i], 1e-9);
    EXPECT_NEAR(expected.yaw, filter.particles().yaw[i], 1e-9);
  }
  // Re-initialising discards the odometry travelled since the last update.
  const Pose2 restart{2.0, 2.0, -1.0};
  filter.initializeGaussian(restart, Eigen::Matrix3d::Zero());
  ASSERT_TRUE(filter.update(compose(odom2, {1.0, 0.0, 1.0}), scan).updated);
  EXPECT_EQ(restart.x, filter.particles().x[0]);
  EXPECT_EQ(restart.yaw, filter.particles().yaw[0]);
}

}  // namespace
}  // namespace pf
