#include "pf_localization/ros/localizer/limited_log.h"

#include <ros/console.h>
#include <ros/time.h>

namespace pf_ros {

bool LimitedLog::due(const std::string& key, double now_s, int* suppressed) {
  std::lock_guard<std::mutex> lock(mutex_);
  Entry& e = entries_[key];
  if (e.logged && now_s - e.last < period_) {
    ++e.suppressed;
    return false;
  }
  if (suppressed) *suppressed = e.suppressed;
  e = Entry{now_s, true, 0};
  return true;
}

bool LimitedLog::due(const std::string& key, int* suppressed) {
  return due(key, ros::WallTime::now().toSec(), suppressed);
}

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
