// Where pf_node's odometry (odom -> base) comes from: tf, or the odometry
// topic. Most robots publish it on /tf, and then the topic is ignored (tf2
// would otherwise see every odometry stamp twice); robots that publish it
// only as a nav_msgs/Odometry topic get it into the tf buffer from there.
// The topic waits a moment (kGrace s of its own stamps) for /tf to show
// odometry before it is taken as the source. Which source is in use is
// announced once, and again when it changes. Not thread-safe: pf_node calls it from its main
// spinner only.
#pragma once

#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <tf2_msgs/TFMessage.h>

#include <optional>
#include <string>

namespace pf_ros {

class OdometrySource {
 public:
  /// s of odometry messages to wait for odom -> base on /tf before the
  /// odometry topic is taken as the source instead.
  static constexpr double kGrace = 0.5;

  enum class Kind { kUndecided, kTf, kTopic };

  /// What to do with one message of the odometry topic.
  struct TopicMessage {
    /// When the topic is the source: the transform to put in the tf buffer.
    std::optional<geometry_msgs::TransformStamped> transform;
    /// Non-empty: the message is unusable, and why (for a rate-limited warning).
    std::string problem;
    std::string problem_key;  // the kind of problem, for the rate limit
  };

  /// `topic`: the odometry topic's name, for the announcement.
  OdometrySource(std::string odom_frame, std::string base_frame, std::string topic,
                 double grace = kGrace);

  /// A /tf message. True when it is the first to carry odom -> base: tf is the
  /// source from then on (the caller may stop watching /tf and the topic).
  bool onTf(const tf2_msgs::TFMessage& msg);

  /// A message of the odometry topic.
  TopicMessage onTopic(const nav_msgs::Odometry& msg);

  Kind kind() const { return kind_; }

  /// The line to log (at INFO) when the source in use changed since the last
  /// call, e.g. "odometry: from tf odom -> base_link"; nothing otherwise.
  std::optional<std::string> takeAnnouncement();

 private:
  const std::string odom_frame_, base_frame_, topic_;
  const double grace_;
  Kind kind_ = Kind::kUndecided;
  Kind announced_ = Kind::kUndecided;
  ros::Time first_stamp_;  // of the topic's first message
};

}  // namespace pf_ros
