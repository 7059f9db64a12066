// OdometrySource: odometry from tf when /tf carries odom -> base, from the
// odometry topic otherwise, and one log line for the source in use.
#include "pf_localization/ros/input/odometry_source.h"

#include <gtest/gtest.h>

#include <limits>

namespace pf_ros {
namespace {

tf2_msgs::TFMessage tfWith(const std::string& parent, const std::string& child) {
  tf2_msgs::TFMessage msg;
  geometry_msgs::TransformStamped t;
  t.header.frame_id = parent;
  t.child_frame_id = child;
  t.transform.rotation.w = 1.0;
  msg.transforms.push_back(t);
  return msg;
}

nav_msgs::Odometry odometry(double stamp, double x) {
  nav_msgs::Odometry msg;
  msg.header.frame_id = "odom";
  msg.header.stamp = ros::Time(stamp);
  msg.child_frame_id = "base_link";
  msg.pose.pose.position.x = x;
  msg.pose.pose.orientation.w = 1.0;
  return msg;
}

OdometrySource source() { return OdometrySource("odom", "base_link", "/odom"); }

TEST(OdometrySource, OdometryOnTfIsTheSourceAndSaidOnce) {
  OdometrySource odom = source();
  EXPECT_FALSE(odom.onTf(tfWith("base_link", "laser")));
  EXPECT_FALSE(odom.takeAnnouncement());
  EXPECT_TRUE(odom.onTf(tfWith("odom", "base_link")));
  EXPECT_EQ(OdometrySource::Kind::kTf, odom.kind());
  EXPECT_EQ("odometry: from tf odom -> base_link", odom.takeAnnouncement().value_or(""));
  EXPECT_FALSE(odom.takeAnnouncement());
  EXPECT_FALSE(odom.onTf(tfWith("odom", "base_link")));  // already known
  // The topic's messages are ignored from then on, silently.
  for (double t : {10.0, 11.0, 12.0}) {
    const auto use = odom.onTopic(odometry(t, 1.0));
    EXPECT_FALSE(use.transform);
    EXPECT_TRUE(use.problem.empty());
  }
}

TEST(OdometrySource, TheTopicAfterItsGraceWhenTfHasNoOdometry) {
  OdometrySource odom = source();
  EXPECT_FALSE(odom.onTopic(odometry(10.0, 0.0)).transform);
  EXPECT_FALSE(odom.onTopic(odometry(10.4, 0.1)).transform);
  EXPECT_EQ(OdometrySource::Kind::kUndecided, odom.kind());
  EXPECT_FALSE(odom.takeAnnouncement());
  const auto use = odom.onTopic(odometry(10.5, 0.2));
  ASSERT_TRUE(use.transform);
  EXPECT_EQ("odom", use.transform->header.frame_id);
  EXPECT_EQ("base_link", use.transform->child_frame_id);
  EXPECT_DOUBLE_EQ(0.2, use.transform->transform.translation.x);
  EXPECT_EQ(ros::Time(10.5), use.transform->header.stamp);
  EXPECT_EQ("odometry: from the odom topic /odom (tf has no odom -> base_link)",
            odom.takeAnnouncement().value_or(""));
  EXPECT_TRUE(odom.onTopic(odometry(10.6, 0.3)).transform);
  EXPECT_FALSE(odom.takeAnnouncement());
}

TEST(OdometrySource, SaidAgainWhenTfStartsCarryingIt) {
  OdometrySource odom = source();
  odom.onTopic(odometry(10.0, 0.0));
  ASSERT_TRUE(odom.onTopic(odometry(11.0, 0.0)).transform);
  ASSERT_TRUE(odom.takeAnnouncement());
  EXPECT_TRUE(odom.onTf(tfWith("odom", "base_link")));
  const std::string line = odom.takeAnnouncement().value_or("");
  EXPECT_EQ(0u, line.find("odometry: from tf odom -> base_link")) << line;
  EXPECT_FALSE(odom.onTopic(odometry(12.0, 0.0)).transform);
}

TEST(OdometrySource, UnusableMessagesAreNamed) {
  OdometrySource odom = source();
  nav_msgs::Odometry no_child = odometry(10.0, 0.0);
  no_child.child_frame_id.clear();
  const auto frames = odom.onTopic(no_child);
  EXPECT_FALSE(frames.transform);
  EXPECT_NE(std::string::npos, frames.problem.find("empty frame_id or child_frame_id"));
  odom.onTopic(odometry(10.0, 0.0));
  const auto nan = odom.onTopic(odometry(11.0, std::numeric_limits<double>::quiet_NaN()));
  EXPECT_FALSE(nan.transform);
  EXPECT_NE(std::string::npos, nan.problem.find("non-finite"));
  EXPECT_NE(frames.problem_key, nan.problem_key);
  EXPECT_EQ(OdometrySource::Kind::kUndecided, odom.kind());
}

}  // namespace
}  // namespace pf_ros
