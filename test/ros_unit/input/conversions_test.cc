#include "pf_localization/ros/input/conversions.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace pf_ros {
namespace {

geometry_msgs::Quaternion quat(double x, double y, double z, double w) {
  geometry_msgs::Quaternion q;
  q.x = x;
  q.y = y;
  q.z = z;
  q.w = w;
  return q;
}

TEST(ConversionsTest, QuaternionFromYaw) {
  const geometry_msgs::Quaternion q = quaternionFromYaw(M_PI / 2);
  EXPECT_EQ(q.x, 0.0);
  EXPECT_EQ(q.y, 0.0);
  EXPECT_DOUBLE_EQ(q.z, std::sqrt(0.5));
  EXPECT_DOUBLE_EQ(q.w, std::sqrt(0.5));
  const geometry_msgs::Quaternion identity = quaternionFromYaw(0.0);
  EXPECT_EQ(identity.z, 0.0);
  EXPECT_EQ(identity.w, 1.0);
}

TEST(ConversionsTest, YawRoundTripAcrossPlusMinusPi) {
  const std::vector<double> yaws = {0.0,  0.5,  -0.5,         M_PI / 2, -M_PI / 2,      3.0,
                                    -3.0, M_PI, -M_PI,        3.2,      -3.2,           M_PI - 1e-9,
                                    7.0,  -7.0, -M_PI + 1e-9, 2 * M_PI, 4 * M_PI + 0.25};
  for (const double yaw : yaws) {
    const double back = yawOf(quaternionFromYaw(yaw));
    EXPECT_GT(back, -M_PI) << yaw;
    EXPECT_LE(back, M_PI) << yaw;
    // Across the +-pi seam, -pi + tiny and pi - tiny are the same angle.
    EXPECT_NEAR(pf::angleDiff(back, yaw), 0.0, 1e-12) << yaw;
  }
  EXPECT_NEAR(yawOf(quaternionFromYaw(3.2)), 3.2 - 2 * M_PI, 1e-12);
  EXPECT_NEAR(yawOf(quaternionFromYaw(-3.2)), 2 * M_PI - 3.2, 1e-12);
}

TEST(ConversionsTest, YawOfExactCases) {
  EXPECT_EQ(yawOf(quat(0, 0, 0, 1)), 0.0);
  EXPECT_EQ(yawOf(quat(0, 0, 1, 0)), M_PI);      // half turn about z
  EXPECT_EQ(yawOf(quat(0, 0, -1, 0)), M_PI);     // the same rotation: never -pi
  EXPECT_EQ(yawOf(quat(0, 0, 2, 2)), M_PI / 2);  // not unit length: still 90 degrees
  EXPECT_EQ(yawOf(quat(0, 0, -3, 3)), -M_PI / 2);
}

TEST(ConversionsTest, YawIgnoresRollAndPitch) {
  // A pure roll of 0.5 rad has no yaw.
  EXPECT_EQ(yawOf(quat(std::sin(0.25), 0, 0, std::cos(0.25))), 0.0);
  // A pure pitch of 0.4 rad has no yaw.
  EXPECT_EQ(yawOf(quat(0, std::sin(0.2), 0, std::cos(0.2))), 0.0);
}

TEST(ConversionsTest, PoseAndTransform) {
  const pf::Pose2 p{1.5, -2.25, 0.75};
  const geometry_msgs::Pose pose = toPoseMsg(p);
  EXPECT_EQ(pose.position.x, 1.5);
  EXPECT_EQ(pose.position.y, -2.25);
  EXPECT_EQ(pose.position.z, 0.0);
  EXPECT_EQ(pose.orientation.z, std::sin(0.375));
  EXPECT_EQ(pose.orientation.w, std::cos(0.375));
  const pf::Pose2 back = toPose2(pose);
  EXPECT_EQ(back.x, 1.5);
  EXPECT_EQ(back.y, -2.25);
  EXPECT_NEAR(back.yaw, 0.75, 1e-15);

  const geometry_msgs::Transform t = toTransformMsg(p);
  EXPECT_EQ(t.translation.x, 1.5);
  EXPECT_EQ(t.translation.y, -2.25);
  EXPECT_EQ(t.translation.z, 0.0);
  EXPECT_EQ(t.rotation.z, std::sin(0.375));
  EXPECT_EQ(t.rotation.w, std::cos(0.375));
  const pf::Pose2 tb = toPose2(t);
  EXPECT_EQ(tb.x, 1.5);
  EXPECT_EQ(tb.y, -2.25);
  EXPECT_NEAR(tb.yaw, 0.75, 1e-15);
}

TEST(ConversionsTest, PoseIgnoresHeight) {
  geometry_msgs::Pose pose;
  pose.position.x = 1.0;
  pose.position.y = 2.0;
  pose.position.z = 3.0;
  pose.orientation = quaternionFromYaw(0.0);
  const pf::Pose2 p = toPose2(pose);
  EXPECT_EQ(p.x, 1.0);
  EXPECT_EQ(p.y, 2.0);
  EXPECT_EQ(p.yaw, 0.0);
}

TEST(ConversionsTest, CovarianceToRosPutsYawAtIndex5) {
  Eigen::Matrix3d cov;
  cov << 1, 2, 3,  //
      4, 5, 6,     //
      7, 8, 9;
  const boost::array<double, 36> ros = toRosCovariance(cov);
  // Row-major 6x6 over (x, y, z, roll, pitch, yaw).
  boost::array<double, 36> expected;
  expected.fill(0.0);
  expected[0] = 1;   // xx
  expected[1] = 2;   // xy
  expected[5] = 3;   // x yaw
  expected[6] = 4;   // yx
  expected[7] = 5;   // yy
  expected[11] = 6;  // y yaw
  expected[30] = 7;  // yaw x
  expected[31] = 8;  // yaw y
  expected[35] = 9;  // yaw yaw
  EXPECT_EQ(ros, expected);
}

TEST(ConversionsTest, CovarianceFromRosReadsTheXYYawBlock) {
  boost::array<double, 36> ros;
  for (int i = 0; i < 36; ++i) ros[i] = i;
  Eigen::Matrix3d expected;
  expected << 0, 1, 5,  //
      6, 7, 11,         //
      30, 31, 35;
  EXPECT_EQ(fromRosCovariance(ros), expected);

  Eigen::Matrix3d cov;
  cov << 0.25, 0.01, -0.02,  //
      0.01, 0.5, 0.03,       //
      -0.02, 0.03, 0.1;
  EXPECT_EQ(fromRosCovariance(toRosCovariance(cov)), cov);
}

nav_msgs::OccupancyGrid gridMsg(uint32_t w, uint32_t h, float res, std::vector<int8_t> data) {
  nav_msgs::OccupancyGrid msg;
  msg.info.width = w;
  msg.info.height = h;
  msg.info.resolution = res;
  msg.info.origin.position.x = -2.5;
  msg.info.origin.position.y = 4.0;
  msg.info.origin.orientation = quaternionFromYaw(0.0);
  msg.data = std::move(data);
  return msg;
}

TEST(ConversionsTest, GridToCore) {
  const pf::OccupancyGrid g = toCore(gridMsg(3, 2, 0.05f, {0, 100, -1, 50, 0, 0}));
  EXPECT_EQ(g.width(), 3);
  EXPECT_EQ(g.height(), 2);
  // The float32 0.05f is read as the decimal 0.05 the map file said.
  EXPECT_EQ(g.resolution(), 0.05);
  EXPECT_EQ(g.origin().x, -2.5);
  EXPECT_EQ(g.origin().y, 4.0);
  EXPECT_EQ(g.origin().yaw, 0.0);
  EXPECT_EQ(g.data(), std::vector<int8_t>({0, 100, -1, 50, 0, 0}));
  ASSERT_EQ(3u, g.freeCells().size());
  EXPECT_EQ(0, g.freeCells()[0]);
  EXPECT_EQ(4, g.freeCells()[1]);
  EXPECT_EQ(5, g.freeCells()[2]);
}

TEST(ConversionsTest, GridToCoreRejectsMalformedGrids) {
  EXPECT_THROW(toCore(gridMsg(3, 2, 0.05f, {0, 0, 0, 0, 0})), std::invalid_argument);
  EXPECT_THROW(toCore(gridMsg(3, 2, 0.05f, {0, 0, 0, 0, 0, 0, 0})), std::invalid_argument);
  EXPECT_THROW(toCore(gridMsg(0, 2, 0.05f, {})), std::invalid_argument);
  EXPECT_THROW(toCore(gridMsg(1, 1, 0.0f, {0})), std::invalid_argument);
  EXPECT_THROW(toCore(gridMsg(1, 1, -0.1f, {0})), std::invalid_argument);
  EXPECT_THROW(toCore(gridMsg(1, 1, std::numeric_limits<float>::quiet_NaN(), {0})),
               std::invalid_argument);
  EXPECT_THROW(toCore(gridMsg(70000, 70000, 0.05f, {0})), std::invalid_argument);
  try {
    toCore(gridMsg(3, 2, 0.05f, {0, 0, 0, 0, 0}));
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "OccupancyGrid message: 5 cell values for a 3 x 2 grid");
  }
}

