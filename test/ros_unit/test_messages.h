// Messages the ROS side's unit tests share: a small room as a map message,
// and a scan waiting for the filter, stamped at a given time.
#pragma once

#include <nav_msgs/OccupancyGrid.h>
#include <sensor_msgs/LaserScan.h>

#include <boost/make_shared.hpp>
#include <cstddef>

#include "pf_localization/ros/scheduling/latest_scan_slot.h"

namespace pf_ros::test {

// 4 x 3 m at 0.05 m: walls around, an unknown 0.5 x 0.5 m patch at (3, 2) m.
inline nav_msgs::OccupancyGrid room() {
  nav_msgs::OccupancyGrid map;
  map.header.frame_id = "map";
  map.info.width = 80;
  map.info.height = 60;
  map.info.resolution = 0.05f;
  map.info.origin.orientation.w = 1.0;
  map.data.assign(80 * 60, 0);
  for (int y = 0; y < 60; ++y) {
    for (int x = 0; x < 80; ++x) {
      if (x == 0 || y == 0 || x == 79 || y == 59) map.data[y * 80 + x] = 100;
      if (x >= 60 && x < 70 && y >= 40 && y < 50) map.data[y * 80 + x] = -1;
    }
  }
  return map;
}

// A scan of sensor `sensor` stamped `t` on both clocks, as the inputs hand it on.
inline PendingScan scanStamped(double t, std::size_t sensor = 0) {
  auto scan = boost::make_shared<sensor_msgs::LaserScan>();
  scan->header.stamp = ros::Time(t);
  return PendingScan{scan, ros::WallTime(t), ros::Time(t), sensor, nullptr};
}

}  // namespace pf_ros::test
