#include "pf_localization/core/filter/particle_filter.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "pf_localization/core/estimate/hypotheses.h"
#include "pf_localization/core/filter/weighting.h"
#include "pf_localization/core/recovery/recovery.h"
#include "pf_localization/core/util/scratch_storage.h"

namespace pf {

std::unique_ptr<SensorModel> makeSensorModel(const OccupancyGrid& grid,
                                             const ParticleFilterParams& params) {
  LikelihoodFieldModelParams sensor = params.sensor;
  sensor.threads = resolvedThreads(params.threads);
  switch (params.laser_model_type) {
    case LaserModelType::kBeam:
      return std::make_unique<BeamModel>(grid, sensor, params.beam);
    case LaserModelType::kLikelihoodFieldProb:
      return std::make_unique<LikelihoodFieldModel>(grid, sensor);
    case LaserModelType::kLikelihoodField:
      break;
  }
  // amcl's likelihood_field never skips beams.
  sensor.beam_skip = false;
  return std::make_unique<LikelihoodFieldModel>(grid, sensor);
}

ParticleFilter::ParticleFilter(const ParticleFilterParams& params)
    : params_((validate(params), params)),
      threads_(resolvedThreads(params.threads)),
      random_(params.seed),
      motion_(params.motion, oneUpdateStep(params)) {
  // Room for the largest cloud from the start: the particle count swings
  // between min and max particles, and reallocating would make the process's
  // memory swing with it (and allocate on the update path). See
  // docs/design.md, "Storage is prefaulted".
  reserveStorage(static_cast<std::size_t>(params_.kld.max_particles));
}

void ParticleFilter::reserveStorage(std::size_t max) {
  // setParams reserves more under live particles: prefault keeps them.
  for (std::vector<double>* v :
       {&particles_.x, &particles_.y, &particles_.yaw, &particles_.weight}) {
    prefault(v, max);
  }
  recovery_.reserve(max);
  sensor_.reserve(max);
  motion_.faults().reserve(max);
}

namespace {

// Whether the sensor model built from `a` would be the one built from `b`.
bool sameSensor(const ParticleFilterParams& a, const ParticleFilterParams& b) {
  const LikelihoodFieldModelParams &s = a.sensor, &t = b.sensor;
  return a.laser_model_type == b.laser_model_type && s.z_hit == t.z_hit && s.z_rand == t.z_rand &&
         s.sigma_hit == t.sigma_hit && s.max_distance == t.max_distance &&
         s.max_beams == t.max_beams && s.range_min == t.range_min && s.range_max == t.range_max &&
         s.likelihood_exponent == t.likelihood_exponent && a.threads == b.threads &&
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
  const OdometryMotionModel motion(params.motion, oneUpdateStep(params));
  std::unique_ptr<SensorModel> model;
  if (sensor_.hasModel() && !sameSensor(params, params_)) {
    // The model holds its parameters and its table of beam likelihoods; the
    // distance field under them depends on laser_likelihood_max_dist too.
    model = makeSensorModel(sensor_.model().field().grid(), params);
  }
  if (params.kld.max_particles > params_.kld.max_particles) {
    reserveStorage(static_cast<std::size_t>(params.kld.max_particles));
  }
  const uint64_t seed = params_.seed;
  params_ = params;
  params_.seed = seed;
  threads_ = resolvedThreads(params_.threads);
  motion_.setModel(motion);
  if (model) {
    sensor_.setModel(std::move(model));
    evidence_.emplace(sensor_.model().field());
    shareMapChanges(true);
    search_.forgetModel();
  }
}

bool ParticleFilter::setMap(const OccupancyGrid& grid) {
  if (grid.empty()) throw std::invalid_argument("the map is empty");
  sensor_.setModel(makeSensorModel(grid, params_));
  evidence_.emplace(sensor_.model().field());
  layer_.emplace(sensor_.model().field());
  look_alikes_.setMap(sensor_.model().field());
  look_alike_places_.clear();
  search_.forgetModel();
  refinement_.reset();  // fitted to the old map
  if (isInitialized() && grid.isFreeAt(estimate_.pose.x, estimate_.pose.y)) return true;
  particles_.resize(0);  // keeps the reserved storage
  search_.stop();
  estimate_ = PoseEstimate();
  gate_.restart();  // no estimate until an initialisation and an update
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
  estimate_ = estimatePose(particles_, params_.clusters, threads_);
  search_.stop();
  restartAfterInitialization(true);
}

void ParticleFilter::initializeUniform() {
  if (!sensor_.hasModel()) throw std::logic_error("global localization needs a map");
  const OccupancyGrid& grid = sensor_.model().field().grid();
  if (grid.freeCells().empty()) {
    throw std::logic_error("global localization needs a map with free cells");
  }
  particles_.resize(params_.kld.max_particles);
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    particles_.setPose(i, randomFreePose(grid, &random_));
  }
  particles_.setUniformWeights();
  estimate_ = estimatePose(particles_, params_.clusters, threads_);
  const double cell = grid.resolution();
  search_.start(static_cast<double>(grid.freeCells().size()) * cell * cell);
  restartAfterInitialization(false);
}

void ParticleFilter::restartAfterInitialization(bool place_given) {
  // The new particles describe the robot now: the odometry travelled since the
  // last update must not move them again, so the next update skips motion.
  gate_.restart();
  refinement_.reset();
  confidence_.restart(estimate_.covariance, place_given);
  recovery_.restart();
  look_alikes_.restart();
  look_alike_places_.clear();
  motion_.faults().restart(params_.motion);
}

std::string skipMessage(const UpdateReport& report) {
  std::string message = toString(report.skip_reason);
  if (!report.skip_detail.empty()) message += ": " + report.skip_detail;
  return message;
}

namespace {

// m: a beam ending this close to a mapped obstacle, where the robot is
// believed to be, agrees with the map: it is never taken for something that
// moved in. Two cells of the usual 0.05 m map, about three beam_std.
constexpr double kOnMapDistance = 0.1;
// m of odometry since the last update beyond which the tracked pose is not
// known well enough to judge beams from (map_change_mask.h): between
// updates every update_min_d a robot goes 0.2 m; a sparse log (the Intel
// lab's, a scan every metre) goes further.
constexpr double kMaxJudgedStep = 0.5;

// The report of what the gate decided (taking its detail).
UpdateReport gateReport(GateDecision* gate, std::size_t particles) {
  UpdateReport report;
  report.particles = particles;
  report.skip_reason = gate->skip;
  report.skip_detail = std::move(gate->detail);
  report.fit_dropped = gate->fit_dropped;
  if (gate->scans) {
    report.beams_used = static_cast<int>(beamCount(*gate->scans));
    report.beams_dropped = droppedBeams(*gate->scans);
  }
  return report;
}

// Whether a scan fit with covariance `fit` (zero where the scan says
// nothing) pins the position along heading `yaw` to within `margin` (m):
// the fit's information along it, with the other directions given.
bool pinsAlong(const Eigen::Matrix3d& fit, double yaw, double margin) {
  const Eigen::Vector3d u(std::cos(yaw), std::sin(yaw), 0.0);
  return u.dot(fitInformation(fit).information * u) * margin * margin >= 1.0;
}

}  // namespace

std::optional<Pose2> ParticleFilter::trackedPose(const Pose2& odom) const {
  if (!sensor_.hasModel() || !odom.isFinite()) return std::nullopt;
  if (gate_.hasUpdated()) {
    return compose(refinement_.mapToOdom(estimate_.pose, *gate_.odomAtUpdate()), odom);
  }
  // Before the first update, a pose the cloud was drawn around is where the
  // robot is now (the first update moves nothing).
  if (isInitialized() && confidence_.placeKnown()) return estimate_.pose;
  return std::nullopt;
}

ScanGroup ParticleFilter::maskTransients(const Pose2& odom, const ScanGroup& measured) {
  const std::optional<Pose2> robot = trackedPose(odom);
  if (!robot) return transients_.mask(odom, measured, {}, &masked_scans_);
  const LikelihoodField& field = sensor_.model().field();
  // Two references: std::function holds them without allocating.
  const auto on_map = [&field, &robot](double x, double y) {
    const Pose2 end = compose(*robot, {x, y, 0.0});
    return field.distanceAt(end.x, end.y) < kOnMapDistance;
  };
  return transients_.mask(odom, measured, on_map, &masked_scans_);
}

std::optional<Pose2> ParticleFilter::judgingPose(const Pose2& odom) const {
  if (!judgesFromTrackedPose(odom)) return std::nullopt;
  return trackedPose(odom);
}

ScanGroup ParticleFilter::maskMapChanges(const std::optional<Pose2>& robot,
                                         const ScanGroup& scans) {
  if (!robot) {
    changes_.clear();
    return scans;
  }
  return changes_.mask(*evidence_, scans, *robot, &changed_scans_);
}

bool ParticleFilter::judgesFromTrackedPose(const Pose2& odom) const {
  // A place not told apart from its look-alikes, a cloud that holds several,
  // an estimate that jumped and is not confirmed yet, a lost one: for the
  // filter's evidence to settle, and what the map lacks at the tracked place
  // may be what tells. A look-alike that fitted better once is not enough:
  // the look-alike judge sees every beam, and unmasked, a change of the map
  // (cabinets along a corridor's wall) pulls the tracked pose onto it.
  if (!evidence_ || !confidence_.placeKnown() || confidence_.settling() ||
      confidence_.confidence().state == LocalizationState::kLost || places_ > 1) {
    return false;
  }
  // After a long step, or odometry that may be what is wrong, the tracked
  // pose is not known well enough to tell a change of the map from its own
  // error (the CARMEN logs keep a scan every metre; odometry_fault_tracker.h).
  if (motion_.faults().suspect(params_.motion)) return false;
  if (!gate_.hasUpdated()) return true;
  const Pose2 step = between(*gate_.odomAtUpdate(), odom);
  return std::hypot(step.x, step.y) <= kMaxJudgedStep;
}

UpdateReport ParticleFilter::update(const Pose2& odom, const ScanGroup& measured) {
  const ScanGroup unmasked = maskTransients(odom, measured);
  // The pose tracked since the last update, before the gate makes this one
  // the last.
  const std::optional<Pose2> judging = judgingPose(odom);
  // The gate judges the odometry by every beam: a scan that stops fitting
  // where it says is what the beams masked for changes of the map would hide.
  GateDecision gate = gate_.decide(odom, unmasked, sensor_.get(), isInitialized(), estimate_.pose,
                                   motion_.faults().suspect(params_.motion), params_);
  // The beams that see a change of the map, judged for the fit between
  // updates too: it moves the tracked pose the next update judges from.
  const bool between = gate.skip == SkipReason::kNotMoved;
  const ScanGroup scans = maskMapChanges(judging, unmasked);
  UpdateReport report = gateReport(&gate, particles_.size());
  report.beams_masked = transients_.masked();
  report.beams_changed = changes_.masked();
  report.map_evidence = changes_.counts();
  report.map_agrees = changes_.agrees();
  report.map_changed_share = changes_.changedShare();
  if (gate.scans) report.beams_dropped -= report.beams_masked;
  if (between) {
    report.refinement =
        refinement_.betweenUpdates(sensor_.model(), scans, odom, *gate_.odomAtUpdate(), estimate_,
                                   confidence_.confidence().state, params_);
  }
  if (!gate.runs()) return report;

  // Where the last estimate would be now had the odometry been right.
  std::optional<Pose2> predicted;
  if (gate.from) {
    predicted = compose(refinement_.mapToOdom(estimate_.pose, *gate.from), odom);
    motion_.apply(*gate.from, odom, &particles_, &random_, threads_, gate.view);
  }
  // What the filter weighs: the beams the map explains at the tracked pose.
  std::vector<PreparedScan> masked;
  if (changes_.masked() > 0) masked = prepareScans(sensor_.model(), scans);
  const std::vector<PreparedScan>& weighed = changes_.masked() > 0 ? masked : *gate.scans;
  weigh(weighed, gate.view, &report);
  if (gate.from && OdometryFaultTracker::observable(gate.step, params_.motion)) {
    motion_.faults().adapt(particles_.weight, params_.motion, threads_, gate.view);
  }
  report.fault_fraction = motion_.faults().fraction();
  report.ess = effectiveSampleSize(particles_.weight, threads_);
  estimateAndJudge(weighed, *gate.scans, predicted, &report);
  report.refinement = refinement_.atUpdate(sensor_.model(), scans, odom, predicted,
                                           confidence_.confidence().state, params_, &estimate_);
  if (report.refinement.accepted) confidence_.addFit(report.refinement.covariance);
  // Without an accepted fit nothing says what the scan pinned: keep hedging.
  motion_.faults().setAlongTrackObservable(
      !report.refinement.accepted ||
      pinsAlong(report.refinement.covariance, estimate_.pose.yaw, params_.motion.fault_margin));
  resample(&report);
  confidence_.demoteAfterLowFit(recovery_.lowFitViews(), params_.recovery.patience);
  report.updated = true;
  report.particles = particles_.size();
  learnMapChanges(measured, report.map_agrees);
  return report;
}

void ParticleFilter::learnMapChanges(const ScanGroup& scans, bool map_agrees) {
  if (!layer_ || !map_agrees || confidence_.confidence().state == LocalizationState::kLost ||
      !layer_->wants(estimate_.pose)) {
    return;
  }
  layer_->add(scans, estimate_.pose);
  shareMapChanges(false);
}

void ParticleFilter::shareMapChanges(bool all) {
  if (!layer_ || !evidence_) return;
  if (all) {
    layer_->takeChangedCells();
    const std::size_t cells = static_cast<std::size_t>(layer_->width()) * layer_->height();
    for (std::size_t i = 0; i < cells; ++i) {
      if (layer_->removed(i)) evidence_->setGone(i, true);
      if (layer_->added(i)) evidence_->setAdded(i, true);
    }
    return;
  }
  for (std::size_t i : layer_->takeChangedCells()) {
    evidence_->setGone(i, layer_->removed(i));
    evidence_->setAdded(i, layer_->added(i));
  }
}

void ParticleFilter::estimateAndJudge(const std::vector<PreparedScan>& scans,
                                      const std::vector<PreparedScan>& all_beams,
                                      const std::optional<Pose2>& predicted, UpdateReport* report) {
  // The estimate comes from the weighted cloud, before resampling: resampling
  // only adds noise, and the random particles recovery injects must not count.
  estimate_ = estimatePose(particles_, params_.clusters, threads_);
  const SensorModel& model = sensor_.model();
  confidence_.assess(particles_, estimate_,
                     hitFraction(model, scans, estimate_.pose, params_.confidence.hit_distance),
                     params_.confidence, threads_);
  gate_.recordFit(model, all_beams, estimate_.pose, params_);
  // Tempering and recovery follow the evidence of this scan (fitState());
  // only the published verdict waits for a jumped estimate to be confirmed.
  confidence_.holdAfterJump(predicted, estimate_.pose, params_.confidence);
  const std::size_t places =
      hypothesesOf(estimate_, params_.confidence.rival_weight_ratio, 0).count;
  const LookAlikeView view = look_alikes_.judge(model, all_beams, estimate_.pose, &*evidence_);
  confidence_.holdWhileAmbiguous(places, view.as_good);
  search_.observe(places);
  listLookAlikes(all_beams, view, places);
  places_ = places;
  confidence_.coverLookAlikes(estimate_.pose, view.fit, look_alike_places_);
  report->look_alikes = view.as_good;
  report->look_alikes_better = view.better.size();
  recovery_.observeLookAlikes(view.better);
}

void ParticleFilter::listLookAlikes(const std::vector<PreparedScan>& scans,
                                    const LookAlikeView& view, std::size_t places) {
  look_alike_places_ = view.places;
  if (places < 2) return;
  // A cloud spread over several places may hold none at the true place but
  // one a rack bay along it: the look-alikes of each are places too.
  const Hypotheses held = hypothesesOf(estimate_, params_.confidence.rival_weight_ratio);
  std::vector<Pose2> others;
  for (std::size_t i = 1; i < held.listed.size(); ++i) others.push_back(held.listed[i].pose);
  const std::vector<LookAlikePlace> around = look_alikes_.placesAround(
      sensor_.model(), scans, others, view.fit - LookAlikes::kAsGoodMargin);
  look_alike_places_.insert(look_alike_places_.end(), around.begin(), around.end());
}

void ParticleFilter::weigh(const std::vector<PreparedScan>& scans, double view,
                           UpdateReport* report) {
  const double ess_fraction =
      std::max(temperingEssFraction(confidence_.fitState(), confidence_.confidence(), params_),
               search_.minEssFraction());
  const SensorModel* smoothed =
      search_.model(sensor_.model(), params_.sensor.sigma_hit, params_.sensor.max_distance, scans,
                    particles_, params_.kld, threads_);
  const Weighing w = sensor_.weigh(smoothed ? *smoothed : sensor_.model(), scans, ess_fraction,
                                   params_.sensor.likelihood_exponent, &particles_, threads_, view);
  report->search_sigma = search_.sigma();
  report->tempering = w.tempering;
  report->beams_skipped = w.beams_skipped;
  report->mean_beam_likelihood = w.mean_beam_likelihood;
  recovery_.observe(w.mean_beam_likelihood, params_.recovery, view);
}

void ParticleFilter::resample(UpdateReport* report) {
  const OccupancyGrid& grid = sensor_.model().field().grid();
  const RecoveryPlan plan = recovery_.plan(confidence_.fitState(), particles_.size(),
                                           static_cast<std::size_t>(params_.kld.max_particles),
                                           !grid.freeCells().empty(), params_.recovery);
  const ResampleOutcome out =
      recovery_.resample(plan, report->ess, params_, grid, &random_, &particles_, threads_);
  report->resampled = out.resampled;
  report->injected = out.injected;
  report->moved = out.moved;
  report->expanded = out.expanded;
}

Hypotheses ParticleFilter::hypotheses() const {
  Hypotheses h = hypothesesOf(estimate_, params_.confidence.rival_weight_ratio);
  addLookAlikes(look_alike_places_, &h);
  return h;
}

std::optional<Pose2> ParticleFilter::mapToOdom() const {
  if (!gate_.hasUpdated()) return std::nullopt;
  return refinement_.mapToOdom(estimate_.pose, *gate_.odomAtUpdate());
}

}  // namespace pf
