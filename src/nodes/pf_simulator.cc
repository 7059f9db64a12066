// pf_simulator: drives a simulated robot along a path script on a map and
// writes what the real robot would have recorded, as a ROS 1 bag.
//
//   pf_simulator --map maps/building.yaml --path bags/tracking.path
//                --seed 1 --out bags/tracking.bag [--rig neato|amr|cloud|warehouse]
//                [--compression bz2|lz4|none] [--odom-error K] [--unsigned-odometry]
//                [--no-people] [--scan-period S] [--block NAME:T0:T1] [--start-time SECONDS]
//                [--changes FILE [--change-mask OUT.yaml]]
//
// Every rig publishes, as the Neato's AC109 recording does:
//   /odom          nav_msgs/Odometry odom -> base_link, 20 Hz
//   /tf            odom -> base_link and base_link -> each sensor's frame, 20 Hz;
//                  the real robot has no /tf_static, so neither do we
//   /ground_truth  geometry_msgs/PoseStamped, map: the true base_link pose, 10 Hz
// and its own sensors:
//   neato (the default): a Neato XV-11
//     /scan        sensor_msgs/LaserScan, base_laser_link (x -0.1016, z 0.0889,
//                  yaw pi), 5 Hz: 360 beams at 1 deg from angle 0, range
//                  0.02-5 m, invalid beams 0.0 (ray_caster.h)
//   amr: a small AMR with two 270-degree safety lidars on opposite corners
//        (amr_rig.h, safety_lidar.h)
//     /scan_front  sensor_msgs/LaserScan, front_laser, 12.5 Hz
//     /scan_rear   sensor_msgs/LaserScan, rear_laser, 10 Hz
//                  541 beams at 0.5 deg from -135 deg, 0.05-20 m, no return +inf
//   cloud: the AMR's body with a 16-ring 3D lidar on a mast (ring_lidar.h)
//     /points      sensor_msgs/PointCloud2, velodyne (z 0.6), 10 Hz: organized,
//                  16 x 1800, float32 x y z intensity, NaN without a return
//     /scan        sensor_msgs/LaserScan, laser (the same place), with the cloud:
//                  720 beams at 0.5 deg from angle 0, 0.05-20 m, no return +inf
//                  in the building's 3D world (building_clutter.h: a 2.5 m
//                  ceiling, objects of other heights that are not on the map)
//   warehouse: the AMR's body with one 270-degree safety lidar on its front edge
//        (amr_rig.h), for maps/warehouse.yaml
//     /scan        sensor_msgs/LaserScan, laser (x 0.32, z 0.2), 10 Hz or --scan-period:
//                  541 beams at 0.5 deg from -135 deg, 0.05-25 m, no return +inf,
//                  with the warehouse's pallets that are not on the map
//                  (warehouse_map.h)
//
// The robot starts at the script's start pose in the map and at the origin
// of odom. The simulation steps at 100 Hz; scans are offset from the odometry
// (the Neato's, the cloud's and the warehouse's by 70 ms), so a consumer must interpolate tf
// rather than find exact stamps. --block covers a planar lidar (by name:
// laser, front, rear) from T0 to T1 s after the start: every beam then reads
// range_min (sensor_block.h). Bag time equals header stamp, and the bag
// depends on nothing but the map, the script, the seed and the options: the
// same inputs give the same bytes.
//
// --map may name a floors file (floors_file.h; neato, amr rigs): a script's `floor NAME` (a
// lift ride) shows the sensors that floor's map; /floor (std_msgs/String) names it, and the first.
//
// --changes FILE makes the world differ from the map (map_changes.h): every
// sensor of every rig looks at the changed world (the 3D worlds' walls
// included), the path must keep clear of it, and the changed share is
// printed. --change-mask OUT.yaml writes the true change mask as a map_server
// pair, OUT.yaml and OUT.pgm, with the map's resolution and origin: pixel 0
// (black) an object the map lacks, 205 (grey) an object the map has that is
// gone, 254 (white) unchanged (mode trinary: loaded as a map, the added
// objects are its obstacles and the removed ones unknown). Without
// --changes the world is the map, and the bag is what it was before.
#include <geometry_msgs/PoseStamped.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/PointField.h>
#include <std_msgs/String.h>
#include <tf2_msgs/TFMessage.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <iostream>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "pf_localization/core/map/map_loader.h"
#include "pf_localization/ros/input/conversions.h"
#include "pf_localization/sim/amr_rig.h"
#include "pf_localization/sim/building_clutter.h"
#include "pf_localization/sim/diff_drive_robot.h"
#include "pf_localization/sim/floor_worlds.h"
#include "pf_localization/sim/map_changes.h"
#include "pf_localization/sim/path_script.h"
#include "pf_localization/sim/planar_lidar.h"
#include "pf_localization/sim/planar_sensor.h"
#include "pf_localization/sim/ray_caster.h"
#include "pf_localization/sim/ring_lidar.h"
#include "pf_localization/sim/scene_3d.h"
#include "pf_localization/sim/sensor_block.h"
#include "pf_localization/sim/warehouse_map.h"

