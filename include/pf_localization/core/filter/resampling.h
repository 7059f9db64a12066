// Low-variance (systematic) resampling, with the particle count adapted by
// KLD-sampling.
//
// Systematic resampling: Thrun, Burgard & Fox, "Probabilistic Robotics"
// (2005), table 4.4. One random offset and N evenly spaced pointers into the
// cumulative weights pick every survivor in a single O(N) pass, with less
// variance than drawing each survivor independently.
//
// KLD-sampling: Fox, "Adapting the Sample Size in Particle Filters Through
// KLD-Sampling", IJRR 22(12), 2003. The number of particles needed so that,
// with probability `confidence`, the KL divergence between the sample-based
// and the true posterior stays below `kld_err` grows with k, the number of
// histogram bins the posterior occupies:
//   n = (k - 1) / (2 err) * (1 - 2/(9(k-1)) + sqrt(2/(9(k-1))) z)^3
// where z is the upper `confidence` quantile of the standard normal.
#pragma once

#include <cstddef>
#include <vector>

#include "pf_localization/core/filter/particle_set.h"
#include "pf_localization/core/util/parameter_table.h"
#include "pf_localization/core/util/random.h"

namespace pf {

/// 1 / sum(w^2) of normalised weights: N for uniform weights, 1 when one
/// particle carries all the weight.
double effectiveSampleSize(const std::vector<double>& weights, int threads = 1);

/// Replaces `particles` with `n` survivors drawn systematically by weight;
/// the survivors get uniform weights.
void systematicResample(ParticleSet* particles, std::size_t n, Random* random);
/// The same into `out` (not `in`), whose storage is reused: a filter that
/// alternates two sets allocates nothing per update. On up to `threads`
/// threads, with the same survivors for any count.
void systematicResample(const ParticleSet& in, std::size_t n, Random* random, ParticleSet* out,
                        int threads = 1);

struct KldParams {
  int min_particles = 500;
  int max_particles = 50000;
  double kld_err = 0.01;     // bound on the KL divergence (unitless)
  double confidence = 0.99;  // probability that the bound holds
  double bin_xy = 0.5;       // histogram bin size (m)
  double bin_yaw = 0.1745;   // histogram bin size (rad), 10 degrees
};

/// The parameters of KldParams (parameter_table.h): the particle bounds and
/// KLD-sampling's error bound and confidence. (The histogram's bins are ours
/// to choose, not the user's.)
const ParameterTable<KldParams>& kldParameters();

/// The z with P(Z <= z) = p for a standard normal Z (p in (0, 1)): 2.326 for 0.99.
double normalQuantile(double p);

/// KLD bound on the particle count for k occupied bins (not clamped).
double kldBound(std::size_t k, double kld_err, double confidence);

/// The bins of KLD-sampling's histogram (bin_xy, bin_yaw) whose weight
/// promises at least one survivor of a resample of the current size: the
/// cloud's support, in bins. Counted block by block on up to `threads`
/// threads: the same for any count.
std::size_t occupiedBins(const ParticleSet& particles, const KldParams& params, int threads = 1);

/// The particle count KLD-sampling asks for after resampling `particles`:
/// k counts the bins expected to receive at least one survivor, clamped to
/// [min_particles, max_particles]. The bins are counted block by block on
/// up to `threads` threads (particle_blocks.h): the same for any count.
std::size_t kldParticleCount(const ParticleSet& particles, const KldParams& params,
                             int threads = 1);

}  // namespace pf
