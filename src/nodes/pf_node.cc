// pf_node: the live ROS front door of the particle filter.
//
// Subscribes scan, odom, map (latched) and initialpose; publishes map -> odom
// on tf, the particles on particlecloud and the estimate on pf_pose. All the
// localization itself happens in pf_ros::ScanLocalizer and the core; this file
// only moves messages, waits for tf and tells the user what is wrong.
#include <geometry_msgs/PoseArray.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <message_filters/subscriber.h>
#include <nav_msgs/OccupancyGrid.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/LaserScan.h>
#include <std_srvs/Empty.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/message_filter.h>
#include <tf2_ros/transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include <map>
#include <memory>
#include <string>

#include "pf_localization/ros/conversions.h"
#include "pf_localization/ros/localizer_config.h"
#include "pf_localization/ros/scan_localizer.h"

namespace pf_ros {
namespace {

// Bad input tends to repeat on every message; one line per kind and period
// tells the user without drowning the log. Wall time, so the limit also holds
// while a bag is paused or replayed fast.
class LimitedLog {
 public:
  explicit LimitedLog(double period) : period_(period) {}
  bool due(const std::string& key) {
    const ros::WallTime now = ros::WallTime::now();
    auto it = last_.find(key);
    if (it != last_.end() && (now - it->second).toSec() < period_) return false;
    last_[key] = now;
    return true;
  }

 private:
  double period_;
  std::map<std::string, ros::WallTime> last_;
};

std::string failureText(tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
  switch (reason) {
    case tf2_ros::filter_failure_reasons::OutTheBack:
      return "its stamp is older than the tf buffer";
    case tf2_ros::filter_failure_reasons::EmptyFrameID:
      return "its frame_id is empty";
    default:
      return "no transform arrived for its stamp before the queue filled up";
  }
}

// s of odometry messages to wait for odom -> base on /tf before the odometry
// topic is taken as the source instead.
constexpr double kOdomSourceGrace = 0.5;

// s a scan may be older than the previous one before time counts as jumping back.
constexpr double kTimeJumpTolerance = 1.0;

class PfNode {
 public:
  PfNode(const LocalizerConfig& config, ros::NodeHandle nh)
      : config_(config),
        nh_(nh),
        buffer_(ros::Duration(30.0)),
        listener_(buffer_),
        localizer_(config, &buffer_),
        scan_sub_(nh_, "scan", 20),
        scan_filter_(scan_sub_, buffer_, config.odom_frame, 20, nh_) {
    scan_filter_.registerCallback(&PfNode::onScan, this);
    scan_filter_.registerFailureCallback(
        [this](const sensor_msgs::LaserScanConstPtr& scan,
               tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
          onScanDropped(scan, reason);
        });
    odom_sub_ = nh_.subscribe("odom", 50, &PfNode::onOdom, this);
    tf_watch_sub_ = nh_.subscribe("/tf", 100, &PfNode::onTf, this);
    map_sub_ = nh_.subscribe("map", 1, &PfNode::onMap, this);
    initial_pose_sub_ = nh_.subscribe("initialpose", 2, &PfNode::onInitialPose, this);
    pose_pub_ = nh_.advertise<geometry_msgs::PoseWithCovarianceStamped>("pf_pose", 2, true);
    cloud_pub_ = nh_.advertise<geometry_msgs::PoseArray>("particlecloud", 2, true);
    global_srv_ = nh_.advertiseService("global_localization", &PfNode::onGlobalLocalization, this);
    nomotion_srv_ =
        nh_.advertiseService("request_nomotion_update", &PfNode::onNoMotionUpdate, this);
    tf_timer_ =
        nh_.createTimer(ros::Duration(1.0 / config.tf_publish_rate), &PfNode::onTfTimer, this);
    if (config.initial_pose) {
      ROS_INFO("pf_node: initial pose (%.3f, %.3f, %.3f) in %s; waiting for a map",
               config.initial_pose->x, config.initial_pose->y, config.initial_pose->yaw,
               config.global_frame.c_str());
    } else {
      ROS_INFO("pf_node: no initial pose given: global localization once a map arrives");
    }
  }

 private:
  void onMap(const nav_msgs::OccupancyGridConstPtr& msg) {
    const std::string error = localizer_.setMap(*msg);
    if (!error.empty()) {
      ROS_ERROR("pf_node: %s", error.c_str());
      return;
    }
    ROS_INFO("pf_node: map %u x %u cells at %.3f m; %zu particles", msg->info.width,
             msg->info.height, msg->info.resolution, localizer_.filter().particles().size());
    publishEstimate(msg->header.stamp);
  }

