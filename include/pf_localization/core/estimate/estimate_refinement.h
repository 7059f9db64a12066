// The scan fit of the filter's estimate (scan_refiner.h: Cartographer's
// scan-to-map matching, Hess et al., ICRA 2016), at each update and on the
// scans between updates, and the map -> odom it gives.
//
// At an update the cloud is the prior: the fit moves the estimate only as far
// as the scan's evidence outweighs the cloud's, and what is published covers
// both covariances. Between updates each scan is fitted from the last
// update's estimate moved by the odometry since (never from the previous fit,
// so fits cannot walk away from the cloud): the published map -> odom then
// follows the map instead of the odometry's drift. A lost filter is not
// fitted, and a robot standing still keeps its last fit (another would only
// add this scan's noise, which tf users see as jitter). See docs/design.md,
// "The estimate is fitted to the scan".
#pragma once

#include <optional>

#include "pf_localization/core/estimate/cluster_estimate.h"
#include "pf_localization/core/estimate/confidence.h"
#include "pf_localization/core/estimate/scan_refiner.h"
#include "pf_localization/core/filter/particle_filter_params.h"
#include "pf_localization/core/sensor/scan_group.h"
#include "pf_localization/core/sensor/sensor_model.h"
#include "pf_localization/core/util/pose2.h"

namespace pf {

class EstimateRefinement {
 public:
  /// Forgets the last fit (a new map, an initialisation).
  void reset() {
    refined_.reset();
    open_.setZero();
    carried_ = false;
  }

  /// At an update whose odometry is `odom`: fits `scan` from `*estimate`
  /// with its covariance as the prior and, when accepted, moves the estimate
  /// there and fuses its covariance with the fit's. Not when refine_estimate
  /// is off, nor when `state` is lost, unless the last published pose was
  /// carried by the odometry (below): the fit then starts from `predicted`.
  /// Forgets the previous fit.
  ///
  /// Along the directions a fit leaves open (a featureless corridor's
  /// length) the estimate is `predicted`, the last published pose carried by
  /// the odometry, instead of the cloud's mean: the cloud is metres long
  /// there and its mean wanders, while the odometry drifts by centimetres.
  /// Not when `predicted` lies beyond the cloud's spread along them (an
  /// odometry fault, a kidnapping): the cloud knows better then.
  ///
  /// The cloud's mean can also sit on the wrong one of two door patterns a
  /// metre apart, where the motion noise spread the cloud over both: when
  /// `predicted` lies elsewhere within the cloud's spread (chi-square, 3 dof,
  /// 99.9 %), the scan is fitted from there too, and the fit whose end
  /// points lie better on the map (ScanRefinement::scan_cost) is taken.
  ScanRefinement atUpdate(const SensorModel& model, const ScanGroup& scans, const Pose2& odom,
                          const std::optional<Pose2>& predicted, LocalizationState state,
                          const ParticleFilterParams& params, PoseEstimate* estimate);

  /// On a scan between updates at odometry `odom`, the last update's
  /// `estimate` at `odom_at_update`: fits the scan from where the odometry
  /// puts that estimate now, the heaviest cluster's covariance as the prior.
  /// An accepted fit becomes the map -> odom; a rejected one leaves the last.
  ScanRefinement betweenUpdates(const SensorModel& model, const ScanGroup& scans, const Pose2& odom,
                                const Pose2& odom_at_update, const PoseEstimate& estimate,
                                LocalizationState state, const ParticleFilterParams& params);

  /// map -> odom: of the latest accepted fit since the update at
  /// `odom_at_update`, or `estimate` composed with its inverse.
  Pose2 mapToOdom(const Pose2& estimate, const Pose2& odom_at_update) const;

 private:
  // Whether the last fit belongs to the update at `odom_at_update`: after an
  // odometry fault (a new reference without an update) it is stale.
  bool isCurrent(const Pose2& odom_at_update) const;

  struct Fit {
    Pose2 map_to_odom;
    Pose2 odom_at_update;  // of the update the fit started from
    Pose2 odom_at_fit;     // the odometry at the scan that was fitted
  };
  std::optional<Fit> refined_;
  // Projector onto the directions (x, y, yaw) the last accepted update fit
  // left open; zero when it pinned all three.
  Eigen::Matrix3d open_ = Eigen::Matrix3d::Zero();
  // Whether the last accepted update fit took a direction from the odometry.
  bool carried_ = false;
};

}  // namespace pf
