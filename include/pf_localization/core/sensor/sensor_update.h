// The sensor step of the filter update: the sensor model on the map
// (sensor_model.h) and the weighing of the particles by a scan, MCL's
// importance weights (Thrun et al., "Probabilistic Robotics", table 8.2),
// tempered by applyLikelihood (weighting.h); while a global
// initialisation's cloud is too sparse for the model, by GlobalSearch's
// smoothed copy of it. Keeps the scratch storage, so that an update
// allocates nothing.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include "pf_localization/core/filter/particle_set.h"
#include "pf_localization/core/filter/resampling.h"
#include "pf_localization/core/filter/weighting.h"
#include "pf_localization/core/recovery/global_search.h"
#include "pf_localization/core/sensor/likelihood_field_model.h"
#include "pf_localization/core/sensor/sensor_model.h"

namespace pf {

/// What weighing one scan gave.
struct Weighing {
  double tempering = 1.0;  // the exponent applied to the scan's likelihood (1: none)
  int beams_skipped = 0;   // of the scan's beams, left out by beam skipping
  // How well the cloud explains the scan: the per-beam geometric mean
  // likelihood, averaged with the posterior weights.
  double mean_beam_likelihood = 0.0;
  double search_sigma = 0.0;  // the hit std dev of GlobalSearch's smoothed model (0: the model's)
};

/// The log-likelihood of a group of scans for every particle of
/// `particles`, into `log_likelihood`: one scan's as the model gives it,
/// several scans' summed, each times its LaserScan::weight (empty ones
/// skipped), with `scratch` for one scan's. On up to `threads` threads.
/// Returns how many beams the model counted (beam skipping may leave some out).
std::size_t groupLogLikelihoods(const SensorModel& model, const std::vector<PreparedScan>& scans,
                                const ParticleSet& particles, std::vector<double>* log_likelihood,
                                std::vector<double>* scratch, int threads = 1);

class SensorUpdate {
 public:
  /// A new model (a new map or new sensor parameters): a smoothed copy of
  /// the old one is dropped, and the new one is warmed up for every scan
  /// range expected (expectRange), so that the next update does not build
  /// its tables.
  void setModel(std::unique_ptr<SensorModel> model);
  /// Takes the model out (ParticleFilter::releaseMap): none is left.
  std::unique_ptr<SensorModel> releaseModel();
  /// Scans of `range_max` are to be weighed (a sensor's, seen before the
  /// map or with the last one): the model, and every later one, builds what
  /// they need now. Up to LikelihoodTables::kMaxTables ranges are kept, the
  /// latest.
  void expectRange(double range_max);
  /// The range_max values expected, oldest first.
  const std::vector<double>& ranges() const { return ranges_; }
  bool hasModel() const { return static_cast<bool>(model_); }
  /// Null without a model.
  const SensorModel* get() const { return model_.get(); }
  /// Precondition: hasModel().
  const SensorModel& model() const { return *model_; }

  /// Multiplies the weights of `particles` by the likelihood of `scan`,
  /// tempered so that at least `min_ess_fraction` of the effective sample
  /// size is left, and normalises them. `likelihood_exponent` is the sensor
  /// model's: the mean beam likelihood undoes it. The weighting runs on up
  /// to `threads` threads, with the same result for any count (the model
  /// scores on its own). Precondition: hasModel().
  Weighing weigh(const PreparedScan& scan, double min_ess_fraction, double likelihood_exponent,
                 ParticleSet* particles, int threads = 1);
  /// The same for the scans of several sensors (scan_group.h): their
  /// log-likelihoods, each times its PreparedScan::weight, add up. One scan
  /// weighs exactly as weigh() does.
  Weighing weigh(const std::vector<PreparedScan>& scans, double min_ess_fraction,
                 double likelihood_exponent, ParticleSet* particles, int threads = 1);

  /// The same two, weighing by `model` instead of the update's own (a
  /// smoothed copy of it: global_search.h). The second takes the scans'
  /// likelihood to the power `evidence_share`, the share of a new view the
  /// update brings (view_share.h; 0: the weights stay as they are); the mean
  /// beam likelihood is the scans' own.
  Weighing weigh(const SensorModel& model, const PreparedScan& scan, double min_ess_fraction,
                 double likelihood_exponent, ParticleSet* particles, int threads = 1);
  Weighing weigh(const SensorModel& model, const std::vector<PreparedScan>& scans,
                 double min_ess_fraction, double likelihood_exponent, ParticleSet* particles,
                 int threads = 1, double evidence_share = 1.0);

  /// The weighing of a filter update: `particles` by `scans`, an update
  /// that brings a share `view` of a new view (view_share.h), by the model
  /// or, while a global search's cloud is too sparse for it, by the search's
  /// smoothed copy (`sensor`: the model's parameters; `kld`: what sets how
  /// dense a cloud is); tempered to leave at least `min_ess_fraction` of the
  /// effective sample size, or the search's own floor while its cloud
  /// settles. Precondition: hasModel().
  Weighing weighCloud(const std::vector<PreparedScan>& scans, double view, double min_ess_fraction,
                      const LikelihoodFieldModelParams& sensor, const KldParams& kld,
                      ParticleSet* particles, int threads);
  /// A global search over `free_area` m^2 starts (GlobalSearch::start); an
  /// initialisation at a pose stops it.
  void startSearch(double free_area) { search_.start(free_area); }
  void stopSearch() { search_.stop(); }
  /// The places the update's cloud holds (GlobalSearch::observe).
  void observePlaces(std::size_t places) { search_.observe(places); }

  /// Prefaults the scratch for `n` particles.
  void reserve(std::size_t n);

 private:
  // Tempers and normalises log_likelihood_ into the weights; the report.
  Weighing finish(std::size_t beams, std::size_t beams_counted, double min_ess_fraction,
                  double likelihood_exponent, ParticleSet* particles, int threads,
                  double evidence_share = 1.0);

  std::unique_ptr<SensorModel> model_;
  std::vector<double> ranges_;  // the scans' range_max values expected, oldest first
  GlobalSearch search_;  // the smoothed model while a global initialisation's cloud is sparse
  std::vector<double> log_likelihood_;
  std::vector<double> sensor_log_likelihood_;  // one sensor's, while a group is summed
  WeightingScratch scratch_;
};

}  // namespace pf
