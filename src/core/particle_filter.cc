#include "pf_localization/core/particle_filter.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace pf {

std::unique_ptr<SensorModel> makeSensorModel(const OccupancyGrid& grid,
                                             const ParticleFilterParams& params) {
  switch (params.laser_model_type) {
    case LaserModelType::kBeam:
      return std::make_unique<BeamModel>(grid, params.sensor, params.beam);
    case LaserModelType::kLikelihoodFieldProb:
      return std::make_unique<LikelihoodFieldModel>(grid, params.sensor);
    case LaserModelType::kLikelihoodField:
      break;
  }
  // amcl's likelihood_field never skips beams.
  LikelihoodFieldModelParams sensor = params.sensor;
  sensor.beam_skip = false;
  return std::make_unique<LikelihoodFieldModel>(grid, sensor);
}

ParticleFilter::ParticleFilter(const ParticleFilterParams& params)
    : params_((validate(params), params)), random_(params.seed), motion_model_(params.motion) {
  // Room for the largest cloud from the start: the particle count swings
  // between min and max particles, and reallocating would make the process's
  // memory swing with it (and allocate on the update path). The storage is
  // also written once here: the kernel backs untouched pages lazily, so
  // reserving alone let the resident memory creep up by megabytes, hours into
  // a run, the first time a re-initialisation or recovery made the cloud
  // larger than ever before (scripts/soak.sh showed it).
  reserveStorage(static_cast<std::size_t>(params_.kld.max_particles));
}

void ParticleFilter::reserveStorage(std::size_t max) {
  // Growing to `max` and back writes the new pages and keeps what is there
  // (setParams reserves more under live particles).
  const auto prefault = [max](auto* v) {
    const std::size_t n = v->size();
    v->resize(std::max(max, n));
    v->resize(n);  // keeps the capacity, and the pages
  };
  for (ParticleSet* set : {&particles_, &spare_}) {
    for (std::vector<double>* v : {&set->x, &set->y, &set->yaw, &set->weight}) prefault(v);
  }
  for (std::vector<double>* v :
       {&weighting_.log_prior, &weighting_.log_posterior, &log_likelihood_}) {
    prefault(v);
  }
  prefault(&faulty_);
}

namespace {

// Whether the sensor model built from `a` would be the one built from `b`.
bool sameSensor(const ParticleFilterParams& a, const ParticleFilterParams& b) {
  const LikelihoodFieldModelParams &s = a.sensor, &t = b.sensor;
  return a.laser_model_type == b.laser_model_type && s.z_hit == t.z_hit && s.z_rand == t.z_rand &&
         s.sigma_hit == t.sigma_hit && s.max_distance == t.max_distance &&
         s.max_beams == t.max_beams && s.range_min == t.range_min && s.range_max == t.range_max &&
         s.likelihood_exponent == t.likelihood_exponent && s.threads == t.threads &&
         s.beam_skip == t.beam_skip && s.beam_skip_distance == t.beam_skip_distance &&
         s.beam_skip_threshold == t.beam_skip_threshold &&
         s.beam_skip_error_threshold == t.beam_skip_error_threshold &&
         a.beam.z_short == b.beam.z_short && a.beam.z_max == b.beam.z_max &&
         a.beam.lambda_short == b.beam.lambda_short;
}

}  // namespace

void ParticleFilter::setParams(const ParticleFilterParams& params) {
  validate(params);
  // Everything that can throw comes before the first change.
  OdometryMotionModel motion(params.motion);
  std::unique_ptr<SensorModel> model;
  if (model_ && !sameSensor(params, params_)) {
    // The model holds its parameters and its table of beam likelihoods; the
    // distance field under them depends on laser_likelihood_max_dist too.
    model = makeSensorModel(model_->field().grid(), params);
  }
  if (params.kld.max_particles > params_.kld.max_particles) {
    reserveStorage(static_cast<std::size_t>(params.kld.max_particles));
  }
  const uint64_t seed = params_.seed;
  params_ = params;
  params_.seed = seed;
  motion_model_ = motion;
  if (model) model_ = std::move(model);
  fault_fraction_ =
      std::clamp(fault_fraction_, params_.motion.fault_fraction, params_.motion.fault_fraction_max);
}

