// The weighting step of the filter update: the prior weights times the
// scan's likelihood, tempered when the evidence is too strong for the cloud,
// normalised; and how well the weighted cloud explains the scan.
//
// Apart from ParticleFilter so that each step can be measured on its own
// (bench/filter_benchmark.cc); the filter keeps the scratch storage, so that
// an update allocates nothing.
#pragma once

#include <vector>

namespace pf {

/// Working storage of applyLikelihood, kept between updates.
struct WeightingScratch {
  std::vector<double> log_prior;
  std::vector<double> log_posterior;
};

/// Multiplies the normalised prior `weights` by exp(beta * log_likelihood)
/// and normalises them, beta the largest exponent in [0, 1] (found by
/// bisection) that leaves at least min_ess_fraction times the prior's
/// effective sample size (0 disables tempering: beta = 1). When every
/// particle has likelihood zero the weights are left as they were. Returns
/// beta. On up to `threads` threads, with the same result for any count
/// (particle_blocks.h).
double applyLikelihood(const std::vector<double>& log_likelihood, double min_ess_fraction,
                       std::vector<double>* weights, WeightingScratch* scratch, int threads = 1);

/// sum_i weights[i] * exp(log_likelihood[i] / beams): the per-beam geometric
/// mean likelihood, averaged with the weights.
double meanBeamLikelihood(const std::vector<double>& weights,
                          const std::vector<double>& log_likelihood, double beams, int threads = 1);

}  // namespace pf
