// The weighting step of the filter update: the prior weights times the
// scan's likelihood, tempered when the evidence is too strong for the cloud,
// normalised; how cautiously to temper (temperingEssFraction); and how well
// the weighted cloud explains the scan. Tempering raises the likelihood to a
// power below 1, the idea of annealed importance sampling (Neal, Statistics
// and Computing 11, 2001). The filter keeps the scratch storage, so that an
// update allocates nothing.
#pragma once

#include <vector>

#include "pf_localization/core/estimate/confidence.h"
#include "pf_localization/core/filter/particle_filter_params.h"

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

// How cautiously a scan's evidence is weighed: the ESS fraction that
// applyLikelihood tempers the likelihood to keep. Cautious while rival
// hypotheses stand, so that they survive until the scans separate them; not
// for a wide cloud whose beams fit (see docs/design.md, "Tempering follows
// the last verdict").
/// tempering_ess_fraction while the last update's scan said "localized", or
/// "uncertain" only by the cloud's spread; tempering_ess_fraction_uncertain
/// otherwise. `fit_state` is that scan's verdict before holdAfterJump,
/// `last` the confidence it gave (rivals, hit fraction).
double temperingEssFraction(LocalizationState fit_state, const Confidence& last,
                            const ParticleFilterParams& params);

}  // namespace pf
