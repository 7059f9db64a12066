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
  /// Whether a timed publication is due at `now`. The first call is, and so
  /// is any call after time went back (a bag restarted).
  bool due(const ros::Time& now, const ros::Duration& period);
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
