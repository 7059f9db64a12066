#include "pf_localization/core/estimate/cluster_estimate.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "pf_localization/core/filter/particle_blocks.h"
#include "pf_localization/core/util/bin_table.h"
#include "pf_localization/core/util/fast_math.h"
#include "pf_localization/core/util/scratch_storage.h"

namespace pf {
namespace {

int find(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

// Adds term(i, row) for every particle i in [begin, end) into the row
// (kWidth values) of its group, group[i], in `rows`. Runs of particles in
// one group (nearly the whole cloud when tracking) add in registers,
// starting from and returning to the group's row: the additions are the
// same, in the same order, as adding each term to the row in memory, which
// made every particle wait for the one before through a store and a load.
template <int kWidth, typename Term>
void accumulateRuns(const int* group, std::size_t begin, std::size_t end, double* rows, Term term) {
  std::size_t i = begin;
  while (i < end) {
    const int g = group[i];
    double* row = rows + static_cast<std::size_t>(kWidth) * g;
    double acc[kWidth];
    std::copy(row, row + kWidth, acc);
    for (; i < end && group[i] == g; ++i) term(i, acc);
    std::copy(acc, acc + kWidth, row);
  }
}

// The packed histogram bin (BinTable::key) of one particle; yaw bins wrap
// around, [0, yaw_bins). The reference for packClusterBinsAvx2.
uint64_t packedBinOf(double x, double y, double yaw, double cell_xy, int64_t yaw_bins,
                     double yaw_bin_size) {
  const double yaw01 = (normalizeAngle(yaw) + M_PI) / (2.0 * M_PI);
  return BinTable::key(binIndex(x, cell_xy), binIndex(y, cell_xy),
                       std::clamp<int64_t>(binIndex(yaw01, yaw_bin_size), 0, yaw_bins - 1));
}

#if defined(__x86_64__)
// Four coordinates' bins in `cell`s as BinTable fields: floor(v / cell),
// NaN to 0, clamped to [lo, hi], offset by `half`.
__attribute__((target("avx2"))) inline __m256i binField(__m256d v, __m256d cell, __m256d lo,
                                                        __m256d hi, __m256i half) {
  const __m256d b = _mm256_floor_pd(_mm256_div_pd(v, cell));
  const __m256d nan_to_zero = _mm256_and_pd(b, _mm256_cmp_pd(b, b, _CMP_ORD_Q));
  const __m256d clamped = _mm256_min_pd(_mm256_max_pd(nan_to_zero, lo), hi);
  return _mm256_add_epi64(_mm256_cvtepi32_epi64(_mm256_cvttpd_epi32(clamped)), half);
}

// packedBinOf for four particles at a time, with the same operations on
// each (division, floor, the same clamps), so the same keys. A block with a
// heading that one step of 2 pi does not wrap (or NaN) is left to the scalar
// code. Returns how many particles it packed (a multiple of four).
__attribute__((target("avx2"))) std::size_t packClusterBinsAvx2(const ParticleSet& particles,
                                                                std::size_t begin, std::size_t n,
                                                                double cell_xy, int64_t yaw_bins,
                                                                double yaw_bin_size,
                                                                uint64_t* out) {
  const __m256d cell = _mm256_set1_pd(cell_xy), yaw_cell = _mm256_set1_pd(yaw_bin_size);
  const __m256d pi = _mm256_set1_pd(M_PI), minus_pi = _mm256_set1_pd(-M_PI);
  const __m256d two_pi = _mm256_set1_pd(2.0 * M_PI);
  // BinTable's fields hold [-2^20, 2^20); binIndex's own +-2^52 clamp is
  // inside that once BinTable clamps, and NaN goes to bin 0 as in binIndex.
  const __m256d lo = _mm256_set1_pd(-1048576.0), hi = _mm256_set1_pd(1048575.0);
  const __m256d zero = _mm256_setzero_pd();
  const __m256d yaw_hi = _mm256_set1_pd(static_cast<double>(yaw_bins - 1));
  const __m256i half = _mm256_set1_epi64x(int64_t{1} << 20);

  std::size_t i = begin;
  for (; i + 4 <= n; i += 4) {
    const __m256d a = _mm256_loadu_pd(particles.yaw.data() + i);
    // normalizeAngle's one step: a > pi and a <= -pi never both hold.
    __m256d w = _mm256_sub_pd(a, _mm256_and_pd(_mm256_cmp_pd(a, pi, _CMP_GT_OQ), two_pi));
    w = _mm256_add_pd(w, _mm256_and_pd(_mm256_cmp_pd(a, minus_pi, _CMP_LE_OQ), two_pi));
    const __m256d wrapped =
        _mm256_and_pd(_mm256_cmp_pd(w, pi, _CMP_LE_OQ), _mm256_cmp_pd(w, minus_pi, _CMP_GT_OQ));
    if (_mm256_movemask_pd(wrapped) != 0xF) break;
    const __m256d yaw01 = _mm256_div_pd(_mm256_add_pd(w, pi), two_pi);
    const __m256d yaw_bin =
        _mm256_min_pd(_mm256_max_pd(_mm256_floor_pd(_mm256_div_pd(yaw01, yaw_cell)), zero), yaw_hi);
    const __m256i fyaw =
        _mm256_add_epi64(_mm256_cvtepi32_epi64(_mm256_cvttpd_epi32(yaw_bin)), half);
    const __m256i fx = binField(_mm256_loadu_pd(particles.x.data() + i), cell, lo, hi, half);
    const __m256i fy = binField(_mm256_loadu_pd(particles.y.data() + i), cell, lo, hi, half);
    const __m256i key = _mm256_or_si256(
        _mm256_or_si256(_mm256_slli_epi64(fx, 42), _mm256_slli_epi64(fy, 21)), fyaw);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + i), key);
  }
  return i;
}
#endif

}  // namespace

