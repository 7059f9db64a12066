// pf_node's tf: a buffer of 30 s, filled by a listener whose callbacks run
// on roscpp's poll thread as the messages arrive (InlineCallbackQueue: no
// thread or spinner of the listener's own), so that a transform that
// completes a waiting scan hands it on at once (docs/performance.md,
// "Wake-ups: tf and scans on the poll thread"). The other subscriptions that
// run on the poll thread (the scans, /clock) use the same queue.
#pragma once

#include <ros/node_handle.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <memory>

#include "pf_localization/ros/scheduling/inline_callback_queue.h"

namespace pf_ros {

class TfInput {
 public:
  /// Listens on `nh`; what cannot run at once goes to roscpp's global queue
  /// (the main spinner's).
  explicit TfInput(const ros::NodeHandle& nh);
  /// Stops listening before the buffer and the queue go.
  ~TfInput();
  TfInput(const TfInput&) = delete;
  TfInput& operator=(const TfInput&) = delete;

  tf2_ros::Buffer& buffer() { return buffer_; }
  /// The poll thread's queue, for the other subscriptions that run there.
  ros::CallbackQueueInterface* queue() { return &queue_; }
  /// `nh` with its callbacks on the poll thread's queue; it must not outlive
  /// this object.
  ros::NodeHandle onPollThread(const ros::NodeHandle& nh) { return withQueue(nh, &queue_); }

 private:
  tf2_ros::Buffer buffer_;
  InlineCallbackQueue queue_;
  std::unique_ptr<tf2_ros::TransformListener> listener_;  // made in the constructor's body
};

}  // namespace pf_ros
