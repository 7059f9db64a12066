#include "pf_localization/ros/diagnostics/limited_log.h"

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

}  // namespace pf_ros
