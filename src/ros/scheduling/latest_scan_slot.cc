#include "pf_localization/ros/scheduling/latest_scan_slot.h"

#include <algorithm>
#include <chrono>
#include <utility>

namespace pf_ros {

bool LatestScanSlot::put(PendingScan scan) {
  bool replaced = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto same = std::find_if(waiting_.begin(), waiting_.end(),
                                   [&](const PendingScan& w) { return w.sensor == scan.sensor; });
    replaced = same != waiting_.end();
    if (replaced) {
      ++dropped_;
      waiting_.erase(same);
    }
    waiting_.push_back(std::move(scan));
  }
  ready_.notify_one();
  return replaced;
}

std::optional<PendingScan> LatestScanSlot::take(ros::WallDuration timeout) {
  std::unique_lock<std::mutex> lock(mutex_);
  ready_.wait_for(lock, std::chrono::nanoseconds(timeout.toNSec()),
                  [this] { return closed_ || !waiting_.empty(); });
  if (closed_ || waiting_.empty()) return std::nullopt;
  std::optional<PendingScan> out = std::move(waiting_.front());
  waiting_.erase(waiting_.begin());
  ++in_hand_;
  return out;
}

std::optional<PendingScan> LatestScanSlot::takeUnclaimed() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (waiting_.empty() || in_hand_ > 0) return std::nullopt;
  std::optional<PendingScan> out = std::move(waiting_.front());
  waiting_.erase(waiting_.begin());
  return out;
}

void LatestScanSlot::done() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (in_hand_ > 0) --in_hand_;
}

bool LatestScanSlot::idle() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return waiting_.empty() && in_hand_ == 0;
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
