// pf_node's rate-limited warnings (bad input, dropped scans): at most one
// line per kind of problem and period (LimitedLog), saying how many like it
// were held back since the last one. Thread-safe, as LimitedLog is.
#pragma once

#include <string>
#include <utility>

#include "pf_localization/ros/diagnostics/limited_log.h"

namespace pf_ros {

class LimitedWarn {
 public:
  /// `prefix`: the start of every line ("pf_node"); `period`: s between two
  /// lines of the same kind.
  LimitedWarn(std::string prefix, double period) : prefix_(std::move(prefix)), log_(period) {}

  /// Logs `text` at WARN when a line of kind `key` is due.
  void warn(const std::string& key, const std::string& text);
  /// Whether a line of kind `key` is due (for lines at another level).
  bool due(const std::string& key) { return log_.due(key); }

  /// The line warn() logs: `text`, and how many were held back, if any.
  static std::string line(const std::string& text, int suppressed);

 private:
  const std::string prefix_;
  LimitedLog log_;
};

}  // namespace pf_ros
