#include "pf_localization/ros/diagnostics/limited_warn.h"

#include <ros/console.h>

namespace pf_ros {

void LimitedWarn::warn(const std::string& key, const std::string& text) {
  int suppressed = 0;
  if (!log_.due(key, &suppressed)) return;
  ROS_WARN("%s: %s", prefix_.c_str(), line(text, suppressed).c_str());
}

std::string LimitedWarn::line(const std::string& text, int suppressed) {
  if (suppressed <= 0) return text;
  return text + " (" + std::to_string(suppressed) + " more like it since the last such line)";
}

}  // namespace pf_ros
