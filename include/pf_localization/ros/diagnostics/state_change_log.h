// A log line for each change of the localization state (localized /
// uncertain / lost), which is news where the same state on every scan is not.
#pragma once

#include <optional>
#include <string>

#include "pf_localization/core/estimate/confidence.h"

namespace pf_ros {

/// The line for a change of the localization state: INFO when it becomes
/// localized, WARN otherwise; nothing while the state stays the same.
class StateChangeLog {
 public:
  struct Line {
    bool warning = false;
    std::string text;
  };
  std::optional<Line> onConfidence(const pf::Confidence& confidence);

 private:
  std::optional<pf::LocalizationState> last_;
};

}  // namespace pf_ros
