#include "pf_localization/ros/output/estimate_publisher.h"

#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/PoseArray.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>

#include <algorithm>

#include "pf_localization/ros/diagnostics/diagnostic_status.h"
#include "pf_localization/ros/input/conversions.h"

namespace pf_ros {

bool cloudDue(const ros::Time& last, const ros::Time& stamp, double rate, bool always) {
  const double period = rate > 0.0 ? 1.0 / rate : 0.0;
  return always || last.isZero() || stamp < last || (stamp - last).toSec() >= period;
}

EstimatePublisher::EstimatePublisher(ros::NodeHandle& nh)
    : pose_pub_(nh, "pf_pose", 2),
      // amcl's name for the same message, so that its users' tools keep working.
      amcl_pose_pub_(nh, "amcl_pose", 2),
      hypotheses_pub_(nh, "pf_hypotheses", 2),
      status_pub_(nh, "pf_status", 5),
      changes_pub_(nh, "pf_map_changes", 1) {
  cloud_pub_ = nh.advertise<geometry_msgs::PoseArray>("particlecloud", 2, true);
  diagnostics_pub_ = nh.advertise<diagnostic_msgs::DiagnosticArray>("/diagnostics", 5);
}

void EstimatePublisher::publishEstimate(const ScanLocalizer& localizer, const ros::Time& stamp,
                                        bool always) {
  if (const auto pose = localizer.estimate(stamp)) {
    pose_pub_.publish(*pose);
    amcl_pose_pub_.publish(*pose);
  }
  const LocalizerConfig& config = localizer.config();
  if (!cloudDue(last_cloud_stamp_, stamp, config.gui_publish_rate, always)) return;
  // Built only for a subscriber: 500 000 particles take a while.
  if (cloud_pub_.getNumSubscribers() == 0) return;
  cloud_pub_.publish(
      localizer.particleCloud(stamp, static_cast<std::size_t>(config.cloud_max_poses)));
  last_cloud_stamp_ = stamp;
}

void EstimatePublisher::publishConfidence(const ScanLocalizer& localizer, const ros::Time& stamp,
                                          const pf::UpdateReport& report, int config_generation,
                                          const UpdateTiming& timing, std::uint64_t dropped,
                                          std::size_t cap) {
  const pf::Hypotheses hypotheses = localizer.filter().hypotheses();
  pf_localization::PoseHypotheses hypotheses_msg;
  hypotheses_msg.header.stamp = stamp;
  hypotheses_msg.header.frame_id = localizer.config().global_frame;
  toHypothesesMsg(hypotheses, &hypotheses_msg);
  hypotheses_pub_.publish(std::move(hypotheses_msg));

  const std::string name = ros::this_node::getName() + ": localization";
  diagnostic_msgs::DiagnosticArray array;
  array.header.stamp = stamp;
  array.status.push_back(toDiagnosticStatus(localizer.filter(), report, name, config_generation));
  timing.addTo(&array.status.front(), dropped, cap);
  addHypotheses(&array.status.front(), hypotheses);
  addSensors(&array.status.front(), localizer.sensorHealth(), stamp.toSec());
  addMapChanges(&array.status.front(), localizer.mapChanges());
  if (!floor_.empty()) {
    diagnostic_msgs::KeyValue floor;
    floor.key = "floor";
    floor.value = floor_;
    array.status.front().values.insert(array.status.front().values.begin(), floor);
    array.status.front().message += " on floor " + floor_;
  }
  if (searching_) {
    diagnostic_msgs::DiagnosticStatus& s = array.status.front();
    s.level = std::max<std::uint8_t>(s.level, diagnostic_msgs::DiagnosticStatus::WARN);
    s.message = "searching every floor: " + s.message;
  }
  diagnostics_pub_.publish(array);
  status_pub_.publish(array.status.front());
  publishMapChanges(localizer, stamp);
  if (const auto line = state_log_.onConfidence(localizer.filter().confidence())) {
    if (line->warning) {
      ROS_WARN("pf_node: %s", line->text.c_str());
    } else {
      ROS_INFO("pf_node: %s", line->text.c_str());
    }
  }
}

void EstimatePublisher::publishMapChanges(const ScanLocalizer& localizer, const ros::Time& stamp) {
  const pf::MapChangeLayer* layer = localizer.mapChanges();
  if (layer == nullptr || layer->scans() == changes_scans_) return;
  // Time going back (a bag started over) makes it due.
  if (!last_changes_stamp_.isZero() && stamp >= last_changes_stamp_ &&
      (stamp - last_changes_stamp_).toSec() < kMapChangesPeriod) {
    return;
  }
  publishMapChangesNow(localizer, stamp);
}

void EstimatePublisher::publishMapChangesNow(const ScanLocalizer& localizer,
                                             const ros::Time& stamp) {
  const pf::MapChangeLayer* layer = localizer.mapChanges();
  if (layer == nullptr) return;
  // A message of a cell per map cell: filled into the last one's storage.
  nav_msgs::OccupancyGrid msg = changes_pub_.spare();
  if (localizer.mapChangesMsg(stamp, &msg)) changes_pub_.publish(std::move(msg));
  last_changes_stamp_ = stamp;
  changes_scans_ = layer->scans();
}

}  // namespace pf_ros
