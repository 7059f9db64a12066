#include "pf_localization/ros/latest_scan_slot.h"

#include <chrono>
#include <utility>

namespace pf_ros {

bool LatestScanSlot::put(PendingScan scan) {
  bool replaced = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    replaced = waiting_.has_value();
    if (replaced) ++dropped_;
    waiting_ = std::move(scan);
  }
  ready_.notify_one();
  return replaced;
}

std::optional<PendingScan> LatestScanSlot::take(ros::WallDuration timeout) {
  std::unique_lock<std::mutex> lock(mutex_);
  ready_.wait_for(lock, std::chrono::nanoseconds(timeout.toNSec()),
                  [this] { return closed_ || waiting_.has_value(); });
  if (closed_ || !waiting_) return std::nullopt;
  std::optional<PendingScan> out = std::move(waiting_);
  waiting_.reset();
  return out;
}

void LatestScanSlot::close() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    closed_ = true;
  }
  ready_.notify_all();
}

bool LatestScanSlot::closed() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return closed_;
}

std::uint64_t LatestScanSlot::dropped() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return dropped_;
}

}  // namespace pf_ros