void packClusterBins(const ParticleSet& particles, std::size_t begin, std::size_t end,
                     double cell_xy, int64_t yaw_bins, uint64_t* out) {
  const double yaw_bin_size = 1.0 / static_cast<double>(yaw_bins);
  std::size_t i = begin;
#if defined(__x86_64__)
  static const bool avx2 = __builtin_cpu_supports("avx2");
  if (avx2) i = packClusterBinsAvx2(particles, begin, end, cell_xy, yaw_bins, yaw_bin_size, out);
#endif
  for (; i < end; ++i) {
    out[i] = packedBinOf(particles.x[i], particles.y[i], particles.yaw[i], cell_xy, yaw_bins,
                         yaw_bin_size);
  }
}

void packClusterBins(const ParticleSet& particles, double cell_xy, int64_t yaw_bins,
                     uint64_t* out) {
  packClusterBins(particles, 0, particles.size(), cell_xy, yaw_bins, out);
}

namespace {

// Adds particle i's second moments about `mean` (its cluster's, or the
// whole cloud's) (in plain arrays: an Eigen temporary per particle went
// through the stack and stalled on store forwarding), with the same
// products in the same order as w d d^T.
inline void addMomentTerms(const ParticleSet& particles, const Pose2& mean, std::size_t i,
                           double* m) {
  const double d[3] = {particles.x[i] - mean.x, particles.y[i] - mean.y,
                       angleDiff(particles.yaw[i], mean.yaw)};
  const double w = particles.weight[i];
  for (int r = 0; r < 3; ++r) {
    const double wd = w * d[r];
    for (int col = 0; col < 3; ++col) m[3 * col + r] += wd * d[col];
  }
}

// summarize() of the `count` particles index(0), index(1), ...
template <typename Index>
Cluster summarizeIndexed(const ParticleSet& particles, std::size_t count, Index index,
                         int threads) {
  struct Sums {
    double w = 0.0, sx = 0.0, sy = 0.0, ss = 0.0, sc = 0.0;
  };
  // The headings' sines and cosines a chunk at a time (sinCos vectorises; a
  // C library call per particle was a tenth of a million-particle update).
  const Sums sums = reduceBlockRanges(
      count, threads, Sums(),
      [&](std::size_t begin, std::size_t end, Sums& a) {
        constexpr std::size_t kChunk = 1024;
        alignas(64) double yaw[kChunk], sin_yaw[kChunk], cos_yaw[kChunk];
        for (std::size_t from = begin; from < end; from += kChunk) {
          const std::size_t m = std::min(kChunk, end - from);
          for (std::size_t j = 0; j < m; ++j) yaw[j] = particles.yaw[index(from + j)];
          sinCos(yaw, m, sin_yaw, cos_yaw);
          for (std::size_t j = 0; j < m; ++j) {
            const std::size_t i = index(from + j);
            const double w = particles.weight[i];
            a.w += w;
            a.sx += w * particles.x[i];
            a.sy += w * particles.y[i];
            a.ss += w * sin_yaw[j];
            a.sc += w * cos_yaw[j];
          }
        }
      },
      [](Sums& into, const Sums& from) {
        into.w += from.w;
        into.sx += from.sx;
        into.sy += from.sy;
        into.ss += from.ss;
        into.sc += from.sc;
      });
  Cluster c;
  c.count = count;
  c.weight = sums.w;
  if (!(c.weight > 0.0)) return c;
  c.mean = {sums.sx / c.weight, sums.sy / c.weight, normalizeAngle(std::atan2(sums.ss, sums.sc))};
  // The moments in plain arrays (addMomentTerms), not an Eigen matrix per
  // particle: the same products and sums.
  struct Moments {
    double m[9] = {};
  };
  const Moments moments = reduceBlocks(
      count, threads, Moments(),
      [&](std::size_t k, Moments& a) { addMomentTerms(particles, c.mean, index(k), a.m); },
      [](Moments& into, const Moments& from) {
        for (int e = 0; e < 9; ++e) into.m[e] += from.m[e];
      });
  c.covariance = Eigen::Map<const Eigen::Matrix3d>(moments.m) / c.weight;
  return c;
}

}  // namespace