namespace {

using pf::Pose2;
using pf::sim::PlanarLidar;
using pf::sim::RingLidar;

constexpr int64_t kTickNs = 10'000'000;   // 100 Hz simulation step
constexpr double kTick = kTickNs * 1e-9;  // s
constexpr int kOdomEvery = 5;             // ticks: 20 Hz /odom and /tf
constexpr int kTruthEvery = 10;           // 10 Hz /ground_truth
constexpr int kScanEvery = 20;            // the Neato's 5 Hz /scan by default ...
constexpr int kScanOffset = 7;            // ... 70 ms after an odometry tick (the cloud's too)
constexpr int kCloudEvery = 10;           // the ring lidar's 10 Hz by default
constexpr int kWarehouseEvery = 10;       // the warehouse lidar's 10 Hz by default
constexpr double kNeatoRadius = 0.17;     // m, a Neato is 0.33 m across

enum class RigKind { kNeato, kAmr, kCloud, kWarehouse };
struct Options {
  std::string map, path, out;
  uint64_t seed = 0;
  RigKind rig = RigKind::kNeato;
  std::string compression = "bz2";
  double odom_error = 1.0;
  bool unsigned_odometry = false;
  bool people = true;
  double start_time = 1000.0;
  // Ticks between scans (the neato, cloud and warehouse rigs): the sensor's own rate, or
  // a sparse log's period (the CARMEN logs keep one scan every few seconds).
  std::optional<int> scan_every;
  std::vector<pf::sim::SensorBlock> blocks;
  std::string changes, change_mask;  // a changes file, where to write its mask
};

constexpr char kUsage[] =
    "usage: pf_simulator --map MAP.yaml|FLOORS.yaml --path SCRIPT.path --out OUT.bag\n"
    "                    [--seed N] [--compression bz2|lz4|none]\n"
    "                    [--rig neato|amr|cloud|warehouse]  the robot and its sensors\n"
    "                         (default neato):\n"
    "                         neato  a Neato XV-11, /scan\n"
    "                         amr    an AMR with front and rear 270-degree lidars,\n"
    "                                /scan_front (12.5 Hz) and /scan_rear (10 Hz)\n"
    "                         cloud  the AMR with a 16-ring 3D lidar, /points, and a\n"
    "                                360-degree lidar at the same place, /scan\n"
    "                         warehouse  the AMR with one 270-degree 25 m lidar on its\n"
    "                                front, /scan, among maps/warehouse.yaml's pallets\n"
    "                    [--odom-error K]   scale the odometry errors (0: perfect)\n"
    "                    [--unsigned-odometry]  log reversing as driving forwards\n"
    "                    [--no-people]      ignore the script's 'person' lines\n"
    "                    [--start-time S]   first stamp, s (default 1000)\n"
    "                    [--scan-period S]  s between scans, neato, cloud and warehouse\n"
    "                                       rigs (default 0.2, 0.1 and 0.1)\n"
    "                    [--block NAME:T0:T1]  cover the lidar NAME (neato: laser; amr:\n"
    "                                       front, rear; cloud, warehouse: laser) from T0 to T1 s\n"
    "                                       after the start: all its beams read range_min;\n"
    "                                       may be repeated\n"
    "                    [--changes FILE]   the world differs from the map by FILE's\n"
    "                                       changes (map_changes.h): the sensors see it\n"
    "                    [--change-mask OUT.yaml]  write the true change mask (map_server\n"
    "                                       pair; pixels 0 added, 205 removed, 254 unchanged)\n";

// A wrong call: the problem and the usage on stderr, exit 2.
[[noreturn]] void usage(const std::string& problem) {
  std::cerr << "pf_simulator: " << problem << "\n" << kUsage;
  std::exit(2);
}

RigKind rigKind(const std::string& name) {
  if (name == "neato") return RigKind::kNeato;
  if (name == "amr") return RigKind::kAmr;
  if (name == "cloud") return RigKind::kCloud;
  if (name != "warehouse") usage("--rig must be neato, amr, cloud or warehouse");
  return RigKind::kWarehouse;
}

Options parseOptions(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "-h" || arg == "--help") {
      std::cout << kUsage;
      std::exit(0);
    }
    const auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage(arg + " needs a value");
      return argv[++i];
    };
    const auto number = [&]() {
      const std::string v = value();
      char* end = nullptr;
      const double d = std::strtod(v.c_str(), &end);
      if (end == v.c_str() || *end != '\0' || !std::isfinite(d)) usage(arg + ": bad number " + v);
      return d;
    };
    if (arg == "--map") {
      o.map = value();
    } else if (arg == "--path") {
      o.path = value();
    } else if (arg == "--out") {
      o.out = value();
    } else if (arg == "--seed") {
      const double s = number();
      if (s < 0 || s != std::floor(s)) usage("--seed must be a non-negative integer");
      o.seed = static_cast<uint64_t>(s);
    } else if (arg == "--rig") {
      o.rig = rigKind(value());
    } else if (arg == "--compression") {
      o.compression = value();
      if (o.compression != "bz2" && o.compression != "lz4" && o.compression != "none") {
        usage("--compression must be bz2, lz4 or none");
      }
    } else if (arg == "--odom-error") {
      o.odom_error = number();
      if (o.odom_error < 0.0) usage("--odom-error must not be negative");
    } else if (arg == "--unsigned-odometry") {
      o.unsigned_odometry = true;
    } else if (arg == "--no-people") {
      o.people = false;
    } else if (arg == "--scan-period") {
      const double period = number();
      o.scan_every = static_cast<int>(std::lround(period / kTick));
      if (*o.scan_every < 1 || std::fabs(*o.scan_every * kTick - period) > 1e-9 || period > 60.0) {
        usage("--scan-period must be a multiple of 0.01 s, at most 60 s");
      }
    } else if (arg == "--block") {
      try {
        o.blocks.push_back(pf::sim::parseSensorBlock(value()));
      } catch (const std::invalid_argument& e) {
        usage(std::string("--block: ") + e.what());
      }
    } else if (arg == "--changes") {
      o.changes = value();
    } else if (arg == "--change-mask") {
      o.change_mask = value();
    } else if (arg == "--start-time") {
      o.start_time = number();
      if (o.start_time <= 0.0) usage("--start-time must be positive");
    } else {
      usage("unknown option " + arg);
    }
  }
  if (o.map.empty() || o.path.empty() || o.out.empty())
    usage("--map, --path and --out are required");
  if (!o.change_mask.empty() && o.changes.empty()) usage("--change-mask needs --changes");
  if (o.rig == RigKind::kAmr && o.scan_every) {
    usage("--scan-period: the amr rig's lidars keep their own rates");
  }
  return o;
}

