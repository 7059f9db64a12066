#include "pf_localization/ros/map_to_odom_republisher.h"


#include <algorithm>
#include <utility>

namespace pf_ros {

MapToOdomRepublisher::MapToOdomRepublisher(const ros::NodeHandle& nh,
                                           const MapToOdomRepublisherOptions& options,
                                           TickHook hook)
    : options_(options), hook_(std::move(hook)), nh_(nh) {
  nh_.setCallbackQueue(&queue_);
  timer_ = nh_.createTimer(ros::Duration(1.0 / options_.rate), &MapToOdomRepublisher::onTimer, this);
  spinner_ = std::make_unique<ros::AsyncSpinner>(1, &queue_);
  spinner_->start();
}

MapToOdomRepublisher::~MapToOdomRepublisher() {
  timer_.stop();
  spinner_->stop();
}

bool MapToOdomRepublisher::set(const std::optional<geometry_msgs::TransformStamped>& map_to_odom,
                               const ros::Time& scan_stamp) {
  std::lock_guard<std::mutex> lock(mutex_);
  transform_ = map_to_odom;
  if (!scan_stamp.isZero()) scan_stamp_ = std::max(scan_stamp_, scan_stamp);
  const ros::Time now = ros::Time::now();
  ros::Time stamp = std::max(now, scan_stamp_) + ros::Duration(options_.transform_tolerance);
  // A correction must reach tf now even when the clock has not moved since
  // the last timed publication.
  if (!last_stamp_.isZero() && stamp <= last_stamp_) stamp = last_stamp_ + ros::Duration(1e-3);
  return publishLocked(stamp);
}

void MapToOdomRepublisher::reset() {
  std::lock_guard<std::mutex> lock(mutex_);
  transform_.reset();
  scan_stamp_ = ros::Time();
  last_stamp_ = ros::Time();
}

void MapToOdomRepublisher::setRate(double hz) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (hz == options_.rate) return;
  options_.rate = hz;
  timer_.setPeriod(ros::Duration(1.0 / hz));
}

void MapToOdomRepublisher::setTransformTolerance(double seconds) {
  std::lock_guard<std::mutex> lock(mutex_);
  options_.transform_tolerance = seconds;
}

std::size_t MapToOdomRepublisher::published() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return published_;
}

void MapToOdomRepublisher::onTimer(const ros::TimerEvent&) {
  const ros::Time now = ros::Time::now();
  if (now.isZero()) return;  // simulated time has not started
  if (hook_) hook_(now);
  std::lock_guard<std::mutex> lock(mutex_);
  const ros::Time stamp = std::max(now, scan_stamp_) + ros::Duration(options_.transform_tolerance);
  // Between updates, only a later stamp is news (and tf2 refuses a repeated one).
  if (stamp <= last_stamp_) return;
  publishLocked(stamp);
}

bool MapToOdomRepublisher::publishLocked(ros::Time stamp) {
  if (!options_.enabled || !transform_) return false;
  geometry_msgs::TransformStamped t = *transform_;
  t.header.stamp = stamp;
  broadcaster_.sendTransform(t);
  last_stamp_ = stamp;
  ++published_;
  return true;
}

}  // namespace pf_ros
