#include "pf_localization/core/filter/particle_filter.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "pf_localization/core/filter/weighting.h"
#include "pf_localization/core/sensor/beam_model.h"
#include "pf_localization/core/sensor/likelihood_field_model.h"
#include "pf_localization/core/util/scratch_storage.h"

namespace pf {

std::unique_ptr<SensorModel> makeSensorModel(OccupancyGrid grid,
                                             const ParticleFilterParams& params) {
  LikelihoodFieldModelParams sensor = params.sensor;
  sensor.threads = resolvedThreads(params.threads);
  switch (params.laser_model_type) {
    case LaserModelType::kBeam:
      return std::make_unique<BeamModel>(grid, sensor, params.beam);
    case LaserModelType::kLikelihoodFieldProb:
      return std::make_unique<LikelihoodFieldModel>(std::move(grid), sensor);
    case LaserModelType::kLikelihoodField:
      break;
  }
  // amcl's likelihood_field never skips beams.
  sensor.beam_skip = false;
  return std::make_unique<LikelihoodFieldModel>(std::move(grid), sensor);
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
  motion_.reserve(max);
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
    screen_.setField(sensor_.model().field());
  }
}

bool ParticleFilter::setMap(PreparedMap map) {
  if (!sameSensor(map.params, params_)) {  // reconfigured while it was built
    map = PreparedMap::build(map.model->field().grid(), mapRecipe());
  }
  sensor_.setModel(std::move(map.model));  // builds the tables of ranges expected since
  screen_.setMap(std::move(map.screen));
  estimate_.setMap(std::move(map.symmetries));
  const OccupancyGrid& grid = sensor_.model().field().grid();
  if (isInitialized() && grid.isFreeAt(estimate_.pose().x, estimate_.pose().y)) return true;
  particles_.resize(0);  // keeps the reserved storage
  sensor_.stopSearch();
  estimate_.forget();
  gate_.restart();  // no estimate until an initialisation and an update
  return false;
}

std::optional<PreparedMap> ParticleFilter::releaseMap() {
  if (!hasMap()) return std::nullopt;
  // In this order: the model holds the field the screen's parts refer to.
  std::vector<MapSymmetry> symmetries = estimate_.symmetries();
  BeamScreen::MapParts screen = screen_.releaseMap();
  return PreparedMap{sensor_.releaseModel(), std::move(screen), std::move(symmetries), params_};
}

void ParticleFilter::expectScanRange(double range_max) {
  if (!std::isfinite(range_max) || !(range_max > 0.0)) return;
  sensor_.expectRange(scoredRangeMax(range_max, params_.sensor.range_max));
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
  sensor_.stopSearch();
  restartAfterInitialization(estimatePose(particles_, params_.clusters, threads_), true);
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
  const double cell = grid.resolution();
  sensor_.startSearch(static_cast<double>(grid.freeCells().size()) * cell * cell);
  restartAfterInitialization(estimatePose(particles_, params_.clusters, threads_), false);
}

void ParticleFilter::restartAfterInitialization(const PoseEstimate& estimate, bool place_given) {
  // The new particles describe the robot now: the odometry travelled since the
  // last update must not move them again, so the next update skips motion.
  gate_.restart();
  estimate_.restart(estimate, place_given);
  recovery_.restart();
  motion_.restart();
}

std::string skipMessage(const UpdateReport& report) {
  std::string message = toString(report.skip_reason);
  if (!report.skip_detail.empty()) message += ": " + report.skip_detail;
  return message;
}

namespace {

// m of odometry since the last update beyond which the tracked pose is not
// known well enough to judge beams from (map_change_mask.h): between
// updates every update_min_d a robot goes 0.2 m; a sparse log (the Intel
// lab's, a scan every metre) goes further.
constexpr double kMaxJudgedStep = 0.5;

}  // namespace

