#include "pf_localization/core/util/worker_pool.h"

#include <pthread.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>

namespace pf {
namespace {

// The calling thread's nice value (Linux keeps one per thread), or 0.
int threadNice() {
  errno = 0;
  const int nice = ::getpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid)));
  return errno == 0 ? nice : 0;
}

}  // namespace

WorkerPool& WorkerPool::instance() {
  static WorkerPool pool;
  return pool;
}

WorkerPool::~WorkerPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  for (std::thread& worker : workers_) worker.join();
}

void WorkerPool::takeTasks(std::unique_lock<std::mutex>* lock) {
  while (next_ < tasks_) {
    const std::size_t k = next_++;
    lock->unlock();
    call_(task_, k);
    lock->lock();
    if (--unfinished_ == 0) done_.notify_all();
  }
}

void WorkerPool::runErased(int threads, std::size_t tasks, Call call, void* task) {
  const auto alone = [&] {
    for (std::size_t k = 0; k < tasks; ++k) call(task, k);
  };
  if (threads <= 1 || tasks <= 1) return alone();
  // Another job under way (another filter's, or this one's around work
  // nested in it): this one on its caller's thread alone.
  std::unique_lock<std::mutex> job(job_mutex_, std::try_to_lock);
  if (!job.owns_lock()) return alone();
  std::unique_lock<std::mutex> lock(mutex_);
  const std::size_t helpers =
      std::min<std::size_t>(static_cast<std::size_t>(threads) - 1, tasks - 1);
  while (workers_.size() < helpers) {
    const std::size_t id = workers_.size();
    workers_.emplace_back([this, id] { work(id); });
  }
  call_ = call;
  task_ = task;
  tasks_ = tasks;
  next_ = 0;
  unfinished_ = tasks;
  participants_ = helpers;
  nice_ = threadNice();
  ++generation_;
  wake_.notify_all();
  takeTasks(&lock);
  done_.wait(lock, [&] { return unfinished_ == 0; });
  call_ = nullptr;
  task_ = nullptr;
  tasks_ = 0;
}

void WorkerPool::work(std::size_t id) {
  // Named for per-thread CPU figures (top, perf, scripts/live_cpu.sh).
  pthread_setname_np(pthread_self(), "pf_worker");
  std::size_t seen = 0;
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_.wait(lock, [&] { return stop_ || (generation_ != seen && id < participants_); });
    if (stop_) return;
    seen = generation_;
    if (threadNice() != nice_) {
      ::setpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid)), nice_);
    }
    takeTasks(&lock);
  }
}

}  // namespace pf
