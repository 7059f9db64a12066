// map -> odom on /tf from its own thread: published after every filter update
// and republished at tf_publish_rate by a timer on a callback queue of its
// own, served by a spinner thread of its own. A filter update (80 ms for
// 500 000 particles) or anything else on the node's main spinner therefore
// never delays it (issue 15: under load the timer used to wait behind the
// filter, and tf users downstream saw 8 s gaps). It only ever touches the
// latest transform handed to it, under its own mutex, never the filter.
#pragma once

#include <geometry_msgs/TransformStamped.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <tf2_ros/transform_broadcaster.h>

#include <functional>
#include <memory>
#include <mutex>
#include <optional>

namespace pf_ros {

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

  /// Starts the timer and its thread at once (with nothing to publish yet).
  MapToOdomRepublisher(const ros::NodeHandle& nh, const MapToOdomRepublisherOptions& options,
                       TickHook hook = {});
  ~MapToOdomRepublisher();
  MapToOdomRepublisher(const MapToOdomRepublisher&) = delete;
  MapToOdomRepublisher& operator=(const MapToOdomRepublisher&) = delete;

  /// The new map -> odom (its stamp is ignored; nullopt: nothing to publish
  /// until the next set()), after the scan stamped `scan_stamp` (zero: none):
  /// published at once, stamped max(now, scan_stamp) + transform_tolerance,
  /// or just after the previous stamp when that is not later (tf2 refuses a
  /// repeated stamp). Returns whether it was published.
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
  void onTimer(const ros::TimerEvent&);
  // Publishes the stored transform stamped at least `stamp`; mutex_ held.
  bool publishLocked(ros::Time stamp);

  MapToOdomRepublisherOptions options_;
  TickHook hook_;
  ros::CallbackQueue queue_;
  ros::NodeHandle nh_;
  tf2_ros::TransformBroadcaster broadcaster_;
  mutable std::mutex mutex_;
  std::optional<geometry_msgs::TransformStamped> transform_;
  ros::Time scan_stamp_, last_stamp_;
  std::size_t published_ = 0;
  ros::Timer timer_;
  std::unique_ptr<ros::AsyncSpinner> spinner_;
};

}  // namespace pf_ros
