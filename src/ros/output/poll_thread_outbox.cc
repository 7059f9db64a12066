#include "pf_localization/ros/output/poll_thread_outbox.h"

#include <poll.h>
#include <ros/poll_manager.h>
#include <ros/ros.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <utility>

namespace pf_ros {
namespace {

// The batch open on this thread, innermost.
thread_local PollThreadOutbox::Batch* t_batch = nullptr;

}  // namespace

void PollThreadOutbox::start() {
  if (shared_) return;
  auto shared = std::make_shared<Shared>();
  shared->fd = ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
  if (shared->fd < 0) {
    ROS_ERROR("pf_node: no eventfd for the poll thread (errno %d): publishing where computed",
              errno);
    return;
  }
  ros::PollSet& polls = ros::PollManager::instance()->getPollSet();
  // The poll set may still call a callback just taken out of it: it holds
  // `shared` and finds it no longer alive.
  polls.addSocket(shared->fd, [shared](int) { runQueued(shared.get()); });
  polls.addEvents(shared->fd, POLLIN);
  shared_ = std::move(shared);
}

void PollThreadOutbox::stop() {
  if (!shared_) return;
  {
    std::lock_guard<std::mutex> running(shared_->run_mutex);
    shared_->alive = false;
  }
  ros::PollManager::instance()->getPollSet().delSocket(shared_->fd);
  ::close(shared_->fd);
  shared_.reset();
}

void PollThreadOutbox::post(Job job) {
  for (Batch* b = t_batch; b != nullptr; b = b->outer_) {
    if (b->outbox_ != this) continue;
    b->jobs_.push_back(std::move(job));
    return;
  }
  std::vector<Job> one;
  one.push_back(std::move(job));
  if (!hand(&one)) one.front()();
}

bool PollThreadOutbox::hand(std::vector<Job>* jobs) {
  if (!shared_) return false;
  bool was_empty = false;
  {
    std::lock_guard<std::mutex> lock(shared_->queue_mutex);
    was_empty = shared_->jobs.empty();
    for (Job& job : *jobs) shared_->jobs.push_back(std::move(job));
  }
  jobs->clear();
  // Queued behind others, they go with them: that wake-up is on its way.
  if (!was_empty) return true;
  const std::uint64_t one = 1;
  if (::write(shared_->fd, &one, sizeof one) < 0 && errno != EAGAIN) {
    ROS_ERROR_THROTTLE(5.0, "pf_node: cannot wake the poll thread (errno %d)", errno);
  }
  return true;
}

void PollThreadOutbox::runQueued(Shared* shared) {
  std::lock_guard<std::mutex> running(shared->run_mutex);
  if (!shared->alive) return;
  std::uint64_t count = 0;
  // Before taking the queue: a job queued after this read wakes it again.
  // (Nothing to read: a wake-up whose jobs an earlier one took.)
  if (::read(shared->fd, &count, sizeof count) < 0 && errno != EAGAIN) return;
  std::vector<Job> jobs;
  {
    std::lock_guard<std::mutex> lock(shared->queue_mutex);
    jobs.swap(shared->jobs);
  }
  for (Job& job : jobs) job();
}

PollThreadOutbox::Batch::Batch(PollThreadOutbox* outbox) : outbox_(outbox), outer_(t_batch) {
  t_batch = this;
}

PollThreadOutbox::Batch::~Batch() {
  t_batch = outer_;
  if (jobs_.empty()) return;
  if (outbox_->hand(&jobs_)) return;
  for (Job& job : jobs_) job();  // not started (or stopped): at once, in order
}

}  // namespace pf_ros
