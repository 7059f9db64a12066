// pf_simulator: drives a simulated Neato XV-11 along a path script on a map
// and writes what the real robot would have recorded, as a ROS 1 bag.
//
//   pf_simulator --map maps/building.yaml --path bags/tracking.path
//                --seed 1 --out bags/tracking.bag [--compression bz2|lz4|none]
//                [--odom-error K] [--unsigned-odometry] [--no-people] [--scan-period S]
//                [--start-time SECONDS]
//
// Topics, as on the real robot (the Neato's AC109 recording):
//   /scan          sensor_msgs/LaserScan, base_laser_link, 5 Hz: 360 beams at
//                  1 deg from angle 0, range 0.02-5 m, invalid beams 0.0
//   /odom          nav_msgs/Odometry odom -> base_link, 20 Hz
//   /tf            odom -> base_link and base_link -> base_laser_link (the
//                  Neato's mounting: x -0.1016, z 0.0889, yaw pi), 20 Hz; the
//                  real robot has no /tf_static, so neither do we
//   /ground_truth  geometry_msgs/PoseStamped, map: the true base_link pose, 10 Hz
//
// The robot starts at the script's start pose in the map and at the origin
// of odom. The simulation steps at 100 Hz; scans are offset from the odometry
// by 70 ms, so a consumer must interpolate tf rather than find exact stamps.
// Bag time equals header stamp, and the bag depends on nothing but the map,
// the script and the seed: the same inputs give the same bytes.
#include <geometry_msgs/PoseStamped.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_msgs/TFMessage.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "pf_localization/core/map_loader.h"
#include "pf_localization/ros/conversions.h"
#include "pf_localization/sim/diff_drive_robot.h"
#include "pf_localization/sim/path_script.h"
#include "pf_localization/sim/ray_caster.h"

namespace {

using pf::Pose2;
using pf::sim::NeatoLaserParams;

constexpr int64_t kTickNs = 10'000'000;   // 100 Hz simulation step
constexpr double kTick = kTickNs * 1e-9;  // s
constexpr int kOdomEvery = 5;             // ticks: 20 Hz /odom and /tf
constexpr int kTruthEvery = 10;           // 10 Hz /ground_truth
constexpr int kScanEvery = 20;            // 5 Hz /scan by default ...
constexpr int kScanOffset = 7;            // ... 70 ms after an odometry tick
constexpr int kBeams = 360;
constexpr double kRobotRadius = 0.17;         // m, a Neato is 0.33 m across
const Pose2 kLaserMount{-0.1016, 0.0, M_PI};  // base_link -> base_laser_link
constexpr double kLaserHeight = 0.0889;       // m

struct Options {
  std::string map, path, out;
  uint64_t seed = 0;
  std::string compression = "bz2";
  double odom_error = 1.0;
  bool unsigned_odometry = false;
  bool people = true;
  double start_time = 1000.0;
  // Ticks between scans: the Neato's 5 Hz, or a sparse log's period (the
  // CARMEN logs keep one scan every few seconds).
  int scan_every = kScanEvery;
};

constexpr char kUsage[] =
    "usage: pf_simulator --map MAP.yaml --path SCRIPT.path --out OUT.bag\n"
    "                    [--seed N] [--compression bz2|lz4|none]\n"
    "                    [--odom-error K]   scale the odometry errors (0: perfect)\n"
    "                    [--unsigned-odometry]  log reversing as driving forwards\n"
    "                    [--no-people]      ignore the script's 'person' lines\n"
    "                    [--start-time S]   first stamp, s (default 1000)\n"
    "                    [--scan-period S]  s between scans (default 0.2: 5 Hz)\n";

// A wrong call: the problem and the usage on stderr, exit 2.
[[noreturn]] void usage(const std::string& problem) {
  std::cerr << "pf_simulator: " << problem << "\n" << kUsage;
  std::exit(2);
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
      if (o.scan_every < 1 || std::fabs(o.scan_every * kTick - period) > 1e-9 || period > 60.0) {
        usage("--scan-period must be a multiple of 0.01 s, at most 60 s");
      }
    } else if (arg == "--start-time") {
      o.start_time = number();
      if (o.start_time <= 0.0) usage("--start-time must be positive");
    } else {
      usage("unknown option " + arg);
    }
  }
  if (o.map.empty() || o.path.empty() || o.out.empty())
    usage("--map, --path and --out are required");
  return o;
}

