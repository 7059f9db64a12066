// The layer of the map's changes across a restart (map_changes_saver.h): a
// room whose map has a box that is gone and lacks one that is there, toured
// by a layer of its own, saved, and restored into a ScanLocalizer's filter
// on the same map, or refused.
#include "pf_localization/ros/output/map_changes_saver.h"

#include <gtest/gtest.h>
#include <tf2/buffer_core.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "pf_localization/core/map/map_change_file.h"
#include "pf_localization/ros/input/conversions.h"
#include "pf_localization/ros/localizer/scan_localizer.h"
#include "pf_localization/ros/params/saved_pose.h"
#include "support/rooms.h"
#include "support/scan_simulator.h"

namespace pf_ros {
namespace {

const pf::test::Box kAdded{3.0, 1.2, 3.4, 1.6};    // in the world, not on the map
const pf::test::Box kRemoved{0.8, 1.8, 1.2, 2.2};  // on the map, not in the world

pf::OccupancyGrid mapGrid() { return pf::test::room(4.0, 3.0, 0.05, {kRemoved}); }
pf::OccupancyGrid worldGrid() { return pf::test::room(4.0, 3.0, 0.05, {kAdded}); }

nav_msgs::OccupancyGrid mapMsg(const pf::OccupancyGrid& grid) {
  nav_msgs::OccupancyGrid map = toMsg(grid);
  map.header.frame_id = "map";
  return map;
}

// A layer of the map toured twice in the world.
pf::MapChangeLayer learned(const pf::DistanceField& field) {
  pf::test::ScanSpec spec;
  spec.beams = 360;
  spec.angle_increment = 2.0 * M_PI / 360;
  pf::MapChangeLayer layer(field);
  for (int k = 0; k < 2; ++k) {
    for (const pf::Pose2& p : {pf::Pose2{2.0, 1.5, 0.0}, pf::Pose2{1.5, 1.0, 1.0},
                               pf::Pose2{2.5, 2.0, -2.0}, pf::Pose2{2.0, 1.0, 3.0}}) {
      layer.add(pf::test::simulateScan(worldGrid(), p, spec), p);
    }
  }
  return layer;
}

std::string readAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

class MapChangesSaverTest : public ::testing::Test {
 protected:
  MapChangesSaverTest()
      : dir_(std::filesystem::temp_directory_path() /
             ("map_changes_saver_test_" + std::to_string(::getpid()))),
        path_((dir_ / "sub" / "pf_node.map_changes").string()) {}
  ~MapChangesSaverTest() override { std::filesystem::remove_all(dir_); }

  // A localizer with the map, and what restoreMapChanges made of path_.
  MapChangesRestore restoreInto(ScanLocalizer* localizer, const std::string& signature) {
    EXPECT_EQ("", localizer->setMap(map_));
    return restoreMapChanges(path_, signature, &localizer->filter());
  }

