// The particles cut into fixed blocks: the unit of the filter's parallel
// work, chosen so that the result never depends on the thread count.
//
// Work that depends on order (a random stream, a floating-point sum) is done
// block by block: each block has its own stream and its own partial sums,
// and the partial sums are added in block order. The blocks' boundaries
// depend only on the particle count (as many blocks of equal size as it
// takes to hold at most 2^16 particles each), so the threads that run them (any
// number, in any order) give the same bits. A cloud of one block, which
// every cloud of the filter's default budget is (max_particles 50 000), is
// processed exactly as the sequential code always did: one stream, one sum.
//
// Work that is particle by particle (scoring, moving, copying) is split
// evenly over the threads instead; where the particles are few, splitting
// costs more than it saves, so it stays on the calling thread.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

#include "pf_localization/core/util/random.h"
#include "pf_localization/core/util/worker_pool.h"

namespace pf {

/// The most particles in a block: 2^16, above the default max_particles
/// (50 000), so that a cloud of the default budget is a single block.
inline constexpr std::size_t kParticleBlock = std::size_t{1} << 16;

/// Below this many particles per thread, splitting particle-by-particle work
/// over threads costs more (waking the pool's workers and waiting for them)
/// than it saves:
/// about 0.1 ms of work at the motion and weighting steps' few ns per
/// particle.
inline constexpr std::size_t kMinParticlesPerThread = 16384;

/// The number of blocks of `n` particles (0 for none).
inline std::size_t blockCount(std::size_t n) { return (n + kParticleBlock - 1) / kParticleBlock; }

/// The particles [blockBegin(b, n), blockEnd(b, n)) of block `b` of `n`:
/// the blocks are as equal as whole particles allow, so that the threads
/// get even shares (fixed 2^16-particle blocks split 100 000 as 2:1).
inline std::size_t blockBegin(std::size_t b, std::size_t n) { return n * b / blockCount(n); }
inline std::size_t blockEnd(std::size_t b, std::size_t n) { return blockBegin(b + 1, n); }

/// How many threads to use for `n` particles of particle-by-particle work,
/// given `threads` (at least 1).
inline int threadsFor(std::size_t n, int threads) {
  const std::size_t useful = std::max<std::size_t>(1, n / kMinParticlesPerThread);
  return static_cast<int>(
      std::min<std::size_t>(static_cast<std::size_t>(std::max(threads, 1)), useful));
}

/// Calls f(b, begin, end) for every block b of `n` particles, on up to
/// `threads` threads (worker_pool.h), in no particular order.
template <typename F>
void forEachBlock(std::size_t n, int threads, F&& f) {
  auto block = [&](std::size_t b) { f(b, blockBegin(b, n), blockEnd(b, n)); };
  WorkerPool::instance().run(threads, blockCount(n), block);
}

/// Reduces the particles [0, n) block by block: each block's State starts
/// from `init` and takes its particles in order, in one or more calls
/// add(begin, end, state) over consecutive ranges; the blocks' States are
/// then merged in block order (merge(into, from)). One block's State is the
/// result as it is, so a cloud of one block gives the bits of the plain
/// sequential loop.
template <typename State, typename AddRange, typename Merge>
State reduceBlockRanges(std::size_t n, int threads, const State& init, AddRange&& add,
                        Merge&& merge) {
  const std::size_t blocks = blockCount(n);
  if (blocks <= 1) {
    State state = init;
    add(std::size_t{0}, n, state);
    return state;
  }
  struct Partial {
    State state;  // (a struct: std::vector<bool> has no data())
  };
  thread_local std::vector<Partial> partial;  // kept: no allocation per update
  partial.assign(blocks, Partial{init});
  Partial* out = partial.data();
  forEachBlock(n, threads, [&](std::size_t b, std::size_t begin, std::size_t end) {
    State state = init;
    add(begin, end, state);
    out[b].state = state;
  });
  State state = partial[0].state;
  for (std::size_t b = 1; b < blocks; ++b) merge(state, partial[b].state);
  return state;
}

/// reduceBlockRanges particle by particle: add(i, state) for each i in turn.
template <typename State, typename Add, typename Merge>
State reduceBlocks(std::size_t n, int threads, const State& init, Add&& add, Merge&& merge) {
  return reduceBlockRanges(
      n, threads, init,
      [&](std::size_t begin, std::size_t end, State& state) {
        for (std::size_t i = begin; i < end; ++i) add(i, state);
      },
      merge);
}

/// The sum of term(i) over [0, n), added block by block (reduceBlocks).
template <typename Term>
double sumBlocks(std::size_t n, int threads, Term&& term) {
  return reduceBlocks(
      n, threads, 0.0, [&](std::size_t i, double& sum) { sum += term(i); },
      [](double& into, double from) { into += from; });
}

/// Calls f(begin, end) on even slices of [0, n) that cover it, on up to
/// `threads` threads: particle by particle work, whose result does not
/// depend on how it is split. On one thread, one slice: f(0, n).
template <typename F>
void forEachSlice(std::size_t n, int threads, F&& f) {
  const std::size_t t = static_cast<std::size_t>(threadsFor(n, threads));
  if (t <= 1) {
    f(std::size_t{0}, n);
    return;
  }
  // Slices of about kMinParticlesPerThread, many more than threads, taken
  // in turn by whichever thread is free: a thread that the OS leaves
  // waiting (the cores are shared) then holds the others up for one small
  // slice, not for a 1/t share of the work.
  const std::size_t slices = std::max(t, n / kMinParticlesPerThread);
  auto slice = [&](std::size_t k) { f(n * k / slices, n * (k + 1) / slices); };
  WorkerPool::instance().run(static_cast<int>(t), slices, slice);
}

/// The random streams of the blocks of a cloud: block 0 draws from the
/// filter's own stream, so that a cloud of one block draws exactly what it
/// always did; every other block from a stream of its own, seeded from the
/// filter's stream in block order when the streams are made. Storage is kept
/// between calls (one object per use, reused): no allocation per update.
class BlockStreams {
 public:
  /// Streams for the blocks of `n` particles.
  void reset(std::size_t n, Random* random) {
    random_ = random;
    others_.clear();
    for (std::size_t b = 1; b < blockCount(n); ++b) others_.emplace_back(random->bits());
  }
  /// Block b's stream (b < blockCount(n)).
  Random* stream(std::size_t b) { return b == 0 ? random_ : &others_[b - 1]; }

 private:
  Random* random_ = nullptr;
  std::vector<Random> others_;
};

}  // namespace pf
