// pf_node's output topics: the estimate on pf_pose and, for amcl's users,
// amcl_pose; the particles on particlecloud; the places the cloud holds
// with real weight on pf_hypotheses; how far to trust the estimate
// on /diagnostics (for robot monitors) and pf_status (for anything that only
// wants this node's verdict); and a log line for each change of the
// localization state (localized / uncertain / lost), which is news where the
// same state on every scan is not (StateChangeLog). Not thread-safe: pf_node
// calls it with the filter's lock held, since it reads the filter.
#pragma once

#include <diagnostic_msgs/DiagnosticStatus.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <nav_msgs/OccupancyGrid.h>
#include <pf_localization/PoseHypotheses.h>
#include <ros/ros.h>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "pf_localization/core/estimate/confidence.h"
#include "pf_localization/ros/diagnostics/state_change_log.h"
#include "pf_localization/ros/diagnostics/update_timing.h"
#include "pf_localization/ros/localizer/scan_localizer.h"
#include "pf_localization/ros/output/latched_topic.h"

namespace pf_ros {

/// Whether the particle cloud is due at `stamp`, the last one sent at `last`
/// (zero: none yet), at most `rate` times a second (<= 0: every time).
/// `always`: a re-initialisation, shown whatever the rate. Time going back
/// makes it due.
bool cloudDue(const ros::Time& last, const ros::Time& stamp, double rate, bool always);

class EstimatePublisher {
 public:
  /// Advertises the topics on `nh`.
  explicit EstimatePublisher(ros::NodeHandle& nh);

  /// The estimate, and the cloud when cloudDue() (gui_publish_rate) and
  /// something subscribes to it, as at most `cloud_max_poses` poses.
  void publishEstimate(const ScanLocalizer& localizer, const ros::Time& stamp, bool always);

  /// s: pf_map_changes, the layer of where the world no longer matches the
  /// map, is published at most this often (stamps' time), when it learned
  /// something: a building's map of 1 000 x 1 000 cells is a megabyte.
  static constexpr double kMapChangesPeriod = 2.0;

  /// pf_hypotheses, /diagnostics and pf_status after an update, and
  /// pf_map_changes when due (kMapChangesPeriod), with
  /// `timing`'s figures, `dropped` scans and the particle `cap`; logs a
  /// change of state.
  void publishConfidence(const ScanLocalizer& localizer, const ros::Time& stamp,
                         const pf::UpdateReport& report, int config_generation,
                         const UpdateTiming& timing, std::uint64_t dropped, std::size_t cap);
  /// pf_map_changes now, whatever learned or due (restored, or cleared).
  void publishMapChangesNow(const ScanLocalizer& localizer, const ros::Time& stamp);

  /// The floor of a building the robot is on (floors.h): pf_status and
  /// /diagnostics name it (a "floor" value, and "on floor NAME" after the
  /// message); empty, as without a floors file: nothing is added.
  /// `searching`: no floor is known while every floor is searched; the
  /// status is then at least a warning, its message led by "searching every
  /// floor: ", since the filter's verdict is about a floor that may not be
  /// the robot's.
  void setFloor(const std::string& floor, bool searching = false) {
    floor_ = floor;
    searching_ = searching;
  }

 private:
  // pf_map_changes when due and the layer learned something since.
  void publishMapChanges(const ScanLocalizer& localizer, const ros::Time& stamp);

  // Latched, published only while subscribed (latched_topic.h).
  LatchedTopic<geometry_msgs::PoseWithCovarianceStamped> pose_pub_, amcl_pose_pub_;
  LatchedTopic<pf_localization::PoseHypotheses> hypotheses_pub_;
  LatchedTopic<diagnostic_msgs::DiagnosticStatus> status_pub_;
  LatchedTopic<nav_msgs::OccupancyGrid> changes_pub_;
  ros::Time last_changes_stamp_;
  std::size_t changes_scans_ = 0;  // the layer's scans when it was last published
  ros::Publisher cloud_pub_, diagnostics_pub_;
  ros::Time last_cloud_stamp_;
  StateChangeLog state_log_;
  std::string floor_;
  bool searching_ = false;
};

}  // namespace pf_ros
