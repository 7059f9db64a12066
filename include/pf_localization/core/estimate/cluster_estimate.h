// The pose estimate and its covariance, from a weighted particle cloud.
//
// Particles are binned on a coarse (x, y, yaw) grid and neighbouring occupied
// bins are joined into clusters. The estimate is the weighted mean of the
// heaviest cluster, with a circular mean for yaw, so that a cloud split between
// two places reports one of them rather than a point between them. The
// covariance is that cluster's weighted covariance; yaw deviations are taken
// from the circular mean.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "pf_localization/core/filter/particle_set.h"

namespace pf {

struct ClusterParams {
  double cell_xy = 0.5;      // bin size (m)
  double cell_yaw = 0.5236;  // bin size (rad), 30 degrees
  // Bins holding less than this fraction of the heaviest bin's weight are
  // not joined to their neighbours. Thousands of barely weighted particles
  // (recovery's random guesses) touch each other all over a map; joined, they
  // made one cluster the size of the building, whose weighted mean was
  // dragged metres away from the particles that carry the weight. [0, 1]
  double join_weight_ratio = 1e-3;
};

struct Cluster {
  double weight = 0.0;  // summed particle weight
  Pose2 mean;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  // x, y, yaw
  std::size_t count = 0;
};

struct PoseEstimate {
  Pose2 pose;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  // of the heaviest cluster
  std::vector<Cluster> clusters;                         // heaviest first
};

/// Weighted mean and covariance of a set of particles (indices into
/// `particles`), on up to `threads` threads with the same result for any
/// count (particle_blocks.h).
Cluster summarize(const ParticleSet& particles, const std::vector<std::size_t>& indices,
                  int threads = 1);
/// The same for the whole cloud (no list of its indices to build).
Cluster summarize(const ParticleSet& particles, int threads = 1);

/// The histogram bin of every particle that estimatePose clusters by, packed
/// by BinTable::key: x and y in cells of `cell_xy`, the heading (wrapped into
/// (-pi, pi]) in `yaw_bins` bins that wrap around. Four particles at a time
/// where the processor has AVX2, with the same keys as one by one.
void packClusterBins(const ParticleSet& particles, double cell_xy, int64_t yaw_bins, uint64_t* out);
/// The same for the particles [begin, end) only (out[begin, end)).
void packClusterBins(const ParticleSet& particles, std::size_t begin, std::size_t end,
                     double cell_xy, int64_t yaw_bins, uint64_t* out);

/// Clusters the cloud and summarises every cluster; the estimate is the heaviest.
/// An empty set gives an estimate with no clusters. On up to `threads`
/// threads: a cloud of several blocks (particle_blocks.h) is binned and
/// summed block by block, so the result is the same for any count.
PoseEstimate estimatePose(const ParticleSet& particles, const ClusterParams& params,
                          int threads = 1);

}  // namespace pf