  std::filesystem::path dir_;
  std::string path_;
  nav_msgs::OccupancyGrid map_ = mapMsg(mapGrid());
  std::string signature_ = mapSignature(map_);
  pf::DistanceField field_{mapGrid(), 2.0};
  LocalizerConfig config_;
  tf2::BufferCore tf_;
};

TEST_F(MapChangesSaverTest, WhatIsSavedOnAMapIsRestoredOnIt) {
  const pf::MapChangeLayer layer = learned(field_);
  ASSERT_GT(layer.summary().added, 0u);
  ASSERT_GT(layer.summary().removed, 0u);
  MapChangesSaver saver(path_, 0.5);
  saver.setMap(signature_);
  EXPECT_EQ("", saver.writePending());  // nothing copied yet
  EXPECT_FALSE(std::filesystem::exists(path_));
  saver.offer(&layer, ros::WallTime(100.0));
  ASSERT_EQ("", saver.writePending());  // its folder made
  ASSERT_TRUE(std::filesystem::exists(path_));

  ScanLocalizer localizer(config_, &tf_);
  const MapChangesRestore r = restoreInto(&localizer, signature_);
  EXPECT_TRUE(r.restored);
  EXPECT_EQ(MapChangesRestore::Level::kInfo, r.level);
  EXPECT_NE(std::string::npos, r.message.find(std::to_string(layer.summary().added) + " cells new"))
      << r.message;
  EXPECT_NE(std::string::npos, r.message.find(path_)) << r.message;
  const auto msg = localizer.mapChangesMsg(ros::Time(1.0));
  ASSERT_TRUE(msg);
  EXPECT_EQ(layer.occupancy(), msg->data);
  EXPECT_EQ(layer.summary().added_scans, localizer.mapChanges()->summary().added_scans);
}

TEST_F(MapChangesSaverTest, AnotherMapsOrABrokenFileLeavesTheLayerEmpty) {
  ScanLocalizer missing(config_, &tf_);
  MapChangesRestore r = restoreInto(&missing, signature_);
  EXPECT_FALSE(r.restored);
  EXPECT_EQ(MapChangesRestore::Level::kInfo, r.level);
  EXPECT_NE(std::string::npos, r.message.find("no map changes saved")) << r.message;

  const pf::MapChangeLayer layer = learned(field_);
  const std::string bytes = pf::mapChangesFile(layer, "another map");
  ASSERT_EQ("", writeFileAtomically(path_, bytes));
  ScanLocalizer other(config_, &tf_);
  r = restoreInto(&other, signature_);
  EXPECT_FALSE(r.restored);
  EXPECT_EQ(MapChangesRestore::Level::kWarn, r.level);
  EXPECT_NE(std::string::npos, r.message.find("another map; this one: " + signature_)) << r.message;
  EXPECT_EQ(0u, other.mapChanges()->summary().seen);

  ASSERT_EQ("", writeFileAtomically(path_, pf::mapChangesFile(layer, signature_).substr(0, 100)));
  ScanLocalizer cut(config_, &tf_);
  r = restoreInto(&cut, signature_);
  EXPECT_FALSE(r.restored);
  EXPECT_EQ(MapChangesRestore::Level::kWarn, r.level);
  EXPECT_NE(std::string::npos, r.message.find("refused (cut short")) << r.message;
  EXPECT_EQ(0u, cut.mapChanges()->summary().seen);
}

TEST_F(MapChangesSaverTest, CopiesOnlyWhatChangedAtMostOnceAPeriod) {
  pf::MapChangeLayer layer = learned(field_);
  MapChangesSaver saver(path_, 0.5);  // a copy every 2 s at most
  saver.setMap(signature_);
  saver.offer(&layer, ros::WallTime(100.0));
  ASSERT_EQ("", saver.writePending());
  const std::string first = readAll(path_);
  std::filesystem::remove(path_);
  saver.offer(&layer, ros::WallTime(103.0));  // nothing learned since
  EXPECT_EQ("", saver.writePending());
  EXPECT_FALSE(std::filesystem::exists(path_));

  layer.clear();
  saver.changed();
  saver.offer(&layer, ros::WallTime(104.0));
  saver.offer(&layer, ros::WallTime(105.0));  // changed already copied
  ASSERT_EQ("", saver.writePending());
  const std::string cleared_bytes = readAll(path_);
  const pf::MapChangesFileContents cleared = pf::readMapChangesFile(cleared_bytes);
  ASSERT_EQ("", cleared.error);
  pf::MapChangeLayer restored(field_);
  ASSERT_EQ("", restored.decode(cleared.state));
  EXPECT_EQ(0u, restored.summary().seen);

  // Learned again within the period: copied at the next offer after it, or
  // at once when asked (shutdown).
  layer = learned(field_);
  saver.offer(&layer, ros::WallTime(105.5));
  EXPECT_EQ("", saver.writePending());
  EXPECT_EQ(cleared_bytes, readAll(path_));
  saver.offer(&layer, ros::WallTime(105.6), true);
  ASSERT_EQ("", saver.writePending());
  EXPECT_EQ(first, readAll(path_));

  // A layer restored from the file is not copied back to it.
  saver.setMap(signature_, layer.scans());
  std::filesystem::remove(path_);
  saver.offer(&layer, ros::WallTime(300.0));
  EXPECT_EQ("", saver.writePending());
  EXPECT_FALSE(std::filesystem::exists(path_));

  MapChangesSaver off(path_ + ".off", 0.0);
  off.setMap(signature_);
  off.offer(&layer, ros::WallTime(200.0), true);
  EXPECT_EQ("", off.writePending());
  EXPECT_FALSE(std::filesystem::exists(path_ + ".off"));
}

// A building's floors: each floor's layer in its own file, a floor's last
// copy written even when the next floor's comes before the write.
TEST_F(MapChangesSaverTest, EachFloorsLayerGoesToItsOwnFile) {
  const std::string ground = floorMapChangesPath(path_, "ground");
  const std::string upper = floorMapChangesPath(path_, "upper");
  EXPECT_EQ((dir_ / "sub" / "pf_node.ground.map_changes").string(), ground);
  const pf::MapChangeLayer layer = learned(field_);
  pf::MapChangeLayer other(field_);
  other.add(pf::test::simulateScan(worldGrid(), pf::Pose2{2.0, 1.5, 0.0}, pf::test::ScanSpec{}),
            pf::Pose2{2.0, 1.5, 0.0});
  MapChangesSaver saver(path_, 0.5);
  saver.setMap(signature_, 0, ground);
  saver.offer(&layer, ros::WallTime(100.0), true);  // the ride's last copy of the floor left
  saver.setMap("upper's map", 0, upper);
  saver.offer(&other, ros::WallTime(100.1), true);
  ASSERT_EQ("", saver.writePending());
  EXPECT_FALSE(std::filesystem::exists(path_));  // the single map's file is not a floor's
  EXPECT_EQ(pf::mapChangesFile(layer, signature_), readAll(ground));
  EXPECT_EQ(pf::mapChangesFile(other, "upper's map"), readAll(upper));
  ScanLocalizer localizer(config_, &tf_);
  ASSERT_EQ("", localizer.setMap(map_));
  EXPECT_TRUE(restoreMapChanges(ground, signature_, &localizer.filter()).restored);
  EXPECT_EQ(layer.occupancy(), localizer.mapChangesMsg(ros::Time(1.0))->data);
  EXPECT_FALSE(restoreMapChanges(upper, signature_, &localizer.filter()).restored);

  // Any name makes a file name of its own, in the same folder.
  EXPECT_EQ("/r/pf_node.level%202%2F3.map_changes",
            floorMapChangesPath("/r/pf_node.map_changes", "level 2/3"));
  EXPECT_EQ("/r/layer.upper", floorMapChangesPath("/r/layer", "upper"));
  EXPECT_EQ("/r.d/.layer.upper", floorMapChangesPath("/r.d/.layer", "upper"));
}

TEST_F(MapChangesSaverTest, WritesAFileWholeOrSaysWhy) {
  ASSERT_EQ("", writeFileAtomically(path_, "one"));
  ASSERT_EQ("", writeFileAtomically(path_, "two"));
  EXPECT_EQ("two", readAll(path_));
  for (const auto& entry : std::filesystem::directory_iterator(dir_ / "sub")) {
    EXPECT_EQ("pf_node.map_changes", entry.path().filename().string());  // no temporary left
  }
  EXPECT_NE("", writeFileAtomically("/proc/pf_node.map_changes", "x"));
}

TEST(DefaultMapChangesPath, IsInRosHomeNamedForTheNode) {
  const char* ros_home = std::getenv("ROS_HOME");
  const std::string saved = ros_home ? ros_home : "";
  ::setenv("ROS_HOME", "/tmp/rh", 1);
  EXPECT_EQ("/tmp/rh/pf_node.map_changes", defaultMapChangesPath("/pf_node"));
  EXPECT_EQ("/tmp/rh/robot1_pf_node.map_changes", defaultMapChangesPath("/robot1/pf_node"));
  ::unsetenv("ROS_HOME");
  const char* home = std::getenv("HOME");
  if (home) {
    EXPECT_EQ(std::string(home) + "/.ros/pf_node.map_changes", defaultMapChangesPath(""));
  }
  if (ros_home) ::setenv("ROS_HOME", saved.c_str(), 1);
}

}  // namespace
}  // namespace pf_ros
