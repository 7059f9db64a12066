// Where pf_node runs a scan's update: on the thread that brought the scan
// (roscpp's poll thread), or handed over to the filter thread.
//
// A hand-over costs two thread wake-ups (the filter thread's for the scan,
// the poll thread's again for each message the update publishes) and runs the
// update on a core whose caches the node's messages did not warm. A short
// update therefore runs where its scan arrived. A long one must not: while it
// runs, the poll thread sends no timed map -> odom copy and takes no tf. The
// rule: an update stays on the poll thread when each of the last kWindow
// updates, scaled up to the particle count the next one weighs, took at most
// kBudget of wall time; so a cloud that grew (global localization, a
// recovery) is handed over until updates of its size have shown their cost.
// docs/performance.md, "The fixed cost", has the figures.
#pragma once

#include <cstddef>

#include "pf_localization/ros/diagnostics/rolling_percentiles.h"

namespace pf_ros {

class UpdatePlacement {
 public:
  /// s of wall time an update may hold the poll thread: a map -> odom copy
  /// due meanwhile comes this much later. On the wall clock the copy is due
  /// 25 ms before tf users' two periods are up; under simulated time 50 ms
  /// of the bag's clock, which a replay at 10x runs through in 5 ms of wall
  /// time.
  static constexpr double kBudget = 0.003;
  /// Updates remembered: 2 s at a 5 Hz laser.
  static constexpr std::size_t kWindow = 10;

  /// One update of `particles` particles took `wall_s` seconds.
  void addUpdate(double wall_s, std::size_t particles);

  /// Whether an update of `particles` particles may run on the poll thread:
  /// kWindow updates were seen and each, scaled to `particles` where it had
  /// fewer, took at most kBudget.
  bool onPollThread(std::size_t particles) const;

  /// Forgets every update (a new map: the costs seen no longer apply).
  void reset();

 private:
  // Each update scaled to a cloud of n particles is within the budget when
  // the longest is, and n times the longest per particle is.
  RollingPercentiles wall_s_{kWindow};
  RollingPercentiles wall_s_per_particle_{kWindow};
};

}  // namespace pf_ros
