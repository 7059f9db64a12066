// ScanLocalizer: the ROS-message layer shared by pf_node and pf_bag_runner.
// A 4 x 3 m walled room, scans simulated from a known pose, tf fed by hand.
#include "pf_localization/ros/localizer/scan_localizer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <iostream>
#include <limits>
#include <optional>

#include "pf_localization/ros/input/conversions.h"
#include "support/rooms.h"
#include "support/scan_simulator.h"

namespace pf_ros {
namespace {

// Walls around the room and a 0.5 x 0.5 m pillar off-centre, so that no pose
// has a mirror twin.
pf::OccupancyGrid room() { return pf::test::room(4.0, 3.0, 0.05, {{2.5, 0.5, 3.0, 1.0}}); }

nav_msgs::OccupancyGrid mapMsg(const pf::OccupancyGrid& grid) {
  nav_msgs::OccupancyGrid map = toMsg(grid);
  map.header.frame_id = "map";
  return map;
}

// The laser: 360 beams over a full turn from -pi, 0.02 to 5 m, reading +inf
// where nothing is within range; mounted at `mount` on the base.
pf::test::ScanSpec laserSpec(const pf::Pose2& mount) {
  pf::test::ScanSpec spec;
  spec.beams = 360;
  spec.angle_increment = M_PI / 180.0;
  spec.range_min = 0.02;
  spec.range_max = 5.0;
  spec.sensor_pose = mount;
  spec.no_return = std::numeric_limits<float>::infinity();
  return spec;
}

// The message the laser publishes for `scan`, in frame "laser" (the mounting
// is tf's business, not the message's).
sensor_msgs::LaserScan scanMsg(const pf::LaserScan& scan, const ros::Time& stamp) {
  sensor_msgs::LaserScan msg;
  msg.header.frame_id = "laser";
  msg.header.stamp = stamp;
  msg.angle_min = static_cast<float>(scan.angle_min);
  msg.angle_increment = static_cast<float>(scan.angle_increment);
  msg.angle_max =
      static_cast<float>(scan.angle_min + (scan.ranges.size() - 1.0) * scan.angle_increment);
  msg.time_increment = static_cast<float>(scan.sweep.time_increment);
  msg.range_min = static_cast<float>(scan.range_min);
  msg.range_max = static_cast<float>(scan.range_max);
  msg.ranges = scan.ranges;
  return msg;
}

geometry_msgs::TransformStamped transform(const std::string& parent, const std::string& child,
                                          const pf::Pose2& pose, const ros::Time& stamp) {
  geometry_msgs::TransformStamped t;
  t.header.frame_id = parent;
  t.header.stamp = stamp;
  t.child_frame_id = child;
  t.transform = toTransformMsg(pose);
  return t;
}

class ScanLocalizerTest : public ::testing::Test {
 protected:
  ScanLocalizerTest() {
    config_.filter.kld.min_particles = 300;
    config_.filter.kld.max_particles = 1000;
    config_.filter.seed = 7;
    config_.filter.update_min_d = 0.0;
    config_.filter.update_min_a = 0.0;
    tf_.setTransform(transform("base_link", "laser", mount_, ros::Time(0)), "test", true);
  }

  // Robot at `truth` in the map; odometry says `odom`; both stamped `t`.
  sensor_msgs::LaserScan observe(const pf::Pose2& truth, const pf::Pose2& odom, double t) {
    const ros::Time stamp(t);
    tf_.setTransform(transform("odom", "base_link", odom, stamp), "test");
    tf_.setTransform(transform("odom", "base_link", odom, stamp + ros::Duration(0.01)), "test");
    return scanMsg(scans_.scanFrom(truth), stamp);
  }

