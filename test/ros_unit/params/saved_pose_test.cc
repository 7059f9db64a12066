// The pose saved on the parameter server and its map: the map's
// signature, ~saved_pose_map's value, whether a configured pose is a saved
// one, and what the first map decides about it.
#include "pf_localization/ros/params/saved_pose.h"

#include <gtest/gtest.h>

#include <cmath>

#include "pf_localization/ros/input/conversions.h"
#include "ros_unit/test_messages.h"

namespace pf_ros {
namespace {

using test::room;

TEST(MapSignature, TheSameMapSentAgainHasTheSameOne) {
  EXPECT_EQ(mapSignature(room()), mapSignature(room()));
  EXPECT_NE(std::string::npos, mapSignature(room()).find("80 x 60 cells of 0.05"));
}

TEST(MapSignature, AnotherMapHasAnotherOne) {
  const std::string base = mapSignature(room());
  nav_msgs::OccupancyGrid cell = room();
  cell.data[30 * 80 + 40] = 100;  // one cell
  EXPECT_NE(base, mapSignature(cell));
  nav_msgs::OccupancyGrid moved = room();
  moved.info.origin.position.x = -1.0;
  EXPECT_NE(base, mapSignature(moved));
  nav_msgs::OccupancyGrid finer = room();
  finer.info.resolution = 0.025f;
  EXPECT_NE(base, mapSignature(finer));
}

TEST(SavedPoseMap, ReadsBackWhatWasSaved) {
  const pf::Pose2 pose{3.5641234567, -0.451, 0.003};
  const SavedPoseMap saved = parseSavedPoseMap(savedPoseMapValue(mapSignature(room()), pose));
  EXPECT_EQ(mapSignature(room()), saved.map_signature);
  ASSERT_TRUE(saved.pose);
  EXPECT_DOUBLE_EQ(pose.x, saved.pose->x);
  EXPECT_DOUBLE_EQ(pose.y, saved.pose->y);
  EXPECT_DOUBLE_EQ(pose.yaw, saved.pose->yaw);
  // A value without a pose (written by hand, say): the signature only.
  const SavedPoseMap bare = parseSavedPoseMap("some map");
  EXPECT_EQ("some map", bare.map_signature);
  EXPECT_FALSE(bare.pose);
}

TEST(SavedPoseMap, ReadsBackTheFloor) {
  const pf::Pose2 pose{12.25, 7.5, -1.25};
  const std::string value = savedPoseMapValue(mapSignature(room()), pose, "upper");
  EXPECT_NE(std::string::npos, value.find("; floor upper")) << value;
  const SavedPoseMap saved = parseSavedPoseMap(value);
  EXPECT_EQ(mapSignature(room()), saved.map_signature);
  EXPECT_EQ("upper", saved.floor);
  ASSERT_TRUE(saved.pose);
  EXPECT_DOUBLE_EQ(pose.x, saved.pose->x);
  EXPECT_DOUBLE_EQ(pose.yaw, saved.pose->yaw);
  // A floor's name is the rest of the value, whatever it holds.
  EXPECT_EQ("2; pose 1 2 3",
            parseSavedPoseMap(savedPoseMapValue("m", pose, "2; pose 1 2 3")).floor);
  EXPECT_TRUE(isSavedPose(saved, pose));
  // Without floors, or saved by a version that had none: no floor, as before.
  const std::string plain = savedPoseMapValue(mapSignature(room()), pose);
  EXPECT_EQ(std::string::npos, plain.find("floor")) << plain;
  EXPECT_EQ("", parseSavedPoseMap(plain).floor);
  EXPECT_TRUE(parseSavedPoseMap(plain).pose);
}

TEST(IsSavedPose, OnlyThePoseTheEarlierRunSaved) {
  const pf::Pose2 saved_pose{1.5, 1.0, 0.3};
  const SavedPoseMap saved = parseSavedPoseMap(savedPoseMapValue("m", saved_pose));
  EXPECT_TRUE(isSavedPose(saved, saved_pose));
  // Read back through XML-RPC's decimal text: within rounding.
  EXPECT_TRUE(isSavedPose(saved, pf::Pose2{1.5 + 1e-12, 1.0, 0.3}));
  // A pose given at launch overwrote ~initial_pose_*: used as given.
  EXPECT_FALSE(isSavedPose(saved, pf::Pose2{2.0, 1.0, 0.3}));
  EXPECT_FALSE(isSavedPose(saved, std::nullopt));
  EXPECT_FALSE(isSavedPose(std::nullopt, saved_pose));
  EXPECT_TRUE(isSavedPose(parseSavedPoseMap("m"), saved_pose));  // nothing to compare with
}

SavedPoseDecision decide(const nav_msgs::OccupancyGrid& saved_on, const pf::Pose2& pose,
                         const nav_msgs::OccupancyGrid& first_map) {
  const SavedPoseMap saved = parseSavedPoseMap(savedPoseMapValue(mapSignature(saved_on), pose));
  return decideSavedPose(saved, pose, mapSignature(first_map), toCore(first_map));
}

TEST(DecideSavedPose, TheSameMapResumes) {
  const SavedPoseDecision d = decide(room(), pf::Pose2{1.5, 1.0, 0.3}, room());
  EXPECT_TRUE(d.resume);
  EXPECT_NE(std::string::npos, d.message.find("resuming from the pose saved by an earlier run"))
      << d.message;
  EXPECT_NE(std::string::npos, d.message.find("(1.500, 1.000, 0.300)")) << d.message;
}

TEST(DecideSavedPose, AnotherMapStartsGlobalLocalization) {
  nav_msgs::OccupancyGrid other = room();
  other.data[30 * 80 + 40] = 100;
  const SavedPoseDecision d = decide(room(), pf::Pose2{1.5, 1.0, 0.3}, other);
  EXPECT_FALSE(d.resume);
  EXPECT_NE(std::string::npos, d.message.find("saved on another map")) << d.message;
  EXPECT_NE(std::string::npos, d.message.find("global localization")) << d.message;
}

TEST(DecideSavedPose, OnlyOnTheFloorItWasSavedOn) {
  const pf::Pose2 pose{1.5, 1.0, 0.3};
  const SavedPoseMap saved =
      parseSavedPoseMap(savedPoseMapValue(mapSignature(room()), pose, "upper"));
  const pf::OccupancyGrid grid = toCore(room());
  const SavedPoseDecision there = decideSavedPose(saved, pose, mapSignature(room()), grid, "upper");
  EXPECT_TRUE(there.resume) << there.message;
  EXPECT_NE(std::string::npos, there.message.find("on floor 'upper'")) << there.message;
  // Another floor, even of the same map: the floors file has no floor 'upper'.
  const SavedPoseDecision other =
      decideSavedPose(saved, pose, mapSignature(room()), grid, "ground");
  EXPECT_FALSE(other.resume);
  EXPECT_NE(std::string::npos, other.message.find("saved on floor 'upper'")) << other.message;
  EXPECT_NE(std::string::npos, other.message.find("Starting on floor 'ground' with global"))
      << other.message;
  // Without floors the floor is not looked at.
  EXPECT_TRUE(decideSavedPose(saved, pose, mapSignature(room()), grid).resume);
  // A pose saved without a floor is used on any floor of its map.
  const SavedPoseMap plain = parseSavedPoseMap(savedPoseMapValue(mapSignature(room()), pose));
  EXPECT_TRUE(decideSavedPose(plain, pose, mapSignature(room()), grid, "ground").resume);
}

TEST(DecideSavedPose, APoseOutsideTheFreeSpaceStartsGlobalLocalization) {
  const SavedPoseDecision wall = decide(room(), pf::Pose2{0.01, 1.0, 0.0}, room());
  EXPECT_FALSE(wall.resume);
  EXPECT_NE(std::string::npos, wall.message.find("occupied")) << wall.message;
  const SavedPoseDecision unknown = decide(room(), pf::Pose2{3.2, 2.2, 0.0}, room());
  EXPECT_FALSE(unknown.resume);
  EXPECT_NE(std::string::npos, unknown.message.find("unknown")) << unknown.message;
  const SavedPoseDecision outside = decide(room(), pf::Pose2{7.0, 1.0, 0.0}, room());
  EXPECT_FALSE(outside.resume);
  EXPECT_NE(std::string::npos, outside.message.find("outside")) << outside.message;
}

}  // namespace
}  // namespace pf_ros
