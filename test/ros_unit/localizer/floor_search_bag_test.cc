// Global localization on every floor (core/recovery/floor_search.h) over
// bags/floors.bag's own scans and odometry, read with the rosbag API (no
// master, no node): the robot drives on the ground floor, rides the lift at
// 37.19 s and drives on the upper floor. A search started at a bag time (the
// call of global_localization) with a seed must name the floor the robot is
// on within 10 s of bag time, and never another. The search is fed as
// pf_node feeds it (ScanLocalizer::observeUpdates: every scan, with the
// odometry at its stamp), its filters have config/pf.yaml's parameters, and
// its verdict is read after every scan.
//
// DISABLED_SeedTable measures seeds 1..10 at three call times and prints the
// table of docs/how-it-works/map.md, "A building's floors":
//   <workspace>/devel/lib/pf_localization/pf_ros_test --gtest_also_run_disabled_tests
// --gtest_filter='FloorSearchBag.DISABLED_SeedTable'
#include <geometry_msgs/PoseStamped.h>
#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/LaserScan.h>
#include <std_msgs/String.h>
#include <tf2_msgs/TFMessage.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "pf_localization/core/map/floors_file.h"
#include "pf_localization/core/map/map_loader.h"
#include "pf_localization/core/recovery/floor_search.h"
#include "pf_localization/ros/input/conversions.h"
#include "pf_localization/ros/params/localizer_config.h"