// A Neato's odometry: a few per mille of wheel radius mismatch bends straight
// lines by under a degree per metre, the track width error over-counts turns
// by 1.5 %, and slip adds a random walk. The AMR rigs keep it: what they are
// for is their sensors.
pf::sim::DiffDriveParams odometryErrors(double scale) {
  pf::sim::DiffDriveParams p;
  p.left_radius_error = 0.002 * scale;
  p.right_radius_error = -0.001 * scale;
  p.track_width_error = 0.015 * scale;
  p.slip_sigma = 0.004 * scale;
  return p;
}

// A scan every `every` ticks, the first 70 ms after an odometry tick (or at
// the start, for a scan on every tick up to 70 ms apart).
pf::sim::ScanSchedule offsetSchedule(int every) {
  return {every * kTickNs, (kScanOffset % every) * kTickNs};
}

// The Neato's laser, scanning every `every` ticks from 70 ms.
PlanarLidar neatoLidar(int every) {
  PlanarLidar l;
  l.name = "laser";
  l.frame = "base_laser_link";
  l.topic = "/scan";
  l.mount = {-0.1016, 0.0, M_PI};
  l.height = 0.0889;
  l.angle_min = 0.0;
  l.beams = 360;
  l.angle_increment = 2.0 * M_PI / l.beams;
  const pf::sim::NeatoLaserParams model;
  l.range_min = model.range_min;
  l.range_max = model.range_max;
  l.schedule = offsetSchedule(every);
  l.scan_time = kScanEvery * kTick;  // one turn of the laser, however sparse the log
  return l;
}

