#include "pf_localization/core/estimate/estimate_refinement.h"

#include <Eigen/Core>
#include <cmath>

namespace pf {

namespace {

// chi-square with 1 degree of freedom at 99.9 %: how far (squared, in the
// cloud's standard deviations) the odometry's prediction may lie from the
// cloud's mean along an open direction and still be believed.
constexpr double kPredictionGate = 10.83;

// `from` moved to `to` along the directions of projector `open`, when that
// move lies within the cloud's spread.
Pose2 alongOpen(const Eigen::Matrix3d& open, const Pose2& from, const Pose2& to,
                const Eigen::Matrix3d& cloud) {
  if (open.isZero()) return from;
  const Eigen::Vector3d d = open * poseDifference(to, from);
  if (squaredMahalanobis(d, cloud) > kPredictionGate) return from;
  return {from.x + d(0), from.y + d(1), normalizeAngle(from.yaw + d(2))};
}

// chi-square with 3 degrees of freedom at 99.9 %: how far (squared, in the
// cloud's standard deviations) the odometry's prediction may lie from the
// cloud's mean and still be a start for a fit.
constexpr double kPredictionStartGate = 16.27;

// Whether a fit from `b` would end where the one that ended at `a` did. A
// basin of the robust cost reaches about as far as an end point still pulls
// (outlier_distance, 0.3 m); skipping the second fit from within a tenth of a
// metre and 0.05 rad (0.25 m at 5 m) saves it on most updates and moves no
// bag's ATE by more than a millimetre (docs/design.md).
bool sameBasin(const Pose2& a, const Pose2& b) {
  return std::hypot(a.x - b.x, a.y - b.y) < 0.1 && std::fabs(angleDiff(a.yaw, b.yaw)) < 0.05;
}

// Each scan's share of the fit's beam budget `max_beams` (<= 0: all): the
// fit's cost grows with its beams, and every sensor's end points lie on the
// same map, so several sensors share one budget.
int shareOf(int max_beams, const ScanGroup& scans) {
  if (max_beams <= 0 || scans.size() <= 1) return max_beams;
  const int n = static_cast<int>(scans.size());
  return (max_beams + n - 1) / n;
}

}  // namespace

ScanRefinement EstimateRefinement::atUpdate(const SensorModel& model, const ScanGroup& scans,
                                            const Pose2& odom,
                                            const std::optional<Pose2>& predicted,
                                            LocalizationState state,
                                            const ParticleFilterParams& params,
                                            PoseEstimate* estimate) {
  refined_.reset();
  const Eigen::Matrix3d open_before = open_;
  const bool carried_before = carried_;
  open_.setZero();
  carried_ = false;
  ScanRefinement r;
  r.pose = estimate->pose;
  if (!params.refine_estimate) {
    r.rejection = ScanRejection::kRefinementOff;
    return r;
  }
  // A lost filter's estimate is nowhere near the robot: a fit from there
  // would only polish a wrong pose. But when the last published pose was
  // carried by the odometry along a corridor, the cloud may be lost only
  // because it spread along it: the odometry's prediction is then the start.
  const bool lost = state == LocalizationState::kLost;
  if (lost && !(predicted && carried_before)) {
    r.rejection = ScanRejection::kFilterLost;
    return r;
  }
  // Where the last fit left the pose open, the odometry says where it is.
  Pose2 start = estimate->pose;
  if (lost) {
    start = *predicted;
  } else if (predicted) {
    start = alongOpen(open_before, estimate->pose, *predicted, estimate->covariance);
  }
  const ScanRefiner refiner(model.field(), params.refiner);
  const PreparedScan prepared =
      joinedEndPoints(prepareScans(model, scans, shareOf(params.refiner.max_beams, scans)));
  r = refiner.refine(prepared, start, estimate->covariance);
  // The cloud's mean can sit on a wrong door pattern while the odometry's
  // prediction is where the robot is: fitted from both, the scan decides.
  if (predicted && !lost && !(r.accepted && sameBasin(r.pose, *predicted)) &&
      squaredMahalanobis(poseDifference(*predicted, estimate->pose), estimate->covariance) <=
          kPredictionStartGate) {
    const ScanRefinement from_prediction =
        refiner.refine(prepared, *predicted, estimate->covariance);
    if (from_prediction.accepted && (!r.accepted || from_prediction.scan_cost < r.scan_cost)) {
      r = from_prediction;
    }
  }
  if (!r.accepted) return r;
  open_ = fitInformation(r.covariance).open;
  if (predicted) r.pose = alongOpen(open_, r.pose, *predicted, estimate->covariance);
  // Whether a direction came from the odometry: at the start or at the end.
  carried_ = lost || !open_before.isZero() || !open_.isZero();
  refined_ = Fit{compose(r.pose, inverse(odom)), odom, odom};
  // The cloud was the fit's prior: what is known of the pose is both.
  estimate->pose = r.pose;
  estimate->covariance = fusedCovariance(r.covariance, estimate->covariance);
  return r;
}

ScanRefinement EstimateRefinement::betweenUpdates(const SensorModel& model, const ScanGroup& scans,
                                                  const Pose2& odom, const Pose2& odom_at_update,
                                                  const PoseEstimate& estimate,
                                                  LocalizationState state,
                                                  const ParticleFilterParams& params) {
  ScanRefinement r;
  if (!params.refine_estimate || state == LocalizationState::kLost) return r;
  if (isCurrent(odom_at_update)) {
    const Pose2 moved = between(refined_->odom_at_fit, odom);
    if (std::hypot(moved.x, moved.y) < 1e-3 && std::fabs(moved.yaw) < 1e-3) {
      r.pose = compose(refined_->map_to_odom, odom);
      r.rejection = ScanRejection::kNotMovedSinceFit;
      return r;
    }
  }
  const Pose2 predicted = compose(compose(estimate.pose, inverse(odom_at_update)), odom);
  const std::optional<Eigen::Matrix3d> prior =
      estimate.clusters.empty() ? std::nullopt
                                : std::optional<Eigen::Matrix3d>(estimate.clusters[0].covariance);
  r = ScanRefiner(model.field(), params.refiner)
          .refine(joinedEndPoints(prepareScans(
                      model, scans, shareOf(params.refiner.max_beams_between_updates, scans))),
                  predicted, prior);
  if (r.accepted) refined_ = Fit{compose(r.pose, inverse(odom)), odom_at_update, odom};
  return r;
}

Pose2 EstimateRefinement::mapToOdom(const Pose2& estimate, const Pose2& odom_at_update) const {
  if (isCurrent(odom_at_update)) return refined_->map_to_odom;
  return compose(estimate, inverse(odom_at_update));
}

bool EstimateRefinement::isCurrent(const Pose2& at) const {
  return refined_ && refined_->odom_at_update.x == at.x && refined_->odom_at_update.y == at.y &&
         refined_->odom_at_update.yaw == at.yaw;
}

}  // namespace pf
