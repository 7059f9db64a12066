// The particle filter's options: what ParticleFilter and the parts it
// composes are built from, and the one check of them (validate).
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>

#include "pf_localization/core/beam_model.h"
#include "pf_localization/core/confidence.h"
#include "pf_localization/core/likelihood_field_model.h"
#include "pf_localization/core/occupancy_grid.h"
#include "pf_localization/core/odometry_motion_model.h"
#include "pf_localization/core/parameter_table.h"
#include "pf_localization/core/pose_estimator.h"
#include "pf_localization/core/resampler.h"
#include "pf_localization/core/scan_refiner.h"
#include "pf_localization/core/sensor_model.h"

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

/// The parameters of RecoveryParams (parameter_table.h): amcl's two averages.
/// The rest of RecoveryParams are the filter's own constants.
const ParameterTable<RecoveryParams>& recoveryParameters();
/// Throws std::invalid_argument naming the first of those constants out of range.
void validateInternals(const RecoveryParams& params);

/// Every parameter of ParticleFilterParams, its parts' included, in the order
/// config/pf.yaml lists them.
const ParameterTable<ParticleFilterParams>& particleFilterParameters();

/// Throws std::invalid_argument naming the first parameter out of range and
/// its valid range ("invalid parameter NAME = VALUE: must be RANGE").
void validate(const ParticleFilterParams& params);

}  // namespace pf
