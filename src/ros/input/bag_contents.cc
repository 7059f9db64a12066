#include "pf_localization/ros/input/bag_contents.h"

#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/view.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_msgs/TFMessage.h>

#include <map>
#include <set>
#include <utility>

namespace pf_ros {
namespace {

// The bag's topics and their message types.
using TopicTypes = std::map<std::string, std::string>;

TopicTypes topicTypes(const rosbag::Bag& bag) {
  TopicTypes topics;
  for (const rosbag::ConnectionInfo* c : rosbag::View(bag).getConnections()) {
    topics[c->topic] = c->datatype;
  }
  return topics;
}

// The topics of `type` (all of them when empty), separated by spaces; "none" when none.
std::string topicsOf(const TopicTypes& topics, const std::string& type = "") {
  std::string out;
  for (const auto& t : topics) {
    if (type.empty() || t.second == type) out += (out.empty() ? "" : " ") + t.first;
  }
  return out.empty() ? "none" : out;
}

// Each sensor's topic must be in the bag with its message type; a missing or
// mistyped one is named with the bag's topics of that type and the option
// that picks them.
void checkTopics(const BagTopics& sensors, const TopicTypes& topics) {
  const auto check = [&](const std::string& topic, const std::string& type,
                         const std::string& option) {
    const auto found = topics.find(topic);
    if (found != topics.end() && found->second == type) return;
    throw BagContentError(
        (found == topics.end() ? "no " + topic + " topic in the bag"
                               : topic + " is a " + found->second + ", not a " + type) +
        "; its " + type + " topics: " + topicsOf(topics, type) + ". Name each sensor's with " +
        option + " TOPIC (every topic of the bag: " + topicsOf(topics) + ")");
  };
  for (const std::string& t : sensors.scan_topics) {
    check(t, "sensor_msgs/LaserScan", "--scan-topic");
  }
  for (const std::string& t : sensors.cloud_topics) {
    check(t, "sensor_msgs/PointCloud2", "--cloud-topic");
  }
}

// tf's frame ids without tf1's leading slash, as tf2 takes them.
std::string frameId(const std::string& id) {
  return !id.empty() && id.front() == '/' ? id.substr(1) : id;
}

// The transforms a bag holds, parent -> child, as pf_bag_runner feeds them to
// tf2: /tf and /tf_static, and the odometry topic's when odometry is not on /tf.
struct FrameGraph {
  std::set<std::pair<std::string, std::string>> edges;  // parent, child
  std::map<std::string, std::string> parent;            // child -> its first parent

  bool add(const std::string& from, const std::string& to) {
    const std::string p = frameId(from), c = frameId(to);
    if (p.empty() || c.empty() || !edges.insert({p, c}).second) return false;
    parent.emplace(c, p);
    return true;
  }
  // Whether tf can chain a to b: a path over the transforms, either way.
  bool connected(const std::string& a, const std::string& b) const {
    std::set<std::string> seen{a};
    std::vector<std::string> todo{a};
    while (!todo.empty()) {
      const std::string f = todo.back();
      todo.pop_back();
      if (f == b) return true;
      for (const auto& e : edges) {
        const std::string* next = e.first == f ? &e.second : e.second == f ? &e.first : nullptr;
        if (next && seen.insert(*next).second) todo.push_back(*next);
      }
    }
    return false;
  }
  // "a -> b, c -> d", or "none".
  std::string list() const {
    std::string out;
    for (const auto& e : edges) out += (out.empty() ? "" : ", ") + e.first + " -> " + e.second;
    return out.empty() ? "none" : out;
  }
  // The frames from `frame` up to its root: "laser <- base_link <- odom".
  std::string chain(const std::string& frame) const {
    std::string out = frame, f = frame;
    for (int depth = 0; depth < 32 && parent.count(f); ++depth) {
      f = parent.at(f);
      out += " <- " + f;
    }
    return out;
  }
};

// The first message of `topic` readable as M; null when there is none.
template <typename M>
boost::shared_ptr<M> firstMessage(const rosbag::Bag& bag, const std::string& topic) {
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery(topic))) {
    if (auto msg = m.instantiate<M>()) return msg;
  }
  return nullptr;
}

// The frame of a sensor's messages (of type M), from its topic's first one;
// empty when none is readable (the replay reports those).
template <typename M>
std::string sensorFrame(const rosbag::Bag& bag, const std::string& topic) {
  const auto msg = firstMessage<M>(bag, topic);
  return msg ? frameId(msg->header.frame_id) : "";
}

// Every sensor's frame, in the order of pf_ros::sensorTopics.
std::vector<std::string> sensorFrames(const rosbag::Bag& bag, const BagTopics& opt) {
  std::vector<std::string> frames;
  for (const std::string& t : opt.scan_topics) {
    frames.push_back(sensorFrame<sensor_msgs::LaserScan>(bag, t));
  }
  for (const std::string& t : opt.cloud_topics) {
    frames.push_back(sensorFrame<sensor_msgs::PointCloud2>(bag, t));
  }
  return frames;
}