  LocalizerConfig config_;
  tf2::BufferCore tf_;
  // The laser is mounted backwards, as on the AC109 Neato.
  pf::Pose2 mount_{-0.1, 0.0, M_PI};
  pf::OccupancyGrid grid_ = room();
  nav_msgs::OccupancyGrid map_ = mapMsg(grid_);
  pf::test::ScanSimulator scans_{grid_, laserSpec(mount_)};
};

TEST_F(ScanLocalizerTest, ScanBeforeMapIsRejectedWithAClearReason) {
  ScanLocalizer localizer(config_, &tf_);
  const ScanResult r = localizer.processScan(observe({1, 1, 0}, {0, 0, 0}, 10.0));
  EXPECT_EQ(r.error, ScanError::kNoMap) << errorMessage(r);
  EXPECT_FALSE(localizer.mapToOdom(ros::Time(10)).has_value());
}

TEST_F(ScanLocalizerTest, MissingLaserMountingSaysWhichTransformIsMissing) {
  ScanLocalizer localizer(config_, &tf_);
  ASSERT_EQ(localizer.setMap(map_), "");
  sensor_msgs::LaserScan scan = observe({1, 1, 0}, {0, 0, 0}, 10.0);
  scan.header.frame_id = "tilted_laser";
  const ScanResult r = localizer.processScan(scan);
  EXPECT_EQ(r.error, ScanError::kNoLaserMounting) << errorMessage(r);
  // The message leads with the one transform that is missing.
  EXPECT_EQ(r.error_detail.rfind("no transform base_link -> tilted_laser ", 0), 0u)
      << r.error_detail;
  EXPECT_FALSE(r.report.updated);
}

TEST_F(ScanLocalizerTest, MissingOdometrySaysWhichTransformIsMissing) {
  ScanLocalizer localizer(config_, &tf_);
  ASSERT_EQ(localizer.setMap(map_), "");
  const sensor_msgs::LaserScan scan = scanMsg(scans_.scanFrom({1, 1, 0}), ros::Time(10));
  const ScanResult r = localizer.processScan(scan);
  EXPECT_EQ(r.error, ScanError::kNoOdometry) << errorMessage(r);
  EXPECT_EQ(r.error_detail.rfind("no transform odom -> base_link at t=10.000 ", 0), 0u)
      << r.error_detail;
  EXPECT_FALSE(r.report.updated);
}

TEST_F(ScanLocalizerTest, AScanWithoutFrameIsRejected) {
  ScanLocalizer localizer(config_, &tf_);
  ASSERT_EQ(localizer.setMap(map_), "");
  sensor_msgs::LaserScan scan = observe({1, 1, 0}, {0, 0, 0}, 10.0);
  scan.header.frame_id.clear();
  EXPECT_EQ(localizer.processScan(scan).error, ScanError::kEmptyLaserFrame);
}

TEST_F(ScanLocalizerTest, TracksFromTheConfiguredInitialPose) {
  const pf::Pose2 start{1.0, 1.0, 0.3};
  config_.initial_pose = pf::Pose2{1.2, 0.9, 0.4};  // 0.22 m and 0.1 rad off
  ScanLocalizer localizer(config_, &tf_);
  ASSERT_EQ(localizer.setMap(map_), "");
  // Odometry starts at its own origin: map -> odom is the start pose.
  for (int k = 0; k < 10; ++k) {
    const pf::Pose2 motion{0.1 * k, 0.0, 0.05 * k};
    const ScanResult r =
        localizer.processScan(observe(pf::compose(start, motion), motion, 10.0 + k));
    ASSERT_EQ(r.error, ScanError::kNone) << errorMessage(r);
    ASSERT_TRUE(r.report.updated) << pf::skipMessage(r.report);
  }
  const auto m2o = localizer.mapToOdom(ros::Time(20));
  ASSERT_TRUE(m2o.has_value());
  const pf::Pose2 est = toPose2(m2o->transform);
  EXPECT_NEAR(est.x, start.x, 0.05);
  EXPECT_NEAR(est.y, start.y, 0.05);
  EXPECT_NEAR(pf::angleDiff(est.yaw, start.yaw), 0.0, 0.03);
  EXPECT_EQ(m2o->header.frame_id, "map");
  EXPECT_EQ(m2o->child_frame_id, "odom");
}

TEST_F(ScanLocalizerTest, InitialPoseBeforeTheMapIsUsedWhenTheMapArrives) {
  ScanLocalizer localizer(config_, &tf_);
  geometry_msgs::PoseWithCovarianceStamped pose;
  pose.header.frame_id = "map";
  pose.pose.pose = toPoseMsg({2.0, 1.5, 1.0});
  ASSERT_EQ(localizer.setInitialPose(pose), "");
  ASSERT_EQ(localizer.setMap(map_), "");
  const auto est = localizer.estimate(ros::Time(1));
  ASSERT_TRUE(est.has_value());
  EXPECT_NEAR(est->pose.pose.position.x, 2.0, 0.1);
  EXPECT_NEAR(est->pose.pose.position.y, 1.5, 0.1);
}

TEST_F(ScanLocalizerTest, NanInitialPoseIsRejected) {
  ScanLocalizer localizer(config_, &tf_);
  ASSERT_EQ(localizer.setMap(map_), "");
  geometry_msgs::PoseWithCovarianceStamped pose;
  pose.header.frame_id = "map";
  pose.pose.pose = toPoseMsg({std::nan(""), 1.0, 0.0});
  EXPECT_NE(localizer.setInitialPose(pose).find("not finite"), std::string::npos);
}

TEST_F(ScanLocalizerTest, MapWithoutFreeCellsIsRejected) {
  ScanLocalizer localizer(config_, &tf_);
  nav_msgs::OccupancyGrid full = map_;
  full.data.assign(full.data.size(), 100);
  EXPECT_NE(localizer.setMap(full).find("no free cell"), std::string::npos);
  EXPECT_FALSE(localizer.filter().hasMap());
}

TEST_F(ScanLocalizerTest, MalformedMapIsRejected) {
  ScanLocalizer localizer(config_, &tf_);
  nav_msgs::OccupancyGrid bad = map_;
  bad.data.pop_back();
  EXPECT_NE(localizer.setMap(bad).find("ignoring the map"), std::string::npos);
}

TEST_F(ScanLocalizerTest, AMapInTheCoresFormIsTheMessagesMap) {
  // A map loaded from a file goes in without a message: the same grid, the
  // same map-change grid's info, the same checks.
  ScanLocalizer from_msg(config_, &tf_), from_grid(config_, &tf_);
  ASSERT_EQ(from_msg.setMap(map_), "");
  ASSERT_EQ(from_grid.setMap(room()), "");
  EXPECT_EQ(from_msg.filter().map()->data(), from_grid.filter().map()->data());
  EXPECT_EQ(from_msg.filter().map()->resolution(), from_grid.filter().map()->resolution());
  const auto a = from_msg.mapChangesMsg(ros::Time(1.0)),
             b = from_grid.mapChangesMsg(ros::Time(1.0));
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->info, b->info);
  ScanLocalizer elsewhere(config_, &tf_);
  EXPECT_NE(elsewhere.setMap(room(), "odom").find("not the global frame"), std::string::npos);
  EXPECT_FALSE(elsewhere.filter().hasMap());
  pf::OccupancyGrid full(4, 4, 0.05, {}, std::vector<int8_t>(16, 100));
  EXPECT_NE(elsewhere.setMap(full).find("no free cell"), std::string::npos);
}

TEST_F(ScanLocalizerTest, AnInitialPoseIsMovedOnByTheOdometrySinceItsStamp) {
  // Given at t = 10 while the robot drives: by the latest odometry (t = 11)
  // it moved 0.8 m ahead and turned 0.1 rad, in its own frame. set_map's pose
  // waits for its map to be built, seconds on a large floor.
  ScanLocalizer localizer(config_, &tf_);
  ASSERT_EQ(localizer.setMap(map_), "");
  tf_.setTransform(transform("odom", "base_link", {2.0, 1.0, M_PI / 2}, ros::Time(10)), "test");
  tf_.setTransform(transform("odom", "base_link", {2.0, 1.8, M_PI / 2 + 0.1}, ros::Time(11)),
                   "test");
  geometry_msgs::PoseWithCovarianceStamped given;
  given.header.frame_id = "map";
  given.header.stamp = ros::Time(10);
  given.pose.pose = toPoseMsg({1.0, 1.5, 0.0});
  ASSERT_EQ(localizer.setInitialPose(given), "");
  EXPECT_NEAR(1.8, localizer.config().initial_pose->x, 1e-9);
  EXPECT_NEAR(1.5, localizer.config().initial_pose->y, 1e-9);
  EXPECT_NEAR(0.1, localizer.config().initial_pose->yaw, 1e-9);
  // Before the first update after it, map -> odom is the one that pose gives
  // with the latest odometry (published on, not dropped).
  const auto m2o = localizer.mapToOdom(ros::Time(11));
  ASSERT_TRUE(m2o);
  const pf::Pose2 base = pf::compose(toPose2(m2o->transform), {2.0, 1.8, M_PI / 2 + 0.1});
  EXPECT_NEAR(1.8, base.x, 1e-9);
  EXPECT_NEAR(1.5, base.y, 1e-9);
  EXPECT_NEAR(0.1, base.yaw, 1e-9);
  // Global localization has no such pose.
  ASSERT_EQ(localizer.startGlobalLocalization(), "");
  EXPECT_FALSE(localizer.mapToOdom(ros::Time(11)));
  // A zero stamp is "now": the pose as given.
  given.header.stamp = ros::Time();
  ASSERT_EQ(localizer.setInitialPose(given), "");
  EXPECT_EQ(1.0, localizer.config().initial_pose->x);
}

TEST_F(ScanLocalizerTest, AMapIsCheckedAndBuiltApartThenInstalled) {
  // pf_node builds a new map without the filter's lock: building reads only
  // the recipe, refuses what setMap refuses, and installing is setMap's.
  ScanLocalizer localizer(config_, &tf_);
  const ScanLocalizer::MapRecipe recipe = localizer.mapRecipe();
  nav_msgs::OccupancyGrid bad = map_;
  bad.data.pop_back();
  ScanLocalizer::ReadyMap refused = ScanLocalizer::prepareMap(bad, recipe);
  EXPECT_FALSE(refused.map);
  EXPECT_NE(refused.error.find("ignoring the map"), std::string::npos);
  nav_msgs::OccupancyGrid elsewhere = map_;
  elsewhere.header.frame_id = "odom";
  EXPECT_NE(ScanLocalizer::prepareMap(elsewhere, recipe).error.find("not the global frame"),
            std::string::npos);
  EXPECT_NE(localizer.setMap(std::move(refused)).find("ignoring the map"), std::string::npos);
  EXPECT_FALSE(localizer.filter().hasMap());

  ScanLocalizer::ReadyMap ready = ScanLocalizer::prepareMap(map_, recipe);
  ASSERT_TRUE(ready.map) << ready.error;
  EXPECT_FALSE(localizer.filter().hasMap());  // built, not installed
  ASSERT_EQ(localizer.setMap(std::move(ready)), "");
  ScanLocalizer direct(config_, &tf_);
  ASSERT_EQ(direct.setMap(map_), "");
  EXPECT_EQ(direct.filter().map()->data(), localizer.filter().map()->data());
  EXPECT_EQ(direct.filter().particles().x, localizer.filter().particles().x);
  const auto a = direct.mapChangesMsg(ros::Time(1.0)), b = localizer.mapChangesMsg(ros::Time(1.0));
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->info, b->info);
}

