// Monte Carlo localization: the particle filter that composes the motion
// model, a sensor model (sensor_model.h: the likelihood field, with or
// without beam skipping, or the beam model), the resampler and the pose
// estimator.
//
// Thrun, Burgard & Fox, "Probabilistic Robotics" (2005), table 8.2 (MCL) with
// the augmentation of table 8.3 (random particles injected when the short-term
// average of the measurement likelihood falls below the long-term one), and
// KLD-sampling (Fox 2003) to adapt the particle count.
//
// The filter runs an update only after the robot has moved update_min_d or
// turned update_min_a since the last one, and on the first scan after an
// initialisation: a robot standing still would otherwise keep multiplying
// the same evidence into its weights and grow falsely confident. It updates
// sooner when a scan no longer fits where the odometry says the robot is
// (update_fit_drop): that is when waiting for more odometry costs most.
//
// Deterministic: the same parameters (seed included) and the same calls give
// the same particles, bit for bit.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pf_localization/core/beam_model.h"
#include "pf_localization/core/confidence.h"
#include "pf_localization/core/laser_scan.h"
#include "pf_localization/core/likelihood_field_model.h"
#include "pf_localization/core/occupancy_grid.h"
#include "pf_localization/core/odometry_motion_model.h"
#include "pf_localization/core/particle_set.h"
#include "pf_localization/core/pose_estimator.h"
#include "pf_localization/core/random.h"
#include "pf_localization/core/resampler.h"
#include "pf_localization/core/scan_refiner.h"
#include "pf_localization/core/sensor_model.h"
#include "pf_localization/core/weighting.h"

