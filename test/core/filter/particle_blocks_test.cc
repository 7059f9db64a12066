// The filter's parallel work (particle_blocks.h): the same bits for any
// thread count, and a cloud of one block as the sequential code left it.
#include "pf_localization/core/filter/particle_blocks.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <thread>
#include <vector>

#include "pf_localization/core/estimate/cluster_estimate.h"
#include "pf_localization/core/filter/particle_filter.h"
#include "pf_localization/core/filter/resampling.h"
#include "support/rooms.h"
#include "support/scan_simulator.h"

namespace pf {
namespace {

TEST(ParticleBlocks, BlocksCoverTheCloudInEqualShares) {
  EXPECT_EQ(0u, blockCount(0));
  EXPECT_EQ(1u, blockCount(1));
  EXPECT_EQ(1u, blockCount(kParticleBlock));
  EXPECT_EQ(0u, blockBegin(0, kParticleBlock));
  EXPECT_EQ(kParticleBlock, blockEnd(0, kParticleBlock));
  EXPECT_EQ(2u, blockCount(kParticleBlock + 1));
  // 100 000 particles: two blocks of 50 000, not 65 536 and 34 464.
  EXPECT_EQ(50000u, blockEnd(0, 100000));
  EXPECT_EQ(50000u, blockBegin(1, 100000));
  EXPECT_EQ(100000u, blockEnd(1, 100000));
  // A million: 16 blocks, each within a particle of the others, none over
  // the limit, each starting where the one before ended.
  const std::size_t n = 1000000;
  ASSERT_EQ(16u, blockCount(n));
  for (std::size_t b = 0; b < blockCount(n); ++b) {
    const std::size_t size = blockEnd(b, n) - blockBegin(b, n);
    EXPECT_TRUE(size == n / 16 || size == n / 16 + 1) << b;
    EXPECT_LE(size, kParticleBlock);
    if (b > 0) {
      EXPECT_EQ(blockEnd(b - 1, n), blockBegin(b, n));
    }
  }
  EXPECT_EQ(n, blockEnd(15, n));
  // The default budget is one block: its clouds are processed as before.
  EXPECT_EQ(1u, blockCount(static_cast<std::size_t>(KldParams().max_particles)));
}

TEST(ParticleBlocks, SmallCloudsStayOnOneThread) {
  EXPECT_EQ(1, threadsFor(5000, 8));
  EXPECT_EQ(1, threadsFor(2 * kMinParticlesPerThread - 1, 8));
  EXPECT_EQ(2, threadsFor(2 * kMinParticlesPerThread, 8));
  EXPECT_EQ(2, threadsFor(1000000, 2));
  EXPECT_EQ(1, threadsFor(1000000, 0));
}

TEST(ParticleBlocks, AReductionAddsTheBlocksInOrderForAnyThreadCount) {
  // Terms whose sum depends on the order of the additions.
  const std::size_t n = 3 * kParticleBlock + 17;
  std::vector<double> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = std::pow(10.0, static_cast<double>(i % 23) - 11.0);
  const auto sum = [&](int threads) {
    return sumBlocks(n, threads, [&](std::size_t i) { return v[i]; });
  };
  double expected = 0.0;
  for (std::size_t b = 0; b < blockCount(n); ++b) {
    double part = 0.0;
    for (std::size_t i = blockBegin(b, n); i < blockEnd(b, n); ++i) part += v[i];
    expected = b == 0 ? part : expected + part;
  }
  for (int threads : {1, 2, 3, 8}) EXPECT_EQ(expected, sum(threads)) << threads << " threads";
  // One block: the plain loop's bits.
  double plain = 0.0;
  for (std::size_t i = 0; i < kParticleBlock; ++i) plain += v[i];
  EXPECT_EQ(plain, sumBlocks(kParticleBlock, 2, [&](std::size_t i) { return v[i]; }));
}

TEST(ParticleBlocks, BlockZeroDrawsFromTheFiltersOwnStream) {
  Random a(7), b(7);
  BlockStreams streams;
  streams.reset(kParticleBlock, &a);  // one block: no seeds drawn
  EXPECT_EQ(b.bits(), streams.stream(0)->bits());
  // Several blocks: the others' seeds come first, in block order.
  Random c(7), d(7);
  streams.reset(3 * kParticleBlock, &c);
  d.bits();
  d.bits();
  EXPECT_EQ(d.bits(), streams.stream(0)->bits());
  EXPECT_NE(streams.stream(1)->bits(), streams.stream(2)->bits());
}

TEST(WorkerPool, RunsEveryTaskOnceAndReturnsWhenAllAreDone) {
  for (int threads : {1, 2, 4}) {
    std::vector<std::atomic<int>> runs(37);
    auto task = [&](std::size_t k) { runs[k]++; };
    WorkerPool::instance().run(threads, runs.size(), task);
    for (const auto& r : runs) EXPECT_EQ(1, r.load()) << threads << " threads";
  }
}

TEST(WorkerPool, JobsFromTwoThreadsAtOnceBothFinish) {
  // One of them finds the pool busy and runs its tasks alone.
  std::vector<std::atomic<long>> sums(2);
  const auto job = [&](int j) {
    for (int round = 0; round < 200; ++round) {
      auto task = [&](std::size_t k) { sums[j] += static_cast<long>(k); };
      WorkerPool::instance().run(2, 100, task);
    }
  };
  std::thread a(job, 0), b(job, 1);
  a.join();
  b.join();
  EXPECT_EQ(200L * 4950, sums[0].load());
  EXPECT_EQ(200L * 4950, sums[1].load());
}

TEST(WorkerPool, WorkersRunAtTheirCallersLowerPriority) {
  // A caller that lowered its own priority, as pf_node's filter thread does.
  int caller = 0, lowest = 100;
  std::mutex m;
  std::thread lowered([&] {
    const auto tid = static_cast<id_t>(::syscall(SYS_gettid));
    ::setpriority(PRIO_PROCESS, tid, ::getpriority(PRIO_PROCESS, tid) + 3);
    caller = ::getpriority(PRIO_PROCESS, tid);
    auto task = [&](std::size_t) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));  // every worker gets a task
      const int nice = ::getpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid)));
      std::lock_guard<std::mutex> lock(m);
      lowest = std::min(lowest, nice);
    };
    WorkerPool::instance().run(2, 4, task);
  });
  lowered.join();
  EXPECT_EQ(caller, lowest);
}