TEST_F(ScanLocalizerTest, AReplacedMapComesOutForALaterFloorChange) {
  // A building's floors (floors.h): the map a new one replaces is handed
  // back, its grid and metadata whole, and installs again as it was.
  ScanLocalizer localizer(config_, &tf_);
  std::optional<pf::PreparedMap> replaced;
  ScanLocalizer::ReadyMap ground = ScanLocalizer::prepareMap(map_, localizer.mapRecipe());
  ASSERT_EQ(localizer.setMap(std::move(ground), &replaced), "");
  EXPECT_FALSE(replaced);  // the first map replaces none
  const pf::OccupancyGrid* ground_grid = localizer.filter().map();
  const nav_msgs::MapMetaData ground_info = map_.info;

  const nav_msgs::OccupancyGrid upper =
      mapMsg(pf::test::room(3.0, 3.0, 0.05, {{1.0, 1.0, 1.5, 1.5}}));
  ASSERT_EQ(localizer.setMap(ScanLocalizer::prepareMap(upper, localizer.mapRecipe()), &replaced),
            "");
  ASSERT_TRUE(replaced);
  EXPECT_EQ(ground_grid, &replaced->model->field().grid());  // the same grid, not a copy
  EXPECT_EQ(upper.info.width, localizer.mapChangesMsg(ros::Time(1.0))->info.width);

  ScanLocalizer::ReadyMap back{"", std::move(replaced), ground_info};
  ASSERT_EQ(localizer.setMap(std::move(back), &replaced), "");
  EXPECT_EQ(ground_grid, localizer.filter().map());
  EXPECT_EQ(ground_info.width, localizer.mapChangesMsg(ros::Time(1.0))->info.width);
  ASSERT_TRUE(replaced);
  EXPECT_EQ(upper.info.width, static_cast<unsigned>(replaced->model->field().grid().width()));
}

