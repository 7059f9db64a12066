#include "pf_localization/ros/localizer/scan_localizer.h"

#include <tf2/exceptions.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

#include "pf_localization/ros/input/conversions.h"
#include "pf_localization/ros/input/point_cloud.h"
#include "pf_localization/ros/input/pose_transform.h"
#include "pf_localization/ros/params/live_params.h"

namespace pf_ros {
namespace {

std::string describe(const ros::Time& t) {
  std::ostringstream s;
  s.precision(3);
  s << std::fixed << t.toSec();
  return s.str();
}

}  // namespace

const char* toString(ScanError error) {
  switch (error) {
    case ScanError::kNone:
      return "none";
    case ScanError::kNoMap:
      return "no map received yet";
    case ScanError::kEmptyLaserFrame:
      return "the scan has an empty frame_id";
    case ScanError::kNoLaserMounting:
      return "cannot place the laser on the robot";
    case ScanError::kNoOdometry:
      return "no odometry at the scan's stamp";
    case ScanError::kBadCloud:
      return "cannot read the point cloud";
  }
  return "unknown scan error";
}

std::string errorMessage(const ScanResult& result) {
  std::string message = toString(result.error);
  if (!result.error_detail.empty()) message += ": " + result.error_detail;
  return message;
}

ScanLocalizer::ScanLocalizer(const LocalizerConfig& config, const tf2::BufferCore* tf)
    : config_(config),
      configured_pose_(config.initial_pose),
      configured_cov_(config.initial_cov),
      tf_(tf),
      filter_(config.filter),
      cloud_reducer_(config.cloud),
      health_(sensorTopics(config)),
      weights_(scanWeights(config)) {}

std::string ScanLocalizer::setMap(const nav_msgs::OccupancyGrid& map) {
  return setMap(prepareMap(map, mapRecipe()));
}

std::string ScanLocalizer::setMap(pf::OccupancyGrid grid, const std::string& frame_id) {
  return setMap(prepareMap(std::move(grid), frame_id, mapRecipe()));
}

ScanLocalizer::ReadyMap ScanLocalizer::prepareMap(const nav_msgs::OccupancyGrid& map,
                                                  const MapRecipe& recipe) {
  pf::OccupancyGrid grid;
  try {
    grid = toCore(map);
  } catch (const std::invalid_argument& e) {
    return {std::string("ignoring the map: ") + e.what(), std::nullopt, map.info};
  }
  ReadyMap ready = prepareMap(std::move(grid), map.header.frame_id, recipe);
  ready.info = map.info;
  return ready;
}

ScanLocalizer::ReadyMap ScanLocalizer::prepareMap(pf::OccupancyGrid grid,
                                                  const std::string& frame_id,
                                                  const MapRecipe& recipe) {
  const nav_msgs::MapMetaData info = toMapInfo(grid);
  if (grid.freeCells().empty()) {
    return {"ignoring the map: it has no free cell, so no pose on it is possible", std::nullopt,
            info};
  }
  if (!frame_id.empty() && frame_id != recipe.global_frame) {
    return {"ignoring the map: its frame '" + frame_id + "' is not the global frame '" +
                recipe.global_frame + "'",
            std::nullopt, info};
  }
  return {"", pf::PreparedMap::build(std::move(grid), recipe.filter), info};
}

std::string ScanLocalizer::setMap(ReadyMap ready, std::optional<pf::PreparedMap>* replaced) {
  if (!ready.map) return ready.error;
  if (replaced) *replaced = filter_.releaseMap();
  const bool kept = filter_.setMap(std::move(*ready.map));
  if (!kept) given_map_to_odom_.reset();
  map_info_ = ready.info;
  const bool first = !had_map_;
  had_map_ = true;
  if (kept) return "";
  // A first map starts from the configured pose; a replaced map whose free
  // space no longer holds the estimate leaves nothing to track from.
  if (first && config_.initial_pose) {
    filter_.initializeGaussian(*config_.initial_pose, config_.initial_cov);
    return "";
  }
  return startGlobalLocalization();
}

std::string ScanLocalizer::reconfigure(const LocalizerConfig& config) {
  try {
    filter_.setParams(config.filter);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  copyLiveParams(config, &config_);
  return "";
}

std::string ScanLocalizer::setInitialPose(const geometry_msgs::PoseWithCovarianceStamped& msg) {
  const pf::Pose2 given = toPose2(msg.pose.pose);
  if (!given.isFinite()) return "ignoring the initial pose: it is not finite (NaN or inf)";
  const auto& q = msg.pose.pose.orientation;
  if (!std::isfinite(q.x + q.y + q.z + q.w) ||
      q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w < 1e-9) {
    return "ignoring the initial pose: its orientation is not a valid quaternion";
  }
  Eigen::Matrix3d cov = fromRosCovariance(msg.pose.covariance);
  if (!cov.allFinite()) return "ignoring the initial pose: its covariance is not finite";
  // rviz sends a fixed covariance; an all-zero one means "no opinion".
  if (cov.isZero()) cov = config_.initial_cov;
  const PoseNow now = tf_ ? movedByOdometrySince(*tf_, given, msg.header.stamp, config_.odom_frame,
                                                 config_.base_frame)
                          : PoseNow{given, std::nullopt};
  const pf::Pose2& pose = now.pose;
  config_.initial_pose = pose;
  config_.initial_cov = cov;
  given_map_to_odom_.reset();
  if (!filter_.hasMap()) return "";  // used when the map arrives
  try {
    filter_.initializeGaussian(pose, cov);
  } catch (const std::invalid_argument& e) {
    return std::string("ignoring the initial pose: ") + e.what();
  }
  given_map_to_odom_ = now.map_to_odom;  // none: map -> odom waits for the first update
  return "";
}

std::string ScanLocalizer::startGlobalLocalization() {
  given_map_to_odom_.reset();
  if (!filter_.hasMap()) return "global localization needs a map; none has arrived yet";
  try {
    filter_.initializeUniform();
  } catch (const std::logic_error& e) {
    return std::string("global localization failed: ") + e.what();
  }
  return "";
}

std::string ScanLocalizer::restart() {
  given_map_to_odom_.reset();
  config_.initial_pose = configured_pose_;
  config_.initial_cov = configured_cov_;
  if (!filter_.hasMap()) return "";
  if (!configured_pose_) return startGlobalLocalization();
  filter_.initializeGaussian(*configured_pose_, configured_cov_);
  return "";
}

std::optional<geometry_msgs::TransformStamped> ScanLocalizer::lookUp(const std::string& frame,
                                                                     const ros::Time& stamp,
                                                                     ScanResult* result) const {
  if (!filter_.hasMap()) {
    result->error = ScanError::kNoMap;
    result->error_detail = "waiting for one on the map topic";
    return std::nullopt;
  }
  if (frame.empty()) {
    result->error = ScanError::kEmptyLaserFrame;
    result->error_detail = "cannot place the laser on the robot";
    return std::nullopt;
  }
  geometry_msgs::TransformStamped laser, odom;
  try {
    // The mounting is rigid: the newest transform is as good as one at the
    // stamp, and does not fail on a mount published at a low rate.
    laser = tf_->lookupTransform(config_.base_frame, frame, ros::Time(0));
  } catch (const tf2::TransformException& e) {
    result->error = ScanError::kNoLaserMounting;
    result->error_detail =
        "no transform " + config_.base_frame + " -> " + frame +
        " (the laser's mounting; the odometry was not looked up yet): " + e.what();
    return std::nullopt;
  }
  try {
    odom = tf_->lookupTransform(config_.odom_frame, config_.base_frame, stamp);
  } catch (const tf2::TransformException& e) {
    result->error = ScanError::kNoOdometry;
    result->error_detail = "no transform " + config_.odom_frame + " -> " + config_.base_frame +
                           " at t=" + describe(stamp) + " (the laser's mounting " +
                           config_.base_frame + " -> " + frame + " was found): " + e.what();
    return std::nullopt;
  }
  result->odom = toPose2(odom.transform);
  return laser;
}

ScanResult ScanLocalizer::processScan(const sensor_msgs::LaserScan& scan, std::size_t sensor) {
  filter_.expectScanRange(scan.range_max);  // the table for it, with the map even before one
  ScanResult result;
  const auto laser = lookUp(scan.header.frame_id, scan.header.stamp, &result);
  if (!laser) return result;
  result.warning = scanInconsistency(scan);
  pf::LaserScan core = toCore(scan, toPose2(laser->transform));
  core.sweep = sweepMotion(scan, *tf_, config_, *result.odom);
  update(std::move(core), sensor, scan.header.stamp, &result);
  return result;
}

ScanResult ScanLocalizer::processCloud(const sensor_msgs::PointCloud2& cloud, std::size_t sensor) {
  ScanResult result;
  const auto mount = lookUp(cloud.header.frame_id, cloud.header.stamp, &result);
  if (!mount) return result;
  if (const auto error = readCloud(cloud, &cloud_points_)) {
    result.error = ScanError::kBadCloud;
    result.error_detail = std::string(kindName(error->kind)) + ": " + error->detail;
    return result;
  }
  const pf::SensorMount sensor_mount = toSensorMount(mount->transform);
  if (const auto error = pf::validateMount(sensor_mount)) {
    result.error = ScanError::kBadCloud;
    result.error_detail =
        "the mounting " + config_.base_frame + " -> " + cloud.header.frame_id + ": " + *error;
    return result;
  }
  update(cloud_reducer_.reduce(cloud_points_, sensor_mount).scan, sensor, cloud.header.stamp,
         &result);
  return result;
}

// Only with several sensors: one has nothing to compare with, and its scans
// need no second look.
void ScanLocalizer::observeHealth(const pf::LaserScan& scan, std::size_t sensor,
                                  const ros::Time& stamp) {
  while (health_.size() <= sensor) health_.add("sensor " + std::to_string(health_.size()));
  const pf::SensorModel* model = filter_.sensorModel();
  const pf::PreparedScan prepared = model->prepare(scan);
  const double fit = model->hitFraction(prepared, filter_.estimate().pose,
                                        filter_.params().confidence.hit_distance);
  health_.observe(sensor, stamp.toSec(), scan.ranges.size(),
                  scan.ranges.size() - static_cast<std::size_t>(prepared.dropped), fit);
}

void ScanLocalizer::update(pf::LaserScan scan, std::size_t sensor, const ros::Time& stamp,
                           ScanResult* result) {
  if (sensor < weights_.size()) scan.weight = weights_[sensor];
  group_.clear();
  group_.push_back(std::move(scan));
  if (latest_.size() <= sensor) latest_.resize(sensor + 1);
  // The other sensors' latest scans since the last update, each where the
  // robot was at its stamp.
  for (std::size_t other = 0; other < latest_.size(); ++other) {
    const std::optional<SensorScan>& s = latest_[other];
    if (other == sensor || !s || s->used) continue;
    if (std::fabs((stamp - s->stamp).toSec()) > kMaxSensorScanAge) continue;
    group_.push_back(s->scan);
    group_.back().robot_offset = pf::between(*result->odom, s->odom);
  }
  result->report = filter_.update(*result->odom, group_);
  if (observer_) observer_(*result->odom, group_, stamp);
  if (latest_.size() > 1) observeHealth(group_.front(), sensor, stamp);
  latest_[sensor] = SensorScan{std::move(group_.front()), *result->odom, stamp, false};
  if (result->report.updated) {
    for (std::optional<SensorScan>& s : latest_) {
      if (s) s->used = true;
    }
  }
}

std::optional<geometry_msgs::TransformStamped> ScanLocalizer::mapToOdom(
    const ros::Time& stamp) const {
  auto m2o = filter_.mapToOdom();
  if (!m2o) m2o = given_map_to_odom_;
  if (!m2o) return std::nullopt;
  geometry_msgs::TransformStamped t;
  t.header.stamp = stamp;
  t.header.frame_id = config_.global_frame;
  t.child_frame_id = config_.odom_frame;
  t.transform = toTransformMsg(*m2o);
  return t;
}

std::optional<geometry_msgs::PoseWithCovarianceStamped> ScanLocalizer::estimate(
    const ros::Time& stamp) const {
  if (!filter_.isInitialized()) return std::nullopt;
  geometry_msgs::PoseWithCovarianceStamped msg;
  msg.header.stamp = stamp;
  msg.header.frame_id = config_.global_frame;
  msg.pose.pose = toPoseMsg(filter_.estimate().pose);
  // The confidence's covariance: the whole cloud's when rival hypotheses
  // exist, so that an ambiguous estimate never looks precise.
  msg.pose.covariance = toRosCovariance(filter_.confidence().covariance);
  return msg;
}

std::optional<nav_msgs::OccupancyGrid> ScanLocalizer::mapChangesMsg(const ros::Time& stamp) const {
  nav_msgs::OccupancyGrid msg;
  if (!mapChangesMsg(stamp, &msg)) return std::nullopt;
  return msg;
}

bool ScanLocalizer::mapChangesMsg(const ros::Time& stamp, nav_msgs::OccupancyGrid* msg) const {
  const pf::MapChangeLayer* changes = filter_.mapChanges();
  if (!changes) return false;
  msg->header.stamp = stamp;
  msg->header.frame_id = config_.global_frame;
  msg->info = map_info_;
  changes->occupancy(&msg->data);
  return true;
}

geometry_msgs::PoseArray ScanLocalizer::particleCloud(const ros::Time& stamp) const {
  geometry_msgs::PoseArray msg;
  msg.header.stamp = stamp;
  msg.header.frame_id = config_.global_frame;
  toPoseArray(filter_.particles(), &msg);
  return msg;
}

geometry_msgs::PoseArray ScanLocalizer::particleCloud(const ros::Time& stamp,
                                                      std::size_t max_poses) const {
  geometry_msgs::PoseArray msg;
  msg.header.stamp = stamp;
  msg.header.frame_id = config_.global_frame;
  toPoseArray(filter_.particles(), max_poses, &msg);
  return msg;
}

std::string scanInconsistency(const sensor_msgs::LaserScan& scan) {
  if (!scan.intensities.empty() && scan.intensities.size() != scan.ranges.size()) {
    return "the scan has " + std::to_string(scan.intensities.size()) + " intensities for " +
           std::to_string(scan.ranges.size()) + " ranges (intensities are not used)";
  }
  if (scan.ranges.size() > 1 && std::isfinite(scan.angle_increment) &&
      scan.angle_increment != 0.0f) {
    const double last = scan.angle_min + (scan.ranges.size() - 1.0) * scan.angle_increment;
    // Half a beam of slack: drivers round angle_max in both directions.
    if (std::fabs(last - scan.angle_max) > 0.5 * std::fabs(scan.angle_increment) + 1e-6) {
      std::ostringstream text;
      text << "the scan's angle_max " << scan.angle_max
           << " rad disagrees with angle_min + (n - 1) "
           << "* angle_increment = " << last << " rad for its " << scan.ranges.size()
           << " ranges; beams are placed by angle_min and angle_increment";
      return text.str();
    }
  }
  return "";
}

pf::SweepMotion sweepMotion(const sensor_msgs::LaserScan& scan, const tf2::BufferCore& tf,
                            const LocalizerConfig& config, const pf::Pose2& odom_at_stamp) {
  pf::SweepMotion sweep;
  const double dt = scan.time_increment;
  if (!config.deskew_scans || !std::isfinite(dt) || dt == 0.0 || scan.ranges.size() < 2) {
    return sweep;
  }
  const double span = std::fabs(dt) * static_cast<double>(scan.ranges.size() - 1);
  // Longer than a second is not one turn of a spinning laser: a bogus
  // time_increment is not worth bending the scan for.
  if (span > 1.0) return sweep;
  // The velocity over the sweep that ends at the stamp: odometry after the
  // stamp has not arrived yet when a live scan does.
  const double window = std::max(span, 0.05);
  if (scan.header.stamp.toSec() <= window) return sweep;  // no time before it
  pf::Pose2 earlier;
  try {
    earlier = toPose2(tf.lookupTransform(config.odom_frame, config.base_frame,
                                         scan.header.stamp - ros::Duration(window))
                          .transform);
  } catch (const tf2::TransformException&) {
    return sweep;  // the first scans of a run: used as they are
  }
  sweep.base_velocity = pf::velocityBetween(earlier, odom_at_stamp, window);
  sweep.time_increment = dt;
  // A negative time_increment means the last index was taken first.
  const bool stamp_is_first = config.scan_stamp == "first_beam";
  if (dt > 0.0) {
    sweep.first_beam_time = stamp_is_first ? 0.0 : -span;
  } else {
    sweep.first_beam_time = stamp_is_first ? span : 0.0;
  }
  return sweep;
}

geometry_msgs::TransformStamped odometryToTransform(const nav_msgs::Odometry& odom) {
  geometry_msgs::TransformStamped t;
  t.header = odom.header;
  t.child_frame_id = odom.child_frame_id;
  t.transform.translation.x = odom.pose.pose.position.x;
  t.transform.translation.y = odom.pose.pose.position.y;
  t.transform.translation.z = odom.pose.pose.position.z;
  t.transform.rotation = odom.pose.pose.orientation;
  return t;
}

}  // namespace pf_ros