  void onOdom(const nav_msgs::OdometryConstPtr& msg) {
    // Robots that publish odometry only as a topic get it into the tf buffer
    // here. When tf carries it too (the usual case) the topic is ignored:
    // tf2 would otherwise see every odometry stamp twice.
    if (msg->header.frame_id.empty() || msg->child_frame_id.empty()) {
      warn("odom frames", "odometry message with an empty frame_id or child_frame_id: ignored");
      return;
    }
    if (odom_on_tf_) return;
    // Give /tf a moment to show its odometry before taking the topic's.
    if (first_odom_stamp_.isZero()) first_odom_stamp_ = msg->header.stamp;
    if ((msg->header.stamp - first_odom_stamp_).toSec() < kOdomSourceGrace) return;
    const geometry_msgs::TransformStamped t = odometryToTransform(*msg);
    if (!toPose2(t.transform).isFinite()) {
      warn("odom nan", "odometry message with a non-finite pose: ignored");
      return;
    }
    buffer_.setTransform(t, "odom_topic");
  }

  // Watches /tf only until it shows whether odometry travels there.
  void onTf(const tf2_msgs::TFMessageConstPtr& msg) {
    for (const auto& t : msg->transforms) {
      if (t.header.frame_id == config_.odom_frame && t.child_frame_id == config_.base_frame) {
        odom_on_tf_ = true;
        tf_watch_sub_.shutdown();
        ROS_INFO("pf_node: odometry %s -> %s comes from tf", config_.odom_frame.c_str(),
                 config_.base_frame.c_str());
        return;
      }
    }
  }

  void onScan(const sensor_msgs::LaserScanConstPtr& scan) {
    if (timeJumpedBack(scan->header.stamp)) return;
    const ScanResult result = localizer_.processScan(*scan);
    if (!result.error.empty()) {
      warn(result.error.substr(0, 24), result.error);
      return;
    }
    const pf::UpdateReport& r = result.report;
    if (r.updated) {
      publishEstimate(scan->header.stamp);
      ROS_DEBUG("pf_node: update with %d beams, %zu particles, ESS %.0f%s", r.beams_used,
                r.particles, r.ess, r.resampled ? ", resampled" : "");
    } else if (r.skip_reason.rfind("not moved", 0) != 0) {
      warn(r.skip_reason.substr(0, 16), "scan not used: " + r.skip_reason);
    }
    last_scan_stamp_ = scan->header.stamp;
    publishMapToOdom(scan->header.stamp + ros::Duration(config_.transform_tolerance));
  }

  // A scan older than the previous one by more than a second means time
  // went back (a bag restarted, with --loop or by hand): tf data and the
  // filter's odometry reference belong to the old timeline, so both start
  // over, as tf itself does on such a jump.
  bool timeJumpedBack(const ros::Time& stamp) {
    if (last_scan_stamp_.isZero() ||
        stamp + ros::Duration(kTimeJumpTolerance) >= last_scan_stamp_) {
      return false;
    }
    ROS_WARN(
        "pf_node: time jumped back by %.1f s (a bag restarted?): clearing tf and restarting "
        "the filter %s",
        (last_scan_stamp_ - stamp).toSec(),
        config_.initial_pose ? "from the initial pose" : "with global localization");
    buffer_.clear();
    const std::string error = localizer_.restart();
    if (!error.empty()) ROS_WARN("pf_node: %s", error.c_str());
    last_scan_stamp_ = ros::Time();
    last_tf_stamp_ = ros::Time();
    return true;
  }

  void onScanDropped(const sensor_msgs::LaserScanConstPtr& scan,
                     tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
    warn("scan dropped " + scan->header.frame_id,
         "scan dropped: " + failureText(reason) + ". It needs tf from '" + scan->header.frame_id +
             "' to '" + config_.base_frame + "' (the laser's mounting) and '" + config_.base_frame +
             "' to '" + config_.odom_frame + "' (odometry) at t=" +
             std::to_string(scan->header.stamp.toSec()) + "; check that both are published");
  }

  void onInitialPose(const geometry_msgs::PoseWithCovarianceStampedConstPtr& msg) {
    geometry_msgs::PoseWithCovarianceStamped pose = *msg;
    if (pose.header.frame_id.empty()) {
      warn("initialpose frame",
           "initial pose with an empty frame_id: taken to be in " + config_.global_frame);
    } else if (pose.header.frame_id != config_.global_frame) {
      if (!transformToGlobal(&pose)) return;
    }
    const std::string error = localizer_.setInitialPose(pose);
    if (!error.empty()) {
      warn("initialpose", error);
      return;
    }
    const pf::Pose2 p = toPose2(pose.pose.pose);
    ROS_INFO("pf_node: re-initialised at (%.3f, %.3f, %.3f) in %s", p.x, p.y, p.yaw,
             config_.global_frame.c_str());
    publishEstimate(msg->header.stamp);
  }

