// map -> odom on /tf from a thread of its own: published after every filter
// update, and again whenever 1 / tf_publish_rate s pass without one. A
// filter update (80 ms for 500 000 particles) or anything else on the
// node's spinner therefore never delays it (issue 15: under load the
// ros::Timer used to wait behind the filter on the one spinner, and tf users
// downstream saw 8 s gaps). It only ever touches the latest transform handed
// to it, under its own mutex, never the filter. Its own loop rather than a ros::Timer on a
// callback queue of its own: that would take two thread hops (roscpp's timer
// thread, then the queue's spinner) per tick, each a chance to be descheduled
// on a loaded computer.
#pragma once

#include <geometry_msgs/TransformStamped.h>
#include <ros/ros.h>
#include <tf2_ros/transform_broadcaster.h>

#include <condition_variable>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>

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

struct MapToOdomRepublisherOptions {
  double rate = 20.0;                // Hz of republishing (tf_publish_rate); > 0
  double transform_tolerance = 0.1;  // s each stamp is post-dated by, so tf users never extrapolate
  bool enabled = true;               // false (tf_broadcast false): nothing is ever published
};

class MapToOdomRepublisher {
 public:
  /// Called on the republishing thread with the clock's time before each
  /// timed publication, without any lock held (pf_node checks there whether
  /// simulated time jumped back).
  using TickHook = std::function<void(const ros::Time& now)>;

  explicit MapToOdomRepublisher(const MapToOdomRepublisherOptions& options, TickHook hook = {});

  /// Starts the thread (once; the hook may be called from then on).
  void start();
  ~MapToOdomRepublisher();
  MapToOdomRepublisher(const MapToOdomRepublisher&) = delete;
  MapToOdomRepublisher& operator=(const MapToOdomRepublisher&) = delete;

  /// The new map -> odom (its stamp is ignored; nullopt: nothing to publish
  /// until the next set()), after the scan stamped `scan_stamp` (zero: none):
  /// published at once, stamped max(now, scan_stamp) + transform_tolerance,
  /// or just after the previous stamp when that is not later (tf2 refuses a
  /// repeated stamp); the next timed publication is then one period later.
  /// Returns whether it was published.
  bool set(const std::optional<geometry_msgs::TransformStamped>& map_to_odom,
           const ros::Time& scan_stamp);

  /// Time jumped back: forgets the transform, the scan stamp and the last
  /// stamp published, so that the new timeline's stamps are accepted.
  void reset();

  void setRate(double hz);
  void setTransformTolerance(double seconds);

  /// Number of map -> odom messages published since start.
  std::size_t published() const;

 private:
  // The thread: under simulated time it polls the clock every ms of wall
  // time (as roscpp's timers do); under wall time it sleeps until due.
  void run();
  // Publishes the stored transform stamped `stamp`; mutex_ held.
  bool publishLocked(ros::Time stamp);

  MapToOdomRepublisherOptions options_;
  TickHook hook_;
  tf2_ros::TransformBroadcaster broadcaster_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::optional<geometry_msgs::TransformStamped> transform_;
  ros::Time scan_stamp_, last_stamp_;
  RepublishSchedule schedule_;
  std::size_t published_ = 0;
  std::thread thread_;
};

}  // namespace pf_ros
