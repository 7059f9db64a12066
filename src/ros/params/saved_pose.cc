#include "pf_localization/ros/params/saved_pose.h"

#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <vector>

#include "pf_localization/ros/input/conversions.h"
#include "pf_localization/ros/params/localizer_config.h"

namespace pf_ros {
namespace {

// Separate the map's signature from the pose, and the pose from the floor,
// in ~saved_pose_map.
constexpr const char* kPoseTag = "; pose ";
constexpr const char* kFloorTag = "; floor ";

// m or rad: a pose read back from the parameter server (XML-RPC's decimal
// doubles) is the saved one within rounding; one typed in is not this close.
constexpr double kSamePose = 1e-6;

std::uint64_t fnv1a(const std::vector<int8_t>& data) {
  std::uint64_t h = 14695981039346656037ull;
  for (const int8_t v : data) {
    h ^= static_cast<std::uint8_t>(v);
    h *= 1099511628211ull;
  }
  return h;
}

std::string describe(const pf::Pose2& p) {
  char text[96];
  std::snprintf(text, sizeof text, "(%.3f, %.3f, %.3f)", p.x, p.y, p.yaw);
  return text;
}

std::string whyNotFree(const pf::OccupancyGrid& grid, const pf::Pose2& pose) {
  const pf::CellIndex cell = grid.worldToCell(pose.x, pose.y);
  if (!grid.contains(cell)) return "it lies outside this map";
  if (grid.state(cell) == pf::CellState::kOccupied)
    return "it lies in an occupied cell of this map";
  return "it lies in an unknown cell of this map";
}

}  // namespace

std::string mapSignature(const nav_msgs::OccupancyGrid& map) {
  const auto& o = map.info.origin;
  char text[256];
  std::snprintf(text, sizeof text,
                "%u x %u cells of %.7g m, origin (%.9g, %.9g, %.9g), cells %016" PRIx64,
                map.info.width, map.info.height, static_cast<double>(map.info.resolution),
                o.position.x, o.position.y, yawOf(o.orientation), fnv1a(map.data));
  return text;
}

std::string savedPoseMapValue(const std::string& map_signature, const pf::Pose2& pose,
                              const std::string& floor) {
  char text[128];
  std::snprintf(text, sizeof text, "%.17g %.17g %.17g", pose.x, pose.y, pose.yaw);
  return map_signature + kPoseTag + text + (floor.empty() ? "" : kFloorTag + floor);
}

SavedPoseMap parseSavedPoseMap(const std::string& value) {
  SavedPoseMap saved;
  // The signature never holds the tags; a floor's name may.
  const std::size_t tag = value.find(kPoseTag);
  if (tag == std::string::npos) {
    saved.map_signature = value;
    return saved;
  }
  saved.map_signature = value.substr(0, tag);
  std::string pose_text = value.substr(tag + std::string(kPoseTag).size());
  const std::size_t floor_tag = pose_text.find(kFloorTag);
  if (floor_tag != std::string::npos) {
    saved.floor = pose_text.substr(floor_tag + std::string(kFloorTag).size());
    pose_text.erase(floor_tag);
  }
  std::istringstream in(pose_text);
  pf::Pose2 pose;
  if (in >> pose.x >> pose.y >> pose.yaw && pose.isFinite()) saved.pose = pose;
  return saved;
}

bool isSavedPose(const std::optional<SavedPoseMap>& saved,
                 const std::optional<pf::Pose2>& initial) {
  if (!saved || !initial) return false;
  if (!saved->pose) return true;
  const pf::Pose2& p = *saved->pose;
  return std::abs(p.x - initial->x) < kSamePose && std::abs(p.y - initial->y) < kSamePose &&
         std::abs(p.yaw - initial->yaw) < kSamePose;
}

SavedPoseDecision decideSavedPose(const SavedPoseMap& saved, const pf::Pose2& pose,
                                  const std::string& map_signature, const pf::OccupancyGrid& grid,
                                  const std::string& floor) {
  SavedPoseDecision d;
  const std::string ignoring = "ignoring the initial pose " + describe(pose) +
                               " saved by an earlier run (~" + kSavedPoseMapParam + "): ";
  if (!floor.empty() && !saved.floor.empty() && saved.floor != floor) {
    d.message = ignoring + "it was saved on floor '" + saved.floor +
                "', which the floors file does not have. Starting on floor '" + floor +
                "' with global localization";
  } else if (saved.map_signature != map_signature) {
    d.message = ignoring + "it was saved on another map (" + saved.map_signature +
                "; this one: " + map_signature + "). Starting global localization";
  } else if (!grid.isFreeAt(pose.x, pose.y)) {
    d.message = ignoring + whyNotFree(grid, pose) + ". Starting global localization";
  } else {
    d.resume = true;
    d.message = "resuming from the pose saved by an earlier run at " + describe(pose) +
                (floor.empty() ? " on this map" : " on floor '" + floor + "'");
  }
  return d;
}

}  // namespace pf_ros
