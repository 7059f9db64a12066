#include "pf_localization/ros/input/time_jump_handler.h"

#include <tf2/exceptions.h>

#include <algorithm>
#include <utility>

namespace pf_ros {

TimeJumpHandler::TimeJumpHandler(tf2::BufferCore* tf, std::string odom_frame,
                                 std::string base_frame, LimitedWarn* warn, Restart restart)
    : tf_(tf),
      odom_frame_(std::move(odom_frame)),
      base_frame_(std::move(base_frame)),
      warn_(warn),
      restart_(std::move(restart)) {}

std::optional<double> TimeJumpHandler::jumpBack(const ros::Time& stamp, double tolerance) const {
  if (last_scan_.isZero() || stamp + ros::Duration(tolerance) >= last_scan_) return std::nullopt;
  return (last_scan_ - stamp).toSec();
}

bool TimeJumpHandler::restartIfBack(const ros::Time& stamp, double tolerance) {
  const auto back = jumpBack(stamp, tolerance);
  if (!back) return false;
  tf_->clear();
  last_scan_ = ros::Time();
  restart_(*back);
  return true;
}

std::optional<double> TimeJumpHandler::leftover(const ros::Time& stamp, const ros::Time& now,
                                                bool sim_time) const {
  const auto ahead = aheadOfSimClock(stamp, now, sim_time);
  if (!ahead || jump_from_.isZero() || stamp > jump_from_ + ros::Duration(kSimClockLead)) {
    return std::nullopt;
  }
  return ahead;
}

bool TimeJumpHandler::admitScan(const ros::Time& stamp, const ros::Time& now, bool sim_time) {
  if (const auto ahead = leftover(stamp, now, sim_time)) {
    warn_->warn("scan ahead of clock",
                "scan ignored: stamped " + std::to_string(*ahead) +
                    " s ahead of /clock, so it is from before time jumped back");
    return false;
  }
  return !restartIfBack(stamp, kScanTolerance);
}

void TimeJumpHandler::scanDropped(const std_msgs::Header& header, const ros::Time& now,
                                  bool sim_time) {
  if (!sim_time || header.frame_id.empty()) return;
  const ros::Time latest = latestChainStamp(*tf_, odom_frame_, base_frame_, header.frame_id);
  if (const auto ahead = leftover(latest, now, sim_time)) {
    warn_->warn("stale tf",
                "clearing tf again: it still held transforms from before time jumped back (" +
                    std::to_string(*ahead) + " s ahead of /clock)");
    tf_->clear();
  }
}

void TimeJumpHandler::clockTick(const ros::Time& now, bool sim_time) {
  if (!sim_time || now.isZero()) return;
  if (now + ros::Duration(kSimClockLead) >= clock_high_) {
    clock_high_ = std::max(clock_high_, now);
    return;
  }
  jump_from_ = clock_high_;
  clock_high_ = now;
  restartIfBack(now, kSimClockLead);
}

std::optional<double> aheadOfSimClock(const ros::Time& stamp, const ros::Time& now, bool sim_time) {
  if (!sim_time) return std::nullopt;
  if (now.isZero() || stamp <= now + ros::Duration(kSimClockLead)) return std::nullopt;
  return (stamp - now).toSec();
}

ros::Time latestChainStamp(const tf2::BufferCore& tf, const std::string& odom_frame,
                           const std::string& base_frame, const std::string& laser_frame) {
  ros::Time latest;
  for (const auto& [parent, child] :
       {std::pair{odom_frame, base_frame}, std::pair{base_frame, laser_frame}}) {
    try {
      latest = std::max(latest, tf.lookupTransform(parent, child, ros::Time(0)).header.stamp);
    } catch (const tf2::TransformException&) {
      // A link missing altogether is not this problem; the scan's drop says so.
    }
  }
  return latest;
}

}  // namespace pf_ros