TEST(ConversionsTest, GridToMsgAndBack) {
  const pf::OccupancyGrid g(2, 3, 0.03, {-1.37, -27.9, 0.5}, {0, 100, -1, -1, 0, 100});
  const nav_msgs::OccupancyGrid msg = toMsg(g);
  EXPECT_EQ(msg.info.width, 2u);
  EXPECT_EQ(msg.info.height, 3u);
  EXPECT_EQ(msg.info.resolution, 0.03f);
  EXPECT_EQ(msg.info.origin.position.x, -1.37);
  EXPECT_EQ(msg.info.origin.position.y, -27.9);
  EXPECT_EQ(msg.info.origin.orientation.z, std::sin(0.25));
  EXPECT_EQ(msg.data, std::vector<int8_t>({0, 100, -1, -1, 0, 100}));
  EXPECT_EQ(msg.header.frame_id, "");

  const pf::OccupancyGrid back = toCore(msg);
  EXPECT_EQ(back.resolution(), 0.03);
  EXPECT_EQ(back.origin().x, -1.37);
  EXPECT_EQ(back.origin().y, -27.9);
  EXPECT_NEAR(back.origin().yaw, 0.5, 1e-15);
  EXPECT_EQ(back.data(), g.data());
}

TEST(ConversionsTest, ScanToCoreCopiesEveryField) {
  sensor_msgs::LaserScan msg;
  msg.angle_min = -1.5f;
  msg.angle_max = 1.5f;
  msg.angle_increment = 0.25f;
  msg.range_min = 0.125f;
  msg.range_max = 8.0f;
  const float inf = std::numeric_limits<float>::infinity();
  msg.ranges = {1.0f, std::numeric_limits<float>::quiet_NaN(), inf, 0.0f, 7.5f};
  const pf::LaserScan scan = toCore(msg, {-0.1016, 0.0, M_PI});
  EXPECT_EQ(scan.angle_min, -1.5);
  EXPECT_EQ(scan.angle_increment, 0.25);
  EXPECT_EQ(scan.range_min, 0.125);
  EXPECT_EQ(scan.range_max, 8.0);
  ASSERT_EQ(scan.ranges.size(), 5u);
  EXPECT_EQ(scan.ranges[0], 1.0f);
  EXPECT_TRUE(std::isnan(scan.ranges[1]));
  EXPECT_EQ(scan.ranges[2], inf);
  EXPECT_EQ(scan.ranges[3], 0.0f);
  EXPECT_EQ(scan.ranges[4], 7.5f);
  EXPECT_EQ(scan.sensor_pose.x, -0.1016);
  EXPECT_EQ(scan.sensor_pose.y, 0.0);
  EXPECT_EQ(scan.sensor_pose.yaw, M_PI);
}