// Whether the graph has what the replay needs: odometry from the odom frame
// to the base frame, and each sensor's frame chained to the base frame.
bool framesComplete(const FrameGraph& g, const LocalizerConfig& config,
                    const std::vector<std::string>& frames) {
  if (!g.connected(config.odom_frame, config.base_frame)) return false;
  for (const std::string& f : frames) {
    if (!f.empty() && !g.connected(f, config.base_frame)) return false;
  }
  return true;
}

// The bag's transforms: /tf_static, then /tf until the frames are complete,
// and the odometry topic's first message when odometry is not on /tf.
FrameGraph readFrames(const rosbag::Bag& bag, const BagTopics& opt, const LocalizerConfig& config,
                      const std::vector<std::string>& frames, bool odom_on_tf,
                      std::string* odom_frames) {
  FrameGraph g;
  if (!odom_on_tf) {
    for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery(opt.odom_topic))) {
      if (const auto odom = m.instantiate<nav_msgs::Odometry>()) {
        g.add(odom->header.frame_id, odom->child_frame_id);
        *odom_frames = frameId(odom->header.frame_id) + " -> " + frameId(odom->child_frame_id);
        break;
      }
    }
  }
  for (const std::string topic : {"/tf_static", "/tf"}) {
    for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery(topic))) {
      const auto msg = m.instantiate<tf2_msgs::TFMessage>();
      bool added = false;
      for (const auto& t : msg ? msg->transforms : std::vector<geometry_msgs::TransformStamped>()) {
        added |= g.add(t.header.frame_id, t.child_frame_id);
      }
      if (added && framesComplete(g, config, frames)) return g;
    }
  }
  return g;
}

}  // namespace

void checkFrames(const rosbag::Bag& bag, const BagTopics& opt, const LocalizerConfig& config,
                 bool odom_on_tf) {
  const TopicTypes topics = topicTypes(bag);
  const std::vector<std::string> frames = sensorFrames(bag, opt);
  std::string odom_frames;
  const FrameGraph g = readFrames(bag, opt, config, frames, odom_on_tf, &odom_frames);
  const std::string options =
      ". Name the robot's frames in a --params FILE.yaml (odom_frame: ..., base_frame: ...)";
  if (!g.connected(config.odom_frame, config.base_frame)) {
    // Odometry on /tf connects them: it is not there.
    const std::string odom_topic =
        !topics.count(opt.odom_topic) ? "no " + opt.odom_topic + " topic in the bag"
        : odom_frames.empty()         ? "no nav_msgs/Odometry on " + opt.odom_topic
                                      : opt.odom_topic + " has " + odom_frames;
    throw BagContentError(
        "no odometry " + config.odom_frame + " -> " + config.base_frame + ": not on /tf, and " +
        odom_topic + " (the bag's transforms: " + g.list() +
        "; its nav_msgs/Odometry topics: " + topicsOf(topics, "nav_msgs/Odometry") + ")" + options +
        ", the odometry topic with --odom-topic TOPIC");
  }
  const std::vector<std::string> topic_names = sensorTopics(config);
  for (std::size_t i = 0; i < frames.size() && i < topic_names.size(); ++i) {
    if (frames[i].empty() || g.connected(frames[i], config.base_frame)) continue;
    throw BagContentError("no transform from " + config.base_frame + " to " + frames[i] +
                          ", the frame of " + topic_names[i] +
                          " (the sensor's mounting; its frames in the bag: " + g.chain(frames[i]) +
                          "; the bag's transforms: " + g.list() + ")" + options);
  }
}

void checkSensorTopics(const rosbag::Bag& bag, const BagTopics& topics) {
  checkTopics(topics, topicTypes(bag));
}

bool odometryOnTf(const rosbag::Bag& bag, const LocalizerConfig& config) {
  bool odom_on_tf = false;
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery("/tf"))) {
    const auto msg = m.instantiate<tf2_msgs::TFMessage>();
    for (const auto& t : msg ? msg->transforms : std::vector<geometry_msgs::TransformStamped>()) {
      odom_on_tf |= t.header.frame_id == config.odom_frame && t.child_frame_id == config.base_frame;
    }
    if (odom_on_tf) break;
  }
  return odom_on_tf;
}

std::vector<double> firstScanRanges(const rosbag::Bag& bag, const BagTopics& topics) {
  std::vector<double> ranges;
  for (const std::string& t : topics.scan_topics) {
    if (const auto scan = firstMessage<sensor_msgs::LaserScan>(bag, t)) {
      ranges.push_back(scan->range_max);
    }
  }
  return ranges;
}

}  // namespace pf_ros