Cluster summarize(const ParticleSet& particles, const std::vector<std::size_t>& indices,
                  int threads) {
  return summarizeIndexed(
      particles, indices.size(), [&](std::size_t k) { return indices[k]; }, threads);
}

Cluster summarize(const ParticleSet& particles, int threads) {
  return summarizeIndexed(
      particles, particles.size(), [](std::size_t k) { return k; }, threads);
}

namespace {

// The working storage of estimatePose, kept between calls (per thread), so
// that estimating allocates nothing once the widest cloud has been seen.
struct EstimatorScratch {
  BinTable bin_of;
  std::vector<uint64_t> packed;
  std::vector<BinTable::Bin> keys;
  std::vector<int> particle_bin, parent, cluster_of_root, cluster, cluster_of_bin;
  std::vector<double> bin_weight, sin_yaw, cos_yaw, sums, moments;
  std::vector<Pose2> bin_mean;
};

// A cloud of several blocks (particle_blocks.h) is binned block by block:
// each block's bins in order of first appearance in it, then the blocks'
// bins merged in block order, which is the order of first appearance in
// the whole cloud. Sums over particles are taken per bin of each block and
// added up in block order: the same bits for any thread count.
struct BlockBins {
  BinTable table;
  std::vector<uint64_t> keys;  // the block's bins, in order of first appearance
  std::vector<int> global;     // each of them as a bin of the whole cloud
  std::size_t row = 0;         // the block's first row in BlockScratch::rows
};
struct BlockScratch {
  std::vector<BlockBins> blocks;
  std::vector<int> local_bin;  // each particle's bin in its block
  std::vector<double> rows;    // per block, per bin of the block: the sums
};

// Bins every particle: s->keys the occupied bins in order of first
// appearance, s->particle_bin[i] the index of particle i's bin in them.
void binParticles(const ParticleSet& particles, double cell_xy, int64_t yaw_bins,
                  EstimatorScratch* s) {
  BinTable& bin_of = s->bin_of;
  std::vector<BinTable::Bin>& keys = s->keys;
  std::vector<int>& particle_bin = s->particle_bin;
  bin_of.reset(particles.size());
  keys.clear();
  particle_bin.resize(particles.size());
  // The keys first, for the whole cloud (vectorised), then the look-ups.
  // Bins beyond +-2^20 cells (524 km at 0.5 m) share the edge bin.
  std::vector<uint64_t>& packed = s->packed;
  packed.resize(particles.size());
  packClusterBins(particles, cell_xy, yaw_bins, packed.data());
  // Resampling leaves the copies of one particle side by side, so the bin of
  // the particle before is the likeliest: it spares most hash look-ups.
  uint64_t last_key = ~uint64_t{0};
  int last_id = -1;
  for (std::size_t i = 0; i < particles.size(); ++i) {
    if (packed[i] != last_key) {
      last_id = bin_of.insert(packed[i]);
      last_key = packed[i];
      if (static_cast<std::size_t>(last_id) == keys.size())
        keys.push_back(BinTable::unpack(last_key));
    }
    particle_bin[i] = last_id;
  }
}

// binParticles block by block, with the blocks' bins in *b.
void binParticlesByBlock(const ParticleSet& particles, double cell_xy, int64_t yaw_bins,
                         int threads, EstimatorScratch* s, BlockScratch* b) {
  const std::size_t n = particles.size();
  const std::size_t blocks = blockCount(n);
  std::vector<uint64_t>& packed = s->packed;
  packed.resize(n);
  b->local_bin.resize(n);
  if (b->blocks.size() < blocks) b->blocks.resize(blocks);
  forEachBlock(n, threads, [&](std::size_t k, std::size_t begin, std::size_t end) {
    packClusterBins(particles, begin, end, cell_xy, yaw_bins, packed.data());
    BlockBins& block = b->blocks[k];
    block.table.reset(end - begin);
    block.keys.clear();
    uint64_t last_key = ~uint64_t{0};
    int last_id = -1;
    for (std::size_t i = begin; i < end; ++i) {
      if (packed[i] != last_key) {
        last_id = block.table.insert(packed[i]);
        last_key = packed[i];
        if (static_cast<std::size_t>(last_id) == block.keys.size()) block.keys.push_back(last_key);
      }
      b->local_bin[i] = last_id;
    }
  });
  std::size_t most = 0;  // bins, at most
  for (std::size_t k = 0; k < blocks; ++k) most += b->blocks[k].keys.size();
  s->bin_of.reset(most);
  s->keys.clear();
  std::size_t row = 0;
  for (std::size_t k = 0; k < blocks; ++k) {
    BlockBins& block = b->blocks[k];
    block.global.resize(block.keys.size());
    block.row = row;
    row += block.keys.size();
    for (std::size_t l = 0; l < block.keys.size(); ++l) {
      const int id = s->bin_of.insert(block.keys[l]);
      if (static_cast<std::size_t>(id) == s->keys.size()) {
        s->keys.push_back(BinTable::unpack(block.keys[l]));
      }
      block.global[l] = id;
    }
  }
  s->particle_bin.resize(n);
  forEachBlock(n, threads, [&](std::size_t k, std::size_t begin, std::size_t end) {
    const std::vector<int>& global = b->blocks[k].global;
    for (std::size_t i = begin; i < end; ++i) s->particle_bin[i] = global[b->local_bin[i]];
  });
}

// The first half of sumByBlockBins: adds term(i, row) of every particle i
// into the kWidth-wide row of its bin in its block, in b->rows.
template <int kWidth, typename Term>
void sumIntoBlockRows(std::size_t n, int threads, BlockScratch* b, Term term) {
  const std::size_t blocks = blockCount(n);
  const std::size_t rows = b->blocks[blocks - 1].row + b->blocks[blocks - 1].keys.size();
  b->rows.assign(kWidth * rows, 0.0);
  forEachBlock(n, threads, [&](std::size_t k, std::size_t begin, std::size_t end) {
    // Straight into the rows, not in runs (accumulateRuns): a cloud of
    // several blocks is a large one, rarely converged, whose runs of one
    // bin are short, and a branch at every end of a run cost more than
    // going through memory.
    double* block_rows = b->rows.data() + kWidth * b->blocks[k].row;
    for (std::size_t i = begin; i < end; ++i) {
      term(i, block_rows + static_cast<std::size_t>(kWidth) * b->local_bin[i]);
    }
  });
}

// The second half: adds the columns [kFirst, kFirst + kCount) of the
// blocks' kWidth-wide rows (sumIntoBlockRows) into the kCount-wide row
// out[target(bin)] of each one's bin (a bin of the whole cloud), block
// after block.
template <int kWidth, int kFirst, int kCount, typename Target>
void mergeBlockRows(std::size_t n, const BlockScratch& b, Target target, double* out) {
  for (std::size_t k = 0; k < blockCount(n); ++k) {
    const BlockBins& block = b.blocks[k];
    for (std::size_t l = 0; l < block.keys.size(); ++l) {
      const double* from = b.rows.data() + kWidth * (block.row + l) + kFirst;
      double* to = out + static_cast<std::size_t>(kCount) * target(block.global[l]);
      for (int c = 0; c < kCount; ++c) to[c] += from[c];
    }
  }
}

// Adds term(i, row) of every particle i into the kWidth-wide row
// out[target(bin)] of its bin (`bin` a bin of the whole cloud): per bin of
// each block, then those sums in block order. `out` holds zeros.
template <int kWidth, typename Target, typename Term>
void sumByBlockBins(std::size_t n, int threads, BlockScratch* b, Target target, Term term,
                    double* out) {
  sumIntoBlockRows<kWidth>(n, threads, b, term);
  mergeBlockRows<kWidth, 0, kWidth>(n, *b, target, out);
}

// Joins occupied bins that touch (26-neighbourhood) into clusters, but only
// bins that carry weight (see ClusterParams::join_weight_ratio), given each
// bin's weight in s->bin_weight: s->parent is the union-find forest over
// s->keys.
void joinTouchingBins(double join_weight_ratio, int64_t yaw_bins, EstimatorScratch* s) {
  const BinTable& bin_of = s->bin_of;
  const std::vector<BinTable::Bin>& keys = s->keys;
  std::vector<int>& parent = s->parent;
  const std::vector<double>& bin_weight = s->bin_weight;
  const double join_weight =
      join_weight_ratio * *std::max_element(bin_weight.begin(), bin_weight.end());
  parent.resize(keys.size());
  std::iota(parent.begin(), parent.end(), 0);
  for (std::size_t b = 0; b < keys.size(); ++b) {
    if (bin_weight[b] < join_weight) continue;
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dt = -1; dt <= 1; ++dt) {
          // Joining is symmetric: half the neighbourhood is enough.
          if (dx < 0 || (dx == 0 && (dy < 0 || (dy == 0 && dt <= 0)))) continue;
          const int n =
              bin_of.find(BinTable::key(keys[b].x + dx, keys[b].y + dy,
                                        ((keys[b].yaw + dt) % yaw_bins + yaw_bins) % yaw_bins));
          if (n >= 0 && bin_weight[n] >= join_weight) {
            parent[find(parent, static_cast<int>(b))] = find(parent, n);
          }
        }
      }
    }
  }
}

