// map -> odom on /tf: published after every filter update, and again
// whenever 1.5 periods (1 / tf_publish_rate s) pass without one on the wall
// clock, at most one period under simulated time, so that tf users never
// wait more than two periods (see kWallClockPeriods in the .cc). Neither a filter update
// nor anything else on the node's spinner delays it: it only ever touches the
// latest transform handed to it, under its own mutex, never the filter.
//
// What times the republishing depends on the clock:
// - on the wall clock, a timer (timerfd) in roscpp's own poll set, so that
//   the poll thread, which sends every message anyway, publishes it when it
//   fires: a publication from a thread of its own cost a wake-up of that
//   thread and then one of the poll thread to send it. Each publication
//   after an update re-arms the timer, so that while updates come often
//   enough it never fires;
// - under simulated time, /clock itself: no sleep can be timed on a clock
//   that only /clock moves, so start() subscribes to it on the handle it is
//   given (pf_node's poll thread), and the last /clock message before a
//   publication is due publishes it, on the thread that brought it: the
//   last one whose next, one step of the clock later (rosbag play's: 10 ms
//   of wall time times the rate), would come after the due time. The first
//   one after it would leave a gap of a period plus a step, over two
//   periods whenever a step of a bag played at 4x is 5 ms late. No
//   thread polls the clock (docs/performance.md, "The fixed cost"). The
//   stamps are the latest /clock's (plus transform_tolerance), not roscpp's
//   clock, which its own thread sets a step later.
//
// Only the poll thread publishes, once start() has run: set() on another
// thread (the filter thread, at a lower priority) hands the update's map ->
// odom over and fires the timer at once (the same wake-up of the poll thread
// as roscpp's own, to send a message published elsewhere). A thread of lower priority that
// publishes under the republisher's lock can be preempted there, and the
// /clock messages that come meanwhile find the lock taken and publish
// nothing (0.12 s between stamps, under load).
#pragma once

#include <geometry_msgs/TransformStamped.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <tf2_ros/transform_broadcaster.h>

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "pf_localization/ros/output/republish_schedule.h"

namespace pf_ros {

struct MapToOdomRepublisherOptions {
  double rate = 20.0;                // Hz of republishing (tf_publish_rate); > 0
  double transform_tolerance = 0.1;  // s each stamp is post-dated by, so tf users never extrapolate
  bool enabled = true;               // false (tf_broadcast false): nothing is ever published
};

class MapToOdomRepublisher {
 public:
  /// Called with the clock's time before each timed publication, on the
  /// thread that times it (see above), without any lock held (pf_node checks
  /// there whether simulated time jumped back).
  using TickHook = std::function<void(const ros::Time& now)>;

  explicit MapToOdomRepublisher(const MapToOdomRepublisherOptions& options, TickHook hook = {});

  /// Starts the timed republishing (once; the hook may be called from then
  /// on): under simulated time by subscribing to /clock on `clock_nh` (its
  /// callback queue runs onClock(): the poll thread's, InlineCallbackQueue),
  /// and in both cases by adding the timer to roscpp's poll set
  /// (ros::start() must have run: a NodeHandle exists).
  void start(ros::NodeHandle clock_nh);
  ~MapToOdomRepublisher();
  MapToOdomRepublisher(const MapToOdomRepublisher&) = delete;
  MapToOdomRepublisher& operator=(const MapToOdomRepublisher&) = delete;

  /// The new map -> odom (its stamp is ignored; nullopt: nothing to publish
  /// until the next set()), after the scan stamped `scan_stamp` (zero: none):
  /// published at once (on the poll thread, or on this one before start()),
  /// stamped max(now, scan_stamp) + transform_tolerance, or just after the
  /// previous stamp when that is not later (tf2 refuses a repeated stamp);
  /// the next timed publication is then due one delay later. Returns whether
  /// it was published or handed to the poll thread to publish.
  bool set(const std::optional<geometry_msgs::TransformStamped>& map_to_odom,
           const ros::Time& scan_stamp);

  /// Time jumped back: forgets the transform, the scan stamp and the last
  /// stamp published, so that the new timeline's stamps are accepted.
  void reset();

  void setRate(double hz);
  void setTransformTolerance(double seconds);

  /// Number of map -> odom messages published since start.
  std::size_t published() const;
  /// The stamp of the latest one (zero: none since start or reset()).
  ros::Time lastStamp() const;

  /// Simulated time moved to `now` (/clock): the timed publication when one
  /// is due. Never waits: while set() publishes (which puts the next timed
  /// publication off anyway) the next /clock looks again.
  void onClock(const ros::Time& now);

 private:
  // The timer fired (on roscpp's poll thread): the update handed over by
  // set(), and on the wall clock the timed publication when one is due, and
  // the timer set for the next.
  void onTimer();
  // Publishes the update set() was given (see set()); mutex_ held.
  bool publishUpdateLocked();
  // The timer fires in `seconds` (no timer: nothing); mutex_ held, or the
  // timer not yet polled, or an update handed over (set()).
  void armLocked(double seconds);
  // How long after the latest publication the next timed one is due: 1.5
  // periods on the wall clock, one under simulated time (see the .cc).
  ros::Duration delayLocked() const;
  // The timed publication at `now`, when due (RepublishSchedule::due, the
  // next chance taken to be `step` later: the clock's latest step; zero on
  // the wall clock's timer); `lock` holds mutex_ (and is released around the
  // hook).
  void tick(const ros::Time& now, const ros::Duration& step, std::unique_lock<std::mutex>* lock);
  // The node's time: under simulated time the latest /clock seen here, which
  // roscpp's own clock (set on another thread, after this one's) trails by
  // a step or more; ros::Time::now() before the first /clock and on the wall
  // clock.
  ros::Time clockNow() const;
  // Publishes the stored transform stamped `stamp`; mutex_ held.
  bool publishLocked(ros::Time stamp);

  MapToOdomRepublisherOptions options_;
  TickHook hook_;
  tf2_ros::TransformBroadcaster broadcaster_;
  mutable std::mutex mutex_;
  int timer_fd_ = -1;            // the poll thread's timer (timerfd); -1: none (before start())
  bool wall_clock_ = false;      // start() found the wall clock (not simulated time)
  bool update_pending_ = false;  // set() handed an update over: onTimer() publishes it
  std::atomic<std::thread::id> poll_thread_{};  // the thread that runs onTimer() and onClock()
  bool stop_ = false;
  std::optional<geometry_msgs::TransformStamped> transform_;
  ros::Time scan_stamp_, last_stamp_;
  RepublishSchedule schedule_;
  std::size_t published_ = 0;
  ros::Subscriber clock_sub_;
  std::atomic<std::int64_t> clock_ns_{0};  // the latest /clock (ns); 0: none yet
  // Whether the poll thread may still call onTimer(): the poll set may call
  // a callback of a timer just taken out of it, so it checks this first,
  // under the guard's lock, which the destructor takes to clear it.
  struct PollGuard {
    std::mutex mutex;
    bool alive = true;
  };
  std::shared_ptr<PollGuard> poll_guard_;
};

}  // namespace pf_ros