bool ParticleFilter::setMap(const OccupancyGrid& grid) {
  if (grid.empty()) throw std::invalid_argument("the map is empty");
  model_ = makeSensorModel(grid, params_);
  refined_.reset();  // fitted to the old map
  if (isInitialized() && grid.isFreeAt(estimate_.pose.x, estimate_.pose.y)) return true;
  particles_.resize(0);  // keeps the reserved storage
  estimate_ = PoseEstimate();
  has_estimate_ = false;
  return false;
}

void ParticleFilter::initializeGaussian(const Pose2& mean, const Eigen::Matrix3d& cov) {
  if (!mean.isFinite()) throw std::invalid_argument("initial pose is not finite");
  if (!cov.allFinite() || !cov.isApprox(cov.transpose(), 1e-9)) {
    throw std::invalid_argument("initial covariance must be finite and symmetric");
  }
  // LDLT accepts semi-definite matrices (a zero yaw variance is legitimate).
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(cov);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().array() >= -1e-12).all()) {
    throw std::invalid_argument("initial covariance must be positive semi-definite");
  }
  const Eigen::Matrix3d l = ldlt.matrixL();
  const Eigen::Vector3d sqrt_d = ldlt.vectorD().cwiseMax(0.0).cwiseSqrt();
  const Eigen::Matrix3d factor = ldlt.transpositionsP().transpose() * (l * sqrt_d.asDiagonal());

  particles_.resize(params_.kld.max_particles);
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    const Eigen::Vector3d n(random_.gaussian(1.0), random_.gaussian(1.0), random_.gaussian(1.0));
    const Eigen::Vector3d d = factor * n;
    particles_.setPose(i, {mean.x + d.x(), mean.y + d.y(), normalizeAngle(mean.yaw + d.z())});
  }
  particles_.setUniformWeights();
  estimate_ = estimatePose(particles_, params_.clusters);
  restartAfterInitialization();
}

void ParticleFilter::initializeUniform() {
  if (!model_) throw std::logic_error("global localization needs a map");
  if (model_->field().grid().freeCells().empty()) {
    throw std::logic_error("global localization needs a map with free cells");
  }
  particles_.resize(params_.kld.max_particles);
  for (std::size_t i = 0; i < particles_.size(); ++i) particles_.setPose(i, randomFreePose());
  particles_.setUniformWeights();
  estimate_ = estimatePose(particles_, params_.clusters);
  restartAfterInitialization();
}

void ParticleFilter::restartAfterInitialization() {
  // The new particles describe the robot now: the odometry travelled since the
  // last update must not move them again, so the next update skips motion.
  restart_ = true;
  has_estimate_ = false;
  refined_.reset();
  confidence_ = Confidence();
  confidence_.state = LocalizationState::kUncertain;
  fit_state_ = confidence_.state;
  confidence_.reason = "no scan since the initialisation";
  confidence_.covariance = estimate_.covariance;
  w_slow_ = w_fast_ = 0.0;
  low_fit_updates_ = 0;
  settle_left_ = 0;
  fault_fraction_ = params_.motion.fault_fraction;
}

Pose2 ParticleFilter::randomFreePose() {
  const OccupancyGrid& grid = model_->field().grid();
  const std::vector<int>& free = grid.freeCells();
  const int cell = free[random_.index(free.size())];
  const CellIndex c{cell % grid.width(), cell / grid.width()};
  // Anywhere inside the cell, not only its centre.
  const Pose2 local{(c.x + random_.uniform()) * grid.resolution(),
                    (c.y + random_.uniform()) * grid.resolution(), random_.uniform(-M_PI, M_PI)};
  return compose(grid.origin(), local);
}