TEST(ConversionsTest, ParticlesToPoseArray) {
  pf::ParticleSet particles;
  particles.resize(2);
  particles.setPose(0, {1.0, 2.0, 0.0});
  particles.setPose(1, {-3.0, 0.5, M_PI / 2});
  geometry_msgs::PoseArray out;
  out.header.frame_id = "map";
  out.poses.resize(7);  // stale content from a previous call is replaced
  toPoseArray(particles, &out);
  EXPECT_EQ(out.header.frame_id, "map");
  ASSERT_EQ(out.poses.size(), 2u);
  EXPECT_EQ(out.poses[0].position.x, 1.0);
  EXPECT_EQ(out.poses[0].position.y, 2.0);
  EXPECT_EQ(out.poses[0].orientation.w, 1.0);
  EXPECT_EQ(out.poses[1].position.x, -3.0);
  EXPECT_EQ(out.poses[1].position.y, 0.5);
  EXPECT_DOUBLE_EQ(out.poses[1].orientation.z, std::sqrt(0.5));
}

TEST(ConversionsTest, HypothesesToMsgInTheirOrderWithCountAndCovariance) {
  pf::Hypotheses twins;
  twins.count = 3;  // one more than listed: a capped list
  pf::Hypothesis a;
  a.pose = {1.0, 7.5, M_PI / 2};
  a.weight = 0.5;
  a.covariance << 0.04, 0.01, 0.0, 0.01, 0.09, 0.0, 0.0, 0.0, 0.0025;
  a.particles = 900;
  pf::Hypothesis b;
  b.pose = {11.0, 7.5, -M_PI / 2};
  b.weight = 0.3;
  b.particles = 600;
  twins.listed = {a, b};
  pf_localization::PoseHypotheses msg;
  msg.header.frame_id = "map";
  msg.poses.resize(5);  // stale content from a previous call is replaced
  toHypothesesMsg(twins, &msg);
  EXPECT_EQ("map", msg.header.frame_id);
  EXPECT_EQ(3u, msg.count);
  ASSERT_EQ(2u, msg.poses.size());
  ASSERT_EQ(2u, msg.weights.size());
  ASSERT_EQ(2u, msg.particles.size());
  EXPECT_EQ(1.0, msg.poses[0].pose.position.x);
  EXPECT_EQ(7.5, msg.poses[0].pose.position.y);
  EXPECT_NEAR(M_PI / 2, yawOf(msg.poses[0].pose.orientation), 1e-12);
  EXPECT_EQ(0.04, msg.poses[0].covariance[0]);
  EXPECT_EQ(0.01, msg.poses[0].covariance[1]);
  EXPECT_EQ(0.09, msg.poses[0].covariance[7]);
  EXPECT_EQ(0.0025, msg.poses[0].covariance[35]);
  EXPECT_EQ(11.0, msg.poses[1].pose.position.x);
  EXPECT_NEAR(-M_PI / 2, yawOf(msg.poses[1].pose.orientation), 1e-12);
  EXPECT_EQ(0.5, msg.weights[0]);
  EXPECT_EQ(0.3, msg.weights[1]);
  EXPECT_EQ(900u, msg.particles[0]);
  EXPECT_EQ(600u, msg.particles[1]);
}

}  // namespace
}  // namespace pf_ros
