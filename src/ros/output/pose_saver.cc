#include "pf_localization/ros/output/pose_saver.h"

#include <utility>

#include "pf_localization/ros/input/conversions.h"
#include "pf_localization/ros/params/localizer_config.h"
#include "pf_localization/ros/params/saved_pose.h"

namespace pf_ros {

std::optional<PoseToSave> poseToSave(const ScanLocalizer& localizer,
                                     const std::optional<pf::Pose2>& odom) {
  const auto estimate = localizer.estimate(ros::Time());
  if (!estimate) return std::nullopt;
  pf::Pose2 pose = toPose2(estimate->pose.pose);
  const auto map_to_odom = localizer.filter().mapToOdom();
  if (map_to_odom && odom) pose = pf::compose(*map_to_odom, *odom);
  if (!pose.isFinite()) return std::nullopt;
  const auto& cov = estimate->pose.covariance;
  return PoseToSave{pose, cov[0], cov[7], cov[35]};
}

PoseSaver::PoseSaver(double rate, Write write) : rate_(rate), write_(std::move(write)) {}

void PoseSaver::setMap(const std::string& map_signature, const std::string& floor) {
  std::lock_guard<std::mutex> lock(mutex_);
  map_signature_ = map_signature;
  floor_ = floor;
  pose_.reset();
}

void PoseSaver::set(const std::optional<PoseToSave>& pose) {
  std::lock_guard<std::mutex> lock(mutex_);
  pose_ = pose;
}

std::optional<PoseSaver::Record> PoseSaver::latest() const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!pose_) return std::nullopt;
  return Record{*pose_, map_signature_, floor_};
}

void PoseSaver::saveWhenDue(const ros::Time& now) {
  if (!enabled()) return;
  const ros::Duration period(1.0 / rate_);
  const bool first = schedule_.next().isZero();
  if (now.isZero() || !schedule_.due(now, period)) return;
  schedule_.published(now, period);
  if (!first) saveNow();
}

void PoseSaver::saveNow() {
  if (!enabled() || !write_) return;
  if (const auto record = latest()) write_(*record);
}

void writeSavedPose(const PoseSaver::Record& record, const ros::NodeHandle& pnh) {
  const PoseToSave& s = record.pose;
  pnh.setParam("initial_pose_x", s.pose.x);
  pnh.setParam("initial_pose_y", s.pose.y);
  pnh.setParam("initial_pose_a", s.pose.yaw);
  pnh.setParam("initial_cov_xx", s.cov_xx);
  pnh.setParam("initial_cov_yy", s.cov_yy);
  pnh.setParam("initial_cov_aa", s.cov_aa);
  pnh.setParam(kSavedPoseMapParam, savedPoseMapValue(record.map_signature, s.pose, record.floor));
}

}  // namespace pf_ros
