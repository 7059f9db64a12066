#include "pf_localization/ros/scheduling/inline_callback_queue.h"

#include <boost/make_shared.hpp>
#include <mutex>
#include <utility>

namespace pf_ros {
namespace {

// How many InlineCallbackQueue callbacks this thread is inside.
thread_local int t_running_inline = 0;
// How many OwnMessageScopes this thread is inside.
thread_local int t_own_messages = 0;

struct RunningInline {
  RunningInline() { ++t_running_inline; }
  ~RunningInline() { --t_running_inline; }
};

class FunctionCallback : public ros::CallbackInterface {
 public:
  explicit FunctionCallback(std::function<void()> fn) : fn_(std::move(fn)) {}
  CallResult call() override {
    fn_();
    return Success;
  }

 private:
  std::function<void()> fn_;
};

}  // namespace

OwnMessageScope::OwnMessageScope() { ++t_own_messages; }
OwnMessageScope::~OwnMessageScope() { --t_own_messages; }
bool OwnMessageScope::active() { return t_own_messages > 0; }

void postCallback(ros::CallbackQueueInterface* queue, uint64_t owner_id, std::function<void()> fn) {
  queue->addCallback(boost::make_shared<FunctionCallback>(std::move(fn)), owner_id);
}

void InlineCallbackQueue::addCallback(const ros::CallbackInterfacePtr& callback,
                                      uint64_t owner_id) {
  ros::CallbackInterface::CallResult result;
  {
    // Once per thread: a callback that publishes to this node itself comes
    // back here, and a second shared lock could wait behind removeByID.
    std::shared_lock<std::shared_mutex> running(running_, std::defer_lock);
    if (t_running_inline == 0) running.lock();
    RunningInline inside;
    result = callback->call();
  }
  // Another thread is inside this subscription's callback: the spinner
  // takes it, rather than this thread waiting.
  if (result == ros::CallbackInterface::TryAgain) fallback_->addCallback(callback, owner_id);
}

void InlineCallbackQueue::removeByID(uint64_t owner_id) {
  fallback_->removeByID(owner_id);
  if (t_running_inline > 0) return;
  std::unique_lock<std::shared_mutex> wait_for_running(running_);
}

}  // namespace pf_ros
