// The pose saved on the parameter server, as amcl saves it (saved_pose.h:
// what is saved, and how a later run uses it). PoseSaver holds the latest
// pose to save and the map it is on, and saves it every 1 / save_pose_rate s
// of the clock (amcl's timer) and once more at shutdown.
//
// Threads: the filter's side sets the pose after every change, under a small
// mutex of the saver's own, so that a save (on pf_node's main spinner) never
// waits for an update: one that waited would hold back the scans and
// odometry queued behind it. The schedule is the main spinner's alone.
#pragma once

#include <ros/node_handle.h>
#include <ros/time.h>

#include <functional>
#include <mutex>
#include <optional>
#include <string>

#include "pf_localization/core/util/pose2.h"
#include "pf_localization/ros/localizer/scan_localizer.h"
#include "pf_localization/ros/output/republish_schedule.h"

namespace pf_ros {

/// One pose to save: the estimate and its variances.
struct PoseToSave {
  pf::Pose2 pose;
  double cov_xx = 0.0, cov_yy = 0.0, cov_aa = 0.0;
};

/// What to save after the filter changed: the estimate, carried by the
/// odometry of the latest scan (`odom`, odom -> base; used or not: the
/// estimate is as old as the last update) to the robot's pose then, with the
/// estimate's variances. Nothing without an estimate, or when not finite.
std::optional<PoseToSave> poseToSave(const ScanLocalizer& localizer,
                                     const std::optional<pf::Pose2>& odom);

class PoseSaver {
 public:
  struct Record {
    PoseToSave pose;
    std::string map_signature;
    std::string floor;  // with a building's floors (floors.h); empty otherwise
  };
  /// How a record is saved (writeSavedPose() on the node's ~, in pf_node).
  using Write = std::function<void(const Record&)>;

  /// `rate`: Hz of the periodic save (save_pose_rate; <= 0: never saved).
  explicit PoseSaver(double rate = 0.0, Write write = {});

  /// Whether anything is ever saved (rate > 0).
  bool enabled() const { return rate_ > 0.0; }

  /// A new map, on floor `floor` with a building's floors: nothing to save
  /// until the pose on it is set().
  void setMap(const std::string& map_signature, const std::string& floor = "");
  /// The pose to save from now on (nothing: none).
  void set(const std::optional<PoseToSave>& pose);
  /// What to save: nothing before a map and a pose on it.
  std::optional<Record> latest() const;

  /// The latest record written when a period of the clock (`now`) has passed
  /// since the last look that wrote, give or take the caller's wait; the
  /// first look only starts the schedule, as a timer's first period. Time
  /// going back makes it due. Main spinner only.
  void saveWhenDue(const ros::Time& now);
  /// The latest record written now, when saving is on (a shutdown: the
  /// periodic save may be up to a period old).
  void saveNow();

 private:
  const double rate_;
  const Write write_;
  RepublishSchedule schedule_;  // the main spinner's
  mutable std::mutex mutex_;    // guards what follows
  std::string map_signature_;
  std::string floor_;
  std::optional<PoseToSave> pose_;
};

/// Writes `record` to `pnh`'s ~initial_pose_*, ~initial_cov_* and
/// ~saved_pose_map (the last last: see isSavedPose()). Needs the master.
void writeSavedPose(const PoseSaver::Record& record, const ros::NodeHandle& pnh);

}  // namespace pf_ros
