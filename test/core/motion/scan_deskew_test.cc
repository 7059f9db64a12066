#include "pf_localization/core/motion/scan_deskew.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "core/expect_pose.h"
#include "pf_localization/core/sensor/laser_scan.h"
#include "pf_localization/core/sensor/sensor_model.h"
#include "support/rooms.h"
#include "support/scan_simulator.h"

namespace pf {
namespace {

TEST(MotionOver, StraightLine) {
  expectPoseNear({0.5, 0.0, 0.0}, motionOver({1.0, 0.0, 0.0}, 0.5));
  expectPoseNear({-0.2, 0.1, 0.0}, motionOver({0.4, -0.2, 0.0}, -0.5));
}

TEST(MotionOver, QuarterCircleForwardAndBack) {
  // Radius 1 (v / w = 1) about the centre (0, 1).
  expectPoseNear({1.0, 1.0, M_PI / 2}, motionOver({M_PI / 2, 0.0, M_PI / 2}, 1.0));
  expectPoseNear({-1.0, 1.0, -M_PI / 2}, motionOver({M_PI / 2, 0.0, M_PI / 2}, -1.0));
  // Turning on the spot moves nothing but the yaw.
  expectPoseNear({0.0, 0.0, -0.3}, motionOver({0.0, 0.0, 1.5}, -0.2));
}

TEST(VelocityBetween, RecoversTheArcFromAnyStart) {
  expectPoseNear({M_PI / 2, 0.0, M_PI / 2}, velocityBetween({0, 0, 0}, {1.0, 1.0, M_PI / 2}, 1.0));
  // The same relative motion from (2, 3, pi/2) ends at (1, 4, pi).
  expectPoseNear({M_PI / 4, 0.0, M_PI / 4},
                 velocityBetween({2.0, 3.0, M_PI / 2}, {1.0, 4.0, M_PI}, 2.0));
  expectPoseNear({0.3, 0.0, 0.0}, velocityBetween({1.0, 1.0, 0.0}, {1.03, 1.0, 0.0}, 0.1), 1e-12);
}

TEST(VelocityBetween, InvertsMotionOver) {
  for (const Pose2 v : {Pose2{0.3, 0.0, 1.2}, Pose2{-0.5, 0.1, -2.0}, Pose2{0.2, -0.3, 1e-12}}) {
    const Pose2 moved = compose({1.0, -2.0, 0.7}, motionOver(v, 0.2));
    expectPoseNear(v, velocityBetween({1.0, -2.0, 0.7}, moved, 0.2), 1e-9);
  }
}

TEST(SensorPoseAtBeam, StillSweepKeepsTheMounting) {
  const Pose2 mount{0.1, 0.0, M_PI};
  const Pose2 at = sensorPoseAtBeam(mount, SweepMotion{}, 100);
  EXPECT_EQ(mount.x, at.x);
  EXPECT_EQ(mount.y, at.y);
  EXPECT_EQ(mount.yaw, at.yaw);
  SweepMotion no_timing;
  no_timing.base_velocity = {0.5, 0.0, 1.0};  // moving, but every beam at once
  EXPECT_EQ(mount.x, sensorPoseAtBeam(mount, no_timing, 7).x);
}

TEST(SensorPoseAtBeam, CarriesTheMountingAlongTheBaseMotion) {
  // Turning on the spot at pi/2 rad/s; the stamp is beam 2's (first beam at -1 s).
  SweepMotion sweep;
  sweep.first_beam_time = -1.0;
  sweep.time_increment = 0.5;
  sweep.base_velocity = {0.0, 0.0, M_PI / 2};
  const Pose2 mount{0.1, 0.0, M_PI};
  expectPoseNear(mount, sensorPoseAtBeam(mount, sweep, 2));
  expectPoseNear({0.0, -0.1, M_PI / 2}, sensorPoseAtBeam(mount, sweep, 0));
  expectPoseNear({0.0, 0.1, -M_PI / 2}, sensorPoseAtBeam(mount, sweep, 4));
}

// A straight wall at x = 2 in the frame of the base at the stamp (the inner
// face of a room's right wall, the room 12 m high so that every beam reaches
// it), scanned by a laser mounted at `mount` while the base drives and turns:
// the ranges each beam really measures.
LaserScan wallScannedWhileMoving(const Pose2& mount, const SweepMotion& sweep) {
  test::ScanSpec spec;
  spec.beams = 13;
  spec.angle_min = -0.6;
  spec.angle_increment = 0.1;
  spec.range_min = 0.05;
  spec.range_max = 20.0;
  spec.sensor_pose = mount;
  spec.sweep = sweep;
  return test::simulateScan(test::room(3.1, 12.0, 0.1, {}, {-1.0, -6.0, 0.0}), {}, spec);
}

TEST(PrepareScan, DeskewedWallIsStraight) {
  SweepMotion sweep;
  sweep.first_beam_time = -0.2;  // stamped at the last of 13 beams 1/60 s apart
  sweep.time_increment = 0.2 / 12;
  sweep.base_velocity = {0.4, 0.0, 1.5};  // 0.4 m/s while turning at 1.5 rad/s
  const Pose2 mount{0.1, 0.05, 0.3};
  const LaserScan scan = wallScannedWhileMoving(mount, sweep);

  const PreparedScan fixed = prepareScan(scan, 0, 0.0, 0.0, 0.05);
  ASSERT_EQ(13u, fixed.size());
  for (std::size_t b = 0; b < fixed.size(); ++b) {
    EXPECT_NEAR(2.0, fixed.x[b], 1e-5) << "beam " << b;
    // The beam model's ray from the mounting reaches the same end point.
    EXPECT_NEAR(fixed.x[b], mount.x + fixed.range[b] * std::cos(fixed.angle[b]), 1e-5);
    EXPECT_NEAR(fixed.y[b], mount.y + fixed.range[b] * std::sin(fixed.angle[b]), 1e-5);
  }

  // Read as if taken at once, the first beam lands 6 cm off the wall: the
  // bend that de-skewing removes.
  LaserScan at_once = scan;
  at_once.sweep = SweepMotion{};
  const PreparedScan bent = prepareScan(at_once, 0, 0.0, 0.0, 0.05);
  EXPECT_GT(std::fabs(bent.x[0] - 2.0), 0.05);
}

TEST(PrepareScan, StillSweepGivesTheSameBits) {
  SweepMotion timing_only;
  timing_only.time_increment = 0.01;  // timed beams, but the robot stands still
  LaserScan scan = wallScannedWhileMoving({0.1, 0.05, 0.3}, SweepMotion{});
  LaserScan timed = scan;
  timed.sweep = timing_only;
  const PreparedScan a = prepareScan(scan, 5, 0.0, 0.0, 0.05);
  const PreparedScan b = prepareScan(timed, 5, 0.0, 0.0, 0.05);
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.y, b.y);
  EXPECT_EQ(a.range, b.range);
  EXPECT_EQ(a.angle, b.angle);
}

TEST(ValidateScan, RejectsANonFiniteSweep) {
  LaserScan scan = wallScannedWhileMoving({}, SweepMotion{});
  EXPECT_FALSE(validateScan(scan).has_value());
  scan.sweep.time_increment = std::numeric_limits<double>::quiet_NaN();
  ASSERT_TRUE(validateScan(scan).has_value());
  EXPECT_NE(std::string::npos, validateScan(scan)->find("sweep"));
  scan.sweep = SweepMotion{};
  scan.sweep.base_velocity.yaw = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(validateScan(scan).has_value());
}

}  // namespace
}  // namespace pf
