// Publications handed to roscpp's poll thread, a batch at a time.
//
// roscpp sends every message from its poll thread: publishing on another
// thread wakes it (a pipe write) to watch the socket, and again to stop
// watching it. A filter update that publishes map -> odom and two poses
// woke it about five times; the floor of a localizer (bench/
// plumbing_floor_node.cc), which publishes from the poll thread itself,
// none. Jobs posted on a thread inside a Batch reach the poll thread
// together when the batch ends, with one wake-up (an eventfd in roscpp's
// poll set), and run there in the order posted (docs/performance.md,
// "The fixed cost").
//
// Threads: post() from any thread but while stop() runs. A job must not wait for anything that a
// thread may hold while it waits for the poll thread (pf_node's filter
// mutex, say): publishing does not.
#pragma once

#include <functional>
#include <memory>
#include <mutex>
#include <vector>

namespace pf_ros {

class PollThreadOutbox {
 public:
  using Job = std::function<void()>;

  PollThreadOutbox() = default;
  ~PollThreadOutbox() { stop(); }
  PollThreadOutbox(const PollThreadOutbox&) = delete;
  PollThreadOutbox& operator=(const PollThreadOutbox&) = delete;

  /// Jobs go to the poll thread from now on (ros::start() must have run: a
  /// NodeHandle exists). Before, and when this fails (logged), each runs at
  /// once where it is posted.
  void start();
  /// From now on each job runs at once again; waits for a job running on the
  /// poll thread and drops those not yet run. Call before anything the jobs
  /// use goes.
  void stop();

  /// Runs `job` on the poll thread: when this thread's Batch ends, or at
  /// once if it has none (at once where it is, when not started).
  void post(Job job);

  /// Collects this thread's posts until it ends, then hands them over together.
  class Batch {
   public:
    explicit Batch(PollThreadOutbox* outbox);
    ~Batch();
    Batch(const Batch&) = delete;
    Batch& operator=(const Batch&) = delete;

   private:
    friend class PollThreadOutbox;
    PollThreadOutbox* outbox_;
    std::vector<Job> jobs_;
    Batch* outer_;  // the batch this one is nested in, if any
  };

 private:
  struct Shared {
    std::mutex run_mutex;    // held while jobs run; stop() takes it
    bool alive = true;       // under run_mutex
    std::mutex queue_mutex;  // guards jobs
    std::vector<Job> jobs;
    int fd = -1;  // the eventfd
  };
  // Queues `jobs` (moved from) and wakes the poll thread; false when not started.
  bool hand(std::vector<Job>* jobs);
  static void runQueued(Shared* shared);

  std::shared_ptr<Shared> shared_;
};

}  // namespace pf_ros