// A cloud of `n` particles with uneven weights, spread over a square of
// `size` metres.
ParticleSet spreadCloud(std::size_t n, uint64_t seed, double size = 10.0) {
  Random random(seed);
  ParticleSet set;
  set.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    set.setPose(
        i, {random.uniform(0.0, size), random.uniform(0.0, size), random.uniform(-M_PI, M_PI)});
    set.weight[i] = random.uniform() * random.uniform();
  }
  double total = 0.0;
  for (double w : set.weight) total += w;
  for (double& w : set.weight) w /= total;
  return set;
}

TEST(ParticleBlocks, ResamplingOnTwoThreadsPicksTheSameSurvivorsAsOne) {
  // One block, so that the one-thread path is the sequential loop itself.
  const ParticleSet cloud = spreadCloud(50000, 3);
  ParticleSet one, two;
  Random r1(5), r2(5);
  systematicResample(cloud, 40000, &r1, &one, 1);
  systematicResample(cloud, 40000, &r2, &two, 2);
  EXPECT_EQ(one.x, two.x);
  EXPECT_EQ(one.y, two.y);
  EXPECT_EQ(one.yaw, two.yaw);
  EXPECT_EQ(one.weight, two.weight);
}

TEST(ParticleBlocks, TheEstimateOfSeveralBlocksIsTheSameForAnyThreadCount) {
  // Sparse enough over 500 m that most particles are clusters of their own.
  const ParticleSet cloud = spreadCloud(3 * kParticleBlock + 100, 4, 500.0);
  const PoseEstimate one = estimatePose(cloud, ClusterParams(), 1);
  ASSERT_GT(one.clusters.size(), 100u);
  for (int threads : {2, 3}) {
    const PoseEstimate many = estimatePose(cloud, ClusterParams(), threads);
    ASSERT_EQ(one.clusters.size(), many.clusters.size());
    for (std::size_t k = 0; k < one.clusters.size(); ++k) {
      EXPECT_EQ(one.clusters[k].weight, many.clusters[k].weight);
      EXPECT_EQ(one.clusters[k].count, many.clusters[k].count);
      EXPECT_EQ(one.clusters[k].mean.x, many.clusters[k].mean.x);
      EXPECT_EQ(one.clusters[k].mean.yaw, many.clusters[k].mean.yaw);
      EXPECT_TRUE(one.clusters[k].covariance == many.clusters[k].covariance);
    }
  }
}

