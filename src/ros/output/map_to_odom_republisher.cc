#include "pf_localization/ros/output/map_to_odom_republisher.h"

#include <poll.h>
#include <ros/poll_manager.h>
#include <sys/timerfd.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <thread>
#include <utility>

namespace pf_ros {
namespace {

// s: the shortest the timer is armed for (0 would disarm it).
constexpr double kMinWait = 1e-6;

// Periods without a publication after which map -> odom is republished on
// the wall clock. tf users are promised no gap over two periods: an update
// within one and a half makes the timed copy needless (scans at 14 Hz and
// more: most of them), and the half period left covers the latency of a
// loaded computer. Under simulated time every delay of the wall clock is
// multiplied by the bag's rate and the clock moves in steps, so the timed
// copy comes within one period, at the last /clock before it is due (see the
// header), as the whole margin is needed there.
constexpr double kWallClockPeriods = 1.5;

}  // namespace

MapToOdomRepublisher::MapToOdomRepublisher(const MapToOdomRepublisherOptions& options,
                                           TickHook hook)
    : options_(options), hook_(std::move(hook)) {}

void MapToOdomRepublisher::start(ros::NodeHandle clock_nh) {
  if (poll_guard_ || clock_sub_) return;
  wall_clock_ = !ros::Time::isSimTime();
  if (!wall_clock_) {
    clock_sub_ = clock_nh.subscribe<rosgraph_msgs::Clock>(
        "/clock", 1, [this](const rosgraph_msgs::ClockConstPtr& msg) { onClock(msg->clock); });
  }
  const int fd = ::timerfd_create(CLOCK_MONOTONIC, TFD_CLOEXEC | TFD_NONBLOCK);
  if (fd < 0) {
    ROS_ERROR("pf_node: no timer for republishing map -> odom (timerfd_create: errno %d)", errno);
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    timer_fd_ = fd;
    if (wall_clock_) armLocked(kMinWait);  // the first publication is due at once
  }
  auto guard = std::make_shared<PollGuard>();
  poll_guard_ = guard;
  ros::PollSet& polls = ros::PollManager::instance()->getPollSet();
  polls.addSocket(timer_fd_, [guard, this](int) {
    std::lock_guard<std::mutex> alive(guard->mutex);
    if (guard->alive) onTimer();
  });
  polls.addEvents(timer_fd_, POLLIN);
}

MapToOdomRepublisher::~MapToOdomRepublisher() {
  clock_sub_.shutdown();
  if (poll_guard_) {
    {
      std::lock_guard<std::mutex> lock(poll_guard_->mutex);
      poll_guard_->alive = false;
    }
    ros::PollManager::instance()->getPollSet().delSocket(timer_fd_);
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  if (timer_fd_ >= 0) ::close(timer_fd_);
}

bool MapToOdomRepublisher::set(const std::optional<geometry_msgs::TransformStamped>& map_to_odom,
                               const ros::Time& scan_stamp) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    transform_ = map_to_odom;
    if (!scan_stamp.isZero()) scan_stamp_ = std::max(scan_stamp_, scan_stamp);
    if (timer_fd_ < 0 || std::this_thread::get_id() == poll_thread_.load()) {
      return publishUpdateLocked();
    }
    update_pending_ = true;
    if (!options_.enabled || !transform_) return false;
  }
  // Outside the lock: the poll thread publishes it (onTimer()); a timer it
  // re-armed meanwhile for later has already published it.
  armLocked(kMinWait);
  return true;
}

bool MapToOdomRepublisher::publishUpdateLocked() {
  update_pending_ = false;
  const ros::Time now = clockNow();
  ros::Time stamp = std::max(now, scan_stamp_) + ros::Duration(options_.transform_tolerance);
  // A correction must reach tf now even when the clock has not moved since
  // the last timed publication.
  if (!last_stamp_.isZero() && stamp <= last_stamp_) stamp = last_stamp_ + ros::Duration(1e-3);
  if (!publishLocked(stamp)) return false;
  if (!now.isZero()) {
    schedule_.published(now, delayLocked());
    if (wall_clock_) armLocked(delayLocked().toSec());  // puts the timed publication off
  }
  return true;
}