// Cluster ids in order of first appearance of their bins:
// s->cluster_of_bin[b] for bin b. Returns the number of clusters. The roots
// are found once per bin, not once per particle. As the bins are numbered
// in order of first appearance, so are the clusters.
int labelBins(EstimatorScratch* s) {
  std::vector<int>& parent = s->parent;
  std::vector<int>& cluster_of_root = s->cluster_of_root;
  const std::size_t bins = s->keys.size();
  for (std::size_t b = 0; b < bins; ++b) parent[b] = find(parent, static_cast<int>(b));
  cluster_of_root.assign(bins, -1);
  s->cluster_of_bin.resize(bins);
  int clusters = 0;
  for (std::size_t b = 0; b < bins; ++b) {
    int& id = cluster_of_root[parent[b]];
    if (id < 0) id = clusters++;
    s->cluster_of_bin[b] = id;
  }
  return clusters;
}

// The mean of cluster k from its sums (count, weight, and the weighted sums
// of x, y, sin, cos).
void meanFromSums(const double* sum, Cluster* c) {
  c->count = static_cast<std::size_t>(sum[0]);
  c->weight = sum[1];
  const double w = c->weight > 0.0 ? c->weight : 1.0;
  c->mean = {sum[2] / w, sum[3] / w, normalizeAngle(std::atan2(sum[4], sum[5]))};
}

