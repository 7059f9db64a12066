#include "pf_localization/core/sensor/sensor_update.h"

#include <algorithm>
#include <cmath>

#include "pf_localization/core/filter/particle_blocks.h"
#include "pf_localization/core/sensor/scan_group.h"
#include "pf_localization/core/util/scratch_storage.h"

namespace pf {

Weighing SensorUpdate::weigh(const PreparedScan& scan, double min_ess_fraction,
                             double likelihood_exponent, ParticleSet* particles, int threads) {
  return weigh(*model_, scan, min_ess_fraction, likelihood_exponent, particles, threads);
}

std::size_t groupLogLikelihoods(const SensorModel& model, const std::vector<PreparedScan>& scans,
                                const ParticleSet& particles, std::vector<double>* log_likelihood,
                                std::vector<double>* scratch, int threads) {
  if (scans.size() == 1) return model.logLikelihoods(scans.front(), particles, log_likelihood);
  log_likelihood->assign(particles.size(), 0.0);
  std::size_t beams_counted = 0;
  for (const PreparedScan& scan : scans) {
    if (scan.size() == 0) continue;
    beams_counted += model.logLikelihoods(scan, particles, scratch);
    forEachSlice(log_likelihood->size(), threads, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) (*log_likelihood)[i] += scan.weight * (*scratch)[i];
    });
  }
  return beams_counted;
}

Weighing SensorUpdate::weigh(const std::vector<PreparedScan>& scans, double min_ess_fraction,
                             double likelihood_exponent, ParticleSet* particles, int threads) {
  return weigh(*model_, scans, min_ess_fraction, likelihood_exponent, particles, threads);
}

Weighing SensorUpdate::weigh(const SensorModel& model, const PreparedScan& scan,
                             double min_ess_fraction, double likelihood_exponent,
                             ParticleSet* particles, int threads) {
  const std::size_t beams_counted = model.logLikelihoods(scan, *particles, &log_likelihood_);
  return finish(scan.size(), beams_counted, min_ess_fraction, likelihood_exponent, particles,
                threads);
}

Weighing SensorUpdate::weigh(const SensorModel& model, const std::vector<PreparedScan>& scans,
                             double min_ess_fraction, double likelihood_exponent,
                             ParticleSet* particles, int threads, double evidence_share) {
  const std::size_t beams_counted = groupLogLikelihoods(model, scans, *particles, &log_likelihood_,
                                                        &sensor_log_likelihood_, threads);
  return finish(beamCount(scans), beams_counted, min_ess_fraction, likelihood_exponent, particles,
                threads, evidence_share);
}

void SensorUpdate::setModel(std::unique_ptr<SensorModel> model) {
  model_ = std::move(model);
  search_.forgetModel();
  if (model_) {
    for (double range_max : ranges_) model_->warmUp(range_max);
  }
}

std::unique_ptr<SensorModel> SensorUpdate::releaseModel() {
  search_.forgetModel();
  return std::move(model_);
}

void SensorUpdate::expectRange(double range_max) {
  if (!std::isfinite(range_max) || !(range_max > 0.0)) return;
  if (std::find(ranges_.begin(), ranges_.end(), range_max) != ranges_.end()) return;
  if (ranges_.size() == LikelihoodTables::kMaxTables) ranges_.erase(ranges_.begin());
  ranges_.push_back(range_max);
  if (model_) model_->warmUp(range_max);
}

Weighing SensorUpdate::weighCloud(const std::vector<PreparedScan>& scans, double view,
                                  double min_ess_fraction, const LikelihoodFieldModelParams& sensor,
                                  const KldParams& kld, ParticleSet* particles, int threads) {
  for (const PreparedScan& scan : scans) expectRange(scan.range_max);
  const double ess_fraction = std::max(min_ess_fraction, search_.minEssFraction());
  const SensorModel* smoothed = search_.model(*model_, sensor.sigma_hit, sensor.max_distance, scans,
                                              *particles, kld, threads);
  Weighing w = weigh(smoothed ? *smoothed : *model_, scans, ess_fraction,
                     sensor.likelihood_exponent, particles, threads, view);
  w.search_sigma = search_.sigma();
  return w;
}

Weighing SensorUpdate::finish(std::size_t beams, std::size_t beams_counted, double min_ess_fraction,
                              double likelihood_exponent, ParticleSet* particles, int threads,
                              double evidence_share) {
  Weighing w;
  // A partial view's evidence: the likelihood to the power of its share
  // (the mean below divides the share out again).
  double share = 1.0;
  if (evidence_share <= 0.0) {
    w.tempering = 0.0;  // no new view: the weights stay as they are
  } else {
    if (evidence_share < 1.0) {
      share = evidence_share;
      for (double& l : log_likelihood_) l *= share;
    }
    w.tempering = share * applyLikelihood(log_likelihood_, min_ess_fraction, &particles->weight,
                                          &scratch_, threads);
  }
  w.beams_skipped = static_cast<int>(beams - beams_counted);
  // The per-beam geometric mean is independent of the beam count, so
  // comparable across scans and robots. Weighted with the posterior, not the
  // prior, so that a few particles that found the robot count for what they
  // are worth, and a cloud salted with random particles is not judged by
  // them. Over the beams the model counted: beam skipping may leave some out.
  const double counted =
      static_cast<double>(std::max<std::size_t>(beams_counted, 1)) * likelihood_exponent * share;
  w.mean_beam_likelihood = meanBeamLikelihood(particles->weight, log_likelihood_, counted, threads);
  return w;
}

void SensorUpdate::reserve(std::size_t n) {
  for (std::vector<double>* v :
       {&scratch_.log_prior, &scratch_.log_posterior, &log_likelihood_, &sensor_log_likelihood_}) {
    prefault(v, n);
  }
}

}  // namespace pf
