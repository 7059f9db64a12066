#include "pf_localization/ros/scheduling/update_scheduler.h"

#include <pthread.h>
#include <ros/init.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <string>

#include "pf_localization/ros/scheduling/inline_callback_queue.h"

namespace pf_ros {
namespace {

// Set while this thread runs an update (process()).
thread_local bool t_updating = false;

// Raises the calling thread's nice value by `increment` (at most to 19),
// which the threads it starts later inherit. Needs no privilege; failing, it
// changes nothing.
void lowerThreadPriority(int increment) {
  const id_t tid = static_cast<id_t>(::syscall(SYS_gettid));
  errno = 0;
  const int nice = ::getpriority(PRIO_PROCESS, tid);
  if (errno == 0) ::setpriority(PRIO_PROCESS, tid, std::min(19, nice + increment));
}

}  // namespace

UpdateScheduler::UpdateScheduler(Update update, IsShort is_short, LimitedWarn* warn,
                                 Running running)
    : update_(std::move(update)),
      is_short_(std::move(is_short)),
      warn_(warn),
      running_(running ? std::move(running) : Running([] { return ros::ok(); })) {
  thread_ = std::thread([this] { filterLoop(); });
}

UpdateScheduler::~UpdateScheduler() { stop(); }

void UpdateScheduler::stop() {
  slot_.close();
  if (thread_.joinable()) thread_.join();
}

void UpdateScheduler::onScan(PendingScan scan) {
  if (updateHere(scan)) return;
  if (!slot_.put(std::move(scan))) return;
  warn_->warn("overload",
              "the filter cannot keep up: a scan waiting for it was dropped for a newer one (" +
                  std::to_string(slot_.dropped()) +
                  " since start; see dropped_scans and latency_* in the diagnostics). Lower "
                  "max_particles, or set max_update_time");
}

// A hand-over to the filter thread costs two wake-ups and the caches the
// messages warmed, so a short update runs where its scan arrived. It may run
// inside roscpp's /tf callback, which is safe only while pf_node publishes
// by value, and not inside the delivery of pf_node's own map -> odom
// (docs/ros-interface.md, "Threads, latency and overload"). Scans left for
// the filter thread that it has not taken yet are handled here first, in
// turn, while the updates stay short: in a burst (a player catching up after
// a stall) the filter thread, at its lower priority, may not wake before the
// next scan, which would drop the waiting one for nothing.
bool UpdateScheduler::updateHere(const PendingScan& scan) {
  if (t_updating || OwnMessageScope::active()) return false;
  std::unique_lock<std::mutex> lock(filter_mutex_, std::try_to_lock);
  if (!lock.owns_lock() || !is_short_()) return false;
  while (std::optional<PendingScan> waiting = slot_.takeUnclaimed()) {
    process(*waiting);
    if (!is_short_()) return false;
  }
  if (!slot_.idle()) return false;
  process(scan);
  return true;
}

void UpdateScheduler::process(const PendingScan& scan) {
  t_updating = true;
  update_(scan, slot_);
  t_updating = false;
}

// The newest waiting scan, one at a time.
void UpdateScheduler::filterLoop() {
  lowerThreadPriority(kFilterNiceIncrement);
  // Named for the per-thread CPU in scripts/live_cpu.sh, top and perf.
  pthread_setname_np(pthread_self(), "pf_filter");
  // The destructor's close() wakes the wait; its time-out only bounds how
  // long a shutdown by another way goes unseen (a shorter one would wake an
  // idle node ten times a second for nothing).
  while (running_() && !slot_.closed()) {
    auto pending = slot_.take(ros::WallDuration(1.0));
    if (!pending) continue;
    std::lock_guard<std::mutex> lock(filter_mutex_);
    process(*pending);
    slot_.done();
  }
}

}  // namespace pf_ros
