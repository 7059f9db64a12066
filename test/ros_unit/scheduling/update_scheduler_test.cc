// Where pf_node's updates run: at once on the thread that brought the scan
// when short and nothing else holds or waits for the filter, otherwise on the
// filter thread, the newest scan winning; the filter's lock for the rest.
#include "pf_localization/ros/scheduling/update_scheduler.h"

#include <gtest/gtest.h>

#include <atomic>
#include <boost/make_shared.hpp>
#include <chrono>
#include <condition_variable>
#include <future>
#include <mutex>
#include <thread>
#include <vector>

#include "ros_unit/test_messages.h"

namespace pf_ros {
namespace {

using test::scanStamped;

// Records each update: the scan's stamp and the thread it ran on. An update
// may be held until release() (an update longer than a scan period).
struct Recorder {
  std::mutex mutex;
  std::condition_variable changed;
  std::vector<double> stamps;
  std::vector<std::thread::id> threads;
  std::vector<std::uint64_t> dropped;
  bool hold = false;
  bool holding = false;

  void update(const PendingScan& scan, const LatestScanSlot& slot) {
    std::unique_lock<std::mutex> lock(mutex);
    holding = true;
    changed.notify_all();
    changed.wait(lock, [this] { return !hold; });
    holding = false;
    stamps.push_back(scan.header().stamp.toSec());
    threads.push_back(std::this_thread::get_id());
    dropped.push_back(slot.dropped());
    changed.notify_all();
  }
  void release() {
    std::lock_guard<std::mutex> lock(mutex);
    hold = false;
    changed.notify_all();
  }
  // Waits (up to 5 s) until an update is being held, or `n` updates ran.
  bool waitHolding() {
    std::unique_lock<std::mutex> lock(mutex);
    return changed.wait_for(lock, std::chrono::seconds(5), [this] { return holding; });
  }
  bool waitUpdates(std::size_t n) {
    std::unique_lock<std::mutex> lock(mutex);
    return changed.wait_for(lock, std::chrono::seconds(5), [&] { return stamps.size() >= n; });
  }
};

// Waits (up to 5 s) until no thread holds the filter: the filter thread
// marks its scan done before it lets go.
bool waitFilterFree(UpdateScheduler* scheduler) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (!scheduler->tryWithFilter([] {})) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::yield();
  }
  return true;
}

struct Fixture {
  explicit Fixture(bool is_short)
      : short_updates(is_short),
        scheduler([this](const PendingScan& s, const LatestScanSlot& slot) { rec.update(s, slot); },
                  [this] { return short_updates.load(); }, &warn, [] { return true; }) {}
  Recorder rec;
  std::atomic<bool> short_updates;
  LimitedWarn warn{"test", 5.0};
  UpdateScheduler scheduler;
};

TEST(UpdateScheduler, AShortUpdateRunsAtOnceOnTheThreadThatBroughtTheScan) {
  Fixture f(true);
  f.scheduler.onScan(scanStamped(1.0));
  ASSERT_EQ(1u, f.rec.stamps.size());  // already done when onScan returns
  EXPECT_EQ(std::this_thread::get_id(), f.rec.threads[0]);
}

TEST(UpdateScheduler, ALongUpdateGoesToTheFilterThread) {
  Fixture f(false);
  f.scheduler.onScan(scanStamped(1.0));
  ASSERT_TRUE(f.rec.waitUpdates(1));
  EXPECT_NE(std::this_thread::get_id(), f.rec.threads[0]);
}

TEST(UpdateScheduler, NeverWaitsForTheFilterAnotherThreadHolds) {
  Fixture f(true);
  std::promise<void> holding, release;
  std::thread holder([&] {
    f.scheduler.withFilter([&] {
      holding.set_value();
      release.get_future().wait();
    });
  });
  holding.get_future().wait();
  f.scheduler.onScan(scanStamped(1.0));  // returns although the filter is held
  EXPECT_TRUE(f.rec.stamps.empty());
  EXPECT_FALSE(f.scheduler.tryWithFilter([] {}));
  release.set_value();
  holder.join();
  ASSERT_TRUE(f.rec.waitUpdates(1));
  EXPECT_NE(std::this_thread::get_id(), f.rec.threads[0]);  // the filter thread took it
  EXPECT_TRUE(waitFilterFree(&f.scheduler));
}

