#include "pf_localization/ros/output/saved_pose.h"

#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "pf_localization/ros/input/conversions.h"

namespace pf_ros {
namespace {

// Separates the map's signature from the pose in ~saved_pose_map.
constexpr const char* kPoseTag = "; pose ";

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

std::optional<PoseToSave> poseToSave(const ScanLocalizer& localizer,
                                     const std::optional<pf::Pose2>& odom) {
  const auto estimate = localizer.estimate(ros::Time());
  if (!estimate) return std::nullopt;
  pf::Pose2 pose = toPose2(estimate->pose.pose);
  const auto map_to_odom = localizer.filter().mapToOdom();
  if (map_to_odom && odom) pose = pf::compose(*map_to_odom, *odom);
  if (!pose.isFinite()) return std::nullopt;
  const auto& cov = estimate->pose.covariance;
  return PoseToSave{pose, cov[0], cov[7], cov[35]};
}

std::string savedPoseMapValue(const std::string& map_signature, const pf::Pose2& pose) {
  char text[128];
  std::snprintf(text, sizeof text, "%.17g %.17g %.17g", pose.x, pose.y, pose.yaw);
  return map_signature + kPoseTag + text;
}

SavedPoseMap parseSavedPoseMap(const std::string& value) {
  SavedPoseMap saved;
  const std::size_t tag = value.rfind(kPoseTag);
  if (tag == std::string::npos) {
    saved.map_signature = value;
    return saved;
  }
  saved.map_signature = value.substr(0, tag);
  std::istringstream in(value.substr(tag + std::string(kPoseTag).size()));
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
                                  const std::string& map_signature, const pf::OccupancyGrid& grid) {
  SavedPoseDecision d;
  const std::string ignoring = "ignoring the initial pose " + describe(pose) +
                               " saved by an earlier run (~" + kSavedPoseMapParam + "): ";
  if (saved.map_signature != map_signature) {
    d.message = ignoring + "it was saved on another map (" + saved.map_signature +
                "; this one: " + map_signature + "). Starting global localization";
  } else if (!grid.isFreeAt(pose.x, pose.y)) {
    d.message = ignoring + whyNotFree(grid, pose) + ". Starting global localization";
  } else {
    d.resume = true;
    d.message =
        "resuming from the pose saved by an earlier run at " + describe(pose) + " on this map";
  }
  return d;
}

void PoseSaver::setMap(const std::string& map_signature) {
  std::lock_guard<std::mutex> lock(mutex_);
  map_signature_ = map_signature;
  pose_.reset();
}

void PoseSaver::set(const std::optional<PoseToSave>& pose) {
  std::lock_guard<std::mutex> lock(mutex_);
  pose_ = pose;
}

std::optional<PoseSaver::Record> PoseSaver::latest() const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!pose_) return std::nullopt;
  return Record{*pose_, map_signature_};
}

void writeSavedPose(const PoseSaver::Record& record, const ros::NodeHandle& pnh) {
  const PoseToSave& s = record.pose;
  pnh.setParam("initial_pose_x", s.pose.x);
  pnh.setParam("initial_pose_y", s.pose.y);
  pnh.setParam("initial_pose_a", s.pose.yaw);
  pnh.setParam("initial_cov_xx", s.cov_xx);
  pnh.setParam("initial_cov_yy", s.cov_yy);
  pnh.setParam("initial_cov_aa", s.cov_aa);
  pnh.setParam(kSavedPoseMapParam, savedPoseMapValue(record.map_signature, s.pose));
}

}  // namespace pf_ros
