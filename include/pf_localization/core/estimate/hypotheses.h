// The places the cloud holds with real weight: what pf_node publishes on
// pf_hypotheses, so that a navigation stack can wait or explore while the
// robot could be in one of several look-alike places instead of driving on
// the heaviest guess.
//
// A hypothesis is a cluster of the estimate (cluster_estimate.h) that is
//  - the heaviest, or
//  - a rival by the rule assessConfidence counts rivals with (isRival: at
//    least ConfidenceParams::rival_weight_ratio as heavy as the heaviest),
//    so that "uncertain: N rival hypotheses" always comes with those N
//    listed beside the heaviest, or
//  - a holder of at least kMinHypothesisShare of the cloud's weight.
// The last is wider than the rival count's rule (which steers tempering and
// the published covariance): a true place can hold a tenth of the weight
// while a twin holds the rest. The published verdict follows the list
// (ConfidenceTracker::holdWhileAmbiguous): never "localized" while a second
// place is listed. See docs/design.md, "Look-alike places".
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "pf_localization/core/estimate/cluster_estimate.h"
#include "pf_localization/core/recovery/look_alikes.h"
#include "pf_localization/core/util/pose2.h"

namespace pf {

// A place with this share of the weight is listed, rival or not. One in
// twenty: a robot that drove on the heaviest guess would be wrong that
// often, too often to leave it out; the true room on global.bag held 9 %
// and more. Well above what does not stand for a place: recovery's random
// guesses weigh 0.001 of the cloud together, and the clusters global
// localization leaves for a few updates 1-2 % each.
constexpr double kMinHypothesisShare = 0.05;

// At most this many hypotheses are listed, the heaviest. A global
// localization among ten identical aisles, each with its rack bays and its
// half-turn twin, holds up to about 60 places in its first second; listing
// them all keeps the true one on the list (docs/design.md, "Look-alike
// places"), and 64 keep the message about 23 kB. The count says how many
// there were.
constexpr std::size_t kMaxListedHypotheses = 64;

struct Hypothesis {
  Pose2 pose;           // the cluster's weighted mean
  double weight = 0.0;  // its share of the cloud's weight, (0, 1]; 0 for a look-alike place
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  // x, y, yaw: the cluster's
  std::size_t particles = 0;                             // in the cluster
};

struct Hypotheses {
  std::size_t count = 0;           // clusters that are hypotheses, listed or not
  std::vector<Hypothesis> listed;  // heaviest first, at most kMaxListedHypotheses
};

/// Whether `cluster` is a rival of `heaviest` (assessConfidence's count of
/// rival hypotheses; every rival is a hypothesis).
inline bool isRival(const Cluster& cluster, const Cluster& heaviest, double rival_weight_ratio) {
  return cluster.weight >= rival_weight_ratio * heaviest.weight;
}

/// The hypotheses of `estimate` (its clusters, heaviest first), each
/// weight a share of all clusters' weight together. No clusters (or no
/// weight) give none.
Hypotheses hypothesesOf(const PoseEstimate& estimate, double rival_weight_ratio,
                        std::size_t max_listed = kMaxListedHypotheses);

/// Lists after the cloud's hypotheses the look-alike `places` the scan fits
/// as well as the estimate (look_alikes.h) that the cloud does not hold (no
/// hypothesis within LookAlikes::kMinShift), best fit first: weight 0, no
/// particles, the heaviest hypothesis's covariance (a shift or half turn
/// leaves an x-y covariance as it is). A place within kMinShift of a better
/// fitting one is that place. Counted, and listed up to kMaxListedHypotheses.
void addLookAlikes(std::vector<LookAlikePlace> places, Hypotheses* hypotheses);

/// The covariance, about `estimate`, of where the robot is when the scans
/// (log-likelihood `fit` at the estimate) cannot tell the estimate's place
/// from the look-alike `places`: a mixture of the estimate's place and each
/// look-alike, each with `covariance`, weighted by its likelihood relative
/// to the estimate's (the posterior of equally likely places, as with
/// LookAlikes::kAsGoodMargin). A place within LookAlikes::kMinShift of the
/// estimate or of a better fitting place is that place. No places: `covariance`.
Eigen::Matrix3d lookAlikeCovariance(const Pose2& estimate, const Eigen::Matrix3d& covariance,
                                    double fit, std::vector<LookAlikePlace> places);

}  // namespace pf
