#include "pf_localization/ros/input/bag_contents.h"

#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <sensor_msgs/LaserScan.h>

#include <cstdio>
#include <string>
#include <vector>

namespace pf_ros {
namespace {

sensor_msgs::LaserScan scanOf(float range_max) {
  sensor_msgs::LaserScan scan;
  scan.range_min = 0.05f;
  scan.range_max = range_max;
  scan.ranges = {1.0f, 2.0f};
  return scan;
}

TEST(FirstScanRanges, EachLaserTopicsFirstRangeMax) {
  const std::string path = testing::TempDir() + "first_scan_ranges.bag";
  {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    // In the order of the topics asked for, not of the bag: the rear lidar
    // speaks first. The front one changes its range_max later, which is not
    // read; an unlisted topic is not looked at, a missing one gives nothing.
    bag.write("/scan_rear", ros::Time(1.0), scanOf(12.0f));
    bag.write("/other", ros::Time(1.5), scanOf(40.0f));
    bag.write("/scan_front", ros::Time(2.0), scanOf(25.0f));
    bag.write("/scan_front", ros::Time(3.0), scanOf(30.0f));
  }
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  BagTopics topics;
  topics.scan_topics = {"/scan_front", "/scan_rear", "/scan_missing"};
  EXPECT_EQ(std::vector<double>({25.0, 12.0}), firstScanRanges(bag, topics));
  bag.close();
  std::remove(path.c_str());
}

}  // namespace
}  // namespace pf_ros