// The seed of the random stream of a rig's sensor `index`: sensor 0's is the
// one the Neato's bags were made with; the others' are spread over the
// 64-bit seeds by the golden ratio, so that no two runs' streams meet.
uint64_t sensorSeed(uint64_t seed, uint64_t index) {
  return seed * 2 + 2 + index * 0x9E3779B97F4A7C15ull;
}

struct Rig {
  std::vector<pf::sim::PlanarSensor> lidars;
  std::optional<RingLidar> ring;
  pf::sim::SimRandom ring_random{0};
  // The 3D world (the cloud rig): its planar lidar looks into it too.
  std::optional<pf::sim::Scene3D> scene;
};

// A rig's objects that are not on the map are placed for one map: on another
// they would stand in walls or outside, which this says rather than
// simulates. `whose` names them and the map they are made for.
void checkObjectsOnMap(const pf::OccupancyGrid& map, const std::vector<pf::sim::Box3>& objects,
                       const std::string& whose) {
  for (const pf::sim::Box3& box : objects) {
    for (double x = box.x0; x <= box.x1; x += 0.5 * map.resolution()) {
      for (double y = box.y0; y <= box.y1; y += 0.5 * map.resolution()) {
        if (map.state(map.worldToCell(x, y)) != pf::CellState::kFree) {
          throw std::runtime_error(whose + " are not in free space of this map (or its world)");
        }
      }
    }
  }
}

Rig makeRig(const Options& o, const pf::OccupancyGrid& world,
            const std::vector<pf::sim::Person>& people) {
  using Model = pf::sim::PlanarSensor::Model;
  Rig rig;
  const auto add = [&](PlanarLidar lidar, Model model) {
    const uint64_t index = rig.lidars.size() + (rig.ring ? 1 : 0);
    rig.lidars.emplace_back(std::move(lidar), model, sensorSeed(o.seed, index), o.blocks);
  };
  switch (o.rig) {
    case RigKind::kNeato:
      add(neatoLidar(o.scan_every.value_or(kScanEvery)), Model::kNeato);
      break;
    case RigKind::kAmr:
      add(pf::sim::amrFrontLidar(), Model::kSafety);
      add(pf::sim::amrRearLidar(), Model::kSafety);
      break;
    case RigKind::kCloud: {
      checkObjectsOnMap(world, pf::sim::buildingClutter(),
                        "the cloud rig's objects (building_clutter.h; it is made for "
                        "maps/building.yaml)");
      const pf::sim::ScanSchedule schedule = offsetSchedule(o.scan_every.value_or(kCloudEvery));
      rig.ring = pf::sim::amrRingLidar(schedule);
      rig.ring_random = pf::sim::SimRandom(sensorSeed(o.seed, 0));
      add(pf::sim::amrMastLidar(schedule), Model::kSafety);
      rig.scene.emplace(world, pf::sim::kBuildingCeiling, pf::sim::buildingClutter(), people);
      break;
    }
    case RigKind::kWarehouse: {
      const std::vector<pf::sim::Box3> pallets = pf::sim::warehousePallets();
      checkObjectsOnMap(world, pallets,
                        "the warehouse rig's pallets (warehouse_map.h; it is made for "
                        "maps/warehouse.yaml)");
      add(pf::sim::amrWarehouseLidar(offsetSchedule(o.scan_every.value_or(kWarehouseEvery))),
          Model::kSafety);
      // No ceiling: a level lidar never reaches a warehouse's roof.
      rig.scene.emplace(world, std::numeric_limits<double>::infinity(), pallets, people);
      break;
    }
  }
  for (const pf::sim::SensorBlock& block : o.blocks) {
    bool known = false;
    for (const auto& s : rig.lidars) known = known || s.lidar().name == block.sensor;
    if (!known) usage("--block: this rig has no lidar named '" + block.sensor + "'");
  }
  return rig;
}

