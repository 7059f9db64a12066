// The threads the filter update runs its parallel work on (particle_blocks.h).
//
// A fork-join pool of our own rather than OpenMP: libgomp's idle threads
// spin between parallel regions, and on a robot whose cores are busy with
// other processes a spinning thread takes the time a preempted one needs to
// reach the region's end (docs/design.md, "The update on every core"). Here
// an idle worker sleeps on a condition variable.
//
// A job's workers run at its caller's priority (nice value) where they may:
// pf_node lowers its filter thread's so that tf and odometry come first,
// and work done for it must not come first either. (Raising a priority
// back takes a privilege; without it a worker stays as low as it went.)
//
// One pool per process, grown to the largest thread count asked for. One
// job at a time: a job asked for while another runs (a second filter on
// another thread, or work nested in a job) runs on its caller's thread
// alone, which gives the same result, as every job's result is
// independent of how many threads take part.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <mutex>
#include <thread>
#include <vector>

namespace pf {

class WorkerPool {
 public:
  /// The process's pool.
  static WorkerPool& instance();

  /// Calls task(k) for every k in [0, tasks), on the calling thread and up
  /// to threads - 1 workers, and returns when all are done. Tasks are taken
  /// in order of k by whichever thread is free; they must not throw.
  template <typename Task>
  void run(int threads, std::size_t tasks, Task& task) {
    runErased(
        threads, tasks, [](void* t, std::size_t k) { (*static_cast<Task*>(t))(k); }, &task);
  }

  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

 private:
  // A task without its type (no std::function: it would allocate).
  using Call = void (*)(void* task, std::size_t k);

  WorkerPool() = default;
  void runErased(int threads, std::size_t tasks, Call call, void* task);
  void work(std::size_t id);
  // Takes tasks of the current job until none is left; `lock` holds mutex_.
  void takeTasks(std::unique_lock<std::mutex>* lock);

  std::mutex job_mutex_;  // held by the caller for the whole of a job
  std::mutex mutex_;      // guards the job's fields below and the workers list
  std::condition_variable wake_;
  std::condition_variable done_;
  std::vector<std::thread> workers_;
  Call call_ = nullptr;
  void* task_ = nullptr;
  std::size_t tasks_ = 0;
  std::size_t next_ = 0;          // the next task to take
  std::size_t unfinished_ = 0;    // tasks not yet finished
  std::size_t participants_ = 0;  // workers asked to take part in the job
  std::size_t generation_ = 0;    // one per job: tells a worker there is a new one
  int nice_ = 0;                  // the job's caller's nice value
  bool stop_ = false;
};

}  // namespace pf
