#include "pf_localization/ros/diagnostics/state_change_log.h"

namespace pf_ros {

std::optional<StateChangeLog::Line> StateChangeLog::onConfidence(const pf::Confidence& c) {
  if (c.state == last_) return std::nullopt;
  last_ = c.state;
  if (c.state == pf::LocalizationState::kLocalized) return Line{false, "localized: " + c.reason};
  return Line{true, std::string(pf::toString(c.state)) + ": " + c.reason};
}

}  // namespace pf_ros
