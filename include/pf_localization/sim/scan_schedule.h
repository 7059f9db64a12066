// When a simulated sensor takes its scans: at offset + k * period (k = 0, 1,
// ...) after the start of the run, in nanoseconds. Giving two sensors
// periods and offsets that never meet is how a rig keeps them out of phase,
// as real sensors on one robot are.
#pragma once

#include <cstdint>

namespace pf::sim {

struct ScanSchedule {
  int64_t period_ns = 0;  // > 0
  int64_t offset_ns = 0;  // of the first scan, in [0, period_ns)

  /// Whether a scan is stamped `t_ns` after the start of the run.
  bool scansAt(int64_t t_ns) const {
    return t_ns >= offset_ns && (t_ns - offset_ns) % period_ns == 0;
  }
  double rateHz() const { return 1e9 / period_ns; }
};

}  // namespace pf::sim
