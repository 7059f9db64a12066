// The estimate's stages of an update: the pose of the weighted cloud and the
// verdict on it (judge), then the scan fit that refines it (refine).
//
// judge() takes the clusters' estimate of the weighted cloud (before
// resampling: cluster_estimate.h), the verdict on it (ConfidenceTracker:
// the scan's fit, the jump check, the places the cloud holds) and the map's
// look-alike places the scan fits as well (LookAlikes), which keep the
// verdict from "localized" and widen the covariance while the place is not
// told apart from them. refine() fits the scan from the estimate
// (EstimateRefinement) and fuses the fit into the published covariance.
// Between updates, refitBetweenUpdates() keeps map -> odom on the scans.
// docs/how-it-works/estimate.md has each part and its evidence.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <vector>

#include "pf_localization/core/estimate/cluster_estimate.h"
#include "pf_localization/core/estimate/confidence.h"
#include "pf_localization/core/estimate/confidence_tracker.h"
#include "pf_localization/core/estimate/estimate_refinement.h"
#include "pf_localization/core/estimate/hypotheses.h"
#include "pf_localization/core/estimate/scan_refiner.h"
#include "pf_localization/core/filter/particle_filter_params.h"
#include "pf_localization/core/filter/particle_set.h"
#include "pf_localization/core/map/distance_field.h"
#include "pf_localization/core/map/map_evidence.h"
#include "pf_localization/core/recovery/look_alikes.h"
#include "pf_localization/core/sensor/scan_group.h"
#include "pf_localization/core/sensor/sensor_model.h"
#include "pf_localization/core/util/pose2.h"

namespace pf {

/// What judge() found, for the update's report.
struct JudgeReport {
  // Look-alike places (look_alikes.h) the scan fits as well as the
  // estimate, and those it fits clearly better.
  std::size_t look_alikes = 0;
  std::size_t look_alikes_better = 0;
};

/// What judge() found, for the stages after it.
struct Judgement {
  JudgeReport report;
  std::size_t places = 0;     // the places the cloud holds (hypothesesOf)
  std::vector<Pose2> better;  // motions to the look-alikes the scan fits clearly better
};

class EstimateUpdate {
 public:
  /// A new map, with its look-alike places (findMapSymmetries); the last
  /// fit and the places listed are forgotten.
  void setMap(std::vector<MapSymmetry> symmetries);
  /// The map's look-alike places, as setMap took them.
  const std::vector<MapSymmetry>& symmetries() const { return look_alikes_.symmetries(); }
  /// No estimate (a map the robot is not on).
  void forget() { estimate_ = PoseEstimate(); }
  /// After an initialisation: `estimate` is the new cloud's; "uncertain",
  /// and (`place_given`) told apart from its look-alikes when the cloud was
  /// drawn around a given pose.
  void restart(const PoseEstimate& estimate, bool place_given);

  /// The estimate of the weighted `particles` and the verdict on it.
  /// `fitting`: the beams weighed; `steady`: every beam that did not see
  /// something move in, those that saw a change of the map too (what the
  /// map lacks at the tracked place may be what the place the robot was
  /// carried to has); `predicted`: the last estimate moved by the odometry
  /// since (none on a first update); `evidence`: the map's rays.
  Judgement judge(const SensorModel& model, const ParticleSet& particles,
                  const std::vector<PreparedScan>& fitting, const std::vector<PreparedScan>& steady,
                  const std::optional<Pose2>& predicted, const MapEvidence* evidence,
                  const ParticleFilterParams& params, int threads);
  /// The scan fit of the estimate at an update at odometry `odom`
  /// (EstimateRefinement::atUpdate); an accepted one moves the estimate and
  /// adds to the published covariance.
  ScanRefinement refine(const SensorModel& model, const ScanGroup& scans, const Pose2& odom,
                        const std::optional<Pose2>& predicted, const ParticleFilterParams& params);
  /// Whether the scan fit `fit` (refine()'s) pinned the position along the
  /// estimate's heading to within `margin` (m): the fit's information along
  /// it, with the other directions given. Without an accepted fit nothing
  /// says what the scan pinned: true, so that the odometry faults keep hedging.
  bool fitPinsAlongTrack(const ScanRefinement& fit, double margin) const;
  /// The scan fit between updates (EstimateRefinement::betweenUpdates).
  ScanRefinement refitBetweenUpdates(const SensorModel& model, const ScanGroup& scans,
                                     const Pose2& odom, const Pose2& odom_at_update,
                                     const ParticleFilterParams& params);
  /// "localized" becomes "uncertain" after too many views of low fit
  /// (ConfidenceTracker::demoteAfterLowFit).
  void demoteAfterLowFit(double low_fit_views, int patience) {
    confidence_.demoteAfterLowFit(low_fit_views, patience);
  }

  const PoseEstimate& estimate() const { return estimate_; }
  const Pose2& pose() const { return estimate_.pose; }
  const Confidence& confidence() const { return confidence_.confidence(); }
  /// This update's verdict from its scan alone (ConfidenceTracker::fitState).
  LocalizationState fitState() const { return confidence_.fitState(); }
  /// Whether the place is told apart from its look-alikes.
  bool placeKnown() const { return confidence_.placeKnown(); }
  /// Whether the estimate is known well enough to judge beams from: one
  /// place, told apart from its look-alikes, not jumped unconfirmed, not
  /// lost. A look-alike that fitted better once is not enough: the
  /// look-alike judge sees every beam, and unmasked, a change of the map
  /// (cabinets along a corridor's wall) pulls the tracked pose onto it.
  bool judgesBeams() const;
  /// The places the cloud holds, then the look-alikes the last scan fitted as well.
  Hypotheses hypotheses(double rival_weight_ratio) const;
  /// map -> odom for the update at `odom_at_update` (EstimateRefinement::mapToOdom).
  Pose2 mapToOdom(const Pose2& odom_at_update) const {
    return refinement_.mapToOdom(estimate_.pose, odom_at_update);
  }

 private:
  // The places pf_hypotheses lists after the cloud's: the look-alikes of
  // the estimate (`view`) and, when the cloud holds several `places`, of
  // each listed one, that the scans fit as well as the estimate.
  void listLookAlikes(const SensorModel& model, const std::vector<PreparedScan>& scans,
                      const LookAlikeView& view, std::size_t places, double rival_weight_ratio);

  PoseEstimate estimate_;
  ConfidenceTracker confidence_;
  LookAlikes look_alikes_;  // the map's symmetries, and what each scan says of them
  // The last scan's look-alikes of the places the cloud holds, fitting as
  // well as the estimate.
  std::vector<LookAlikePlace> look_alike_places_;
  std::size_t places_ = 0;  // the places the last update's cloud holds (hypothesesOf)
  EstimateRefinement refinement_;
};

}  // namespace pf