// Adds particle i's terms to its cluster's sums of meanFromSums.
inline void addMeanTerms(const ParticleSet& particles, const double* sin_yaw, const double* cos_yaw,
                         std::size_t i, double* a) {
  const double w = particles.weight[i];
  a[0] += 1.0;
  a[1] += w;
  a[2] += w * particles.x[i];
  a[3] += w * particles.y[i];
  a[4] += w * sin_yaw[i];
  a[5] += w * cos_yaw[i];
}

// Each cluster's covariance from its summed second moments.
void covariancesFromMoments(const std::vector<double>& moments, std::vector<Cluster>* clusters) {
  std::vector<Cluster>& c = *clusters;
  for (std::size_t k = 0; k < c.size(); ++k) {
    c[k].covariance = Eigen::Map<const Eigen::Matrix3d>(&moments[9 * k]);
    if (c[k].weight > 0.0) c[k].covariance /= c[k].weight;
  }
}

// The sums of a cloud of one block: particle by particle, in order, into
// the rows of each particle's bin or cluster.
struct SumsInOrder {
  EstimatorScratch* s;
  // Each bin's weight (weight_term); the means' terms are summed later,
  // per cluster.
  template <typename WeightTerm, typename MeanTerm>
  void binWeights(WeightTerm weight_term, MeanTerm, double* out) {
    accumulateRuns<1>(s->particle_bin.data(), 0, s->particle_bin.size(), out, weight_term);
  }
  // Once the bins are labelled: each cluster's sums of mean_term (six wide).
  template <typename MeanTerm>
  void clusterMeans(MeanTerm mean_term, double* out) {
    s->cluster.resize(s->particle_bin.size());
    for (std::size_t i = 0; i < s->particle_bin.size(); ++i) {
      s->cluster[i] = s->cluster_of_bin[s->particle_bin[i]];
    }
    perCluster<6>(mean_term, out);
  }
  template <int kWidth, typename Term>
  void perCluster(Term term, double* out) {
    accumulateRuns<kWidth>(s->cluster.data(), 0, s->cluster.size(), out, term);
  }
};

