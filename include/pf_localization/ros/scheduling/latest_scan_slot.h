// The hand-over of scans from pf_node's subscriptions to its filter thread
// (the scans whose updates are too long for roscpp's poll thread),
// holding at most one waiting scan per sensor: under overload (a filter update slower
// than the scan period, another process taking the CPU) the newest scan wins
// and the older waiting one of that sensor is dropped and counted (another
// sensor's is not: it is the other half of the view), so that the delay between
// a scan and its map -> odom stays bounded by about one update instead of
// growing with a queue, as amcl's does.
#pragma once

#include <ros/time.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_msgs/Header.h>

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <vector>

namespace pf_ros {

/// A scan, or a 3D sensor's cloud, as it arrived at the node.
struct PendingScan {
  sensor_msgs::LaserScanConstPtr scan;  // a lidar's scan; empty for a cloud
  ros::WallTime arrival_wall;           // for the latency (scan arrival -> its map -> odom)
  ros::Time arrival_clock;              // the node's clock (sim time in a bag), for the scan's age
  std::size_t sensor = 0;               // which topic it came on (sensorTopics()' index)
  sensor_msgs::PointCloud2ConstPtr cloud;  // a 3D sensor's cloud, when scan is empty

  const std_msgs::Header& header() const { return scan ? scan->header : cloud->header; }
};

class LatestScanSlot {
 public:
  /// Leaves `scan` for take(). Returns true when it replaced a scan of the
  /// same sensor that was still waiting (that one is dropped, and counted in
  /// dropped()).
  bool put(PendingScan scan);

  /// The waiting scan that arrived first, waiting up to `timeout` for one;
  /// nothing on time-out or once close() was called. The scan stays in hand
  /// (idle() is false) until done().
  std::optional<PendingScan> take(ros::WallDuration timeout);
  /// The waiting scan that arrived first, at once, when none is in hand:
  /// for a thread that handles it there and then (it is not in hand
  /// afterwards). Nothing when none waits, or the filter thread holds one
  /// (the waiting one would overtake it).
  std::optional<PendingScan> takeUnclaimed();
  /// The scan last taken was handled.
  void done();
  /// No scan waits, and none taken is still being handled: a scan that
  /// arrives now may be handled at once without overtaking an older one.
  bool idle() const;

  /// Wakes take() for good (shutdown).
  void close();

  bool closed() const;

  /// Scans replaced before they were taken, since construction.
  std::uint64_t dropped() const;

 private:
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::vector<PendingScan> waiting_;  // at most one per sensor, in arrival order
  std::uint64_t dropped_ = 0;
  std::size_t in_hand_ = 0;  // taken and not yet done()
  bool closed_ = false;
};

}  // namespace pf_ros
