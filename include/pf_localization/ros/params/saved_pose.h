// The pose saved on the parameter server, as amcl saves it: pf_node writes
// its estimate (at the latest odometry) to ~initial_pose_* and its variances
// to ~initial_cov_*, where readConfig finds them, so that a node restarted
// under the same master (respawn, a crash, a relaunch) resumes where the
// robot is. With it goes ~saved_pose_map: the signature of the map the pose
// was on (size, resolution, origin, a hash of the cells), the pose itself
// and, with a building's floors (floors.h), the floor's name. At start-up a
// configured initial pose that ~saved_pose_map records is a saved one, and
// it is only used on a first map with the same signature that has the pose
// in a free cell (with floors: on the floor it names, where pf_node then
// starts); otherwise global localization (a roscore that had run another
// bag may hold a pose on another map).
// PoseSaver (pose_saver.h) saves it; this is what it saves, and what a later
// run makes of it.
#pragma once

#include <nav_msgs/OccupancyGrid.h>

#include <optional>
#include <string>

#include "pf_localization/core/map/occupancy_grid.h"
#include "pf_localization/core/util/pose2.h"

namespace pf_ros {

// kSavedPoseMapParam (localizer_config.h) names the parameter that holds the
// saved pose's map (and the pose).

/// A map's identity, as text: "W x H cells of R m, origin (x, y, yaw), cells
/// <64-bit FNV-1a hash of the cells, hex>". Equal for the same map sent again.
std::string mapSignature(const nav_msgs::OccupancyGrid& map);

/// ~saved_pose_map's value: "<map signature>; pose <x> <y> <yaw>", and
/// "; floor <name>" after it when `floor` is not empty.
std::string savedPoseMapValue(const std::string& map_signature, const pf::Pose2& pose,
                              const std::string& floor = "");

/// ~saved_pose_map read back: the map's signature, the pose when the value
/// records one, and the floor (empty when it records none: a value saved
/// without floors, or by an earlier version).
struct SavedPoseMap {
  std::string map_signature;
  std::optional<pf::Pose2> pose;
  std::string floor;
};
SavedPoseMap parseSavedPoseMap(const std::string& value);

/// Whether the configured initial pose `initial` is the one an earlier run
/// saved: ~saved_pose_map exists and records that pose (or records none).
/// A pose given at launch overwrites ~initial_pose_* but not
/// ~saved_pose_map; it differs from the recorded pose, and is used as given.
bool isSavedPose(const std::optional<SavedPoseMap>& saved, const std::optional<pf::Pose2>& initial);

/// What to do with a saved initial pose on the first map.
struct SavedPoseDecision {
  bool resume = false;  // false: ignore it, start global localization
  std::string message;  // for the log: INFO when resuming, WARN otherwise
};
/// `map_signature`, `grid`: the first map; `floor`: its floor's name (empty
/// without floors: the saved floor is not looked at). Resumes when the pose
/// was saved on a map of that signature (and on that floor, when both name
/// one) and lies in one of its free cells.
SavedPoseDecision decideSavedPose(const SavedPoseMap& saved, const pf::Pose2& pose,
                                  const std::string& map_signature, const pf::OccupancyGrid& grid,
                                  const std::string& floor = "");

}  // namespace pf_ros