TEST(ScanInconsistency, ConsistentScanHasNone) {
  sensor_msgs::LaserScan scan;
  scan.angle_min = -1.0;
  scan.angle_increment = 0.5;
  scan.angle_max = 1.0;
  scan.ranges.assign(5, 1.0f);
  EXPECT_EQ(scanInconsistency(scan), "");
  scan.intensities.assign(5, 0.0f);
  EXPECT_EQ(scanInconsistency(scan), "");
}

TEST(ScanInconsistency, IntensitiesOfAnotherLengthAreReported) {
  sensor_msgs::LaserScan scan;
  scan.angle_min = -1.0;
  scan.angle_increment = 0.5;
  scan.angle_max = 1.0;
  scan.ranges.assign(5, 1.0f);
  scan.intensities.assign(3, 0.0f);
  EXPECT_NE(scanInconsistency(scan).find("3 intensities for 5 ranges"), std::string::npos);
}

TEST(ScanInconsistency, AngleMaxThatDisagreesIsReported) {
  sensor_msgs::LaserScan scan;
  scan.angle_min = -1.0;
  scan.angle_increment = 0.5;
  scan.angle_max = 2.0;  // five beams end at 1.0
  scan.ranges.assign(5, 1.0f);
  EXPECT_NE(scanInconsistency(scan).find("angle_max"), std::string::npos);
}