TEST(UpdateScheduler, UnderOverloadTheNewestScanWinsAndNoneOvertakesAnOlderOne) {
  Fixture f(false);
  f.rec.hold = true;
  f.scheduler.onScan(scanStamped(1.0));
  ASSERT_TRUE(f.rec.waitHolding());  // the filter thread is inside scan 1's update
  // Short now, but scan 1 is in the filter thread's hands: these must wait
  // behind it, and the newest of them wins.
  f.short_updates = true;
  f.scheduler.onScan(scanStamped(2.0));
  f.scheduler.onScan(scanStamped(3.0));
  f.scheduler.onScan(scanStamped(4.0));
  EXPECT_EQ(2u, f.scheduler.dropped());
  f.rec.release();
  ASSERT_TRUE(f.rec.waitUpdates(2));
  EXPECT_EQ((std::vector<double>{1.0, 4.0}), f.rec.stamps);
  EXPECT_EQ(2u, f.rec.dropped[1]);
  // Idle again: the next short one runs at once, here.
  ASSERT_TRUE(waitFilterFree(&f.scheduler));
  f.scheduler.onScan(scanStamped(5.0));
  ASSERT_EQ(3u, f.rec.stamps.size());
  EXPECT_EQ(std::this_thread::get_id(), f.rec.threads[2]);
}

TEST(UpdateScheduler, AScanTheFilterThreadHasNotTakenRunsHereFirstInTurn) {
  // A burst of scans (a player catching up): the filter thread, at its lower
  // priority, has not woken for the scan left to it when the next arrives.
  // Here it never does: its loop ends at once.
  Recorder rec;
  LimitedWarn warn{"test", 5.0};
  std::atomic<bool> short_updates{false};
  UpdateScheduler scheduler(
      [&](const PendingScan& s, const LatestScanSlot& slot) { rec.update(s, slot); },
      [&] { return short_updates.load(); }, &warn, [] { return false; });
  scheduler.onScan(scanStamped(1.0));  // long: left to the filter thread
  EXPECT_TRUE(rec.stamps.empty());
  short_updates = true;
  scheduler.onScan(scanStamped(2.0));
  scheduler.onScan(scanStamped(3.0));
  EXPECT_EQ((std::vector<double>{1.0, 2.0, 3.0}), rec.stamps);
  EXPECT_EQ(0u, scheduler.dropped());
  for (const std::thread::id& thread : rec.threads) EXPECT_EQ(std::this_thread::get_id(), thread);
}

TEST(UpdateScheduler, AScanThatArrivesInsideAnUpdateIsHandedOver) {
  Recorder rec;
  LimitedWarn warn{"test", 5.0};
  UpdateScheduler* self = nullptr;
  std::atomic<int> nested{0};
  UpdateScheduler scheduler(
      [&](const PendingScan& s, const LatestScanSlot& slot) {
        // The update publishes, and the node's own message completes a scan
        // on this thread: it must not run inside this update.
        if (s.header().stamp.toSec() == 1.0) {
          self->onScan(scanStamped(2.0));
          nested = static_cast<int>(rec.stamps.size());
        }
        rec.update(s, slot);
      },
      [] { return true; }, &warn, [] { return true; });
  self = &scheduler;
  scheduler.onScan(scanStamped(1.0));
  ASSERT_TRUE(rec.waitUpdates(2));
  EXPECT_EQ(0, nested.load());  // scan 2 had not run when scan 1's update went on
  EXPECT_EQ((std::vector<double>{1.0, 2.0}), rec.stamps);
  EXPECT_NE(rec.threads[0], rec.threads[1]);
}

TEST(UpdateScheduler, WithFilterReturnsWhatItRan) {
  Fixture f(true);
  EXPECT_EQ(42, f.scheduler.withFilter([] { return 42; }));
  int ran = 0;
  EXPECT_TRUE(f.scheduler.tryWithFilter([&] { ++ran; }));
  EXPECT_EQ(1, ran);
}

TEST(UpdateScheduler, TheDestructorWakesTheWaitingFilterThreadAtOnce) {
  Recorder rec;
  LimitedWarn warn{"test", 5.0};
  const auto start = std::chrono::steady_clock::now();
  {
    UpdateScheduler scheduler(
        [&](const PendingScan& s, const LatestScanSlot& l) { rec.update(s, l); },
        [] { return false; }, &warn, [] { return true; });
    scheduler.onScan(scanStamped(1.0));
    ASSERT_TRUE(rec.waitUpdates(1));
  }  // the destructor wakes the waiting thread at once
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(900));
}

}  // namespace
}  // namespace pf_ros
