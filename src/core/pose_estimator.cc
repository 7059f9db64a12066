#include "pf_localization/core/pose_estimator.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "pf_localization/core/bin_index.h"
#include "pf_localization/core/bin_table.h"
#include "pf_localization/core/fast_math.h"
#include "pf_localization/core/thread_scratch.h"

namespace pf {
namespace {

struct BinKey {
  int64_t x, y, yaw;
  bool operator==(const BinKey& o) const { return x == o.x && y == o.y && yaw == o.yaw; }
};

int find(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

// Adds term(i, row) for every particle i into the row (kWidth values) of
// its group, group[i], in `rows`. Runs of particles in one group (nearly
// the whole cloud when tracking) add in registers, starting from and
// returning to the group's row: the additions are the same, in the same
// order, as adding each term to the row in memory, which made every
// particle wait for the one before through a store and a load.
template <int kWidth, typename Term>
void accumulateRuns(const std::vector<int>& group, double* rows, Term term) {
  const std::size_t n = group.size();
  std::size_t i = 0;
  while (i < n) {
    const int g = group[i];
    double* row = rows + static_cast<std::size_t>(kWidth) * g;
    double acc[kWidth];
    std::copy(row, row + kWidth, acc);
    for (; i < n && group[i] == g; ++i) term(i, acc);
    std::copy(acc, acc + kWidth, row);
  }
}

}  // namespace

Cluster summarize(const ParticleSet& particles, const std::vector<std::size_t>& indices) {
  Cluster c;
  c.count = indices.size();
  double sx = 0.0, sy = 0.0, ss = 0.0, sc = 0.0;
  for (std::size_t i : indices) {
    const double w = particles.weight[i];
    c.weight += w;
    sx += w * particles.x[i];
    sy += w * particles.y[i];
    ss += w * std::sin(particles.yaw[i]);
    sc += w * std::cos(particles.yaw[i]);
  }
  if (!(c.weight > 0.0)) return c;
  c.mean = {sx / c.weight, sy / c.weight, normalizeAngle(std::atan2(ss, sc))};
  for (std::size_t i : indices) {
    const Eigen::Vector3d d(particles.x[i] - c.mean.x, particles.y[i] - c.mean.y,
                            angleDiff(particles.yaw[i], c.mean.yaw));
    c.covariance += particles.weight[i] * d * d.transpose();
  }
  c.covariance /= c.weight;
  return c;
}

PoseEstimate estimatePose(const ParticleSet& particles, const ClusterParams& params) {
  PoseEstimate estimate;
  if (particles.empty()) return estimate;

  // Bin every particle; yaw bins wrap around, so the last bin touches the
  // first. The working storage is kept between calls (per thread), so that
  // estimating allocates nothing once the widest cloud has been seen.
  const int64_t yaw_bins = std::max<int64_t>(1, std::llround(2.0 * M_PI / params.cell_yaw));
  struct Scratch {
    BinTable bin_of;
    std::vector<BinKey> keys;
    std::vector<int> particle_bin, parent, cluster_of_root, cluster;
    std::vector<double> bin_weight, sin_yaw, cos_yaw, sums, moments;
  };
  Scratch& scratch = threadScratch<Scratch>();
  BinTable& bin_of = scratch.bin_of;
  std::vector<BinKey>& keys = scratch.keys;
  std::vector<int>& particle_bin = scratch.particle_bin;
  std::vector<int>& parent = scratch.parent;
  std::vector<int>& cluster_of_root = scratch.cluster_of_root;
  std::vector<int>& cluster = scratch.cluster;
  std::vector<double>& bin_weight = scratch.bin_weight;
  bin_of.reset(particles.size());
  keys.clear();
  particle_bin.resize(particles.size());
  // Resampling leaves the copies of one particle side by side, so the bin of
  // the particle before is the likeliest: it spares most hash look-ups.
  uint64_t last_key = ~uint64_t{0};
  int last_id = -1;
  for (std::size_t i = 0; i < particles.size(); ++i) {
    const double yaw01 = (normalizeAngle(particles.yaw[i]) + M_PI) / (2.0 * M_PI);
    const BinKey key{binIndex(particles.x[i], params.cell_xy),
                     binIndex(particles.y[i], params.cell_xy),
                     std::clamp<int64_t>(binIndex(yaw01, 1.0 / yaw_bins), 0, yaw_bins - 1)};
    const uint64_t packed = BinTable::key(key.x, key.y, key.yaw);
    if (packed != last_key) {
      last_id = bin_of.insert(packed);
      last_key = packed;
      if (static_cast<std::size_t>(last_id) == keys.size()) keys.push_back(key);
    }
    particle_bin[i] = last_id;
  }

  // Join occupied bins that touch (26-neighbourhood) into clusters, but only
  // bins that carry weight (see ClusterParams::join_weight_ratio).
  bin_weight.assign(keys.size(), 0.0);
  accumulateRuns<1>(particle_bin, bin_weight.data(),
                    [&](std::size_t i, double* a) { a[0] += particles.weight[i]; });
  const double join_weight =
      params.join_weight_ratio * *std::max_element(bin_weight.begin(), bin_weight.end());
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

  // Cluster ids in order of first appearance, then the weighted sums of each
  // cluster in two passes (means, then covariances) over flat arrays.
  // The roots are found once per bin, not once per particle.
  for (std::size_t b = 0; b < keys.size(); ++b) parent[b] = find(parent, static_cast<int>(b));
  cluster_of_root.assign(keys.size(), -1);
  cluster.resize(particles.size());
  int clusters = 0;
  for (std::size_t i = 0; i < particles.size(); ++i) {
    int& id = cluster_of_root[parent[particle_bin[i]]];
    if (id < 0) id = clusters++;
    cluster[i] = id;
  }
  // The headings' sines and cosines for the whole cloud at once (sinCos
  // vectorises), for the mean directions.
  std::vector<double>& sin_yaw = scratch.sin_yaw;
  std::vector<double>& cos_yaw = scratch.cos_yaw;
  sin_yaw.resize(particles.size());
  cos_yaw.resize(particles.size());
  sinCos(particles.yaw.data(), particles.size(), sin_yaw.data(), cos_yaw.data());
  std::vector<Cluster> c(clusters);
  // Per cluster: the count, the weight and the weighted sums of x, y, sin, cos.
  std::vector<double>& sums = scratch.sums;
  sums.assign(6 * static_cast<std::size_t>(clusters), 0.0);
  accumulateRuns<6>(cluster, sums.data(), [&](std::size_t i, double* a) {
    const double w = particles.weight[i];
    a[0] += 1.0;
    a[1] += w;
    a[2] += w * particles.x[i];
    a[3] += w * particles.y[i];
    a[4] += w * sin_yaw[i];
    a[5] += w * cos_yaw[i];
  });
  for (int k = 0; k < clusters; ++k) {
    const double* sum = &sums[6 * static_cast<std::size_t>(k)];
    c[k].count = static_cast<std::size_t>(sum[0]);
    c[k].weight = sum[1];
    const double w = c[k].weight > 0.0 ? c[k].weight : 1.0;
    c[k].mean = {sum[2] / w, sum[3] / w, normalizeAngle(std::atan2(sum[4], sum[5]))};
  }
  // The second moments in plain arrays (an Eigen temporary per particle went
  // through the stack and stalled on store forwarding), with the same
  // products in the same order as w d d^T.
  std::vector<double>& moments = scratch.moments;
  moments.assign(9 * static_cast<std::size_t>(clusters), 0.0);
  accumulateRuns<9>(cluster, moments.data(), [&](std::size_t i, double* m) {
    const Cluster& k = c[cluster[i]];
    const double d[3] = {particles.x[i] - k.mean.x, particles.y[i] - k.mean.y,
                         angleDiff(particles.yaw[i], k.mean.yaw)};
    const double w = particles.weight[i];
    for (int r = 0; r < 3; ++r) {
      const double wd = w * d[r];
      for (int col = 0; col < 3; ++col) m[3 * col + r] += wd * d[col];
    }
  });
  for (int k = 0; k < clusters; ++k) {
    c[k].covariance = Eigen::Map<const Eigen::Matrix3d>(&moments[9 * static_cast<std::size_t>(k)]);
    if (c[k].weight > 0.0) c[k].covariance /= c[k].weight;
  }
  estimate.clusters = std::move(c);
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
