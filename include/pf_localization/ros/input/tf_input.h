// pf_node's tf: a buffer of 30 s, filled from /tf and /tf_static by
// callbacks that run on roscpp's poll thread as the messages arrive
// (InlineCallbackQueue: no thread or spinner of their own), so that a
// transform that completes a waiting scan hands it on at once
// (docs/performance.md, "Wake-ups: tf and scans on the poll thread"). The
// other subscriptions that run on the poll thread (the scans, /clock) use the
// same queue.
//
// It does what tf2_ros::TransformListener does (each transform stored with
// its publisher as the authority, the buffer cleared when time jumps back),
// and one thing more: the node's own transforms are stored inside an
// OwnMessageScope, so that a scan they complete is not updated, and its
// map -> odom not published, by the thread that holds /tf's lock.
#pragma once

#include <ros/message_event.h>
#include <ros/node_handle.h>
#include <ros/subscriber.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/buffer.h>

#include "pf_localization/ros/diagnostics/limited_warn.h"
#include "pf_localization/ros/scheduling/inline_callback_queue.h"

namespace pf_ros {

class TfInput {
 public:
  /// Listens on `nh`; what cannot run at once goes to roscpp's global queue
  /// (the main spinner's). `warn` (it must outlive this object) takes the
  /// transforms that could not be stored.
  TfInput(const ros::NodeHandle& nh, LimitedWarn* warn);
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
  void onTransforms(const ros::MessageEvent<tf2_msgs::TFMessage const>& event, bool is_static);

  tf2_ros::Buffer buffer_;
  InlineCallbackQueue queue_;
  LimitedWarn* warn_;
  ros::Subscriber tf_, tf_static_;
  ros::Time last_message_;  // when the last message came, to see time jump back
};

}  // namespace pf_ros
