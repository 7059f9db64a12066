// Rate limiting of repeated log lines (bad input, dropped scans): one line
// per kind and period tells the user without drowning the log, and counts
// what it held back, so that nothing is dropped silently. LimitedLog decides
// when a line is due (LimitedWarn writes pf_node's warnings through one).
// Wall time, so the limit also holds while a bag is paused or replayed fast.
// Thread-safe: pf_node's threads all log through one.
#pragma once

#include <map>
#include <mutex>
#include <string>

namespace pf_ros {

class LimitedLog {
 public:
  /// `period`: s between two lines of the same kind.
  explicit LimitedLog(double period) : period_(period) {}

  /// Whether a message of this kind is due at wall time `now_s` (s, any
  /// epoch); if so, `suppressed` is how many of its kind were held back since
  /// the last one logged.
  bool due(const std::string& key, double now_s, int* suppressed = nullptr);
  /// The same at the current wall time.
  bool due(const std::string& key, int* suppressed = nullptr);

 private:
  struct Entry {
    double last = 0.0;
    bool logged = false;
    int suppressed = 0;
  };
  const double period_;
  std::mutex mutex_;
  std::map<std::string, Entry> entries_;
};

}  // namespace pf_ros