// A Neato's odometry: a few per mille of wheel radius mismatch bends straight
// lines by under a degree per metre, the track width error over-counts turns
// by 1.5 %, and slip adds a random walk.
pf::sim::DiffDriveParams odometryErrors(double scale) {
  pf::sim::DiffDriveParams p;
  p.left_radius_error = 0.002 * scale;
  p.right_radius_error = -0.001 * scale;
  p.track_width_error = 0.015 * scale;
  p.slip_sigma = 0.004 * scale;
  return p;
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

// /tf (odom -> base_link and the laser's mounting) and /odom at `stamp`.
void writeOdometry(const ros::Time& stamp, const pf::sim::DiffDriveRobot& robot, uint32_t seq,
                   rosbag::Bag* bag) {
  tf2_msgs::TFMessage odom_tf, mount_tf;
  odom_tf.transforms.push_back(transform(stamp, "odom", "base_link", robot.odomPose()));
  mount_tf.transforms.push_back(
      transform(stamp, "base_link", "base_laser_link", kLaserMount, kLaserHeight));
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

// The true range of every beam from `sensor` at time t (s into the run): to
// the map's walls or the nearest person, at most range_max.
std::vector<double> idealRanges(const pf::sim::RayCaster& caster,
                                const std::vector<pf::sim::Person>& people, const Pose2& sensor,
                                double t, double range_max) {
  std::vector<double> ideal(kBeams);
  for (int i = 0; i < kBeams; ++i) {
    const double angle = sensor.yaw + i * (2.0 * M_PI / kBeams);
    double r = caster.cast(sensor.x, sensor.y, angle, range_max);
    for (const pf::sim::Person& p : people) {
      double px, py;
      p.positionAt(t, &px, &py);
      r = std::min(r, pf::sim::castToCircle(sensor.x, sensor.y, angle, px, py, p.radius));
    }
    ideal[i] = r;
  }
  return ideal;
}

// A /scan message at `stamp` with the Neato's readings of `ideal`.
sensor_msgs::LaserScan neatoScan(const ros::Time& stamp, uint32_t seq,
                                 const std::vector<double>& ideal, const NeatoLaserParams& laser,
                                 pf::sim::SimRandom* laser_random) {
  sensor_msgs::LaserScan scan;
  scan.header.seq = seq;
  scan.header.stamp = stamp;
  scan.header.frame_id = "base_laser_link";
  scan.angle_min = 0.0;
  scan.angle_increment = 2.0 * M_PI / kBeams;
  scan.angle_max = (kBeams - 1) * scan.angle_increment;
  scan.time_increment = 0.0;            // every beam is cast from the pose at the stamp
  scan.scan_time = kScanEvery * kTick;  // one turn of the laser, however sparse the log
  scan.range_min = laser.range_min;
  scan.range_max = laser.range_max;
  scan.ranges = pf::sim::neatoReadings(ideal, laser, laser_random);
  return scan;
}

// Writes the run into the bag; returns the fraction of invalid beams.
double simulate(const Options& o, const pf::OccupancyGrid& map, const pf::sim::PathScript& script,
                rosbag::Bag* bag) {
  // Separate streams, so that changing the laser model leaves the odometry alone.
  pf::sim::SimRandom odom_random(o.seed * 2 + 1), laser_random(o.seed * 2 + 2);
  pf::sim::DiffDriveParams odometry = odometryErrors(o.odom_error);
  odometry.unsigned_translation = o.unsigned_odometry;
  pf::sim::DiffDriveRobot robot(odometry, script.start);
  const pf::sim::RayCaster caster(map);
  const NeatoLaserParams laser;
  const std::vector<pf::sim::Person> people =
      o.people ? script.people : std::vector<pf::sim::Person>{};

  const int64_t start_ns = std::llround(o.start_time * 1e9);
  const int64_t last_tick = static_cast<int64_t>(std::ceil(script.duration() / kTick - 1e-9));
  uint32_t odom_seq = 0, truth_seq = 0, scan_seq = 0;
  pf::sim::PathPlayer player(script);
  long beams = 0, invalid = 0;

  for (int64_t tick = 0; tick <= last_tick; ++tick) {
    player.advance(tick == 0 ? 0.0 : kTick, &robot, &odom_random);

    ros::Time stamp;
    stamp.fromNSec(start_ns + tick * kTickNs);
    if (tick % kOdomEvery == 0) writeOdometry(stamp, robot, odom_seq++, bag);
    if (tick % kTruthEvery == 0) writeGroundTruth(stamp, robot, truth_seq++, bag);
    if (tick % o.scan_every == kScanOffset % o.scan_every) {
      const Pose2 sensor = pf::compose(robot.truePose(), kLaserMount);
      const std::vector<double> ideal =
          idealRanges(caster, people, sensor, tick * kTick, laser.range_max);
      const sensor_msgs::LaserScan scan = neatoScan(stamp, scan_seq++, ideal, laser, &laser_random);
      for (float r : scan.ranges) invalid += r == 0.0f;
      beams += kBeams;
      bag->write("/scan", stamp, scan);
    }
  }
  return beams ? static_cast<double>(invalid) / beams : 0.0;
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parseOptions(argc, argv);
  try {
    const pf::OccupancyGrid map = pf::loadMap(o.map);
    const pf::sim::PathScript script = pf::sim::loadPathScript(o.path);
    if (const auto error = pf::sim::checkClearance(script, map, kRobotRadius)) {
      std::cerr << "pf_simulator: " << *error << "\n";
      return 1;
    }
    rosbag::Bag bag(o.out, rosbag::bagmode::Write);
    bag.setCompression(o.compression == "bz2"   ? rosbag::compression::BZ2
                       : o.compression == "lz4" ? rosbag::compression::LZ4
                                                : rosbag::compression::Uncompressed);
    const double invalid = simulate(o, map, script, &bag);
    bag.close();
    std::printf("wrote %s: %.1f s, %zu motions, %.1f %% invalid beams\n", o.out.c_str(),
                script.duration(), script.motions.size(), 100.0 * invalid);
  } catch (const std::exception& e) {
    std::cerr << "pf_simulator: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
