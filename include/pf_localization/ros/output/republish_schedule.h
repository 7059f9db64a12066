// When a message sent at a steady rate is due again: one period after the
// latest one, timed or not, rather than on a fixed beat (map -> odom,
// MapToOdomRepublisher).
#pragma once

#include <ros/time.h>

namespace pf_ros {

/// When map -> odom is due again: one period after the latest publication,
/// timed or after an update, rather than on a fixed beat. Every message costs
/// the node and each subscriber about ten system calls, and tf users still
/// get one at least once a period.
class RepublishSchedule {
 public:
  /// Whether a timed publication is due at `now`: when a period has passed,
  /// or when the next chance to publish, `next_chance` (zero: unknown), comes
  /// after the due time, so that it goes at the last chance before the due
  /// time rather than the first after it. The first call is due, and so is
  /// any call after time went back (a bag restarted).
  bool due(const ros::Time& now, const ros::Duration& period,
           const ros::Time& next_chance = ros::Time());
  /// Something was published at `now`: the next is due one period later.
  void published(const ros::Time& now, const ros::Duration& period) { next_ = now + period; }
  /// Forget the past: due at once.
  void reset() { next_ = ros::Time(); }
  /// When the next is due (zero: at once).
  const ros::Time& next() const { return next_; }

 private:
  ros::Time next_;
};

}  // namespace pf_ros
