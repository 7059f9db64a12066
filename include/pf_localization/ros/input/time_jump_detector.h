// Time going back, and the leftovers of the timeline before it. A bag
// restarted (by hand or with rosbag play --loop) makes the stamps go back:
// the tf buffer and the filter's odometry reference then belong to the old
// timeline, and pf_node starts both over, as tf itself does on such a jump.
// Messages of the old timeline still queued in the node's subscriptions
// arrive after the jump stamped ahead of /clock; they must not restart the
// filter a second time. Everything here takes the times as arguments, so
// that it needs no ROS master; pf_node holds it under its filter mutex.
#pragma once

#include <ros/time.h>
#include <tf2/buffer_core.h>

#include <optional>
#include <string>

namespace pf_ros {

/// Watches the stamps of the scans used for a jump back.
class TimeJumpDetector {
 public:
  /// s a scan may be older than the previous one before time counts as
  /// jumping back (scans reach the filter in order, but not exactly so).
  static constexpr double kScanTolerance = 1.0;

  /// How far (s) `stamp` lies before the latest scan used, when that is
  /// more than `tolerance`; nothing before the first scan (or after reset()).
  std::optional<double> jumpBack(const ros::Time& stamp, double tolerance = kScanTolerance) const;

  /// A scan was used: later stamps are compared with this one.
  void scanUsed(const ros::Time& stamp) { last_scan_ = stamp; }
  /// Time jumped back and everything started over: no scan used yet.
  void reset() { last_scan_ = ros::Time(); }

 private:
  ros::Time last_scan_;
};

/// s of simulated time a message may be stamped ahead of /clock. rosbag play
/// publishes /clock at 100 Hz of wall time, so at rate r the clock lags the
/// messages by up to r / 100 s; a message further ahead than this is left
/// over from before time jumped back. Also the tolerance for /clock itself
/// going back, checked on the republisher's ticks.
constexpr double kSimClockLead = 2.0;

/// How far (s) `stamp` lies ahead of the clock `now`, when further than
/// kSimClockLead. Nothing with wall time (`sim_time` false: a message ahead
/// of the clock then means unsynchronised computers, not a jump) or while
/// the clock has not started (`now` zero).
std::optional<double> aheadOfSimClock(const ros::Time& stamp, const ros::Time& now, bool sim_time);

/// The newest stamp in `tf` of the links a scan from `laser_frame` needs:
/// odometry (`odom_frame` -> `base_frame`) and the laser's mounting
/// (`base_frame` -> `laser_frame`); zero when neither is there. An
/// old-timeline transform that reached the buffer after it was cleared holds
/// its frame's time far ahead, and tf2 then refuses every new transform of
/// that frame as too old (TF_OLD_DATA): compared with the clock, this shows it.
ros::Time latestChainStamp(const tf2::BufferCore& tf, const std::string& odom_frame,
                           const std::string& base_frame, const std::string& laser_frame);

}  // namespace pf_ros