geometry_msgs::TransformStamped transform(const ros::Time& stamp, const std::string& parent,
                                          const std::string& child, const Pose2& pose,
                                          double z = 0.0) {
  geometry_msgs::TransformStamped t;
  t.header.stamp = stamp;
  t.header.frame_id = parent;
  t.child_frame_id = child;
  t.transform = pf_ros::toTransformMsg(pose);
  t.transform.translation.z = z;
  return t;
}

// /tf (odom -> base_link and the sensors' mountings) and /odom at `stamp`.
void writeOdometry(const ros::Time& stamp, const pf::sim::DiffDriveRobot& robot, const Rig& rig,
                   uint32_t seq, rosbag::Bag* bag) {
  tf2_msgs::TFMessage odom_tf, mount_tf;
  odom_tf.transforms.push_back(transform(stamp, "odom", "base_link", robot.odomPose()));
  if (rig.ring) {
    mount_tf.transforms.push_back(
        transform(stamp, "base_link", rig.ring->frame, rig.ring->mount, rig.ring->height));
  }
  for (const pf::sim::PlanarSensor& s : rig.lidars) {
    mount_tf.transforms.push_back(
        transform(stamp, "base_link", s.lidar().frame, s.lidar().mount, s.lidar().height));
  }
  bag->write("/tf", stamp, odom_tf);
  bag->write("/tf", stamp, mount_tf);

  nav_msgs::Odometry odom;
  odom.header.seq = seq;
  odom.header.stamp = stamp;
  odom.header.frame_id = "odom";
  odom.child_frame_id = "base_link";
  odom.pose.pose = pf_ros::toPoseMsg(robot.odomPose());
  // The covariance the Neato driver publishes (x, y, z 0.1; angles 1e5).
  for (int i = 0; i < 6; ++i) odom.pose.covariance[i * 7] = i < 3 ? 0.1 : 1e5;
  odom.twist.twist.linear.x = robot.odomLinearVelocity();
  odom.twist.twist.angular.z = robot.odomAngularVelocity();
  bag->write("/odom", stamp, odom);
}

// /ground_truth at `stamp`: the true base_link pose in the map.
void writeGroundTruth(const ros::Time& stamp, const pf::sim::DiffDriveRobot& robot, uint32_t seq,
                      rosbag::Bag* bag) {
  geometry_msgs::PoseStamped truth;
  truth.header.seq = seq;
  truth.header.stamp = stamp;
  truth.header.frame_id = "map";
  truth.pose = pf_ros::toPoseMsg(robot.truePose());
  bag->write("/ground_truth", stamp, truth);
}

// A LaserScan message from `lidar` at `stamp` with `ranges`.
sensor_msgs::LaserScan scanMessage(const ros::Time& stamp, uint32_t seq, const PlanarLidar& lidar,
                                   std::vector<float> ranges) {
  sensor_msgs::LaserScan scan;
  scan.header.seq = seq;
  scan.header.stamp = stamp;
  scan.header.frame_id = lidar.frame;
  scan.angle_min = lidar.angle_min;
  scan.angle_increment = lidar.angle_increment;
  scan.angle_max = scan.angle_min + (lidar.beams - 1) * scan.angle_increment;
  scan.time_increment = 0.0;  // every beam is cast from the pose at the stamp
  scan.scan_time = lidar.scan_time;
  scan.range_min = lidar.range_min;
  scan.range_max = lidar.range_max;
  scan.ranges = std::move(ranges);
  return scan;
}

// The true ranges of a scan of `lidar` with base_link at `base`, `t` s into
// the run: in the rig's 3D world if it has one, else on the map with the people.
std::vector<double> idealRanges(const PlanarLidar& lidar, const Rig& rig,
                                const pf::sim::RayCaster& walls,
                                const std::vector<pf::sim::Person>& people, const Pose2& base,
                                double t) {
  return rig.scene ? pf::sim::idealRanges(lidar, *rig.scene, base, t)
                   : pf::sim::idealRanges(lidar, walls, people, base, t);
}

