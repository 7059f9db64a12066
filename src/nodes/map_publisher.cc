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
// MAP.yaml may be a building's floors file (core/map/floors_file.h): the
// map offered is then the current floor's, from the initial floor on, and
// follows pf_node's floor (pf_floor, std_msgs/String), which reads the same
// file (~floors_file) and does not take its maps from `map`.
//
// Private parameters:
//   ~map_file (string)  the map YAML or floors file, when not given as the argument
//   ~frame_id (string, "map")  header.frame_id of the map
//   ~delay (double, 0)  wall seconds to wait before offering the map, so tests
//                       can check how a node copes with a map that arrives late
//
// A malformed map is fatal (exit code 1) with the loader's message, which
// names the file and the field. -h / --help prints the usage (exit 0, no
// master needed); a wrong call prints it on stderr (exit 2).
#include <nav_msgs/GetMap.h>
#include <nav_msgs/MapMetaData.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>
#include <std_msgs/String.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "pf_localization/core/map/floors_file.h"
#include "pf_localization/core/map/map_loader.h"
#include "pf_localization/ros/input/conversions.h"

namespace {

constexpr char kUsage[] =
    "usage: rosrun pf_localization map_publisher MAP.yaml|FLOORS.yaml\n"
    "       rosrun pf_localization map_publisher _map_file:=MAP.yaml|FLOORS.yaml\n"
    "Publishes the map latched on map and map_metadata, and serves static_map;\n"
    "with a building's floors file, the floor's that pf_floor names (the initial first).\n"
    "Private parameters: ~map_file, ~frame_id (default map), ~delay (s, default 0).\n";

// -h or --help anywhere; checked before ros::init, so that the answer needs
// no master and no ROS environment.
bool asksForHelp(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "-h") == 0 || std::strcmp(argv[i], "--help") == 0) return true;
  }
  return false;
}

// Sleeps in short steps so Ctrl-C during a long delay still ends the node.
void waitWall(double seconds) {
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(seconds);
  while (ros::ok() && ros::WallTime::now() < end) {
    const double left = (end - ros::WallTime::now()).toSec();
    ros::WallDuration(std::min(0.1, std::max(0.0, left))).sleep();
  }
}

// ~delay, 0 when it is not a non-negative number of seconds (warned).
double readDelay(const ros::NodeHandle& pnh) {
  const double delay = pnh.param("delay", 0.0);
  if (delay >= 0.0 && std::isfinite(delay)) return delay;
  ROS_WARN("map_publisher: ~delay must be a non-negative number of seconds, got %g; using 0",
           delay);
  return 0.0;
}

// The maps to offer: one, or every floor's (`names` then gives their names),
// and the index of the one offered first. Throws pf::MapLoadError or
// pf::FloorsFileError.
struct Maps {
  std::vector<std::string> names;
  std::vector<nav_msgs::OccupancyGrid> maps;
  std::size_t current = 0;
};

nav_msgs::OccupancyGrid loadOne(const std::string& yaml_path) {
  const pf::OccupancyGrid grid = pf::loadMap(yaml_path);
  ROS_INFO("map_publisher: %s: %d x %d cells at %g m/cell, %zu free", yaml_path.c_str(),
           grid.width(), grid.height(), grid.resolution(), grid.freeCells().size());
  return pf_ros::toMsg(grid);
}

Maps loadMaps(const std::string& path) {
  Maps out;
  if (!pf::isFloorsFile(path)) {
    out.maps.push_back(loadOne(path));
    return out;
  }
  const pf::FloorsFile file = pf::loadFloorsFile(path);
  for (const pf::Floor& floor : file.floors) {
    out.names.push_back(floor.name);
    out.maps.push_back(loadOne(floor.map));
  }
  out.current = file.initial;
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (asksForHelp(argc, argv)) {
    std::cout << kUsage;
    return 0;
  }
  // ros::init strips remapping arguments, so what is left in argv is ours.
  ros::init(argc, argv, "map_publisher");
  // An option is a wrong call, not a map file that cannot be opened.
  if (argc > 2 || (argc == 2 && argv[1][0] == '-')) {
    std::cerr << "map_publisher: unexpected argument '" << argv[argc - 1] << "'\n" << kUsage;
    return 2;
  }
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");

  std::string yaml_path;
  if (argc == 2) {
    yaml_path = argv[1];
  } else {
    pnh.getParam("map_file", yaml_path);
  }
  if (yaml_path.empty()) {
    std::cerr << "map_publisher: no map: give MAP.yaml or set ~map_file\n" << kUsage;
    return 2;
  }
  const std::string frame_id = pnh.param<std::string>("frame_id", "map");
  const double delay = readDelay(pnh);

  Maps maps;
  try {
    maps = loadMaps(yaml_path);
  } catch (const std::runtime_error& e) {  // pf::MapLoadError, pf::FloorsFileError
    ROS_FATAL("map_publisher: %s", e.what());
    return 1;
  }

  if (delay > 0.0) {
    ROS_INFO("map_publisher: waiting %g s before publishing the map", delay);
    waitWall(delay);
    if (!ros::ok()) return 0;
  }

  // Everything is offered only after the delay, so the service cannot hand
  // out the map before the topic does.
  ros::Publisher map_pub = nh.advertise<nav_msgs::OccupancyGrid>("map", 1, true);
  ros::Publisher meta_pub = nh.advertise<nav_msgs::MapMetaData>("map_metadata", 1, true);
  nav_msgs::GetMap::Response map;
  const auto offer = [&](std::size_t index) {
    maps.current = index;
    map.map = maps.maps[index];
    // Under use_sim_time with no clock yet this is 0, as with map_server.
    map.map.header.stamp = ros::Time::now();
    map.map.header.frame_id = frame_id;
    map.map.info.map_load_time = map.map.header.stamp;
    meta_pub.publish(map.map.info);
    map_pub.publish(map.map);
  };
  offer(maps.current);
  const ros::ServiceServer service =
      nh.advertiseService<nav_msgs::GetMap::Request, nav_msgs::GetMap::Response>(
          "static_map", [&map](nav_msgs::GetMap::Request&, nav_msgs::GetMap::Response& res) {
            res = map;
            return true;
          });
  ros::Subscriber floor_sub;
  if (!maps.names.empty()) {
    floor_sub = nh.subscribe<std_msgs::String>("pf_floor", 1, [&](const auto& floor) {
      for (std::size_t i = 0; i < maps.names.size(); ++i) {
        if (maps.names[i] == floor->data && i != maps.current) {
          ROS_INFO("map_publisher: floor '%s'", floor->data.c_str());
          offer(i);
        }
      }
    });
  }
  ros::spin();
  return 0;
}