TEST_F(ScanLocalizerTest, OdometryMessageBecomesOdomToBaseTransform) {
  nav_msgs::Odometry odom;
  odom.header.frame_id = "odom";
  odom.header.stamp = ros::Time(3.5);
  odom.child_frame_id = "base_link";
  odom.pose.pose = toPoseMsg({1.0, -2.0, 0.5});
  const geometry_msgs::TransformStamped t = odometryToTransform(odom);
  EXPECT_EQ(t.header.frame_id, "odom");
  EXPECT_EQ(t.child_frame_id, "base_link");
  EXPECT_EQ(t.header.stamp, ros::Time(3.5));
  EXPECT_DOUBLE_EQ(t.transform.translation.x, 1.0);
  EXPECT_DOUBLE_EQ(t.transform.translation.y, -2.0);
  EXPECT_NEAR(yawOf(t.transform.rotation), 0.5, 1e-12);
}

// --- De-skewing --------------------------------------------------------------

// Odometry turning on the spot at `rate` rad/s from t = 0 on, on tf at 100 Hz
// from `from` to `to` s.
void spinOnTf(tf2::BufferCore* tf, double rate, double from, double to) {
  for (double t = from; t <= to + 1e-9; t += 0.01) {
    tf->setTransform(
        transform("odom", "base_link", {0.0, 0.0, pf::normalizeAngle(rate * t)}, ros::Time(t)),
        "test");
  }
}

// A 361-beam scan stamped 10.5 s whose sweep takes 0.2 s.
sensor_msgs::LaserScan timedScan() {
  sensor_msgs::LaserScan scan;
  scan.header.stamp = ros::Time(10.5);
  scan.ranges.assign(361, 1.0f);
  scan.time_increment = 0.2f / 360.0f;
  return scan;
}

