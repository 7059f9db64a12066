// How late pf_node's output is, over the last updates: the latency from a
// scan's arrival to the publication of its map -> odom, the scan's age on
// arrival, the wall time of the update itself, and the scans dropped because
// a newer one arrived while they waited (latest_scan_slot.h). These go to the
// diagnostics after every update, where an overloaded computer shows before
// tf users downstream notice.
#pragma once

#include <diagnostic_msgs/DiagnosticStatus.h>

#include <cstddef>
#include <cstdint>
#include <mutex>

#include "pf_localization/ros/diagnostics/rolling_percentiles.h"

namespace pf_ros {

struct UpdateTimingOptions {
  // Updates the percentiles are taken over: 100 covers 10 s at a 10 Hz laser,
  // long enough for a p95 to mean something, short enough to show a change.
  std::size_t window = 100;
};

/// Thread-safe: the filter thread adds, the same or another thread reports.
class UpdateTiming {
 public:
  explicit UpdateTiming(const UpdateTimingOptions& options = {});

  /// One update: `latency_s` from the scan's arrival to its map -> odom being
  /// published (wall), `age_s` the scan's age when it arrived (the node's
  /// clock minus the stamp), `update_s` the wall time of the filter update.
  void addUpdate(double latency_s, double age_s, double update_s);

  /// p95 of the update wall time over the window (0 before any update).
  double updateTimeP95() const;

  /// Appends latency_{p50,p95,max}_ms, scan_age_{p50,p95,max}_ms,
  /// update_time_{p50,p95,max}_ms (over `window` updates), dropped_scans
  /// (`dropped`, since start) and, when `particle_cap` > 0, particle_cap.
  void addTo(diagnostic_msgs::DiagnosticStatus* status, std::uint64_t dropped,
             std::size_t particle_cap = 0) const;

 private:
  mutable std::mutex mutex_;
  RollingPercentiles latency_, age_, update_;
};

}  // namespace pf_ros
