// map_publisher: a drop-in replacement for map_server's map_server node.
//
//   rosrun pf_localization map_publisher MAP.yaml
//   rosrun pf_localization map_publisher _map_file:=MAP.yaml
//
// Loads the map with pf::loadMap (the same loader pf_bag_runner and the
// simulator use, so every front door sees identical cells) and offers it as
// map_server does: latched nav_msgs/OccupancyGrid on `map`, latched
// nav_msgs/MapMetaData on `map_metadata` and the nav_msgs/GetMap service
// `static_map`.
//
// Private parameters:
//   ~map_file (string)  the map YAML, when not given as the argument
//   ~frame_id (string, "map")  header.frame_id of the map
//   ~delay (double, 0)  wall seconds to wait before offering the map, so tests
//                       can check how a node copes with a map that arrives late
//
// A malformed map is fatal (exit code 1) with the loader's message, which
// names the file and the field.
#include <nav_msgs/GetMap.h>
#include <nav_msgs/MapMetaData.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "pf_localization/core/map_loader.h"
#include "pf_localization/ros/conversions.h"

namespace {

constexpr char kUsage[] =
    "usage: rosrun pf_localization map_publisher MAP.yaml  (or set the private parameter "
    "~map_file)";

// Sleeps in short steps so Ctrl-C during a long delay still ends the node.
void waitWall(double seconds) {
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(seconds);
  while (ros::ok() && ros::WallTime::now() < end) {
    const double left = (end - ros::WallTime::now()).toSec();
    ros::WallDuration(std::min(0.1, std::max(0.0, left))).sleep();
  }
}

}  // namespace

int main(int argc, char** argv) {
  // ros::init strips remapping arguments, so what is left in argv is ours.
  ros::init(argc, argv, "map_publisher");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");

  std::string yaml_path;
  if (argc == 2) {
    yaml_path = argv[1];
  } else if (argc == 1) {
    pnh.getParam("map_file", yaml_path);
  }
  if (argc > 2 || yaml_path.empty()) {
    ROS_FATAL("map_publisher: %s", kUsage);
    return 1;
  }
  const std::string frame_id = pnh.param<std::string>("frame_id", "map");
  double delay = pnh.param("delay", 0.0);
  if (!(delay >= 0.0) || !std::isfinite(delay)) {
    ROS_WARN("map_publisher: ~delay must be a non-negative number of seconds, got %g; using 0",
             delay);
    delay = 0.0;
  }

  nav_msgs::GetMap::Response map;
  try {
    const pf::OccupancyGrid grid = pf::loadMap(yaml_path);
    map.map = pf_ros::toMsg(grid);
    ROS_INFO("map_publisher: %s: %d x %d cells at %g m/cell, %zu free", yaml_path.c_str(),
             grid.width(), grid.height(), grid.resolution(), grid.freeCells().size());
  } catch (const pf::MapLoadError& e) {
    ROS_FATAL("map_publisher: %s", e.what());
    return 1;
  }

  if (delay > 0.0) {
    ROS_INFO("map_publisher: waiting %g s before publishing the map", delay);
    waitWall(delay);
    if (!ros::ok()) return 0;
  }

  // Under use_sim_time with no clock yet this is 0, as with map_server.
  map.map.header.stamp = ros::Time::now();
  map.map.header.frame_id = frame_id;
  map.map.info.map_load_time = map.map.header.stamp;

  // Everything is offered only after the delay, so the service cannot hand
  // out the map before the topic does.
  ros::Publisher map_pub = nh.advertise<nav_msgs::OccupancyGrid>("map", 1, true);
  ros::Publisher meta_pub = nh.advertise<nav_msgs::MapMetaData>("map_metadata", 1, true);
  const ros::ServiceServer service =
      nh.advertiseService<nav_msgs::GetMap::Request, nav_msgs::GetMap::Response>(
          "static_map", [&map](nav_msgs::GetMap::Request&, nav_msgs::GetMap::Response& res) {
            res = map;
            return true;
          });
  meta_pub.publish(map.map.info);
  map_pub.publish(map.map);
  ros::spin();
  return 0;
}