  // An initial pose given in another frame (say odom, or base_link) is moved
  // into the global frame through tf, covariance rotated with it.
  bool transformToGlobal(geometry_msgs::PoseWithCovarianceStamped* pose) {
    geometry_msgs::TransformStamped t;
    try {
      t = buffer_.lookupTransform(config_.global_frame, pose->header.frame_id, ros::Time(0),
                                  ros::Duration(0.5));
    } catch (const tf2::TransformException& e) {
      warn("initialpose tf", "ignoring the initial pose: cannot transform it from frame '" +
                                 pose->header.frame_id + "' to '" + config_.global_frame +
                                 "': " + e.what());
      return false;
    }
    const pf::Pose2 frame = toPose2(t.transform);
    pose->pose.pose = toPoseMsg(pf::compose(frame, toPose2(pose->pose.pose)));
    Eigen::Matrix3d rot = Eigen::Matrix3d::Identity();
    rot.topLeftCorner<2, 2>() << std::cos(frame.yaw), -std::sin(frame.yaw), std::sin(frame.yaw),
        std::cos(frame.yaw);
    pose->pose.covariance =
        toRosCovariance(rot * fromRosCovariance(pose->pose.covariance) * rot.transpose());
    pose->header.frame_id = config_.global_frame;
    return true;
  }

  bool onGlobalLocalization(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
    const std::string error = localizer_.startGlobalLocalization();
    if (!error.empty()) {
      ROS_WARN("pf_node: %s", error.c_str());
      return false;
    }
    ROS_INFO("pf_node: global localization: %zu particles over the free space",
             localizer_.filter().particles().size());
    publishEstimate(ros::Time::now());
    return true;
  }

  bool onNoMotionUpdate(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
    localizer_.filter().requestNoMotionUpdate();
    return true;
  }

  void onTfTimer(const ros::TimerEvent&) {
    // Between scans, keep map -> odom fresh so no tf user has to extrapolate.
    const ros::Time now = ros::Time::now();
    if (now.isZero()) return;  // simulated time has not started
    publishMapToOdom(std::max(now, last_scan_stamp_) + ros::Duration(config_.transform_tolerance));
  }

  void publishEstimate(const ros::Time& stamp) {
    if (const auto pose = localizer_.estimate(stamp)) pose_pub_.publish(*pose);
    cloud_pub_.publish(localizer_.particleCloud(stamp));
  }

  void publishMapToOdom(const ros::Time& stamp) {
    if (!config_.tf_broadcast || stamp <= last_tf_stamp_) return;
    if (const auto t = localizer_.mapToOdom(stamp)) {
      broadcaster_.sendTransform(*t);
      last_tf_stamp_ = stamp;
    }
  }

  void warn(const std::string& key, const std::string& text) {
    if (log_.due(key)) ROS_WARN("pf_node: %s", text.c_str());
  }

  LocalizerConfig config_;
  ros::NodeHandle nh_;
  tf2_ros::Buffer buffer_;
  tf2_ros::TransformListener listener_;
  tf2_ros::TransformBroadcaster broadcaster_;
  ScanLocalizer localizer_;
  message_filters::Subscriber<sensor_msgs::LaserScan> scan_sub_;
  tf2_ros::MessageFilter<sensor_msgs::LaserScan> scan_filter_;
  ros::Subscriber odom_sub_, map_sub_, initial_pose_sub_, tf_watch_sub_;
  bool odom_on_tf_ = false;
  ros::Time first_odom_stamp_;
  ros::Publisher pose_pub_, cloud_pub_;
  ros::ServiceServer global_srv_, nomotion_srv_;
  ros::Timer tf_timer_;
  ros::Time last_scan_stamp_, last_tf_stamp_;
  LimitedLog log_{5.0};
};

}  // namespace
}  // namespace pf_ros

int main(int argc, char** argv) {
  ros::init(argc, argv, "pf_node");
  ros::NodeHandle nh, pnh("~");
  pf_ros::LocalizerConfig config;
  try {
    config = pf_ros::readConfig(*pf_ros::rosParamSource(pnh));
  } catch (const std::exception& e) {
    ROS_FATAL("pf_node: refusing to start: %s", e.what());
    return 1;
  }
  pf_ros::PfNode node(config, nh);
  ros::spin();
  return 0;
}