// The sums of a cloud of several blocks: per bin of each block, then in
// block order (sumByBlockBins), on up to `threads` threads.
struct SumsByBlock {
  EstimatorScratch* s;
  BlockScratch* b;
  std::size_t n;
  int threads;
  // The means' terms per bin of each block, in one pass, kept for
  // clusterMeans; the bins' weights are their second column (mean_term
  // adds the weight there, as weight_term would: the same sums).
  template <typename WeightTerm, typename MeanTerm>
  void binWeights(WeightTerm, MeanTerm mean_term, double* out) {
    sumIntoBlockRows<6>(n, threads, b, mean_term);
    mergeBlockRows<6, 1, 1>(
        n, *b, [](int bin) { return bin; }, out);
  }
  template <typename MeanTerm>
  void clusterMeans(MeanTerm, double* out) {
    mergeBlockRows<6, 0, 6>(
        n, *b, [&](int bin) { return s->cluster_of_bin[bin]; }, out);
  }
  template <int kWidth, typename Term>
  void perCluster(Term term, double* out) {
    const std::vector<int>& cluster_of_bin = s->cluster_of_bin;
    sumByBlockBins<kWidth>(
        n, threads, b, [&](int bin) { return cluster_of_bin[bin]; }, term, out);
  }
};

// The clusters of the binned cloud (s->keys, s->particle_bin): the bins'
// weights, the touching ones joined, then each cluster's mean and
// covariance, every sum taken by `sums`.
template <typename Sums>
std::vector<Cluster> clustersOfBins(const ParticleSet& particles, const ClusterParams& params,
                                    int64_t yaw_bins, int threads, EstimatorScratch* s, Sums sums) {
  // The headings' sines and cosines for the whole cloud at once (sinCos
  // vectorises), for the mean directions.
  const std::size_t n = particles.size();
  s->sin_yaw.resize(n);
  s->cos_yaw.resize(n);
  double* sin_yaw = s->sin_yaw.data();
  double* cos_yaw = s->cos_yaw.data();
  forEachSlice(n, threads, [&](std::size_t begin, std::size_t end) {
    sinCos(particles.yaw.data() + begin, end - begin, sin_yaw + begin, cos_yaw + begin);
  });
  const auto mean_terms = [&](std::size_t i, double* a) {
    addMeanTerms(particles, sin_yaw, cos_yaw, i, a);
  };
  s->bin_weight.assign(s->keys.size(), 0.0);
  sums.binWeights([&](std::size_t i, double* a) { a[0] += particles.weight[i]; }, mean_terms,
                  s->bin_weight.data());
  joinTouchingBins(params.join_weight_ratio, yaw_bins, s);
  const int clusters = labelBins(s);
  std::vector<Cluster> c(clusters);
  s->sums.assign(6 * static_cast<std::size_t>(clusters), 0.0);
  sums.clusterMeans(mean_terms, s->sums.data());
  for (int k = 0; k < clusters; ++k) {
    meanFromSums(&s->sums[6 * static_cast<std::size_t>(k)], &c[k]);
  }
  // Each bin's cluster mean, so that a particle finds its mean in one small
  // table, not through its cluster's id into the clusters.
  s->bin_mean.resize(s->keys.size());
  for (std::size_t b = 0; b < s->keys.size(); ++b) s->bin_mean[b] = c[s->cluster_of_bin[b]].mean;
  s->moments.assign(9 * c.size(), 0.0);
  const Pose2* bin_mean = s->bin_mean.data();
  const int* particle_bin = s->particle_bin.data();
  sums.template perCluster<9>(
      [&](std::size_t i, double* m) { addMomentTerms(particles, bin_mean[particle_bin[i]], i, m); },
      s->moments.data());
  covariancesFromMoments(s->moments, &c);
  return c;
}