UpdateReport ParticleFilter::update(const Pose2& odom, const LaserScan& scan) {
  UpdateReport report;
  report.particles = particles_.size();
  if (!model_) {
    report.skip_reason = "no map yet";
    return report;
  }
  if (!isInitialized()) {
    report.skip_reason = "the filter is not initialised";
    return report;
  }
  if (!odom.isFinite()) {
    report.skip_reason = "the odometry pose is not finite";
    return report;
  }
  if (const auto error = validateScan(scan)) {
    report.skip_reason = "bad scan: " + *error;
    return report;
  }

  const bool first = restart_ || !odom_at_update_;
  std::optional<PreparedScan> checked;  // prepared for the fit check, reused by the update
  double step = 0.0;                    // m of odometry since the last update
  if (!first) {
    const Pose2 delta = between(*odom_at_update_, odom);
    step = std::hypot(delta.x, delta.y);
    if (!(step <= params_.odom_jump_limit)) {
      // Wheels do not carry a robot this far between two scans: the odometry
      // was reset or glitched. Moving the particles by it would throw them
      // away, so the step is skipped and tracking resumes from the new pose.
      odom_at_update_ = odom;
      report.skip_reason = "odometry jumped " + std::to_string(step) +
                           " m since the last update (odom_jump_limit " +
                           std::to_string(params_.odom_jump_limit) +
                           " m): treated as an odometry fault, particles not moved";
      return report;
    }
    // While the faulty particles win (a reversal, a stall), the odometry
    // between updates is what is wrong: every scan updates the filter then,
    // instead of the published pose following the wrong odometry until the
    // robot has "moved" update_min_d.
    const bool odometry_suspect = fault_fraction_ >= params_.motion.fault_suspect_fraction;
    if (!force_update_ && !odometry_suspect && step < params_.update_min_d &&
        std::fabs(delta.yaw) < params_.update_min_a) {
      checked = fitDropped(scan, delta);
      if (!checked) {
        report.skip_reason = "not moved enough since the last update";
        refineBetweenUpdates(odom, scan, &report);
        return report;
      }
      report.fit_dropped = true;
    }
  }

  const PreparedScan prepared = checked ? std::move(*checked) : model_->prepare(scan);
  report.beams_used = static_cast<int>(prepared.size());
  report.beams_dropped = prepared.dropped;
  if (prepared.size() == 0) {
    // Without evidence the cloud would only be moved; keep the odometry
    // reference so the motion is applied once a usable scan comes.
    report.skip_reason = "no valid beam in the scan (" + std::to_string(prepared.dropped) + " of " +
                         std::to_string(scan.ranges.size()) + " invalid)";
    return report;
  }

  // Where the last estimate would be now had the odometry been right.
  const std::optional<Pose2> before = mapToOdom();
  // A fault changes the odometry's translation by twice its length
  // (reversed) or by it (stalled): on a step shorter than half
  // odom_fault_margin even a reversal stays within the stalled particles' own
  // spread, so a scan cannot tell faulty particles from the others, and what
  // weight they win by chance must not grow their share (intel_lab: eight
  // turns on the spot raised it to its maximum, and the next 0.9 m step then
  // spread the cloud 0.6 m).
  const bool faults_observable = !first && 2.0 * step >= params_.motion.fault_margin;
  if (!first) {
    motion_model_.apply(*odom_at_update_, odom, fault_fraction_, &particles_, &random_, &faulty_);
  }
  odom_at_update_ = odom;
  restart_ = false;
  force_update_ = false;

  weigh(prepared, &report);
  if (faults_observable) adaptFaultFraction();
  report.fault_fraction = fault_fraction_;
  report.ess = effectiveSampleSize(particles_.weight);
  // The estimate comes from the weighted cloud, before resampling: resampling
  // only adds noise, and the random particles recovery injects must not count.
  estimate_ = estimatePose(particles_, params_.clusters);
  confidence_ = assessConfidence(
      particles_, estimate_,
      model_->hitFraction(prepared, estimate_.pose, params_.confidence.hit_distance),
      params_.confidence);
  // Tempering and recovery follow the evidence of this scan; only the
  // published verdict waits for a jumped estimate to be confirmed.
  fit_state_ = confidence_.state;
  fit_at_update_ = params_.update_fit_drop > 0.0
                       ? model_->hitFraction(prepared, estimate_.pose, params_.update_fit_distance)
                       : 0.0;
  if (before) {
    holdAfterJump(compose(*before, odom), estimate_.pose, params_.confidence, &settle_left_,
                  &confidence_);
  }
  refineEstimate(scan, &report);
  resample(&report);
  // Scans that have fitted worse than usual for longer than recovery's
  // patience cast doubt on a "localized" verdict, whatever share of the
  // beams fits: a cloud settled on a wrong place that fits most beams looks
  // just so, and says it while recovery waits.
  if (confidence_.state == LocalizationState::kLocalized &&
      low_fit_updates_ > params_.recovery.patience) {
    confidence_.state = LocalizationState::kUncertain;
    confidence_.reason = "the scans have fitted worse than usual for " +
                         std::to_string(low_fit_updates_) + " updates";
  }
  has_estimate_ = true;
  report.updated = true;
  report.particles = particles_.size();
  return report;
}

