#include "pf_localization/ros/input/odometry_source.h"

#include <utility>

#include "pf_localization/ros/input/conversions.h"
#include "pf_localization/ros/localizer/scan_localizer.h"

namespace pf_ros {

OdometrySource::OdometrySource(std::string odom_frame, std::string base_frame, std::string topic,
                               double grace)
    : odom_frame_(std::move(odom_frame)),
      base_frame_(std::move(base_frame)),
      topic_(std::move(topic)),
      grace_(grace) {}

bool OdometrySource::onTf(const tf2_msgs::TFMessage& msg) {
  if (kind_ == Kind::kTf) return false;
  for (const auto& t : msg.transforms) {
    if (t.header.frame_id == odom_frame_ && t.child_frame_id == base_frame_) {
      kind_ = Kind::kTf;
      return true;
    }
  }
  return false;
}

OdometrySource::TopicMessage OdometrySource::onTopic(const nav_msgs::Odometry& msg) {
  TopicMessage out;
  if (msg.header.frame_id.empty() || msg.child_frame_id.empty()) {
    out.problem_key = "odom frames";
    out.problem = "odometry message with an empty frame_id or child_frame_id: ignored";
    return out;
  }
  if (kind_ == Kind::kTf) return out;
  // Give /tf a moment to show its odometry before taking the topic's.
  if (first_stamp_.isZero()) first_stamp_ = msg.header.stamp;
  if ((msg.header.stamp - first_stamp_).toSec() < grace_) return out;
  geometry_msgs::TransformStamped t = odometryToTransform(msg);
  if (!toPose2(t.transform).isFinite()) {
    out.problem_key = "odom nan";
    out.problem = "odometry message with a non-finite pose: ignored";
    return out;
  }
  kind_ = Kind::kTopic;
  out.transform = std::move(t);
  return out;
}

std::optional<std::string> OdometrySource::takeAnnouncement() {
  if (kind_ == announced_) return std::nullopt;
  const Kind before = announced_;
  announced_ = kind_;
  const std::string link = odom_frame_ + " -> " + base_frame_;
  if (kind_ == Kind::kTopic) {
    return "odometry: from the odom topic " + topic_ + " (tf has no " + link + ")";
  }
  if (before == Kind::kTopic) {
    return "odometry: from tf " + link + " (it appeared on tf; the odom topic " + topic_ +
           " is no longer used)";
  }
  return "odometry: from tf " + link;
}

}  // namespace pf_ros
