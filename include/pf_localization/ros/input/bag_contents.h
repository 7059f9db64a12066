// What a bag holds, checked against what a replay of it needs, before the
// replay starts: each sensor's topic with its message type, odometry (odom ->
// base on /tf, or the odometry topic), and a chain of transforms from each
// sensor's frame to the base frame. What is missing is named together with
// what the bag has instead and the option that picks it, so that the first
// run on an unknown bag says what it needs (pf_bag_runner).
#pragma once

#include <rosbag/bag.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "pf_localization/ros/params/localizer_config.h"

namespace pf_ros {

/// The topics a replay reads: each sensor's and the odometry's.
struct BagTopics {
  std::vector<std::string> scan_topics;
  std::vector<std::string> cloud_topics;
  std::string odom_topic;
};

/// A bag lacks what a replay needs; the message says what it has instead.
class BagContentError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Throws BagContentError when a sensor's topic is not in `bag`, or carries
/// another message type.
void checkSensorTopics(const rosbag::Bag& bag, const BagTopics& topics);

/// Whether the bag's /tf carries odometry (odom -> base). Odometry comes from
/// /tf when the bag has it there, else from the odometry topic; never both,
/// or tf2 would see every odometry stamp twice.
bool odometryOnTf(const rosbag::Bag& bag, const LocalizerConfig& config);

/// The range_max of each laser topic's first message in `bag`, in the order
/// of topics.scan_topics (none for a topic without one): what the filter
/// builds likelihood tables for with the map (ParticleFilter::expectScanRange).
std::vector<double> firstScanRanges(const rosbag::Bag& bag, const BagTopics& topics);

/// Throws BagContentError when odometry from config.odom_frame to
/// config.base_frame, or a chain of transforms from a sensor's frame to the
/// base frame, is not in `bag` (`odom_on_tf`: odometryOnTf).
void checkFrames(const rosbag::Bag& bag, const BagTopics& topics, const LocalizerConfig& config,
                 bool odom_on_tf);

}  // namespace pf_ros