void ParticleFilter::weigh(const PreparedScan& scan, UpdateReport* report) {
  const std::size_t beams_counted = model_->logLikelihoods(scan, particles_, &log_likelihood_);
  const std::vector<double>& ll = log_likelihood_;
  // A filter that is not sure of itself weighs evidence more cautiously:
  // rival hypotheses (twin rooms) then survive until the scans really
  // separate them, instead of the luckiest one winning outright. Not when
  // the one thing wrong is a wide cloud whose beams fit: along a corridor
  // between sparse scans (intel_lab: 1 m of odometry per scan), caution
  // would only keep the cloud wide, and the estimate, its mean, off.
  const bool spread_only = fit_state_ == LocalizationState::kUncertain && confidence_.rivals == 0 &&
                           confidence_.hit_fraction >= params_.confidence.localized_hit_fraction;
  const double fraction = fit_state_ == LocalizationState::kLocalized || spread_only
                              ? params_.tempering_ess_fraction
                              : params_.tempering_ess_fraction_uncertain;
  report->tempering = applyLikelihood(ll, fraction, &particles_.weight, &weighting_);
  report->beams_skipped = static_cast<int>(scan.size() - beams_counted);
  // How well the cloud explains the scan: the per-beam geometric mean
  // likelihood (independent of the beam count, so comparable across scans and
  // robots), averaged with the posterior weights. The posterior, not the
  // prior, so that a few particles that found the robot count for what they
  // are worth, and a cloud salted with random particles is not judged by them.
  // Over the beams the model counted: beam skipping may leave some out.
  const double beams = static_cast<double>(std::max<std::size_t>(beams_counted, 1)) *
                       params_.sensor.likelihood_exponent;
  const double mean_beam = meanBeamLikelihood(particles_.weight, ll, beams);
  report->mean_beam_likelihood = mean_beam;

  expand_ = params_.recovery.expansion_ratio > 0.0 && w_slow_ > 0.0 &&
            mean_beam < params_.recovery.expansion_ratio * w_slow_;
  if (params_.recovery.alpha_slow > 0.0) {
    if (w_slow_ == 0.0) {
      w_slow_ = w_fast_ = mean_beam;
    } else {
      w_slow_ += params_.recovery.alpha_slow * (mean_beam - w_slow_);
      w_fast_ += params_.recovery.alpha_fast * (mean_beam - w_fast_);
    }
  }
}

void ParticleFilter::adaptFaultFraction() {
  // Odometry faults come in runs (a robot reverses for a while, wheels spin
  // on a threshold for a while), so the share of the posterior weight that
  // the faulty particles won on this scan is the best guess of how many the
  // next step needs: it rises while a fault lasts and falls back to the
  // floor as soon as the odometry is right again. In a corridor, where the
  // scans cannot tell the faulty particles from the others, their share
  // stays where it was put: at the floor.
  const OdometryMotionParams& m = params_.motion;
  double share = 0.0;
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    share += faulty_[i] ? particles_.weight[i] : 0.0;
  }
  fault_fraction_ = std::clamp(share, m.fault_fraction, m.fault_fraction_max);
}

