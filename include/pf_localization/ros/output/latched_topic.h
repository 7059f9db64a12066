// A latched topic published only while something subscribes to it. roscpp
// serializes every message of a latched topic, read or not, and wakes its
// poll thread for it (a pipe write, then the poll thread's wake-up and
// read): for pf_node's per-update messages that nobody reads, that is most
// of their cost. Without a subscriber the latest message is kept instead,
// and published when one connects, so that every subscriber still gets the
// latest message at once, as from any latched topic.
//
// Thread-safe: publish() and the connection callback (on the handle's
// callback queue) share one small lock.
#pragma once

#include <ros/ros.h>

#include <mutex>
#include <optional>
#include <string>

namespace pf_ros {

template <typename M>
class LatchedTopic {
 public:
  /// Advertises `topic` latched on `nh`.
  LatchedTopic(ros::NodeHandle& nh, const std::string& topic, uint32_t queue_size) {
    pub_ = nh.advertise<M>(
        topic, queue_size, [this](const ros::SingleSubscriberPublisher&) { onConnect(); },
        ros::SubscriberStatusCallback(), ros::VoidConstPtr(), true);
  }
  ~LatchedTopic() { pub_.shutdown(); }
  LatchedTopic(const LatchedTopic&) = delete;
  LatchedTopic& operator=(const LatchedTopic&) = delete;

  /// Published now when something subscribes; otherwise kept for the first
  /// subscriber (replacing any message kept before).
  void publish(M msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (pub_.getNumSubscribers() > 0) {
      pub_.publish(msg);  // serialized here: msg is free again
      kept_.reset();
      spare_ = std::move(msg);
    } else {
      kept_ = std::move(msg);
    }
  }

  /// A message to fill and publish() next: the one kept or last published,
  /// so that a large message's storage is used again rather than allocated
  /// and faulted in for every message. Its contents are stale.
  M spare() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (kept_) {
      M m = std::move(*kept_);
      kept_.reset();
      return m;
    }
    return std::move(spare_);
  }

  /// The message kept for the first subscriber, if any (for tests).
  std::optional<M> kept() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return kept_;
  }

 private:
  void onConnect() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!kept_) return;  // roscpp's latch has sent the latest already
    pub_.publish(*kept_);
    kept_.reset();
  }

  mutable std::mutex mutex_;
  std::optional<M> kept_;
  M spare_;  // the last message published, for spare()
  ros::Publisher pub_;
};

}  // namespace pf_ros
