#include "pf_localization/ros/map_to_odom_republisher.h"

#include <algorithm>
#include <chrono>
#include <utility>

namespace pf_ros {

bool RepublishSchedule::due(const ros::Time& now, const ros::Duration& period) {
  if (next_.isZero() || now + period < next_) next_ = now;
  return now >= next_;
}

MapToOdomRepublisher::MapToOdomRepublisher(const MapToOdomRepublisherOptions& options,
                                           TickHook hook)
    : options_(options), hook_(std::move(hook)) {}

void MapToOdomRepublisher::start() {
  if (!thread_.joinable()) thread_ = std::thread([this] { run(); });
}

MapToOdomRepublisher::~MapToOdomRepublisher() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
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
  if (!publishLocked(stamp)) return false;
  if (!now.isZero()) schedule_.published(now, ros::Duration(1.0 / options_.rate));
  return true;
}

void MapToOdomRepublisher::reset() {
  std::lock_guard<std::mutex> lock(mutex_);
  transform_.reset();
  scan_stamp_ = ros::Time();
  last_stamp_ = ros::Time();
  schedule_.reset();
}

void MapToOdomRepublisher::setRate(double hz) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    options_.rate = hz;
  }
  wake_.notify_all();
}

void MapToOdomRepublisher::setTransformTolerance(double seconds) {
  std::lock_guard<std::mutex> lock(mutex_);
  options_.transform_tolerance = seconds;
}

std::size_t MapToOdomRepublisher::published() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return published_;
}

void MapToOdomRepublisher::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stop_) {
    const ros::Duration period(1.0 / options_.rate);
    const ros::Time now = ros::Time::now();
    // Zero: simulated time has not started.
    if (!now.isZero() && schedule_.due(now, period)) {
      // The tick counts as a publication even when it has nothing new to
      // send (no map -> odom yet, or no later stamp): otherwise it would
      // stay due and the loop would spin.
      schedule_.published(now, period);
      lock.unlock();
      if (hook_) hook_(now);
      lock.lock();
      if (stop_) break;
      const ros::Time stamp =
          std::max(now, scan_stamp_) + ros::Duration(options_.transform_tolerance);
      // Between updates, only a later stamp is news (and tf2 refuses a repeated one).
      if (stamp > last_stamp_) publishLocked(stamp);
    }
    double wait = 0.001;
    if (!ros::Time::isSimTime() && !now.isZero()) {
      wait = std::clamp((schedule_.next() - ros::Time::now()).toSec(), 0.0005, 0.1);
    }
    wake_.wait_for(lock, std::chrono::duration<double>(wait));
  }
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
