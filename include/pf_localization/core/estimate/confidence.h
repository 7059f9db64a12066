// How far to trust the estimate: localized, uncertain or lost, with the
// evidence behind the verdict.
//
// A filter never says "I do not know" by itself: the weighted mean of any
// cloud is a pose, and the heaviest cluster's covariance can be small while a
// rival cluster elsewhere is almost as heavy. So the verdict looks at three
// independent signs:
//  - the fit: the fraction of the scan's beams that end within hit_distance of
//    an obstacle when placed from the estimate (a robot that is where the
//    filter says sees the walls the map has);
//  - the spread of the heaviest cluster;
//  - rivals: other clusters holding a sizeable share of the weight (a
//    symmetric room gives two mirror-image hypotheses that no scan separates).
// Lost: the fit is below lost_hit_fraction. Uncertain: the fit is below
// localized_hit_fraction, the cluster is wide, or a rival holds at least
// rival_weight_ratio of the heaviest cluster's weight. Localized otherwise.
//
// A fourth sign is history: an estimate that has just jumped (another
// cluster won, recovery found a new place) has explained one scan, and in a
// building full of look-alike rooms one scan proves little. So after a jump
// the state is at best uncertain until settle_updates more updates agree.
#pragma once

#include <Eigen/Core>
#include <string>

#include "pf_localization/core/estimate/cluster_estimate.h"

namespace pf {

enum class LocalizationState { kLocalized, kUncertain, kLost };

const char* toString(LocalizationState state);

struct ConfidenceParams {
  double hit_distance = 0.4;             // m: a beam "hits" when it ends this close to an obstacle
  double lost_hit_fraction = 0.5;        // below: lost
  double localized_hit_fraction = 0.75;  // at or above, with the rest: localized
  double localized_std_xy = 0.3;         // m: largest std dev of x or y of the heaviest cluster
  double localized_std_yaw = 0.2;        // rad: largest std dev of its yaw
  double rival_weight_ratio = 0.2;       // a cluster this heavy relative to the first is a rival
  double jump_distance = 0.5;  // m: the estimate moved this far beyond the odometry: a jump
  double jump_yaw = 0.5;       // rad: or turned this far beyond it
  int settle_updates = 10;     // updates after a jump before the state may be localized again
};

struct Confidence {
  LocalizationState state = LocalizationState::kLost;
  std::string reason;         // why, in a few words
  double hit_fraction = 0.0;  // of the beams, at the estimate
  double std_x = 0.0;         // m, heaviest cluster
  double std_y = 0.0;         // m
  double std_yaw = 0.0;       // rad
  int rivals = 0;             // clusters at least rival_weight_ratio as heavy as the first
  // The covariance to publish: the heaviest cluster's, or the whole cloud's
  // when rivals exist, so that an ambiguous estimate never looks precise
  // (ConfidenceTracker also widens it over look-alike places).
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
};

/// Throws std::invalid_argument naming the first parameter out of range.
void validate(const ConfidenceParams& params);

/// The verdict for one update: `estimate` of the weighted cloud `particles`,
/// and the fraction of the scan's beams that hit an obstacle from it. The
/// whole cloud's covariance, when there are rivals, on up to `threads`.
Confidence assessConfidence(const ParticleSet& particles, const PoseEstimate& estimate,
                            double hit_fraction, const ConfidenceParams& params, int threads = 1);

/// The history check: `predicted` is the previous estimate moved by the
/// odometry since, `estimate` the new one. A jump between them starts
/// `*settle_left` at settle_updates; while it is above zero a localized
/// verdict becomes uncertain. Counts down by one per call without a jump.
void holdAfterJump(const Pose2& predicted, const Pose2& estimate, const ConfidenceParams& params,
                   int* settle_left, Confidence* confidence);

}  // namespace pf