// An organized PointCloud2 (height rings, width columns) of a sweep.
sensor_msgs::PointCloud2 cloudMessage(const ros::Time& stamp, uint32_t seq, const RingLidar& lidar,
                                      const std::vector<pf::sim::RingPoint>& points) {
  static_assert(sizeof(pf::sim::RingPoint) == 16, "x, y, z, intensity: four packed float32");
  sensor_msgs::PointCloud2 cloud;
  cloud.header.seq = seq;
  cloud.header.stamp = stamp;
  cloud.header.frame_id = lidar.frame;
  cloud.height = lidar.rings;
  cloud.width = lidar.columns;
  uint32_t offset = 0;
  for (const char* name : {"x", "y", "z", "intensity"}) {
    sensor_msgs::PointField field;
    field.name = name;
    field.offset = offset;
    field.datatype = sensor_msgs::PointField::FLOAT32;
    field.count = 1;
    cloud.fields.push_back(field);
    offset += 4;
  }
  cloud.is_bigendian = false;  // the floats are copied as they are in memory (x86, ARM)
  cloud.point_step = sizeof(pf::sim::RingPoint);
  cloud.row_step = cloud.point_step * cloud.width;
  cloud.data.resize(points.size() * sizeof(pf::sim::RingPoint));
  std::memcpy(cloud.data.data(), points.data(), cloud.data.size());
  cloud.is_dense = false;  // rays without a return are NaN
  return cloud;
}

bool isValidReading(float r) { return r > 0.0f && std::isfinite(r); }

// Writes the run into the bag; returns the fraction of invalid beams of the
// planar lidars (covered ones included).
double simulate(const Options& o, const pf::sim::FloorWorlds& floors,
                const pf::sim::PathScript& script, rosbag::Bag* bag) {
  const std::vector<pf::sim::Person> people =
      o.people ? script.people : std::vector<pf::sim::Person>{};
  Rig rig = makeRig(o, floors.grids[floors.initial], people);
  // Separate streams, so that changing a sensor model leaves the odometry alone.
  pf::sim::SimRandom odom_random(o.seed * 2 + 1);
  pf::sim::DiffDriveParams odometry = odometryErrors(o.odom_error);
  odometry.unsigned_translation = o.unsigned_odometry;
  pf::sim::DiffDriveRobot robot(odometry, script.start);
  const std::vector<pf::sim::RayCaster> worlds(floors.grids.begin(), floors.grids.end());
  std::size_t on = floors.initial;  // the floor's world the sensors see

  const int64_t start_ns = std::llround(o.start_time * 1e9);
  const int64_t last_tick = static_cast<int64_t>(std::ceil(script.duration() / kTick - 1e-9));
  uint32_t odom_seq = 0, truth_seq = 0, cloud_seq = 0;
  std::vector<uint32_t> scan_seq(rig.lidars.size(), 0);
  pf::sim::PathPlayer player(script);
  long beams = 0, invalid = 0;

  for (int64_t tick = 0; tick <= last_tick; ++tick) {
    player.advance(tick == 0 ? 0.0 : kTick, &robot, &odom_random);

    const int64_t t_ns = tick * kTickNs;
    ros::Time stamp;
    stamp.fromNSec(start_ns + t_ns);
    const std::size_t now_on = player.floor().empty() ? on : floors.index(player.floor());
    if (floors.isBuilding() && (tick == 0 || now_on != on)) {
      on = now_on;
      std_msgs::String floor;
      floor.data = floors.names[on];
      bag->write("/floor", stamp, floor);
    }
    if (tick % kOdomEvery == 0) writeOdometry(stamp, robot, rig, odom_seq++, bag);
    if (tick % kTruthEvery == 0) writeGroundTruth(stamp, robot, truth_seq++, bag);
    if (rig.ring && rig.ring->schedule.scansAt(t_ns)) {
      const std::vector<pf::sim::RingPoint> points = pf::sim::ringSweep(
          *rig.ring, *rig.scene, robot.truePose(), t_ns * 1e-9, &rig.ring_random);
      bag->write("/points", stamp, cloudMessage(stamp, cloud_seq++, *rig.ring, points));
    }
    for (std::size_t k = 0; k < rig.lidars.size(); ++k) {
      pf::sim::PlanarSensor& sensor = rig.lidars[k];
      const PlanarLidar& lidar = sensor.lidar();
      if (!lidar.schedule.scansAt(t_ns)) continue;
      const std::vector<double> ideal =
          idealRanges(lidar, rig, worlds[on], people, robot.truePose(), t_ns * 1e-9);
      const sensor_msgs::LaserScan scan =
          scanMessage(stamp, scan_seq[k]++, lidar, sensor.read(ideal, t_ns));
      for (float r : scan.ranges) invalid += !isValidReading(r);
      beams += scan.ranges.size();
      bag->write(lidar.topic, stamp, scan);
    }
  }
  return beams ? static_cast<double>(invalid) / beams : 0.0;
}

