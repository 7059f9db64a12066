#include "pf_localization/sim/diff_drive_robot.h"

#include <gtest/gtest.h>

namespace pf::sim {
namespace {

void expectPose(const Pose2& p, double x, double y, double yaw) {
  EXPECT_NEAR(p.x, x, 1e-12);
  EXPECT_NEAR(p.y, y, 1e-12);
  EXPECT_NEAR(p.yaw, yaw, 1e-12);
}

TEST(IntegrateArcTest, StraightLineAndQuarterCircle) {
  expectPose(integrateArc({1.0, 2.0, 0.0}, 3.0, 0.0), 4.0, 2.0, 0.0);
  expectPose(integrateArc({0.0, 0.0, M_PI / 2}, 2.0, 0.0), 0.0, 2.0, M_PI / 2);
  // A quarter of the unit circle, turning left from the origin.
  expectPose(integrateArc({0.0, 0.0, 0.0}, M_PI / 2, M_PI / 2), 1.0, 1.0, M_PI / 2);
  // Turning in place.
  expectPose(integrateArc({1.0, 1.0, 0.0}, 0.0, -1.0), 1.0, 1.0, -1.0);
}

TEST(IntegrateArcTest, ManySmallArcsEqualOneBigArc) {
  Pose2 p{0.5, -0.5, 0.3};
  for (int i = 0; i < 100; ++i) p = integrateArc(p, 0.02, 0.015);
  const Pose2 q = integrateArc({0.5, -0.5, 0.3}, 2.0, 1.5);
  expectPose(p, q.x, q.y, q.yaw);
}

TEST(DiffDriveRobotTest, PerfectOdometryFollowsTheTruthFromTheOrigin) {
  DiffDriveRobot robot({}, {2.0, 3.0, M_PI / 2});
  robot.step(0.5, 0.0, 2.0, nullptr);
  expectPose(robot.truePose(), 2.0, 4.0, M_PI / 2);
  expectPose(robot.odomPose(), 1.0, 0.0, 0.0);
  EXPECT_DOUBLE_EQ(robot.odomLinearVelocity(), 0.5);
  EXPECT_DOUBLE_EQ(robot.odomAngularVelocity(), 0.0);
}

TEST(DiffDriveRobotTest, LargerWheelsMakeOdometryShortOfTheTruth) {
  DiffDriveParams params;
  params.left_radius_error = params.right_radius_error = 0.02;
  DiffDriveRobot robot(params, {});
  robot.step(1.0, 0.0, 1.0, nullptr);
  expectPose(robot.truePose(), 1.0, 0.0, 0.0);
  expectPose(robot.odomPose(), 1.0 / 1.02, 0.0, 0.0);
}

TEST(DiffDriveRobotTest, UnsignedEncodersLogReversingAsDrivingForwards) {
  DiffDriveParams params;
  params.unsigned_translation = true;
  DiffDriveRobot robot(params, {});
  robot.step(-0.5, 0.0, 2.0, nullptr);  // 1 m backwards
  expectPose(robot.truePose(), -1.0, 0.0, 0.0);
  expectPose(robot.odomPose(), 1.0, 0.0, 0.0);
  EXPECT_DOUBLE_EQ(robot.odomLinearVelocity(), 0.5);
  robot.step(0.0, -0.5, 1.0, nullptr);  // turns keep their sign
  expectPose(robot.odomPose(), 1.0, 0.0, -0.5);
}

TEST(DiffDriveRobotTest, WiderTrackMakesOdometryOverTurn) {
  DiffDriveParams params;
  params.track_width_error = 0.1;
  DiffDriveRobot robot(params, {});
  robot.step(0.0, 1.0, 1.0, nullptr);
  expectPose(robot.truePose(), 0.0, 0.0, 1.0);
  expectPose(robot.odomPose(), 0.0, 0.0, 1.1);
  EXPECT_NEAR(robot.odomAngularVelocity(), 1.1, 1e-12);
}

TEST(DiffDriveRobotTest, UnequalWheelsBendAStraightLine) {
  DiffDriveParams params;
  params.track_width = 0.25;
  params.right_radius_error = 0.01;
  DiffDriveRobot robot(params, {});
  robot.step(1.0, 0.0, 1.0, nullptr);
  // The right wheel is bigger, so it turns less: odometry believes in a right turn.
  const double left = 1.0, right = 1.0 / 1.01;
  const Pose2 expected = integrateArc({}, 0.5 * (left + right), (right - left) / 0.25);
  expectPose(robot.odomPose(), expected.x, expected.y, expected.yaw);
  EXPECT_LT(robot.odomPose().yaw, 0.0);
}

TEST(DiffDriveRobotTest, TeleportMovesOnlyTheTruth) {
  DiffDriveRobot robot({}, {});
  robot.step(0.2, 0.0, 1.0, nullptr);
  robot.teleport({5.0, 5.0, 1.0});
  robot.step(0.2, 0.0, 1.0, nullptr);
  expectPose(robot.truePose(), 5.0 + 0.2 * std::cos(1.0), 5.0 + 0.2 * std::sin(1.0), 1.0);
  expectPose(robot.odomPose(), 0.4, 0.0, 0.0);
}

TEST(DiffDriveRobotTest, SlipIsRandomButSeeded) {
  DiffDriveParams params;
  params.slip_sigma = 0.01;
  DiffDriveRobot a(params, {}), b(params, {});
  SimRandom ra(5), rb(5);
  for (int i = 0; i < 100; ++i) {
    a.step(0.3, 0.1, 0.05, &ra);
    b.step(0.3, 0.1, 0.05, &rb);
  }
  EXPECT_EQ(a.odomPose().x, b.odomPose().x);
  EXPECT_EQ(a.odomPose().yaw, b.odomPose().yaw);
  EXPECT_NE(a.odomPose().x, a.truePose().x);
  EXPECT_NEAR(a.odomPose().x, a.truePose().x, 0.05);
}

}  // namespace
}  // namespace pf::sim