void ParticleFilter::resample(UpdateReport* report) {
  // Augmented MCL: the short-term average of the measurement likelihood
  // falling below the long-term one means the particles no longer explain the
  // scans, and a matching share of the new cloud is drawn from free space.
  // Dips of a few tenths come and go in normal tracking (a person in front
  // of the laser, a doorway); only a fit below trigger_ratio times the usual
  // one injects anything.
  // A map without free cells (a Gaussian start is allowed on one) has nowhere
  // to draw random particles from: then recovery relies on expansion alone.
  // Unless the filter is lost, it injects only once the fit has stayed low
  // for more than `patience` updates in a row: in a large building the fit
  // sags for a few scans wherever the map is poor (open space, clutter,
  // people walking by), and random guesses then only add rivals that happen
  // to fit those scans better. A robot that is really lost or kidnapped is
  // soon "lost" (see Confidence), or stays badly fitted for longer (a cloud
  // that settled on a look-alike place).
  // While "localized" it waits longer (patience_localized): most beams then
  // end on mapped obstacles at the estimate, and the dip is more likely the
  // map's poverty there than a kidnapping.
  // A compact cloud that is "lost" searches at once with lost_share of the
  // budget (see RecoveryParams::lost_share).
  const double usual = params_.recovery.trigger_ratio * w_slow_;
  const double dip = usual > 0.0 ? std::max(0.0, 1.0 - w_fast_ / usual) : 0.0;
  low_fit_updates_ = dip > 0.0 ? low_fit_updates_ + 1 : 0;
  const int patience = fit_state_ == LocalizationState::kLocalized
                           ? params_.recovery.patience_localized
                           : params_.recovery.patience;
  const bool patient = fit_state_ != LocalizationState::kLost && low_fit_updates_ <= patience;
  const bool can_inject = !model_->field().grid().freeCells().empty() && !patient;
  const std::size_t n = particles_.size();
  const double lost_share = params_.recovery.lost_share;
  const bool compact_and_lost =
      fit_state_ == LocalizationState::kLost &&
      static_cast<double>(n) <= (1.0 - lost_share) * params_.kld.max_particles;
  const double inject_probability =
      can_inject ? std::max(dip, compact_and_lost ? lost_share : 0.0) : 0.0;
  if (report->ess >= params_.resample_ess_fraction * n && inject_probability < 0.01 && !expand_) {
    return;
  }

  const std::size_t target = kldParticleCount(particles_, params_.kld);
  // Random particles are spread over the whole map, so they are counted
  // against the largest cloud, not the converged one: a lost filter must
  // search with as many particles as a global localization.
  const std::size_t max = static_cast<std::size_t>(params_.kld.max_particles);
  const auto injected = std::min(
      max, static_cast<std::size_t>(std::floor(inject_probability * max + random_.uniform())));
  const std::size_t kept = std::min(
      max - injected, static_cast<std::size_t>(std::ceil((1.0 - inject_probability) * target)));
  systematicResample(particles_, kept, &random_, &spare_);
  std::swap(particles_, spare_);
  if (expand_) {
    const RecoveryParams& r = params_.recovery;
    for (std::size_t i = 0; i < kept; ++i) {
      particles_.x[i] += random_.gaussian(r.expansion_std_xy);
      particles_.y[i] += random_.gaussian(r.expansion_std_xy);
      particles_.yaw[i] = normalizeAngle(particles_.yaw[i] + random_.gaussian(r.expansion_std_yaw));
    }
    report->expanded = true;
  }
  particles_.resize(kept + injected);
  for (std::size_t i = kept; i < kept + injected; ++i) particles_.setPose(i, randomFreePose());
  particles_.setUniformWeights();
  if (injected > 0 && kept > 0) {
    const double prior = params_.recovery.kidnap_prior;
    const double w_kept = (1.0 - prior) / static_cast<double>(kept);
    const double w_injected = prior / static_cast<double>(injected);
    std::fill(particles_.weight.begin(), particles_.weight.begin() + kept, w_kept);
    std::fill(particles_.weight.begin() + kept, particles_.weight.end(), w_injected);
  }
  report->resampled = true;
  report->injected = injected;
}