UpdateReport ParticleFilter::update(const Pose2& odom, const ScanGroup& measured) {
  const ScreenedScan scan = screen_.screen(odom, measured, tracked(odom));
  GateDecision gate =
      gate_.decide(odom, scan.steady, sensor_.get(), isInitialized(), estimate_.pose(),
                   motion_.suspect(), params_, scan.report.beams_masked);
  UpdateReport report;
  report.gate() = gate;
  report.screen() = scan.report;
  report.particles = particles_.size();
  if (gate.skip_reason == SkipReason::kNotMoved) {  // map -> odom follows the scans between updates
    report.refinement = estimate_.refitBetweenUpdates(sensor_.model(), scan.fitting, odom,
                                                      *gate_.odomAtUpdate(), params_);
  }
  if (!gate.runs()) return report;

  const std::optional<Pose2> predicted = moveCloud(gate, odom);
  const PreparedBeams beams(sensor_.model(), scan, std::move(*gate.scans));
  report.weighing() = sensor_.weighCloud(
      beams.fitting(), gate.view, temperingEssFraction(estimate_.fitState(), confidence(), params_),
      params_.sensor, params_.kld, &particles_, threads_);
  report.fault_fraction =
      motion_.adaptFaults(gate.from.has_value(), gate.step, particles_.weight, threads_, gate.view);
  report.ess = effectiveSampleSize(particles_.weight, threads_);
  Judgement judged = estimate_.judge(sensor_.model(), particles_, beams.fitting(), beams.steady(),
                                     predicted, screen_.evidence(), params_, threads_);
  report.judge() = judged.report;
  gate_.recordFit(sensor_.model(), beams.steady(), estimate_.pose(), params_);
  sensor_.observePlaces(judged.places);
  report.refinement = estimate_.refine(sensor_.model(), scan.fitting, odom, predicted, params_);
  motion_.setAlongTrackObservable(
      estimate_.fitPinsAlongTrack(report.refinement, params_.motion.fault_margin));
  report.recovery() = resampleAndRecover(report, gate.view, std::move(judged.better));
  estimate_.demoteAfterLowFit(recovery_.lowFitViews(), params_.recovery.patience);
  screen_.learn(scan.measured, estimate_.pose(), confidence().state == LocalizationState::kLost);
  report.updated = true;
  report.particles = particles_.size();
  return report;
}

std::optional<Pose2> ParticleFilter::moveCloud(const GateDecision& gate, const Pose2& odom) {
  if (!gate.from) return std::nullopt;  // the first update after an initialisation
  const Pose2 predicted = compose(estimate_.mapToOdom(*gate.from), odom);
  motion_.apply(*gate.from, odom, &particles_, &random_, threads_, gate.view);
  return predicted;
}

TrackedPose ParticleFilter::tracked(const Pose2& odom) const {
  TrackedPose t;
  if (!sensor_.hasModel() || !odom.isFinite()) return t;
  if (gate_.hasUpdated()) {
    t.pose = compose(estimate_.mapToOdom(*gate_.odomAtUpdate()), odom);
  } else if (isInitialized() && estimate_.placeKnown()) {
    // Before the first update, a pose the cloud was drawn around is where the
    // robot is now (the first update moves nothing).
    t.pose = estimate_.pose();
  }
  // After a long step, or odometry that may be what is wrong, the tracked
  // pose is not known well enough to tell a change of the map from its own
  // error (the CARMEN logs keep a scan every metre; odometry_fault_tracker.h).
  if (!t.pose || !estimate_.judgesBeams() || motion_.suspect()) return t;
  if (gate_.hasUpdated()) {
    const Pose2 step = between(*gate_.odomAtUpdate(), odom);
    t.judges = std::hypot(step.x, step.y) <= kMaxJudgedStep;
  } else {
    t.judges = true;
  }
  return t;
}

ResampleOutcome ParticleFilter::resampleAndRecover(const UpdateReport& report, double view,
                                                   std::vector<Pose2> better) {
  recovery_.observe(report.mean_beam_likelihood, params_.recovery, view);
  recovery_.observeLookAlikes(std::move(better));
  const OccupancyGrid& grid = sensor_.model().field().grid();
  const RecoveryPlan plan = recovery_.plan(estimate_.fitState(), particles_.size(),
                                           static_cast<std::size_t>(params_.kld.max_particles),
                                           !grid.freeCells().empty(), params_.recovery);
  return recovery_.resample(plan, report.ess, params_, grid, &random_, &particles_, threads_);
}

Hypotheses ParticleFilter::hypotheses() const {
  return estimate_.hypotheses(params_.confidence.rival_weight_ratio);
}

std::optional<Pose2> ParticleFilter::mapToOdom() const {
  if (!gate_.hasUpdated()) return std::nullopt;
  return estimate_.mapToOdom(*gate_.odomAtUpdate());
}

}  // namespace pf