namespace pf_ros {
namespace {

constexpr char kBag[] = PF_SOURCE_DIR "/bags/floors.bag";
constexpr char kFloors[] = PF_SOURCE_DIR "/maps/building_floors.yaml";
constexpr double kBound = 10.0;  // s of bag time from the call to the floor named

struct Stamped {
  double t;
  pf::Pose2 pose;
};

// What the search needs of the bag, times from its start.
struct BagData {
  std::vector<Stamped> odom, truth;
  std::vector<std::pair<double, pf::LaserScan>> scans;
  std::vector<std::pair<double, std::string>> floors;  // /floor: from when the robot is on which
};

// The pose at `t`, interpolated between the stamped poses around it.
pf::Pose2 at(const std::vector<Stamped>& poses, double t) {
  const auto after = std::lower_bound(poses.begin(), poses.end(), t,
                                      [](const Stamped& s, double v) { return s.t < v; });
  if (after == poses.begin()) return poses.front().pose;
  if (after == poses.end()) return poses.back().pose;
  const Stamped& a = *(after - 1);
  const Stamped& b = *after;
  const double u = (t - a.t) / (b.t - a.t);
  return {a.pose.x + u * (b.pose.x - a.pose.x), a.pose.y + u * (b.pose.y - a.pose.y),
          pf::normalizeAngle(a.pose.yaw + u * pf::angleDiff(b.pose.yaw, a.pose.yaw))};
}

BagData readBag() {
  rosbag::Bag bag(kBag, rosbag::bagmode::Read);
  BagData data;
  std::optional<pf::Pose2> mount;  // base_link -> the laser's frame
  std::vector<std::pair<double, sensor_msgs::LaserScan>> msgs;
  double start = -1.0;
  for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
    const double t = m.getTime().toSec();
    if (start < 0.0) start = t;
    if (const auto odom = m.instantiate<nav_msgs::Odometry>()) {
      data.odom.push_back({t - start, toPose2(odom->pose.pose)});
    } else if (const auto truth = m.instantiate<geometry_msgs::PoseStamped>()) {
      data.truth.push_back({t - start, toPose2(truth->pose)});
    } else if (const auto scan = m.instantiate<sensor_msgs::LaserScan>()) {
      msgs.emplace_back(t - start, *scan);
    } else if (const auto floor = m.instantiate<std_msgs::String>()) {
      data.floors.emplace_back(t - start, floor->data);
    } else if (const auto tf = m.instantiate<tf2_msgs::TFMessage>()) {
      for (const auto& x : tf->transforms) {
        if (x.header.frame_id == "base_link" && !mount) mount = toPose2(x.transform);
      }
    }
  }
  EXPECT_TRUE(mount.has_value());
  for (auto& [t, msg] : msgs) data.scans.emplace_back(t, toCore(msg, mount.value_or(pf::Pose2{})));
  return data;
}

const BagData& bagData() {
  static const BagData data = readBag();
  return data;
}

std::string floorAt(const BagData& data, double t) {
  std::string on;
  for (const auto& [from, name] : data.floors) {
    if (from <= t) on = name;
  }
  return on;
}

struct Outcome {
  std::optional<double> after;  // s of bag time from the call to the first floor named
  std::string named;            // that floor; empty: none within the bag's rest
  std::string wrong;            // a floor named while the robot was on another
  double error = 0.0;           // m, the estimate on the floor named then, against the truth
};

// A search of every floor started at `call` (s into the bag) with `seed`,
// read after every scan until `call + horizon`.
Outcome search(uint64_t seed, double call, double horizon) {
  const BagData& data = bagData();
  LocalizerConfig config;
  config.filter.seed = seed;
  const pf::FloorsFile file = pf::loadFloorsFile(kFloors);
  pf::ParticleFilter recipe_of(config.filter);
  recipe_of.expectScanRange(data.scans.front().second.range_max);
  std::vector<pf::PreparedMap> maps;
  std::vector<std::string> names;
  for (const pf::Floor& floor : file.floors) {
    maps.push_back(pf::PreparedMap::build(pf::loadMap(floor.map), recipe_of.mapRecipe()));
    names.push_back(floor.name);
  }
  pf::FloorSearch floors(config.filter, std::move(maps), names);
  Outcome outcome;
  for (const auto& [t, scan] : data.scans) {
    if (t < call) continue;
    if (t > call + horizon) break;
    floors.update(at(data.odom, t), pf::ScanGroup{scan});
    const pf::FloorSearch::Verdict verdict = floors.verdict();
    if (!verdict.floor) continue;
    const std::string named = names[*verdict.floor];
    if (named != floorAt(data, t) && outcome.wrong.empty()) outcome.wrong = named;
    if (outcome.after) continue;
    outcome.after = t - call;
    outcome.named = named;
    const pf::Pose2 estimate = floors.filter(*verdict.floor).estimate().pose;
    const pf::Pose2 truth = at(data.truth, t);
    outcome.error = std::hypot(estimate.x - truth.x, estimate.y - truth.y);
  }
  return outcome;
}

// The calls: on the ground floor at the start and on the way to the lift,
// and on the upper floor after the ride (floors_global.test's call).
constexpr double kCalls[] = {2.0, 15.0, 43.0};

// Seeds 1..4 at the three calls: the floor named within 10 s of bag time
// (6.5-9.5 s; a run of localized updates counted after the filter's own
// settling took 8.9-11.5 s at the ground floor's calls), never another
// floor, the pose then within 0.1 m (at most 0.03 m).
TEST(FloorSearchBag, NamesTheFloorWithinTenSecondsAndNeverAnother) {
  for (uint64_t seed = 1; seed <= 4; ++seed) {
    for (const double call : kCalls) {
      const Outcome o = search(seed, call, kBound);
      char where[64];
      std::snprintf(where, sizeof where, "seed %d, call at %.0f s", static_cast<int>(seed), call);
      EXPECT_EQ(floorAt(bagData(), call), o.named) << where;
      EXPECT_TRUE(o.wrong.empty()) << where << ": named " << o.wrong;
      EXPECT_LT(o.error, 0.1) << where;
    }
  }
}

TEST(FloorSearchBag, DISABLED_SeedTable) {
  std::printf("| seed |");
  for (const double call : kCalls) {
    std::printf(" call at %.0f s (%s) |", call, floorAt(bagData(), call).c_str());
  }
  std::printf("\n");
  for (uint64_t seed = 1; seed <= 10; ++seed) {
    std::printf("| %2d |", static_cast<int>(seed));
    for (const double call : kCalls) {
      // Up to the ride (a search across it is not what this measures) or 30 s.
      const double horizon = call < 37.0 ? std::min(30.0, 37.0 - call) : 30.0;
      const Outcome o = search(seed, call, horizon);
      if (o.after) {
        std::printf(" %.1f s, %s, %.2f m%s |", *o.after, o.named.c_str(), o.error,
                    o.wrong.empty() ? "" : (" WRONG " + o.wrong).c_str());
      } else {
        std::printf(" none in %.0f s%s |", horizon,
                    o.wrong.empty() ? "" : (" WRONG " + o.wrong).c_str());
      }
      std::fflush(stdout);
    }
    std::printf("\n");
  }
}

}  // namespace
}  // namespace pf_ros
