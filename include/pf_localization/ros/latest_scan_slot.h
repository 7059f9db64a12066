// The hand-over of scans from pf_node's subscription to its filter thread,
// holding at most one waiting scan: under overload (a filter update slower
// than the scan period, another process taking the CPU) the newest scan wins
// and the older waiting one is dropped and counted, so that the delay between
// a scan and its map -> odom stays bounded by about one update instead of
// growing with a queue, as amcl's does.
#pragma once

#include <ros/time.h>
#include <sensor_msgs/LaserScan.h>

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>

namespace pf_ros {

/// A scan as it arrived at the node.
struct PendingScan {
  sensor_msgs::LaserScanConstPtr scan;
  ros::WallTime arrival_wall;  // for the latency (scan arrival -> its map -> odom)
  ros::Time arrival_clock;     // the node's clock (sim time in a bag), for the scan's age
};

class LatestScanSlot {
 public:
  /// Leaves `scan` for take(). Returns true when it replaced a scan that was
  /// still waiting (that one is dropped, and counted in dropped()).
  bool put(PendingScan scan);

  /// The waiting scan, waiting up to `timeout` for one; nothing on time-out or
  /// once close() was called.
  std::optional<PendingScan> take(ros::WallDuration timeout);

  /// Wakes take() for good (shutdown).
  void close();

  bool closed() const;

  /// Scans replaced before they were taken, since construction.
  std::uint64_t dropped() const;

 private:
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::optional<PendingScan> waiting_;
  std::uint64_t dropped_ = 0;
  bool closed_ = false;
};

}  // namespace pf_ros