// The clusters of the cloud: binned in one pass for one block, block by
// block for several.
std::vector<Cluster> clustersOf(const ParticleSet& particles, const ClusterParams& params,
                                int64_t yaw_bins, int threads, EstimatorScratch* s) {
  if (blockCount(particles.size()) <= 1) {
    binParticles(particles, params.cell_xy, yaw_bins, s);
    return clustersOfBins(particles, params, yaw_bins, threads, s, SumsInOrder{s});
  }
  BlockScratch& b = threadScratch<BlockScratch>();
  binParticlesByBlock(particles, params.cell_xy, yaw_bins, threads, s, &b);
  return clustersOfBins(particles, params, yaw_bins, threads, s,
                        SumsByBlock{s, &b, particles.size(), threads});
}

}  // namespace

PoseEstimate estimatePose(const ParticleSet& particles, const ClusterParams& params, int threads) {
  PoseEstimate estimate;
  if (particles.empty()) return estimate;
  // Yaw bins wrap around, so the last bin touches the first.
  const int64_t yaw_bins = std::max<int64_t>(1, std::llround(2.0 * M_PI / params.cell_yaw));
  EstimatorScratch& scratch = threadScratch<EstimatorScratch>();
  estimate.clusters = clustersOf(particles, params, yaw_bins, threads, &scratch);
  // Heaviest first; ties broken by the mean so the order never depends on hashing.
  std::sort(estimate.clusters.begin(), estimate.clusters.end(),
            [](const Cluster& a, const Cluster& b) {
              if (a.weight != b.weight) return a.weight > b.weight;
              if (a.mean.x != b.mean.x) return a.mean.x < b.mean.x;
              return a.mean.y < b.mean.y;
            });
  estimate.pose = estimate.clusters.front().mean;
  estimate.covariance = estimate.clusters.front().covariance;
  return estimate;
}

}  // namespace pf