namespace pf {

// Augmented MCL: w_slow and w_fast are long- and short-term averages of how
// well the cloud explains the scans (the posterior-weighted per-beam
// likelihood). When w_fast falls below trigger_ratio * w_slow, a share
// 1 - w_fast / (trigger_ratio * w_slow) of max_particles is drawn from free
// space at the next resampling. Unlike amcl, the averages are not reset after
// an injection: the memory of what a good fit looks like is what keeps the
// search going until the robot is found again. A compact cloud whose
// estimate is "lost" does not wait for the averages: lost_share of
// max_particles is drawn at once.
struct RecoveryParams {
  double alpha_slow = 0.01;    // long-term average rate, per update (0 disables recovery)
  double alpha_fast = 0.2;     // short-term average rate, per update
  double trigger_ratio = 0.7;  // (0, 1]: 1 injects on any dip, as amcl does
  // How much the injected particles are believed, together: the prior
  // probability that the robot is somewhere else than the tracked particles
  // say. Augmented MCL gives a random particle the weight of a tracked one,
  // so in a large building, where many places fit one scan roughly, one of
  // thousands of random guesses often fits a single scan better than the
  // spread-out tracked cloud and takes over the estimate: a jump across the
  // building. Treated as what it is, a mixture proposal (Thrun, Fox, Burgard
  // & Dellaert, "Robust Monte Carlo localization for mobile robots", AIJ
  // 128, 2001), each injected particle weighs kidnap_prior / injected and
  // each kept one (1 - kidnap_prior) / kept. A rival place must then explain
  // the scans better by about log(injected / kidnap_prior) nats before it
  // wins, which a real kidnapping does within a scan or two and aliasing does
  // not; and a larger particle budget, which injects more guesses, discounts
  // each guess by as much, so it finds more without jumping more. (0, 1]
  double kidnap_prior = 1e-3;
  // Unless the confidence state is "lost", inject only after the fit has
  // been below the trigger for more than this many updates in a row. >= 0
  int patience = 5;
  // The same while "localized" (most beams end on mapped obstacles at the
  // estimate, one compact cluster): a low likelihood then mostly means a
  // poor stretch of map, where random guesses only add rivals to jump to
  // (fr079: a 28 m jump from particles injected while the estimate was
  // 0.14 m off with 87 % of its beams fitting; such stretches last at most
  // 9 updates there with the defaults, 13 with update_min_d 0.1). A cloud that settled on a wrong
  // place fitting most beams stays low for much longer (a kidnapping in bags/kidnap.bag, with other
  // parameters: 40 updates), so it is still searched for; meanwhile, after `patience` such updates,
  // the published state is at best "uncertain". >= patience
  int patience_localized = 10;
  // A compact cloud whose estimate has turned "lost" (most beams end far
  // from anything mapped: never seen while tracking the real bags, whose
  // poorest stretches still fit more than half the beams) was kidnapped
  // or slipped far: at least this share of the budget, max_particles, is
  // drawn at random at once, as a global localization would, instead of
  // the share the slow averages give a few updates later. Without it, a
  // 5000-particle filter in bags/kidnap.bag searched with 789 guesses
  // where the default 50 000 drew 13 192, settled on a look-alike room
  // that fitted 93 % of the beams and stayed there. Not while the cloud
  // already holds more than (1 - lost_share) of the budget: it is
  // searching (a global localization), and halving it would only thin
  // the search. The guesses still weigh kidnap_prior together, so a
  // blocked lidar does not hand the estimate to one. [0, 1), 0: off
  double lost_share = 0.5;
  // Expansion resetting (Ueda et al., "Expansion resetting for recovery
  // from fatal error in Monte Carlo localization", IROS 2004): when a single
  // scan fits below expansion_ratio times the long-term average, the robot
  // has probably slipped or been pushed a little, and the survivors of the
  // next resampling are spread by these standard deviations, which finds it
  // again nearby long before random particles would. 0 disables.
  double expansion_ratio = 0.3;    // [0, 1)
  double expansion_std_xy = 0.3;   // m
  double expansion_std_yaw = 0.3;  // rad
};

// amcl's laser_model_type.
enum class LaserModelType {
  kLikelihoodField,      // likelihood_field_model.h
  kLikelihoodFieldProb,  // the same, with beam skipping when sensor.beam_skip is set
  kBeam,                 // beam_model.h
};

struct ParticleFilterParams {
  KldParams kld;                     // particle count bounds and KLD-sampling
  double update_min_d = 0.2;         // m of travel between updates
  double update_min_a = M_PI / 6.0;  // rad of rotation between updates
  // Between those updates every scan is checked, at the pose the odometry
  // predicts, for the share of its beams that end within update_fit_distance
  // of a mapped obstacle (one pose: the cost of one particle). When that
  // share falls more than update_fit_drop below the last update's, the
  // odometry has gone wrong (a robot reversing while the encoders count
  // forwards, a wheel slipping in a turn) and the filter updates now rather
  // than after update_min_d of motion it cannot trust. The distance is
  // tight (a few map cells): a 0.3 m error barely moves the share within
  // 0.4 m, but halves it within 0.1 m. 0 disables. [0, 1]
  double update_fit_drop = 0.2;
  double update_fit_distance = 0.1;    // m, > 0
  double odom_jump_limit = 5.0;        // m; a longer odometry step between updates is a fault
  double resample_ess_fraction = 0.5;  // resample when ESS < this * N (0..1]
  // When one scan would leave fewer than this fraction of the effective
  // particles it found, its likelihood is tempered (raised to the largest
  // power below 1 that keeps that many). Evidence too strong for the cloud, as right after a
  // global initialisation, then narrows it over several scans instead of
  // collapsing it onto one lucky particle. 0 disables. [0, 1]
  double tempering_ess_fraction = 0.02;
  // The same while the filter is not localized (see Confidence) because of
  // rivals or a poor fit; a cloud that is only wide, with its beams fitting,
  // keeps tempering_ess_fraction. [0, 1]
  double tempering_ess_fraction_uncertain = 0.1;
  uint64_t seed = 0;
  OdometryMotionParams motion;
  // Which sensor model weighs the particles. Beam skipping (sensor.beam_skip)
  // takes effect with kLikelihoodFieldProb only, as in amcl.
  LaserModelType laser_model_type = LaserModelType::kLikelihoodField;
  LikelihoodFieldModelParams sensor;  // also the terms the beam model shares
  BeamModelParams beam;               // the beam model's own terms
  ClusterParams clusters;
  RecoveryParams recovery;
  ConfidenceParams confidence;
  // The published pose (and map -> odom) is the cloud's estimate refined
  // against the map by a scan fit (scan_refiner.h), whenever the filter is
  // not lost and the fit is accepted; the scans between updates are fitted
  // too. Off by default: it must help on every reference recording first,
  // and on neato_ac109_1 the fitted pose agrees with the map but not with
  // that bag's ceiling-camera reference, which is turned 3 deg from the map
  // (README.md, "How good it is").
  bool refine_estimate = false;
  ScanRefinerParams refiner;
};

/// Throws std::invalid_argument naming the first parameter out of range and its valid range.
void validate(const ParticleFilterParams& params);

/// The sensor model `params` names, on `grid`. Throws std::invalid_argument
/// for an out-of-range parameter.
std::unique_ptr<SensorModel> makeSensorModel(const OccupancyGrid& grid,
                                             const ParticleFilterParams& params);

/// What one call to ParticleFilter::update did.
struct UpdateReport {
  bool updated = false;     // motion and sensor update ran
  std::string skip_reason;  // why not, when !updated
  int beams_used = 0;
  int beams_dropped = 0;
  int beams_skipped = 0;  // of beams_used, left out by beam skipping
  std::size_t particles = 0;
  double ess = 0.0;  // before resampling
  bool resampled = false;
  double mean_beam_likelihood = 0.0;  // geometric mean over beams, weighted over particles
  std::size_t injected = 0;           // random particles added by recovery
  double tempering = 1.0;             // exponent applied to this scan's likelihood (1: none)
  bool expanded = false;              // the survivors were spread by expansion resetting
  double fault_fraction = 0.0;        // share of particles to assume an odometry fault next step
  // The update came before update_min_d / update_min_a because the scan no
  // longer fitted at the pose the odometry predicted (update_fit_drop).
  bool fit_dropped = false;
  // The scan fit of the estimate (when refine_estimate is on): accepted, or
  // the reason it was not, as in refinement.rejection.
  ScanRefinement refinement;
};

class ParticleFilter {
 public:
  /// Throws std::invalid_argument (see validate()).
  explicit ParticleFilter(const ParticleFilterParams& params);

