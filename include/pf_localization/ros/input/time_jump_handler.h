// Time going back, handled in one place. A bag restarted (by hand or with
// rosbag play --loop) makes the stamps go back: the tf buffer and the filter's
// odometry reference then belong to the old timeline, and pf_node starts both
// over, as tf itself does on such a jump. Two things show it: a scan stamped
// more than kScanTolerance before the latest scan used; and, under simulated
// time, /clock itself going back while the filter's latest scan lies ahead of
// it (often before any scan of the new timeline gets through tf, which still
// holds the old timeline). Messages of the old timeline still queued in the
// node's subscriptions arrive after the jump stamped ahead of /clock, at times
// the clock had reached before it went back: a scan among them is ignored
// rather than restarting the filter a second time at the wrong place, and tf is
// cleared again when such a transform reached it after it was cleared. Messages
// ahead of every clock seen are not leftovers but a clock that lags: rosbag
// play, catching up after a stall (its disk, or a loaded machine), publishes
// what it is late with before the next /clock, seconds of the bag at a high
// rate. They are used.
//
// The times come in as arguments (`now`: the clock, zero when not asked;
// `sim_time`: whether it is simulated), so that all of it is tested without
// a ROS master. Not thread-safe: pf_node calls it with the filter's lock held.
#pragma once

#include <ros/time.h>
#include <std_msgs/Header.h>
#include <tf2/buffer_core.h>

#include <functional>
#include <optional>
#include <string>

#include "pf_localization/ros/diagnostics/limited_warn.h"

namespace pf_ros {

/// s of simulated time a message may be stamped ahead of /clock. rosbag play
/// publishes /clock at 100 Hz of wall time, so at rate r the clock lags the
/// messages by up to r / 100 s while it keeps pace; a message further ahead
/// than this, at a time the clock had reached before it went back, is left
/// over from the old timeline. Also the tolerance for /clock itself going
/// back.
constexpr double kSimClockLead = 2.0;

class TimeJumpHandler {
 public:
  /// s a scan may be older than the previous one before time counts as
  /// jumping back (scans reach the filter in order, but not exactly so).
  static constexpr double kScanTolerance = 1.0;

  /// What else starts over once tf is cleared (the filter, map -> odom),
  /// told how far (s) time went back.
  using Restart = std::function<void(double back_s)>;

  /// `tf`, `warn` must outlive the handler; `odom_frame` and `base_frame`
  /// name the chain a scan needs (latestChainStamp()).
  TimeJumpHandler(tf2::BufferCore* tf, std::string odom_frame, std::string base_frame,
                  LimitedWarn* warn, Restart restart);

  /// Before a scan stamped `stamp` is used: false when it must not be, being
  /// left over from before time jumped back (warned), or older than the
  /// latest scan used by more than kScanTolerance (everything started over).
  bool admitScan(const ros::Time& stamp, const ros::Time& now, bool sim_time);
  /// A scan was used: later stamps are compared with this one.
  void scanUsed(const ros::Time& stamp) { last_scan_ = stamp; }

  /// A scan tf dropped: under simulated time, tf is cleared again when it still
  /// holds transforms of the scan's chain left over from before the jump. The
  /// scan's own stamp shows no jump: tf drops the oldest scans waiting, and
  /// those older than their odometry's start after later ones got through, as
  /// when a player catches up.
  void scanDropped(const std_msgs::Header& header, const ros::Time& now, bool sim_time);

  /// The clock at a timed map -> odom (the /clock messages as they come,
  /// in order): under simulated time, the clock gone back by more than
  /// kSimClockLead, to more than kSimClockLead before the latest scan used,
  /// starts everything over. Only this clock is followed: the node's own
  /// (ros::Time::now(), set on roscpp's thread) may lag it by more than that
  /// in a burst, and the two taken together would seem to go back.
  void clockTick(const ros::Time& now, bool sim_time);

  /// How far (s) `stamp` lies before the latest scan used, when that is
  /// more than `tolerance`; nothing before the first scan (or after a jump).
  std::optional<double> jumpBack(const ros::Time& stamp, double tolerance = kScanTolerance) const;

 private:
  // How far (s) a message stamped `stamp` lies ahead of /clock (`now`) when
  // it is left over from before the clock went back: further ahead than
  // kSimClockLead, at a time the clock had reached before. Nothing for a
  // lagging clock, or with wall time.
  std::optional<double> leftover(const ros::Time& stamp, const ros::Time& now, bool sim_time) const;
  // When `stamp` lies more than `tolerance` before the latest scan used:
  // clears tf, restarts, and returns true.
  bool restartIfBack(const ros::Time& stamp, double tolerance);

  tf2::BufferCore* tf_;
  const std::string odom_frame_, base_frame_;
  LimitedWarn* warn_;
  Restart restart_;
  ros::Time last_scan_;
  ros::Time clock_high_;  // the latest /clock since it last went back
  ros::Time jump_from_;   // the latest /clock before it last went back; zero: never
};

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