TEST(SweepMotion, FromOdometryOverTheSweepAndTheStampConvention) {
  tf2::BufferCore tf;
  spinOnTf(&tf, 1.0, 9.0, 11.0);
  sensor_msgs::LaserScan scan = timedScan();
  const double span = 360.0 * scan.time_increment;
  LocalizerConfig config;
  config.deskew_scans = true;
  config.scan_stamp = "last_beam";
  const pf::Pose2 odom{0.0, 0.0, 10.5};
  pf::SweepMotion sweep = sweepMotion(scan, tf, config, odom);
  EXPECT_NEAR(sweep.base_velocity.yaw, 1.0, 1e-9);
  EXPECT_NEAR(sweep.base_velocity.x, 0.0, 1e-9);
  EXPECT_NEAR(sweep.first_beam_time, -span, 1e-12);
  EXPECT_DOUBLE_EQ(sweep.time_increment, scan.time_increment);

  config.scan_stamp = "first_beam";
  EXPECT_EQ(sweepMotion(scan, tf, config, odom).first_beam_time, 0.0);
  // Beams timed backwards: the last index is the first taken.
  scan.time_increment = -scan.time_increment;
  EXPECT_NEAR(sweepMotion(scan, tf, config, odom).first_beam_time, span, 1e-12);
  config.scan_stamp = "last_beam";
  EXPECT_EQ(sweepMotion(scan, tf, config, odom).first_beam_time, 0.0);
}

TEST(SweepMotion, StillWhenOffUntimedImplausibleOrWithoutHistory) {
  tf2::BufferCore tf;
  spinOnTf(&tf, 1.0, 10.0, 11.0);
  sensor_msgs::LaserScan scan = timedScan();
  LocalizerConfig config;
  const pf::Pose2 odom{0.0, 0.0, 10.5};
  EXPECT_TRUE(sweepMotion(scan, tf, config, odom).isStill()) << "off by default";
  config.deskew_scans = true;
  EXPECT_FALSE(sweepMotion(scan, tf, config, odom).isStill());
  scan.time_increment = 0.0f;
  EXPECT_TRUE(sweepMotion(scan, tf, config, odom).isStill()) << "no beam timing";
  scan.time_increment = 0.01f;  // 3.6 s for one sweep
  EXPECT_TRUE(sweepMotion(scan, tf, config, odom).isStill()) << "implausible timing";
  scan.time_increment = 0.2f / 360.0f;
  scan.header.stamp = ros::Time(10.1);  // odometry starts at 10.0
  EXPECT_TRUE(sweepMotion(scan, tf, config, odom).isStill()) << "no odometry a sweep back";
}

// Spinning at 2 rad/s, a 0.1 s sweep bends the scan by 0.2 rad from its
// first beam to its last. Read as if taken at once, the scan puts the
// estimate's yaw off by half of that; de-skewed, the estimate is right.
TEST_F(ScanLocalizerTest, DeskewingRemovesTheSpinsYawBias) {
  constexpr double kRate = 2.0, kSweep = 0.1;
  const pf::Pose2 start{1.5, 1.2, 0.0};
  spinOnTf(&tf_, kRate, 9.0, 12.0);
  config_.initial_pose = pf::compose(start, {0.0, 0.0, kRate * 10.0});  // at the first scan
  config_.initial_cov = Eigen::Vector3d(1e-4, 1e-4, 1e-4).asDiagonal();
  config_.scan_stamp = "last_beam";
  // Beam i is taken (359 - i) / 359 of a sweep before the stamp.
  pf::test::ScanSpec spinning = laserSpec(mount_);
  spinning.sweep.first_beam_time = -kSweep;
  spinning.sweep.time_increment = kSweep / 359.0;
  spinning.sweep.base_velocity = {0.0, 0.0, kRate};
  pf::test::ScanSimulator scans(grid_, spinning);
  auto final_yaw_error = [&](bool deskew) {
    config_.deskew_scans = deskew;
    ScanLocalizer localizer(config_, &tf_);
    EXPECT_EQ(localizer.setMap(map_), "");
    double error = 0.0;
    for (int k = 0; k < 10; ++k) {
      const double stamp = 10.0 + 0.1 * k;
      const pf::Pose2 truth = pf::compose(start, {0.0, 0.0, kRate * stamp});
      const ScanResult r = localizer.processScan(scanMsg(scans.scanFrom(truth), ros::Time(stamp)));
      EXPECT_EQ(r.error, ScanError::kNone) << errorMessage(r);
      const auto est = localizer.estimate(ros::Time(stamp));
      error = pf::angleDiff(toPose2(est->pose.pose).yaw, truth.yaw);
    }
    return error;
  };
  const double bent = final_yaw_error(false);
  const double deskewed = final_yaw_error(true);
  std::cout << "yaw error: as taken at once " << bent << " rad, de-skewed " << deskewed << "\n";
  EXPECT_GT(std::fabs(bent), 0.05) << "the bend this test is about";
  EXPECT_LT(std::fabs(deskewed), 0.02);
}