TEST(ParticleBlocks, TheEstimateOfSeveralBlocksAgreesWithOneBlocksSums) {
  // Block by block only changes the order of the additions: the clusters
  // are the same, their sums within rounding.
  const ParticleSet cloud = spreadCloud(2 * kParticleBlock + 100, 6);
  const PoseEstimate whole = estimatePose(cloud, ClusterParams(), 2);
  const Cluster all_of_it = summarize(cloud, 2);
  double weight = 0.0;
  std::size_t count = 0;
  for (const Cluster& c : whole.clusters) {
    weight += c.weight;
    count += c.count;
  }
  EXPECT_EQ(cloud.size(), count);
  EXPECT_NEAR(1.0, weight, 1e-12);
  EXPECT_NEAR(1.0, all_of_it.weight, 1e-12);
  EXPECT_NEAR(5.0, all_of_it.mean.x, 0.05);
}

// The whole filter: a global localization of four blocks' worth of
// particles, with KLD-sampling, over several updates, on 1, 2 and 3
// threads: every particle the same, bit for bit.
TEST(ParticleBlocks, TheFilterGivesTheSameParticlesForAnyThreadCount) {
  const OccupancyGrid grid = test::asymmetricRoom();
  const auto run = [&](int threads) {
    ParticleFilterParams params;
    params.kld.min_particles = 500;
    params.kld.max_particles = static_cast<int>(3 * kParticleBlock + 1000);
    params.seed = 11;
    params.threads = threads;
    params.update_min_d = params.update_min_a = 0.0;
    ParticleFilter filter(params);
    filter.setMap(grid);
    filter.initializeUniform();
    test::ScanSpec spec;
    Pose2 truth{1.5, 1.5, 0.3};
    for (int k = 0; k < 6; ++k) {
      const Pose2 odom{0.05 * k, 0.0, 0.0};
      const Pose2 robot = compose(truth, odom);
      filter.update(odom, test::simulateScan(grid, robot, spec));
    }
    return filter;
  };
  const ParticleFilter one = run(1);
  for (int threads : {2, 3}) {
    const ParticleFilter many = run(threads);
    EXPECT_EQ(one.particles().x, many.particles().x) << threads << " threads";
    EXPECT_EQ(one.particles().y, many.particles().y) << threads << " threads";
    EXPECT_EQ(one.particles().yaw, many.particles().yaw) << threads << " threads";
    EXPECT_EQ(one.particles().weight, many.particles().weight) << threads << " threads";
    EXPECT_EQ(one.estimate().pose.x, many.estimate().pose.x);
    EXPECT_EQ(one.estimate().pose.y, many.estimate().pose.y);
    EXPECT_EQ(one.estimate().pose.yaw, many.estimate().pose.yaw);
  }
}

}  // namespace
}  // namespace pf