void MapToOdomRepublisher::reset() {
  std::lock_guard<std::mutex> lock(mutex_);
  transform_.reset();
  scan_stamp_ = ros::Time();
  last_stamp_ = ros::Time();
  schedule_.reset();
}

void MapToOdomRepublisher::setRate(double hz) {
  std::lock_guard<std::mutex> lock(mutex_);
  options_.rate = hz;
  if (wall_clock_) armLocked(kMinWait);  // the next timed publication goes by the new rate
}

void MapToOdomRepublisher::setTransformTolerance(double seconds) {
  std::lock_guard<std::mutex> lock(mutex_);
  options_.transform_tolerance = seconds;
}

std::size_t MapToOdomRepublisher::published() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return published_;
}

ros::Time MapToOdomRepublisher::lastStamp() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return last_stamp_;
}

void MapToOdomRepublisher::onClock(const ros::Time& now) {
  poll_thread_ = std::this_thread::get_id();
  const ros::Time before = ros::Time().fromNSec(clock_ns_.exchange(now.toNSec()));
  // The clock's latest step: the next /clock will likely be as far on.
  const ros::Duration step = before.isZero() || before >= now ? ros::Duration() : now - before;
  std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock() || stop_) return;
  if (update_pending_) publishUpdateLocked();
  tick(now, step, &lock);
}

void MapToOdomRepublisher::onTimer() {
  poll_thread_ = std::this_thread::get_id();
  std::uint64_t expirations = 0;
  // Nothing to read: set() re-armed it since it fired, so it is not due.
  if (::read(timer_fd_, &expirations, sizeof expirations) < 0) return;
  std::unique_lock<std::mutex> lock(mutex_);
  if (stop_) return;
  if (update_pending_) publishUpdateLocked();
  if (!wall_clock_) return;  // /clock times the copies
  tick(ros::Time::now(), ros::Duration(), &lock);
  if (stop_) return;
  // Until the next is due; set() moves that later.
  armLocked(std::max((schedule_.next() - ros::Time::now()).toSec(), kMinWait));
}

ros::Time MapToOdomRepublisher::clockNow() const {
  const std::int64_t ns = clock_ns_;
  return ns == 0 ? ros::Time::now() : ros::Time().fromNSec(ns);
}

ros::Duration MapToOdomRepublisher::delayLocked() const {
  return ros::Duration((wall_clock_ ? kWallClockPeriods : 1.0) / options_.rate);
}

void MapToOdomRepublisher::armLocked(double seconds) {
  if (timer_fd_ < 0) return;
  itimerspec spec{};
  const auto ns = static_cast<std::int64_t>(std::max(seconds, kMinWait) * 1e9);
  spec.it_value.tv_sec = static_cast<time_t>(ns / 1000000000);
  spec.it_value.tv_nsec = static_cast<decltype(spec.it_value.tv_nsec)>(ns % 1000000000);
  ::timerfd_settime(timer_fd_, 0, &spec, nullptr);
}

void MapToOdomRepublisher::tick(const ros::Time& now, const ros::Duration& step,
                                std::unique_lock<std::mutex>* lock) {
  const ros::Duration period = delayLocked();
  // Zero: simulated time has not started.
  if (now.isZero() || !schedule_.due(now, period, step.isZero() ? ros::Time() : now + step)) return;
  // The tick counts as a publication even when it has nothing new to send
  // (no map -> odom yet, or no later stamp): otherwise it would stay due.
  schedule_.published(now, period);
  if (hook_) {
    lock->unlock();
    hook_(now);
    lock->lock();
    if (stop_) return;
  }
  const ros::Time stamp = std::max(now, scan_stamp_) + ros::Duration(options_.transform_tolerance);
  // Between updates, only a later stamp is news (and tf2 refuses a repeated one).
  if (stamp > last_stamp_) publishLocked(stamp);
}

bool MapToOdomRepublisher::publishLocked(ros::Time stamp) {
  if (!options_.enabled || !transform_) return false;
  geometry_msgs::TransformStamped t = *transform_;
  t.header.stamp = stamp;
  broadcaster_.sendTransform(t);
  last_stamp_ = stamp;
  ++published_;
  return true;
}

}  // namespace pf_ros