double clearanceRadius(RigKind rig) {
  return rig == RigKind::kNeato ? kNeatoRadius : pf::sim::kAmrRadius;
}

// The cells under the rig's own objects that the map lacks (the warehouse
// rig's pallets), added to `changed`'s mask: the lidar sees them as it sees
// the changes. Returns how many.
int addRigObjects(RigKind rig, pf::sim::ChangedWorld* changed) {
  if (rig != RigKind::kWarehouse) return 0;
  int added = 0;
  for (const pf::sim::Box3& box : pf::sim::warehousePallets()) {
    for (int i : pf::sim::cellsInBox(changed->world, {box.x0, box.y0, box.x1, box.y1})) {
      pf::sim::CellChange& c = changed->mask[static_cast<std::size_t>(i)];
      if (c == pf::sim::CellChange::kUnchanged) c = pf::sim::CellChange::kAdded, ++added;
    }
  }
  return added;
}

// The world the sensors see: the map, or with --changes the map changed,
// whose changed share is printed and whose mask --change-mask writes (with
// the rig's own objects the map lacks).
pf::OccupancyGrid worldOf(const Options& o, pf::OccupancyGrid map) {
  if (o.changes.empty()) return map;
  pf::sim::ChangedWorld changed = pf::sim::applyMapChanges(map, pf::sim::loadMapChanges(o.changes));
  std::printf(
      "%s: %d cells changed: %d added, %d removed, %.1f %% of the map's %d occupied cells\n",
      o.changes.c_str(), changed.added + changed.removed, changed.added, changed.removed,
      100.0 * changed.changedShare(), changed.map_occupied);
  if (const int objects = addRigObjects(o.rig, &changed)) {
    std::printf("the rig's objects the map lacks: %d cells more in the mask\n", objects);
  }
  if (!o.change_mask.empty()) {
    pf::saveMap(changed.maskGrid(), o.change_mask);
    std::printf("wrote %s: the true change mask\n", o.change_mask.c_str());
  }
  return std::move(changed.world);
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parseOptions(argc, argv);
  try {
    pf::sim::FloorWorlds floors = pf::sim::FloorWorlds::load(o.map);
    const bool scene = o.rig == RigKind::kCloud || o.rig == RigKind::kWarehouse;
    if (floors.isBuilding() && (scene || !o.changes.empty())) usage("floors: neato or amr only");
    pf::OccupancyGrid& world = floors.grids[floors.initial];
    world = worldOf(o, world);
    const pf::sim::PathScript script = pf::sim::loadPathScript(o.path);
    if (const auto error = pf::sim::checkClearance(
            script, world, clearanceRadius(o.rig),
            [&floors](const std::string& name) { return floors.grid(name); })) {
      std::cerr << "pf_simulator: " << *error << "\n";
      return 1;
    }
    rosbag::Bag bag(o.out, rosbag::bagmode::Write);
    bag.setCompression(o.compression == "bz2"   ? rosbag::compression::BZ2
                       : o.compression == "lz4" ? rosbag::compression::LZ4
                                                : rosbag::compression::Uncompressed);
    const double invalid = simulate(o, floors, script, &bag);
    bag.close();
    std::printf("wrote %s: %.1f s, %zu motions, %.1f %% invalid beams\n", o.out.c_str(),
                script.duration(), script.motions.size(), 100.0 * invalid);
  } catch (const std::exception& e) {
    std::cerr << "pf_simulator: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