// Two lidars: the update on one sensor's scan takes the other's latest scan
// since the last update, where the robot was when it was taken; not one an
// update took already, nor one older than kMaxSensorScanAge.
TEST_F(ScanLocalizerTest, AnUpdateTakesTheOtherSensorsLatestScan) {
  const pf::Pose2 rear_mount{-0.2, 0.1, M_PI / 2};
  tf_.setTransform(transform("base_link", "rear_laser", rear_mount, ros::Time(0)), "test", true);
  pf::test::ScanSimulator rear{grid_, laserSpec(rear_mount)};
  config_.filter.update_min_d = 0.1;
  config_.filter.update_min_a = 1.0;
  config_.initial_pose = pf::Pose2{0.98, 1.0, 0.0};
  config_.initial_cov = Eigen::Vector3d(0.0025, 0.0025, 0.001).asDiagonal();
  ScanLocalizer localizer(config_, &tf_);
  ASSERT_EQ(localizer.setMap(map_), "");
  // The robot drives along x; the odometry is the truth.
  auto at = [&](double x, double t) {
    const pf::Pose2 pose{x, 1.0, 0.0};
    tf_.setTransform(transform("odom", "base_link", pose, ros::Time(t)), "test");
    tf_.setTransform(transform("odom", "base_link", pose, ros::Time(t + 0.01)), "test");
    return pose;
  };
  auto rearScan = [&](double x, double t) {
    sensor_msgs::LaserScan msg = scanMsg(rear.scanFrom(at(x, t)), ros::Time(t));
    msg.header.frame_id = "rear_laser";
    return localizer.processScan(msg, 1);
  };
  auto frontScan = [&](double x, double t) {
    return localizer.processScan(scanMsg(scans_.scanFrom(at(x, t)), ros::Time(t)), 0);
  };
  const ScanResult first = rearScan(0.98, 10.0);  // the first update after the initialisation
  ASSERT_TRUE(first.report.updated) << pf::skipMessage(first.report);
  const int one_scan = first.report.beams_used;
  EXPECT_FALSE(frontScan(1.0, 10.04).report.updated);  // 2 cm: not moved enough
  EXPECT_FALSE(rearScan(1.06, 10.1).report.updated);
  // 12 cm: the update takes the front scan and the rear one of 50 ms before.
  const ScanResult both = frontScan(1.1, 10.15);
  ASSERT_TRUE(both.report.updated) << pf::skipMessage(both.report);
  EXPECT_EQ(2 * one_scan, both.report.beams_used);
  EXPECT_LT(std::hypot(localizer.filter().estimate().pose.x - 1.1,
                       localizer.filter().estimate().pose.y - 1.0),
            0.02);
  // Both were used: the next update on a front scan comes alone.
  const ScanResult after = frontScan(1.22, 10.3);
  ASSERT_TRUE(after.report.updated) << pf::skipMessage(after.report);
  EXPECT_EQ(one_scan, after.report.beams_used);
  // A rear scan older than kMaxSensorScanAge is left out.
  EXPECT_FALSE(rearScan(1.25, 10.35).report.updated);
  const ScanResult stale = frontScan(1.35, 10.35 + kMaxSensorScanAge + 0.05);
  ASSERT_TRUE(stale.report.updated) << pf::skipMessage(stale.report);
  EXPECT_EQ(one_scan, stale.report.beams_used);
}

