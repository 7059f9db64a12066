// What pf_node saves, and when: the estimate carried by the latest odometry,
// only on the map it is on, every period of the clock and at shutdown.
#include "pf_localization/ros/output/pose_saver.h"

#include <gtest/gtest.h>
#include <tf2/buffer_core.h>

#include <cmath>
#include <vector>

#include "ros_unit/test_messages.h"

namespace pf_ros {
namespace {

using test::room;

TEST(PoseSaver, NothingToSaveBeforeAPoseOnTheCurrentMap) {
  PoseSaver saver;
  EXPECT_FALSE(saver.latest());
  saver.setMap("map A");
  EXPECT_FALSE(saver.latest());
  saver.set(PoseToSave{pf::Pose2{1.0, 2.0, 0.5}, 0.1, 0.2, 0.05});
  const auto record = saver.latest();
  ASSERT_TRUE(record);
  EXPECT_EQ("map A", record->map_signature);
  EXPECT_DOUBLE_EQ(2.0, record->pose.pose.y);
  EXPECT_DOUBLE_EQ(0.2, record->pose.cov_yy);
  // A new map: the pose on the old one is not saved with the new signature.
  saver.setMap("map B");
  EXPECT_FALSE(saver.latest());
  saver.set(std::nullopt);
  EXPECT_FALSE(saver.latest());
}

TEST(PoseToSave, TheEstimateCarriedByTheLatestOdometry) {
  tf2::BufferCore tf;
  LocalizerConfig config;
  config.initial_pose = pf::Pose2{1.5, 1.0, M_PI / 2};
  config.initial_cov = Eigen::Vector3d(0.01, 0.02, 0.003).asDiagonal();
  ScanLocalizer localizer(config, &tf);
  EXPECT_FALSE(poseToSave(localizer, std::nullopt));  // no map, no estimate
  ASSERT_EQ("", localizer.setMap(room()));
  const auto at_estimate = poseToSave(localizer, std::nullopt);
  ASSERT_TRUE(at_estimate);
  EXPECT_NEAR(1.5, at_estimate->pose.x, 0.05);
  EXPECT_NEAR(1.0, at_estimate->pose.y, 0.05);
  EXPECT_NEAR(0.01, at_estimate->cov_xx, 0.005);
  EXPECT_NEAR(0.02, at_estimate->cov_yy, 0.01);
  // Without a filter update there is no map -> odom: still the estimate.
  const auto with_odom = poseToSave(localizer, pf::Pose2{0.5, 0.0, 0.0});
  ASSERT_TRUE(with_odom);
  EXPECT_DOUBLE_EQ(at_estimate->pose.x, with_odom->pose.x);
}

TEST(PoseSaver, SavesOncePerPeriodOfTheClockAfterTheFirstLook) {
  std::vector<double> saved_at;
  double now_s = 0.0;
  PoseSaver saver(0.5, [&](const PoseSaver::Record&) { saved_at.push_back(now_s); });
  saver.setMap("map A");
  saver.set(PoseToSave{pf::Pose2{1.0, 2.0, 0.5}, 0.1, 0.2, 0.05});
  for (int tenth = 0; tenth <= 70; ++tenth) {
    now_s = 0.1 * tenth;
    saver.saveWhenDue(ros::Time(now_s));
  }
  // The clock not started (zero) starts nothing; 0.1 s starts the schedule,
  // and each 2 s after it saves.
  ASSERT_EQ(3u, saved_at.size());
  EXPECT_NEAR(2.1, saved_at[0], 1e-6);
  EXPECT_NEAR(4.1, saved_at[1], 1e-6);
  EXPECT_NEAR(6.1, saved_at[2], 1e-6);
  // Time going back (a bag restarted): due at once.
  now_s = 1.0;
  saver.saveWhenDue(ros::Time(now_s));
  EXPECT_EQ(4u, saved_at.size());
  saver.saveNow();
  EXPECT_EQ(5u, saved_at.size());
}

TEST(PoseSaver, NeverSavesWhenOffOrWithNothingToSave) {
  int writes = 0;
  PoseSaver off(0.0, [&](const PoseSaver::Record&) { ++writes; });
  EXPECT_FALSE(off.enabled());
  off.setMap("map A");
  off.set(PoseToSave{});
  for (double t = 1.0; t < 10.0; t += 1.0) off.saveWhenDue(ros::Time(t));
  off.saveNow();
  PoseSaver empty(10.0, [&](const PoseSaver::Record&) { ++writes; });
  for (double t = 1.0; t < 10.0; t += 1.0) empty.saveWhenDue(ros::Time(t));
  empty.saveNow();
  EXPECT_EQ(0, writes);
}

}  // namespace
}  // namespace pf_ros
