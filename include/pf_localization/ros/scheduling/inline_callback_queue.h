// A roscpp callback queue that runs each callback at once, on the thread that
// queues it, instead of waking a spinner to run it.
//
// roscpp reads every message on its poll thread and hands it to a spinner
// through a callback queue, so each message wakes two threads (the cost:
// docs/performance.md, "Wake-ups: tf and scans on the poll thread"). The tf
// listener and the scan's tf message filter (whose callbacks store a
// transform, or run a short update or leave the scan for the filter thread:
// thread-safe, and never waiting for the filter) run here, so a message costs
// one wake-up.
//
// Threads: a callback runs on roscpp's poll thread for a message from another
// process, and for one of this node's own messages published by value (from
// roscpp's publish queue, holding the topic's lock: OwnMessageScope), or on
// the publishing thread for one published by shared pointer. When another thread is already
// inside the same subscription's callback (roscpp then answers TryAgain),
// the callback goes to `fallback` (the main spinner's queue) instead of
// waiting: order is kept, as roscpp's subscription queue hands out its
// messages oldest first to whichever thread calls.
//
// Only for callbacks that never wait for a lock that a thread publishing on
// one of these topics may hold (the filter's, UpdateScheduler's, for one):
// the publisher would wait for itself.
#pragma once

#include <ros/callback_queue_interface.h>
#include <ros/node_handle.h>

#include <cstdint>
#include <functional>
#include <shared_mutex>

namespace pf_ros {

class InlineCallbackQueue : public ros::CallbackQueueInterface {
 public:
  /// `fallback` runs what cannot run at once; it must outlive this queue.
  explicit InlineCallbackQueue(ros::CallbackQueueInterface* fallback) : fallback_(fallback) {}

  /// Runs `callback` now (or leaves it to the fallback queue, see above).
  void addCallback(const ros::CallbackInterfacePtr& callback, uint64_t owner_id) override;

  /// Removes the owner's callbacks left to the fallback queue and, as roscpp's
  /// own queue does when a subscriber goes, waits until no callback runs here
  /// on another thread (not when called from inside one of them: it would
  /// wait for itself).
  void removeByID(uint64_t owner_id) override;

 private:
  ros::CallbackQueueInterface* fallback_;
  std::shared_mutex running_;  // held shared by every callback running here
};

/// Marks this thread, while it lives, as inside the delivery of one of this
/// node's own messages. roscpp delivers a message published by value to the
/// node's own subscriptions from its poll loop, holding the topic's lock for
/// its subscribers; a callback that then published on that topic would wait
/// for that lock, held by its own thread. TfInput opens one around this
/// node's own transforms; UpdateScheduler runs no update inside one (its
/// map -> odom goes on /tf).
class OwnMessageScope {
 public:
  OwnMessageScope();
  ~OwnMessageScope();
  OwnMessageScope(const OwnMessageScope&) = delete;
  OwnMessageScope& operator=(const OwnMessageScope&) = delete;

  /// Whether this thread is inside one.
  static bool active();
};

/// `nh` with its callbacks on `queue` (an InlineCallbackQueue, say).
inline ros::NodeHandle withQueue(ros::NodeHandle nh, ros::CallbackQueueInterface* queue) {
  nh.setCallbackQueue(queue);
  return nh;
}

/// Leaves `fn` to `queue` (the main spinner's, say), under `owner_id` for
/// removeByID: for work that must not run on the thread at hand.
void postCallback(ros::CallbackQueueInterface* queue, uint64_t owner_id, std::function<void()> fn);

}  // namespace pf_ros