// A 3D lidar's cloud: the room's walls at three heights inside the band and
// the floor below it, in frame "velodyne"; reduced to a scan and weighed.
sensor_msgs::PointCloud2 cloudOfWalls(const pf::LaserScan& scan, const ros::Time& stamp) {
  std::vector<float> xyz;
  for (std::size_t i = 0; i < scan.ranges.size(); ++i) {
    const double a = scan.angle_min + i * scan.angle_increment;
    const float r = scan.ranges[i];
    if (!std::isfinite(r)) continue;
    for (const float z : {0.0f, 0.4f, 0.6f, 0.8f}) {  // the floor, then the wall
      const float d = z == 0.0f ? 0.5f * r : r;
      xyz.insert(xyz.end(),
                 {static_cast<float>(d * std::cos(a)), static_cast<float>(d * std::sin(a)), z});
    }
  }
  sensor_msgs::PointCloud2 cloud;
  cloud.header.frame_id = "velodyne";
  cloud.header.stamp = stamp;
  cloud.height = 1;
  cloud.width = static_cast<uint32_t>(xyz.size() / 3);
  for (const char* name : {"x", "y", "z"}) {
    sensor_msgs::PointField f;
    f.name = name;
    f.offset = static_cast<uint32_t>(4 * cloud.fields.size());
    f.datatype = sensor_msgs::PointField::FLOAT32;
    f.count = 1;
    cloud.fields.push_back(f);
  }
  cloud.point_step = 12;
  cloud.row_step = cloud.point_step * cloud.width;
  cloud.is_dense = true;
  cloud.data.resize(cloud.row_step);
  std::memcpy(cloud.data.data(), xyz.data(), cloud.data.size());
  return cloud;
}

TEST_F(ScanLocalizerTest, ACloudIsReducedToAScanAndWeighed) {
  tf_.setTransform(transform("base_link", "velodyne", {0.1, 0.0, 0.0}, ros::Time(0)), "test", true);
  pf::test::ScanSimulator lidar{grid_, laserSpec({0.1, 0.0, 0.0})};
  const pf::Pose2 truth{1.0, 1.5, 0.2};
  config_.initial_pose = pf::Pose2{1.05, 1.45, 0.22};
  config_.initial_cov = Eigen::Vector3d(0.0025, 0.0025, 0.001).asDiagonal();
  ScanLocalizer localizer(config_, &tf_);
  ASSERT_EQ(localizer.setMap(map_), "");
  for (int i = 0; i < 5; ++i) {
    const ros::Time stamp(10.0 + i);
    tf_.setTransform(transform("odom", "base_link", {}, stamp), "test");
    tf_.setTransform(transform("odom", "base_link", {}, stamp + ros::Duration(0.01)), "test");
    const ScanResult r = localizer.processCloud(cloudOfWalls(lidar.scanFrom(truth), stamp), 0);
    ASSERT_EQ(r.error, ScanError::kNone) << errorMessage(r);
    ASSERT_TRUE(r.report.updated) << pf::skipMessage(r.report);
    EXPECT_GT(r.report.beams_used, 30);
  }
  const pf::Pose2 e = localizer.filter().estimate().pose;
  EXPECT_LT(std::hypot(e.x - truth.x, e.y - truth.y), 0.02);
  EXPECT_LT(std::fabs(pf::angleDiff(e.yaw, truth.yaw)), 0.01);
}

TEST_F(ScanLocalizerTest, ACloudWithoutZSaysSo) {
  tf_.setTransform(transform("base_link", "velodyne", {}, ros::Time(0)), "test", true);
  tf_.setTransform(transform("odom", "base_link", {}, ros::Time(10)), "test");
  config_.initial_pose = pf::Pose2{1.0, 1.5, 0.0};
  ScanLocalizer localizer(config_, &tf_);
  ASSERT_EQ(localizer.setMap(map_), "");
  sensor_msgs::PointCloud2 cloud = cloudOfWalls(scans_.scanFrom({1.0, 1.5, 0.0}), ros::Time(10));
  cloud.fields.pop_back();
  const ScanResult r = localizer.processCloud(cloud, 0);
  EXPECT_EQ(r.error, ScanError::kBadCloud);
  EXPECT_NE(r.error_detail.find("'z'"), std::string::npos) << r.error_detail;
}

}  // namespace
}  // namespace pf_ros