  const ParticleFilterParams& params() const { return params_; }

  /// Replaces the parameters while running (dynamic_reconfigure): the
  /// particles, the estimate and the recovery averages are kept; the motion
  /// model and, when a sensor parameter changed, the likelihood field are
  /// built anew from `params`, and a larger max_particles reserves (and
  /// prefaults) the storage as the constructor does. The seed is not
  /// changed: the random stream goes on. Throws std::invalid_argument (see
  /// validate()) and then leaves everything as it was.
  void setParams(const ParticleFilterParams& params);

  /// Installs a map (rebuilding the likelihood field). If particles exist and
  /// the current estimate lies in free space of the new map they are kept;
  /// otherwise the filter becomes uninitialised. Returns whether they were kept.
  /// Throws std::invalid_argument for an empty map.
  bool setMap(const OccupancyGrid& grid);
  bool hasMap() const { return static_cast<bool>(model_); }
  const OccupancyGrid* map() const { return model_ ? &model_->field().grid() : nullptr; }

  /// Particles drawn around `mean` from a Gaussian with covariance `cov`
  /// (x, y, yaw). Throws std::invalid_argument for a non-finite pose or a
  /// covariance that is not symmetric positive semi-definite.
  void initializeGaussian(const Pose2& mean, const Eigen::Matrix3d& cov);
  /// Particles spread uniformly over the map's free cells (global localization).
  /// Throws std::logic_error without a map or when the map has no free cell.
  void initializeUniform();
  bool isInitialized() const { return !particles_.empty(); }

  /// Feeds the odometry pose at the scan's time and the scan. Runs a filter
  /// update when the robot moved enough, when the scan stopped fitting the
  /// pose the odometry predicts (update_fit_drop), on the first scan after
  /// an initialisation, or after requestNoMotionUpdate().
  UpdateReport update(const Pose2& odom, const LaserScan& scan);

  /// The next update() runs even without motion.
  void requestNoMotionUpdate() { force_update_ = true; }

  const ParticleSet& particles() const { return particles_; }
  /// The estimate: its pose and covariance are the refined ones when the
  /// last update's scan fit was accepted; clusters[0].mean stays the cloud's.
  const PoseEstimate& estimate() const { return estimate_; }
  /// How far to trust the estimate, as of the last update.
  const Confidence& confidence() const { return confidence_; }

  /// map -> odom: the estimate composed with the inverse of the odometry pose
  /// it was computed at. Empty until the first update after an initialisation.
  std::optional<Pose2> mapToOdom() const;

 private:
  void weigh(const PreparedScan& scan, UpdateReport* report);
  void resample(UpdateReport* report);
  void adaptFaultFraction();
  // The scan, prepared, when it fits the pose the odometry predicts
  // `since_update` after the last update's estimate clearly worse than that
  // update's scan fitted its estimate (update_fit_drop); nothing otherwise.
  std::optional<PreparedScan> fitDropped(const LaserScan& scan, const Pose2& since_update) const;
  void refineEstimate(const LaserScan& scan, UpdateReport* report);
  void refineBetweenUpdates(const Pose2& odom, const LaserScan& scan, UpdateReport* report);
  bool refinedIsCurrent() const;
  Pose2 randomFreePose();
  void restartAfterInitialization();
  void reserveStorage(std::size_t max_particles);

  ParticleFilterParams params_;
  Random random_;
  OdometryMotionModel motion_model_;
  std::unique_ptr<SensorModel> model_;
  ParticleSet particles_;
  ParticleSet spare_;  // the resampler's output, swapped with particles_
  PoseEstimate estimate_;
  Confidence confidence_;
  std::optional<Pose2> odom_at_update_;
  // map -> odom of the latest accepted scan fit, which may be newer than the
  // last update, and odom_at_update_ at that update. An update clears it
  // before fitting; a rejected fit between updates leaves the last one.
  struct RefinedMapToOdom {
    Pose2 map_to_odom;
    Pose2 odom_at_update;
    Pose2 odom_at_fit;  // the odometry at the scan that was fitted
  };
  std::optional<RefinedMapToOdom> refined_;
  bool force_update_ = false;
  // The share of the last update's beams that ended within
  // update_fit_distance of an obstacle at its estimate (see update_fit_drop).
  double fit_at_update_ = 0.0;
  bool restart_ = false;  // the next update follows an initialisation
  bool has_estimate_ = false;
  double w_slow_ = 0.0;
  double w_fast_ = 0.0;
  int low_fit_updates_ = 0;  // consecutive updates with w_fast below the trigger
  LocalizationState fit_state_ = LocalizationState::kLost;  // the verdict before holdAfterJump
  double fault_fraction_ = 0.0;  // of the next motion update (adaptFaultFraction)
  std::vector<uint8_t> faulty_;  // which particles took an odometry fault in this update
  int settle_left_ = 0;          // updates until a jumped estimate may be localized (holdAfterJump)
  bool expand_ = false;          // this scan's fit collapsed: spread the survivors
  WeightingScratch weighting_;
  std::vector<double> log_likelihood_;
};

}  // namespace pf
