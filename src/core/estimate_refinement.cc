#include "pf_localization/core/estimate_refinement.h"

#include <Eigen/Core>
#include <cmath>

namespace pf {

ScanRefinement EstimateRefinement::atUpdate(const SensorModel& model, const LaserScan& scan,
                                            const Pose2& odom, LocalizationState state,
                                            const ParticleFilterParams& params,
                                            PoseEstimate* estimate) {
  refined_.reset();
  ScanRefinement r;
  r.pose = estimate->pose;
  if (!params.refine_estimate) {
    r.rejection = ScanRejection::kRefinementOff;
    return r;
  }
  // A lost filter's estimate is nowhere near the robot: a fit from there
  // would only polish a wrong pose.
  if (state == LocalizationState::kLost) {
    r.rejection = ScanRejection::kFilterLost;
    return r;
  }
  r = ScanRefiner(model.field(), params.refiner)
          .refine(model.prepare(scan, params.refiner.max_beams), estimate->pose,
                  estimate->covariance);
  if (!r.accepted) return r;
  refined_ = Fit{compose(r.pose, inverse(odom)), odom, odom};
  // The cloud was the fit's prior: what is known of the pose is both.
  estimate->pose = r.pose;
  estimate->covariance = fusedCovariance(r.covariance, estimate->covariance);
  return r;
}

ScanRefinement EstimateRefinement::betweenUpdates(const SensorModel& model, const LaserScan& scan,
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
          .refine(model.prepare(scan, params.refiner.max_beams_between_updates), predicted, prior);
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
