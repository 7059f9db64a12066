// Where and when pf_node runs a scan's update, and the lock that guards the
// filter (docs/ros-interface.md, "Threads, latency and overload").
//
// A scan whose tf is there arrives on the thread that brought it (roscpp's
// poll thread: InlineCallbackQueue). Its update runs at once on that thread
// when it will be short (`is_short`: UpdatePlacement), no scan waits or is
// in the filter thread's hands (it would be overtaken), no other thread holds
// the filter (a new map, a service) and the thread is not already inside an
// update; otherwise the scan goes through a one-scan LatestScanSlot to a
// filter thread of its own, so that under overload the newest scan wins and
// the poll thread never waits for the filter. The filter thread runs at a
// lower priority than the rest of the node (nice + kFilterNiceIncrement), so
// that the filter yields the CPU to tf, odometry and map -> odom; the
// update's worker threads inherit it (worker_pool.h).
//
// Everything else that touches the filter goes through withFilter() (waits
// for an update to end: the main spinner's callbacks) or tryWithFilter()
// (never waits: what runs at a steady rate, such as the republisher's tick).
#pragma once

#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>
#include <utility>

#include "pf_localization/ros/diagnostics/limited_warn.h"
#include "pf_localization/ros/scheduling/latest_scan_slot.h"

namespace pf_ros {

class UpdateScheduler {
 public:
  /// One scan's update, with the filter's lock held; `slot` for its count
  /// of dropped scans, as it is after the update.
  using Update = std::function<void(const PendingScan& scan, const LatestScanSlot& slot)>;
  /// Whether the next update will be short enough to run on the thread that
  /// brought its scan; asked with the filter's lock held.
  using IsShort = std::function<bool()>;
  /// Whether the node still runs (ros::ok): the filter thread stops when not.
  using Running = std::function<bool()>;

  /// How much lower the filter thread's priority is (nice).
  static constexpr int kFilterNiceIncrement = 5;

  /// Starts the filter thread. `warn` (the overload warning) must outlive
  /// the scheduler.
  UpdateScheduler(Update update, IsShort is_short, LimitedWarn* warn, Running running = {});
  /// stop().
  ~UpdateScheduler();
  UpdateScheduler(const UpdateScheduler&) = delete;
  UpdateScheduler& operator=(const UpdateScheduler&) = delete;

  /// A scan whose tf is there: updated here, or handed to the filter thread
  /// (see above). Never waits for an update.
  void onScan(PendingScan scan);

  /// `fn()` with the filter's lock held, waiting for an update to end.
  template <typename F>
  auto withFilter(F&& fn) {
    std::lock_guard<std::mutex> lock(filter_mutex_);
    return std::forward<F>(fn)();
  }

  /// `fn()` with the filter's lock held when no other thread holds it;
  /// false, and nothing run, when one does.
  template <typename F>
  bool tryWithFilter(F&& fn) {
    std::unique_lock<std::mutex> lock(filter_mutex_, std::try_to_lock);
    if (!lock.owns_lock()) return false;
    std::forward<F>(fn)();
    return true;
  }

  /// Wakes the filter thread and waits for it to end; no update runs on it
  /// from then on (withFilter() and tryWithFilter() still work). For a
  /// shutdown: what the updates use may go once no scan comes any more.
  void stop();

  /// Scans dropped for a newer one of their sensor, since start.
  std::uint64_t dropped() const { return slot_.dropped(); }

 private:
  bool updateHere(const PendingScan& scan);
  void process(const PendingScan& scan);
  void filterLoop();

  Update update_;
  IsShort is_short_;
  LimitedWarn* warn_;
  Running running_;
  // Guards the filter: taken for a whole update (by the filter thread, or by
  // the thread that brought the scan, which only ever tries it), and by
  // withFilter()'s callers.
  std::mutex filter_mutex_;
  LatestScanSlot slot_;
  std::thread thread_;  // started in the constructor's body, joined by stop()
};

}  // namespace pf_ros
