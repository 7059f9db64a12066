// The particle cap behind max_update_time: "use what the CPU allows" instead
// of a guessed max_particles. After each update it learns the wall time one
// particle costs on this computer, as it is loaded now, and caps the particle
// count so that an update fits in the budget; KLD-sampling still chooses the
// count below the cap. The cost taken is a high quantile of the recent
// updates' (the budget is meant for the p95 of the update time). A slower or
// busier computer lowers the cap at once; it rises again as the slow updates
// leave the window.
#pragma once

#include <cstddef>

#include "pf_localization/ros/diagnostics/rolling_percentiles.h"

namespace pf_ros {

struct UpdateTimeGovernorOptions {
  double max_update_time = 0.0;  // s of wall time an update may take; <= 0: no cap
  // The cap aims at this fraction of max_update_time, so that the spread the
  // window does not show (a sudden load) stays under it.
  double headroom = 0.6;
  // Updates whose per-particle cost is remembered, and the quantile of them
  // the cap is computed from: 20 updates are 2 s at a 10 Hz laser, and their
  // p95 is their second-largest cost.
  std::size_t window = 20;
  double quantile = 0.95;
  // The cap rises by at most this factor per update: a cost measured on a
  // small cloud underestimates a large one's (caches), so growth is gradual.
  double max_growth = 1.25;
  std::size_t min_cap = 100;  // particles; the cap never goes below this
};

class UpdateTimeGovernor {
 public:
  explicit UpdateTimeGovernor(const UpdateTimeGovernorOptions& options = {});

  bool enabled() const { return options_.max_update_time > 0.0; }
  void setMaxUpdateTime(double seconds) { options_.max_update_time = seconds; }

  /// One update of `particles` particles took `seconds` (wall). Returns the
  /// new cap (0 when disabled, or before the first update with particles).
  std::size_t addUpdate(std::size_t particles, double seconds);

  /// The current cap on the particle count (0: none).
  std::size_t cap() const { return enabled() ? cap_ : 0; }

 private:
  UpdateTimeGovernorOptions options_;
  RollingPercentiles cost_per_particle_;  // s
  std::size_t cap_ = 0;
};

}  // namespace pf_ros
