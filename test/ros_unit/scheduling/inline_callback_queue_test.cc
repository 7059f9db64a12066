#include "pf_localization/ros/scheduling/inline_callback_queue.h"

#include <gtest/gtest.h>
#include <ros/callback_queue.h>

#include <atomic>
#include <boost/make_shared.hpp>
#include <chrono>
#include <future>
#include <thread>

namespace pf_ros {
namespace {

// Counts its calls and where they ran; answers TryAgain to the first
// `try_again` of them, as roscpp does while another thread is inside the
// same subscription's callback.
class CountingCallback : public ros::CallbackInterface {
 public:
  explicit CountingCallback(int try_again = 0) : try_again_(try_again) {}
  CallResult call() override {
    thread = std::this_thread::get_id();
    if (calls++ < try_again_) return TryAgain;
    ++runs;
    return Success;
  }
  std::atomic<int> calls{0}, runs{0};
  std::thread::id thread;

 private:
  const int try_again_;
};

TEST(InlineCallbackQueue, RunsTheCallbackAtOnceOnTheCallingThread) {
  ros::CallbackQueue fallback;
  InlineCallbackQueue queue(&fallback);
  auto cb = boost::make_shared<CountingCallback>();
  queue.addCallback(cb, 1);
  EXPECT_EQ(1, cb->runs);
  EXPECT_EQ(std::this_thread::get_id(), cb->thread);
  EXPECT_TRUE(fallback.isEmpty());
}

TEST(InlineCallbackQueue, TryAgainGoesToTheFallbackQueue) {
  ros::CallbackQueue fallback;
  InlineCallbackQueue queue(&fallback);
  auto cb = boost::make_shared<CountingCallback>(1);
  queue.addCallback(cb, 1);
  EXPECT_EQ(0, cb->runs);
  ASSERT_FALSE(fallback.isEmpty());
  fallback.callAvailable();
  EXPECT_EQ(1, cb->runs);
  EXPECT_EQ(2, cb->calls);
}

TEST(InlineCallbackQueue, RemoveByIdRemovesWhatWentToTheFallback) {
  ros::CallbackQueue fallback;
  InlineCallbackQueue queue(&fallback);
  auto mine = boost::make_shared<CountingCallback>(1);
  auto other = boost::make_shared<CountingCallback>(1);
  queue.addCallback(mine, 7);
  queue.addCallback(other, 8);
  queue.removeByID(7);
  fallback.callAvailable();
  EXPECT_EQ(0, mine->runs);
  EXPECT_EQ(1, other->runs);
}

// Blocks inside its call until released.
class BlockingCallback : public ros::CallbackInterface {
 public:
  CallResult call() override {
    entered.set_value();
    release.get_future().wait();
    finished = true;
    return Success;
  }
  std::promise<void> entered, release;
  std::atomic<bool> finished{false};
};

TEST(InlineCallbackQueue, RemoveByIdWaitsForACallbackRunningOnAnotherThread) {
  ros::CallbackQueue fallback;
  InlineCallbackQueue queue(&fallback);
  auto cb = boost::make_shared<BlockingCallback>();
  std::future<void> entered = cb->entered.get_future();
  std::thread poll([&] { queue.addCallback(cb, 1); });
  entered.wait();
  std::atomic<bool> removed{false};
  std::atomic<bool> finished_when_removed{false};
  std::thread remover([&] {
    queue.removeByID(1);
    finished_when_removed = cb->finished.load();
    removed = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_FALSE(removed) << "removeByID returned while the callback still ran";
  cb->release.set_value();
  poll.join();
  remover.join();
  EXPECT_TRUE(removed);
  EXPECT_TRUE(finished_when_removed);
}

// Unsubscribes from inside its own call, as a callback may.
class SelfRemovingCallback : public ros::CallbackInterface {
 public:
  explicit SelfRemovingCallback(InlineCallbackQueue* queue) : queue_(queue) {}
  CallResult call() override {
    queue_->removeByID(1);
    done = true;
    return Success;
  }
  bool done = false;

 private:
  InlineCallbackQueue* queue_;
};

TEST(InlineCallbackQueue, RemoveByIdFromInsideACallbackDoesNotWaitForItself) {
  ros::CallbackQueue fallback;
  InlineCallbackQueue queue(&fallback);
  auto cb = boost::make_shared<SelfRemovingCallback>(&queue);
  std::thread t([&] { queue.addCallback(cb, 1); });
  t.join();  // hangs (and the test times out) if it waited for itself
  EXPECT_TRUE(cb->done);
}

TEST(PostCallback, RunsOnTheQueueItWasLeftTo) {
  ros::CallbackQueue spinner;
  int runs = 0;
  postCallback(&spinner, 3, [&] { ++runs; });
  postCallback(&spinner, 4, [&] { runs += 10; });
  EXPECT_EQ(0, runs);
  spinner.removeByID(4);
  spinner.callAvailable();
  EXPECT_EQ(1, runs);
}

}  // namespace
}  // namespace pf_ros
