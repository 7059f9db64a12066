// The particle filter's options: what ParticleFilter and the parts it
// composes are built from, and the one check of them (validate).
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>

#include "pf_localization/core/estimate/cluster_estimate.h"
#include "pf_localization/core/estimate/confidence.h"
#include "pf_localization/core/estimate/scan_refiner.h"
#include "pf_localization/core/filter/resampling.h"
#include "pf_localization/core/map/occupancy_grid.h"
#include "pf_localization/core/motion/odometry_motion_model.h"
#include "pf_localization/core/sensor/beam_model.h"
#include "pf_localization/core/sensor/likelihood_field_model.h"
#include "pf_localization/core/sensor/sensor_model.h"
#include "pf_localization/core/util/parameter_table.h"

namespace pf {

// The filter's own constants: values of its algorithms, not parameters (a
// robot or a building does not change them). Each is an option's default
// below, so that a test can vary it; where each value comes from is said
// here, the evidence behind it is in docs/design.md.

// Augmented MCL injects only below this fraction of the usual fit: normal
// tracking dips by a few tenths (a person in front of the laser, a doorway).
// amcl's 1 injects on any dip. docs/design.md, "Recovery waits while localized".
constexpr double kRecoveryTriggerRatio = 0.7;
// The prior probability that the robot is elsewhere than the tracked cloud
// says: the weight of all injected particles together (a mixture proposal,
// Thrun, Fox, Burgard & Dellaert, "Robust Monte Carlo localization for
// mobile robots", AIJ 128, 2001). A rival must then fit better by about
// log(injected / prior) nats: a kidnapping does in a scan or two, aliasing not.
constexpr double kRecoveryKidnapPrior = 1e-3;
// Low-fit updates in a row before injecting, unless lost; and while
// localized, longer than the poorest stretch of map on fr079 (9 updates).
// docs/design.md, "Recovery waits while localized".
constexpr int kRecoveryPatience = 5;
constexpr int kRecoveryPatienceLocalized = 10;
// Share of max_particles drawn at once when a compact cloud turns lost (a
// kidnapping): as a global localization would search. docs/design.md.
constexpr double kRecoveryLostShare = 0.5;
// Expansion resetting (Ueda et al., IROS 2004): a single scan fitting below
// 0.3 of the long-term average spreads the survivors by 0.3 m and 0.3 rad,
// the size of a slip or a push that tracking alone does not follow.
constexpr double kExpansionRatio = 0.3;
constexpr double kExpansionStdXy = 0.3;   // m
constexpr double kExpansionStdYaw = 0.3;  // rad

// Augmented MCL: w_slow and w_fast are long- and short-term averages of how
// well the cloud explains the scans (the posterior-weighted per-beam
// likelihood). When w_fast falls below trigger_ratio * w_slow, a share
// 1 - w_fast / (trigger_ratio * w_slow) of max_particles is drawn from free
// space at the next resampling (Thrun, Burgard & Fox, table 8.3). Unlike
// amcl, the averages are not reset after an injection: the memory of what a
// good fit looks like keeps the search going until the robot is found. Each
// injected particle weighs kidnap_prior / injected, each kept one
// (1 - kidnap_prior) / kept. Unless lost, injection waits `patience` low-fit
// updates (`patience_localized` while localized); a compact cloud that turns
// lost draws lost_share of max_particles at once (not while the cloud holds
// more than 1 - lost_share of the budget: it is searching).
struct RecoveryParams {
  double alpha_slow = 0.01;  // long-term average rate, per update (0 disables recovery)
  double alpha_fast = 0.2;   // short-term average rate, per update
  double trigger_ratio = kRecoveryTriggerRatio;         // (0, 1]
  double kidnap_prior = kRecoveryKidnapPrior;           // (0, 1]
  int patience = kRecoveryPatience;                     // >= 0
  int patience_localized = kRecoveryPatienceLocalized;  // >= patience
  double lost_share = kRecoveryLostShare;               // [0, 1), 0: off
  double expansion_ratio = kExpansionRatio;             // [0, 1), 0: off
  double expansion_std_xy = kExpansionStdXy;            // m
  double expansion_std_yaw = kExpansionStdYaw;          // rad
};

// Between updates a scan whose share of beams within this distance of an
// obstacle, at the pose the odometry predicts, drops this much below the
// last update's means the odometry went wrong (reversing counted forwards):
// update now. Tight on purpose: a 0.3 m error halves the share at 0.1 m but
// barely moves it at 0.4 m. docs/design.md, "Updates wait for motion".
constexpr double kUpdateFitDrop = 0.2;
constexpr double kUpdateFitDistance = 0.1;  // m
// Wheels do not carry a robot 5 m between two scans: a longer odometry step
// is a reset or a glitch, skipped rather than applied.
constexpr double kOdomJumpLimit = 5.0;  // m
// Resample when the effective sample size falls below half the particles
// (amcl's selective_resampling test; Doucet, Godsill & Andrieu 2000).
constexpr double kResampleEssFraction = 0.5;
// A scan that would leave fewer than 2 % of the effective particles it found
// (10 % while not localized) is tempered so that it does not: strong
// evidence narrows the cloud over several scans instead of collapsing it
// onto one lucky particle. docs/design.md, "Tempering follows the last verdict".
constexpr double kTemperingEssFraction = 0.02;
constexpr double kTemperingEssFractionUncertain = 0.1;

// amcl's laser_model_type.
enum class LaserModelType {
  kLikelihoodField,      // likelihood_field_model.h
  kLikelihoodFieldProb,  // the same, with beam skipping when sensor.beam_skip is set
  kBeam,                 // beam_model.h
};

struct ParticleFilterParams {
  KldParams kld;                                          // particle count bounds and KLD-sampling
  double update_min_d = 0.2;                              // m of travel between updates
  double update_min_a = M_PI / 6.0;                       // rad of rotation between updates
  double update_fit_drop = kUpdateFitDrop;                // [0, 1], 0: off
  double update_fit_distance = kUpdateFitDistance;        // m, > 0
  double odom_jump_limit = kOdomJumpLimit;                // m, > 0
  double resample_ess_fraction = kResampleEssFraction;    // (0, 1]
  double tempering_ess_fraction = kTemperingEssFraction;  // [0, 1], 0: off
  // The same while the filter is not localized because of rivals or a poor
  // fit; a cloud that is only wide, with its beams fitting, keeps the other.
  double tempering_ess_fraction_uncertain = kTemperingEssFractionUncertain;
  uint64_t seed = 0;
  // Threads of the filter update (0: one per processor core). The result is
  // the same bits for any count (particle_blocks.h).
  int threads = 0;
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
  // too. On by default (docs/design.md, "The estimate is fitted to the scan").
  bool refine_estimate = true;
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

/// The threads `threads` stands for: itself, or one per processor core for 0.
int resolvedThreads(int threads);

/// Throws std::invalid_argument naming the first parameter out of range and
/// its valid range ("invalid parameter NAME = VALUE: must be RANGE").
void validate(const ParticleFilterParams& params);

}  // namespace pf