void ParticleFilter::refineEstimate(const LaserScan& scan, UpdateReport* report) {
  refined_.reset();
  ScanRefinement& r = report->refinement;
  r.pose = estimate_.pose;
  if (!params_.refine_estimate) {
    r.rejection = "refine_estimate is off";
    return;
  }
  // A lost filter's estimate is nowhere near the robot: a fit from there
  // would only polish a wrong pose.
  if (confidence_.state == LocalizationState::kLost) {
    r.rejection = "the filter is lost";
    return;
  }
  // The cloud is the prior: the fit moves the estimate only as far as the
  // scan's evidence outweighs the cloud's.
  r = ScanRefiner(model_->field(), params_.refiner)
          .refine(model_->prepare(scan, params_.refiner.max_beams), estimate_.pose,
                  estimate_.covariance);
  if (!r.accepted) return;
  refined_ = RefinedMapToOdom{compose(r.pose, inverse(*odom_at_update_)), *odom_at_update_,
                              *odom_at_update_};
  // The fit is sharper than the cloud, but the cloud's spread (or its
  // rivals') is evidence too: what is published covers both.
  estimate_.pose = r.pose;
  estimate_.covariance = coveringCovariance(r.covariance, estimate_.covariance);
  confidence_.covariance = coveringCovariance(r.covariance, confidence_.covariance);
}

std::optional<PreparedScan> ParticleFilter::fitDropped(const LaserScan& scan,
                                                       const Pose2& since_update) const {
  if (!(params_.update_fit_drop > 0.0) || !has_estimate_) return std::nullopt;
  PreparedScan prepared = model_->prepare(scan);
  if (prepared.size() == 0) return std::nullopt;
  const Pose2 predicted = compose(estimate_.pose, since_update);
  const double fit = model_->hitFraction(prepared, predicted, params_.update_fit_distance);
  if (fit >= fit_at_update_ - params_.update_fit_drop) return std::nullopt;
  return prepared;
}

void ParticleFilter::refineBetweenUpdates(const Pose2& odom, const LaserScan& scan,
                                          UpdateReport* report) {
  // The scans between filter updates place the robot too: each is fitted
  // from the last update's estimate moved by the odometry since, so the
  // published map -> odom follows the map instead of the odometry's drift.
  // Each starts from the update's estimate, never from the previous fit, so
  // fits cannot walk away from the cloud.
  if (!params_.refine_estimate || !has_estimate_ || !odom_at_update_ ||
      confidence_.state == LocalizationState::kLost) {
    return;
  }
  ScanRefinement& r = report->refinement;
  if (refinedIsCurrent()) {
    // Standing still there is nothing new to place: another fit would only
    // add this scan's noise to the published pose, which tf users see as
    // jitter.
    const Pose2 moved = between(refined_->odom_at_fit, odom);
    if (std::hypot(moved.x, moved.y) < 1e-3 && std::fabs(moved.yaw) < 1e-3) {
      r.pose = compose(refined_->map_to_odom, odom);
      r.rejection = "not moved since the last fit, which stands";
      return;
    }
  }
  const Pose2 predicted = compose(compose(estimate_.pose, inverse(*odom_at_update_)), odom);
  const std::optional<Eigen::Matrix3d> prior =
      estimate_.clusters.empty() ? std::nullopt
                                 : std::optional<Eigen::Matrix3d>(estimate_.clusters[0].covariance);
  r = ScanRefiner(model_->field(), params_.refiner)
          .refine(model_->prepare(scan, params_.refiner.max_beams), predicted, prior);
  if (r.accepted) {
    refined_ = RefinedMapToOdom{compose(r.pose, inverse(odom)), *odom_at_update_, odom};
  }
}

bool ParticleFilter::refinedIsCurrent() const {
  // A fit belongs to the update it started from: after an odometry fault (a
  // new odom_at_update_ without an update) it is stale.
  if (!refined_ || !odom_at_update_) return false;
  const Pose2& at = *odom_at_update_;
  return refined_->odom_at_update.x == at.x && refined_->odom_at_update.y == at.y &&
         refined_->odom_at_update.yaw == at.yaw;
}

std::optional<Pose2> ParticleFilter::mapToOdom() const {
  if (!has_estimate_ || !odom_at_update_) return std::nullopt;
  if (refinedIsCurrent()) return refined_->map_to_odom;
  return compose(estimate_.pose, inverse(*odom_at_update_));
}

}  // namespace pf
